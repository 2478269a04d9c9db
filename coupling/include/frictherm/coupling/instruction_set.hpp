#pragma once
// The instruction set this code was compiled for (cmake/Arch.cmake, FRICTHERM_ARCH): the run's
// /meta/instruction_set and bench_coupled's first line. Outputs are the same bit for bit between builds
// of one set and equal to round-off between sets (docs/performance.md "Instruction sets").
namespace frictherm::coupling {

constexpr const char* instruction_set() {
#if defined(__AVX512F__)
  return "avx512";
#elif defined(__AVX2__) && defined(__FMA__)
  return "x86-64-v3";
#elif defined(__x86_64__)
  return "x86-64";
#else
  return "compiler default";
#endif
}

}  // namespace frictherm::coupling

// cmake/Arch.cmake: exit status 0 when this CPU runs x86-64-v3 code. AVX2, FMA, BMI1 and BMI2 are
// asked (the names both GCC and clang take); every CPU with them has the level's other parts
// (LZCNT, MOVBE, F16C: Intel since Haswell, AMD since Excavator).
int main() {
  __builtin_cpu_init();
  const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                  __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2");
  return v3 ? 0 : 1;
}

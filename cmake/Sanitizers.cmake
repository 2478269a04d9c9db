# Standing checks (issue 15, docs/robustness.md).
#
# -DFRICTHERM_SANITIZE=ON: AddressSanitizer + UndefinedBehaviorSanitizer on every target (GCC or
# clang); undefined behaviour aborts (-fno-sanitize-recover), so a test that triggers it fails.
# -DFRICTHERM_FUZZ=ON: the libFuzzer targets tests/fuzz/fuzz_scene and fuzz_checkpoint (clang only; other compilers get a
# warning and no target). Every target is compiled with -fsanitize=fuzzer-no-link (coverage for the
# fuzzer); combine with FRICTHERM_SANITIZE=ON (scripts/run_checks.sh does) so findings include
# memory errors and undefined behaviour, not only crashes.
option(FRICTHERM_SANITIZE "Build with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
option(FRICTHERM_FUZZ "Build the libFuzzer target for scene parsing (clang only)" OFF)

if(FRICTHERM_SANITIZE)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    message(FATAL_ERROR "FRICTHERM_SANITIZE=ON needs GCC or clang (got ${CMAKE_CXX_COMPILER_ID})")
  endif()
  set(FRICTHERM_SANITIZE_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=undefined
                               -fno-omit-frame-pointer)
  add_compile_options(${FRICTHERM_SANITIZE_FLAGS})
  add_link_options(${FRICTHERM_SANITIZE_FLAGS})
  message(STATUS "frictherm: AddressSanitizer + UndefinedBehaviorSanitizer build")
endif()

set(FRICTHERM_FUZZ_TARGET OFF)
if(FRICTHERM_FUZZ)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    add_compile_options(-fsanitize=fuzzer-no-link)
    set(FRICTHERM_FUZZ_TARGET ON)
    message(STATUS "frictherm: libFuzzer targets fuzz_scene and fuzz_checkpoint")
  else()
    message(WARNING "FRICTHERM_FUZZ=ON needs clang (-DCMAKE_CXX_COMPILER=clang++); no fuzz target built")
  endif()
endif()

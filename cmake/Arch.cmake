# The instruction set the build targets (issue 35, docs/performance.md "Instruction sets").
#
# -DFRICTHERM_ARCH=portable (default): the x86-64 baseline (SSE2). The program runs on any x86-64 CPU
#   (a cluster's compute nodes of another generation than the machine that built it), and every output
#   is the same bit for bit wherever it was built: the tests that compare two code paths bit for bit
#   (the scalar plane-strain update against Eigen's, the decomposed run against the serial one at
#   contact decisions) hold only without contraction into FMA.
# -DFRICTHERM_ARCH=auto: x86-64-v3 when the compiler takes -march=x86-64-v3 and the build machine's CPU
#   runs it, else portable.
# -DFRICTHERM_ARCH=x86-64-v3: AVX2 + FMA, without checking the build machine. Outputs equal the
#   portable build's to round-off, not bit for bit: FMA rounds a*b + c once, and Eigen's packets are
#   four doubles wide instead of two. Measured 9-15 % more particle-steps per CPU-second.
# -DFRICTHERM_ARCH=native: -march=native (AVX-512 where the CPU has it). FRICTHERM_NATIVE=ON, the
#   older switch, means native.
# The flags apply to every target (the libraries, the program, the tests, the Python module), so an
# inline function compiled into two of them gives the same bits in both.
option(FRICTHERM_NATIVE "Same as FRICTHERM_ARCH=native" OFF)
set(FRICTHERM_ARCH "portable" CACHE STRING "Instruction set: portable, auto, x86-64-v3 or native")
set_property(CACHE FRICTHERM_ARCH PROPERTY STRINGS portable auto x86-64-v3 native)

set(_frictherm_arch "${FRICTHERM_ARCH}")
if(FRICTHERM_NATIVE)
  set(_frictherm_arch native)
endif()
if(NOT _frictherm_arch MATCHES "^(auto|portable|x86-64-v3|native)$")
  message(FATAL_ERROR "FRICTHERM_ARCH is auto, portable, x86-64-v3 or native, not '${_frictherm_arch}'")
endif()
if(FRICTHERM_SANITIZE OR FRICTHERM_FUZZ OR NOT CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64|amd64")
  # The standing checks' instrumented build and other processors keep the compiler's default.
  if(_frictherm_arch STREQUAL "auto")
    set(_frictherm_arch portable)
  endif()
endif()

if(_frictherm_arch STREQUAL "auto")
  set(_frictherm_arch portable)
  include(CheckCXXCompilerFlag)
  check_cxx_compiler_flag(-march=x86-64-v3 FRICTHERM_COMPILER_HAS_X86_64_V3)
  if(FRICTHERM_COMPILER_HAS_X86_64_V3)
    # Does this machine run what -march=x86-64-v3 emits? (arch_check.cpp asks AVX2, FMA, BMI1 and BMI2)
    try_run(_frictherm_v3_runs _frictherm_v3_compiles ${CMAKE_BINARY_DIR}/arch_check
            ${CMAKE_CURRENT_LIST_DIR}/arch_check.cpp)
    if(_frictherm_v3_compiles AND _frictherm_v3_runs EQUAL 0)
      set(_frictherm_arch x86-64-v3)
    endif()
  endif()
endif()

if(_frictherm_arch STREQUAL "x86-64-v3")
  add_compile_options(-march=x86-64-v3)
elseif(_frictherm_arch STREQUAL "native")
  add_compile_options(-march=native)
endif()
set(FRICTHERM_ARCH_USED "${_frictherm_arch}")
message(STATUS "frictherm: instruction set ${FRICTHERM_ARCH_USED} (FRICTHERM_ARCH=${FRICTHERM_ARCH})")

# frictherm_add_module(<module> [LINK_PUBLIC ...] [LINK_PRIVATE ...] [EXCLUDE_DIRS sub-folder ...])
# One library per top-level module folder: sources from <module>/src/**/*.cpp (sub-folders name the
# concerns, private headers included from src/ as "scene/x.hpp"), public headers under
# <module>/include, target frictherm_<module> with the alias and export name frictherm::<module>.
function(frictherm_add_module module)
  cmake_parse_arguments(M "" "" "LINK_PUBLIC;LINK_PRIVATE;EXCLUDE_DIRS" ${ARGN})
  set(target frictherm_${module})
  file(GLOB_RECURSE sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/src/*.cpp)
  foreach(dir ${M_EXCLUDE_DIRS})  # sub-folders built as libraries of their own (thermal/src/distributed)
    list(FILTER sources EXCLUDE REGEX "^${CMAKE_CURRENT_SOURCE_DIR}/src/${dir}/")
  endforeach()
  add_library(${target} ${sources})
  add_library(frictherm::${module} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${module} OUTPUT_NAME ${target})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_include_directories(${target} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)  # private headers: "scene/x.hpp"
  target_link_libraries(${target} PUBLIC ${M_LINK_PUBLIC} PRIVATE ${M_LINK_PRIVATE})
  target_compile_features(${target} PUBLIC cxx_std_17)
  frictherm_set_warnings(${target})
endfunction()

# MPI and PETSc (Debian libopenmpi-dev, petsc-dev with pkg-config PETSc) for the distributed parts;
# a macro so that MPI::* and PkgConfig::PETSC are defined in the calling folder.
macro(frictherm_find_mpi_petsc)
  find_package(MPI COMPONENTS C CXX QUIET)
  find_package(PkgConfig QUIET)
  if(PkgConfig_FOUND)
    pkg_check_modules(PETSC QUIET IMPORTED_TARGET PETSc)
  endif()
endmacro()

# frictherm_add_mpi_library(<module> [LINK_PRIVATE ...]): the module's distributed part,
# <module>/src/distributed/*.cpp, as frictherm_<module>_mpi (alias frictherm::<module>_mpi) on top of
# frictherm_<module>, MPI and PETSc, compiled with FRICTHERM_<MODULE>_MPI. Call after
# frictherm_find_mpi_petsc found both.
function(frictherm_add_mpi_library module)
  cmake_parse_arguments(M "" "" "LINK_PRIVATE" ${ARGN})
  set(target frictherm_${module}_mpi)
  file(GLOB sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/src/distributed/*.cpp)
  add_library(${target} ${sources})
  add_library(frictherm::${module}_mpi ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${module}_mpi OUTPUT_NAME ${target})
  target_include_directories(${target} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(${target} PUBLIC frictherm_${module} MPI::MPI_CXX
                        PRIVATE PkgConfig::PETSC MPI::MPI_C ${M_LINK_PRIVATE})
  string(TOUPPER ${module} upper)
  target_compile_definitions(${target} PUBLIC FRICTHERM_${upper}_MPI)
  frictherm_set_warnings(${target})
endfunction()

# frictherm_optional_mpi_library(<module> <what> [REQUIRES target ...] [LINK_PRIVATE ...]): the module's
# distributed part (frictherm_add_mpi_library) when FRICTHERM_WITH_MPI is on and MPI, PETSc and the
# REQUIRES targets are found; sets the cache flag FRICTHERM_<MODULE>_MPI that tests and benchmarks
# test, and says what was built or what was missing.
function(frictherm_optional_mpi_library module what)
  cmake_parse_arguments(M "" "" "REQUIRES;LINK_PRIVATE" ${ARGN})
  string(TOUPPER ${module} upper)
  set(FRICTHERM_${upper}_MPI OFF CACHE INTERNAL "${what} is built")
  if(NOT FRICTHERM_WITH_MPI)
    return()
  endif()
  frictherm_find_mpi_petsc()
  set(missing "")
  if(NOT MPI_CXX_FOUND OR NOT PETSC_FOUND)
    set(missing "MPI and PETSc")
  endif()
  foreach(t ${M_REQUIRES})
    if(NOT TARGET ${t})
      list(APPEND missing ${t})
    endif()
  endforeach()
  if(missing)
    message(STATUS "${module}: ${what} not built (needs ${missing})")
    return()
  endif()
  frictherm_add_mpi_library(${module} LINK_PRIVATE ${M_LINK_PRIVATE})
  set(FRICTHERM_${upper}_MPI ON CACHE INTERNAL "${what} is built")
  message(STATUS "${module}: ${what} with MPI ${MPI_CXX_VERSION}, PETSc ${PETSC_VERSION}")
endfunction()

# frictherm_add_mpi_test(<name> <source> <library>): a test program with its own main (PETSc and MPI
# initialised once per process), run by ctest as <name>_np2 and <name>_np4 under mpirun
# (oversubscribed: CI has 2 cores; --allow-run-as-root: CI runs as root).
function(frictherm_add_mpi_test name source library)
  add_executable(test_${name} ${source})
  target_link_libraries(test_${name} PRIVATE ${library} GTest::gtest)
  frictherm_test_program(test_${name})  # tests/CMakeLists.txt
  set(environment "${FRICTHERM_MPI_TEST_ENVIRONMENT};OMPI_MCA_rmaps_base_oversubscribe=1")  # tests/CMakeLists.txt
  # Oversubscribed ranks wait for each other in every collective: 120 s covers a busy 2-core machine
  # (they take 1–20 s); instrumented code runs 10–50 times slower, so the sanitizer build allows 1200 s.
  set(timeout 120)
  if(FRICTHERM_SANITIZE)
    set(timeout 1200)
    # Open MPI leaks its own buffers at MPI_Finalize and unloads its components first, so
    # LeakSanitizer's reports come from libmpi and unnamed modules (two-frame stacks no suppression
    # can name). The address and undefined-behaviour checks stay on; only leak detection is off here.
    list(APPEND environment "ASAN_OPTIONS=detect_leaks=0:strict_string_checks=1:detect_stack_use_after_return=1")
  endif()
  foreach(ranks 2 4)
    add_test(NAME ${name}_np${ranks}
             COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${ranks} --oversubscribe --allow-run-as-root
                     ${MPIEXEC_PREFLAGS} $<TARGET_FILE:test_${name}> ${MPIEXEC_POSTFLAGS})
    set_tests_properties(${name}_np${ranks} PROPERTIES
      LABELS "verification;mpi" PROCESSORS ${ranks} TIMEOUT ${timeout}
      ENVIRONMENT "${environment}")
  endforeach()
endfunction()

# The standard headers most sources include, precompiled with each library (frictherm_precompile_headers).
set(FRICTHERM_PCH_STD <algorithm> <array> <cmath> <cstddef> <cstdint> <functional> <limits> <map> <memory>
    <optional> <sstream> <stdexcept> <string> <utility> <vector>)

# frictherm_precompile_headers(<target> <header> ...): with FRICTHERM_PRECOMPILED_HEADERS (CMakeLists.txt),
# the target's sources are compiled against one precompiled copy of these headers and
# FRICTHERM_PCH_STD, force-included ahead of each source's own includes. No source defines a macro
# that changes what these headers declare, so the code compiled is the same; builds under ccache
# (option off) keep checking that every source includes what it uses.
function(frictherm_precompile_headers target)
  if(FRICTHERM_PRECOMPILED_HEADERS)
    target_precompile_headers(${target} PRIVATE ${FRICTHERM_PCH_STD} ${ARGN})
  endif()
endfunction()

# frictherm_unity_build(<target> [BATCH <n>] [ALONE <source> ...]): with FRICTHERM_UNITY_BUILD (CMakeLists.txt),
# the target's sources are compiled in batches of FRICTHERM_UNITY_BATCH (or <n>; 0: all in one) as one file
# each, except the ALONE sources (paths relative to the current folder): the heaviest, whose compile
# time is code generation that a batch does not share, kept apart so that both cores of a small
# machine stay busy.
set(FRICTHERM_UNITY_BATCH 8 CACHE STRING "Sources per unity batch (FRICTHERM_UNITY_BUILD)")
function(frictherm_unity_build target)
  cmake_parse_arguments(U "" "BATCH" "ALONE" ${ARGN})
  if(NOT DEFINED U_BATCH)
    set(U_BATCH ${FRICTHERM_UNITY_BATCH})
  endif()
  if(FRICTHERM_UNITY_BUILD)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${U_BATCH})
    list(TRANSFORM U_ALONE PREPEND ${CMAKE_CURRENT_SOURCE_DIR}/)
    set_source_files_properties(${U_ALONE} TARGET_DIRECTORY ${target} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
  endif()
endfunction()

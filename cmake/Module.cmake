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

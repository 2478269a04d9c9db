# `cmake --install` puts headers, libraries and frictherm-config.cmake in place so that
# another project can find_package(frictherm) and link frictherm::coupling.
include(CMakePackageConfigHelpers)

install(TARGETS frictherm_mechanics frictherm_thermal frictherm_coupling frictherm_hdf5 frictherm_muparser frictherm_images
        EXPORT frictherm-targets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS frictherm RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
foreach(module mechanics thermal coupling)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${module}/include/frictherm
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()

set(FRICTHERM_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/frictherm)
install(EXPORT frictherm-targets NAMESPACE frictherm:: DESTINATION ${FRICTHERM_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/frictherm-config.cmake.in
  ${PROJECT_BINARY_DIR}/frictherm-config.cmake INSTALL_DESTINATION ${FRICTHERM_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/frictherm-config-version.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/frictherm-config.cmake
              ${PROJECT_BINARY_DIR}/frictherm-config-version.cmake
        DESTINATION ${FRICTHERM_CMAKE_DIR})

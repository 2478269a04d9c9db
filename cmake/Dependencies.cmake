# Every dependency comes from a Debian package (see README) and is found here.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(SUNDIALS 6.4 REQUIRED COMPONENTS cvode arkode nvecserial
             sunlinsolklu sunlinsolpcg sunlinsolspgmr sunmatrixsparse)
# SUNDIALS unpacked outside the system's folders (scripts/install_deps.sh program, .deps/sundials): its
# libraries find each other (libsundials_sunlinsolklu needs libsundials_sunmatrixsparse) through the
# executable's search path only when it is a DT_RPATH, which, unlike the linker's default DT_RUNPATH,
# also serves the dependencies of the libraries loaded.
if(NOT SUNDIALS_DIR MATCHES "^/usr/")
  add_link_options(-Wl,--disable-new-dtags)
endif()
find_package(HDF5 REQUIRED COMPONENTS C)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(Boost 1.74 REQUIRED)  # header-only: Boost.Math root finders (mechanics friction laws)
find_package(OpenMP REQUIRED COMPONENTS CXX)
find_package(PkgConfig REQUIRED)
pkg_check_modules(MUPARSER REQUIRED muparser>=2.3)  # libmuparser-dev: friction laws written as expressions
find_package(PNG REQUIRED)   # libpng-dev: PNG micrographs (mechanics/src/image_png_tiff.cpp)
find_package(TIFF REQUIRED)  # libtiff-dev: TIFF micrographs
if(FRICTHERM_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()

# HDF5's FindHDF5 gives variables, not a target: wrap them once.
if(NOT TARGET frictherm_hdf5)
  add_library(frictherm_hdf5 INTERFACE)
  target_include_directories(frictherm_hdf5 SYSTEM INTERFACE ${HDF5_C_INCLUDE_DIRS} ${HDF5_INCLUDE_DIRS})
  target_link_libraries(frictherm_hdf5 INTERFACE ${HDF5_C_LIBRARIES})
  target_compile_definitions(frictherm_hdf5 INTERFACE ${HDF5_C_DEFINITIONS} ${HDF5_DEFINITIONS})
endif()

# muParser (pkg-config gives variables): one exported target with the full library path, linked
# privately by mechanics, so consumers link it but never see its headers.
if(NOT TARGET frictherm_muparser)
  add_library(frictherm_muparser INTERFACE)
  target_include_directories(frictherm_muparser SYSTEM INTERFACE ${MUPARSER_INCLUDE_DIRS})
  target_link_libraries(frictherm_muparser INTERFACE ${MUPARSER_LINK_LIBRARIES})
  target_compile_options(frictherm_muparser INTERFACE ${MUPARSER_CFLAGS_OTHER})
endif()

# libpng and libtiff, like muParser: one exported target with full library paths, linked privately by
# mechanics (consumers link them, never see their headers).
if(NOT TARGET frictherm_images)
  add_library(frictherm_images INTERFACE)
  target_include_directories(frictherm_images SYSTEM INTERFACE ${PNG_INCLUDE_DIRS} ${TIFF_INCLUDE_DIRS})
  target_link_libraries(frictherm_images INTERFACE ${PNG_LIBRARIES} ${TIFF_LIBRARIES})
  target_compile_definitions(frictherm_images INTERFACE ${PNG_DEFINITIONS})
endif()

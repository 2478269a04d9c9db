// The host of the test programs' shared precompiled headers (tests/CMakeLists.txt, frictherm_test_pch):
// CMake compiles them with this target's flags, which every test program that reuses them shares; the
// program itself runs no test (GoogleTest's main finds none and exits 0).

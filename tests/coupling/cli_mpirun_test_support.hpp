#pragma once
// Shared by the tests of `mpirun -n K frictherm run` (test_cli_mpirun*.cpp): the program, the test
// scenes and a scratch folder per test (skipped where mpirun is not installed).
#include "cli_test_support.hpp"

#include <string>

namespace frictherm::test {

/// The frictherm program under test, quoted for the shell.
inline std::string exe() { return std::string("'") + FRICTHERM_EXE + "'"; }

/// tests/coupling/scenes/NAME, quoted for the shell.
inline std::string scene(const char* name) {
  return std::string("'") + FRICTHERM_SOURCE_DIR + "/tests/coupling/scenes/" + name + "'";
}

/// A fresh folder per test, <temp>/frictherm_mpirun_<test name>_<pid>.
class CliMpirunTest : public MpirunScratchTest {
 protected:
  CliMpirunTest() : MpirunScratchTest("frictherm_mpirun_") {}
};

}  // namespace frictherm::test

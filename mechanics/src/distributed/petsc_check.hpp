// PETSc error codes to exceptions (decomposed mechanics). Internal header.
#pragma once

#include <petscsys.h>

#include <stdexcept>
#include <string>

namespace frictherm::mechanics::detail {

inline void petsc_check(PetscErrorCode code, const char* call) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  throw std::runtime_error(std::string("mechanics (decomposed): ") + call + " failed with PETSc error " +
                           std::to_string(static_cast<int>(code)) + (text != nullptr ? std::string(": ") + text : ""));
}

}  // namespace frictherm::mechanics::detail

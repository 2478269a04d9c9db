// PETSc error codes to exceptions (distributed thermal solve). Internal header.
#pragma once

#include <petscksp.h>
#include <petscvec.h>

#include <stdexcept>
#include <string>

namespace frictherm::thermal::detail {

inline void petsc_check(PetscErrorCode code, const char* call) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(code, &text, nullptr);
  throw std::runtime_error(std::string("thermal (distributed): ") + call + " failed with PETSc error " +
                           std::to_string(static_cast<int>(code)) + (text != nullptr ? std::string(": ") + text : ""));
}

}  // namespace frictherm::thermal::detail

// RAII owners for SUNDIALS 6.4 objects and flag-to-exception helpers. Internal header.
#pragma once

#include "frictherm/thermal/integrator.hpp"

#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nonlinearsolver.h>
#include <sundials/sundials_nvector.h>

#include <memory>
#include <string>
#include <type_traits>

namespace frictherm::thermal::detail {

struct ContextDeleter {
  void operator()(SUNContext c) const { SUNContext_Free(&c); }
};
struct NVectorDeleter {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
struct MatrixDeleter {
  void operator()(SUNMatrix a) const { SUNMatDestroy(a); }
};
struct LinSolDeleter {
  void operator()(SUNLinearSolver s) const { SUNLinSolFree(s); }
};
struct NonlinSolDeleter {
  void operator()(SUNNonlinearSolver s) const { SUNNonlinSolFree(s); }
};

using ContextPtr = std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextDeleter>;
using NVectorPtr = std::unique_ptr<std::remove_pointer_t<N_Vector>, NVectorDeleter>;
using MatrixPtr = std::unique_ptr<std::remove_pointer_t<SUNMatrix>, MatrixDeleter>;
using LinSolPtr = std::unique_ptr<std::remove_pointer_t<SUNLinearSolver>, LinSolDeleter>;
using NonlinSolPtr = std::unique_ptr<std::remove_pointer_t<SUNNonlinearSolver>, NonlinSolDeleter>;

// Integrator memory (CVODE, ARKStep, ERKStep) freed by the matching *Free(void**).
using FreeFn = void (*)(void**);
struct MemDeleter {
  FreeFn free_fn = nullptr;
  void operator()(void* p) const {
    if (free_fn != nullptr) free_fn(&p);
  }
};
using MemPtr = std::unique_ptr<void, MemDeleter>;

ContextPtr make_context();                     // SUNContext_Create(NULL, …) (6.x: void* comm)
NVectorPtr make_vector(long n, SUNContext ctx);  // N_VNew_Serial

// SUNDIALS *GetReturnFlagName returns a malloc'd string: copy it and free it.
std::string take_c_string(char* s);

// Collects the last error message SUNDIALS reports through its error-handler hook, instead
// of letting it print to stderr. Signature matches CVErrHandlerFn and ARKErrHandlerFn.
struct ErrorSink {
  std::string last_message;
  static void handler(int error_code, const char* module, const char* function, char* msg,
                      void* user_data);
};

// Throws SolverError("<who>: <call> failed with <FLAG_NAME> (<flag>): <sundials message>")
// when flag < 0. flag_name converts flags to names (e.g. CVodeGetReturnFlagName).
using FlagNameFn = char* (*)(long int);
void check_flag(int flag, const char* call, const std::string& who, FlagNameFn flag_name,
                const ErrorSink& sink);
// Null-pointer result of a SUNDIALS constructor.
void check_ptr(const void* p, const char* call, const std::string& who);

}  // namespace frictherm::thermal::detail

#include "sundials_support.hpp"

#include <nvector/nvector_serial.h>

#include <cstdlib>
#include <sstream>

namespace frictherm::thermal::detail {

ContextPtr make_context() {
  SUNContext ctx = nullptr;
  const int flag = SUNContext_Create(nullptr, &ctx);
  if (flag != 0 || ctx == nullptr) {
    throw SolverError("thermal: SUNContext_Create failed (flag " + std::to_string(flag) + ")", flag,
                      "SUNContext_Create");
  }
  return ContextPtr(ctx);
}

NVectorPtr make_vector(long n, SUNContext ctx) {
  N_Vector v = N_VNew_Serial(static_cast<sunindextype>(n), ctx);
  check_ptr(v, "N_VNew_Serial", "thermal");
  return NVectorPtr(v);
}

std::string take_c_string(char* s) {
  if (s == nullptr) return "UNKNOWN";
  std::string out(s);
  std::free(s);
  return out;
}

void ErrorSink::handler(int error_code, const char* module, const char* function, char* msg,
                        void* user_data) {
  if (user_data == nullptr || error_code >= 0) return;  // keep errors, drop warnings
  auto* sink = static_cast<ErrorSink*>(user_data);
  std::ostringstream os;
  os << "[" << (module ? module : "?") << "::" << (function ? function : "?") << "] "
     << (msg ? msg : "");
  sink->last_message = os.str();
}

void check_flag(int flag, const char* call, const std::string& who, FlagNameFn flag_name,
                const ErrorSink& sink) {
  if (flag >= 0) return;
  const std::string name = flag_name ? take_c_string(flag_name(flag)) : std::to_string(flag);
  std::ostringstream os;
  os << who << ": " << call << " failed with " << name << " (" << flag << ")";
  if (!sink.last_message.empty()) os << ": " << sink.last_message;
  throw SolverError(os.str(), flag, name);
}

void check_ptr(const void* p, const char* call, const std::string& who) {
  if (p == nullptr) {
    throw SolverError(who + ": " + call + " returned NULL (out of memory or bad input)", -1, call);
  }
}

}  // namespace frictherm::thermal::detail

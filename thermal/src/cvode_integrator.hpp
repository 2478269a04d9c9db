// CVODE (SUNDIALS 6.4.1) BDF / Adams integrators. Internal header.
#pragma once

#include "sundials_integrator.hpp"

namespace frictherm::thermal::detail {

class CvodeIntegrator final : public SundialsIntegrator {
 public:
  // lmm: CV_BDF or CV_ADAMS.
  CvodeIntegrator(std::string name, int lmm, const IntegratorOptions& options, LinearSolverKind lin);
  ~CvodeIntegrator() override { release(); }

 protected:
  void release() override;
  void create(double t0) override;
  void reinit(double t0) override;
  int evolve(double t1) override;
  IntegratorStats counters() const override;
  FlagNameFn flag_name_fn() const override;
  const char* evolve_call() const override { return "CVode"; }

 private:
  int lmm_;
  MatrixPtr a_;
  LinSolPtr ls_;
  NonlinSolPtr nls_;
  MemPtr mem_;  // declared last: freed first
};

}  // namespace frictherm::thermal::detail

// Angled surfaces (Nairn, Bardenhagen & Smith 2018, §3: "we re-ran the Coulomb friction example for
// surfaces from 0° to 45° and the results were essentially identical", with the same 5 mm cells).
// The `rotated` sliding block turns the whole set-up (block, base, loads and the specified normal)
// by θ; the base is a rigid material at rest, the loads are spread over the block's particles. Along
// the surface the block must move as in the unrotated run, and as the rigid block.
//
// What we measured: the turned particle lattice does not fill the turned block with exactly 96
// particles. At 5 mm cells the block holds 95 particles at 15° and 92 at 45° (mass 1.0 % and 4.2 %
// short), and with the paper's total forces it accelerates that much faster: 45° then misses the
// 0° history by 4.4 % of v_max although the contact is right. The comparison of contact therefore
// scales the loads to the discretized mass (load per unit mass of the exact block); a second test
// checks that the unscaled runs differ from the rigid block by the mass deficit alone.
#include "sliding_block.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace frictherm;
using namespace frictherm::verification;
using mechanics::FrictionLaw;

namespace {

constexpr double kPi = 3.14159265358979323846;

SlidingHistory run_angle(double degrees, bool mass_scaled) {
  SlidingBlockSetup s;
  s.law = FrictionLaw::coulomb(0.2);
  s.rotated = true;
  s.mass_scaled_loads = mass_scaled;
  s.angle = degrees * kPi / 180.0;
  return run_sliding_block(s);
}

/// max_k |a_k − b_k| / v_max over common samples (both runs sample at the same times).
double max_gap(const SlidingHistory& a, const SlidingHistory& b) {
  double worst = 0.0;
  const std::size_t n = std::min(a.velocity.size(), b.velocity.size());
  for (std::size_t k = 0; k < n; ++k)
    worst = std::max(worst, std::fabs(a.velocity[k] - b.velocity[k]) / SlidingBlockConstants::v_max);
  return worst;
}

/// max_k |v_k − scale v_rigid(t_k)| / v_max.
double rigid_gap(const SlidingHistory& h, const RigidBlock& r, double scale = 1.0) {
  double worst = 0.0;
  for (std::size_t k = 0; k < h.time.size(); ++k)
    worst = std::max(worst, std::fabs(h.velocity[k] - scale * r.velocity(h.time[k])) / SlidingBlockConstants::v_max);
  return worst;
}

}  // namespace

TEST(AngledSurfaces, CoulombBlockIsTheSameAtEveryAngle) {
  using C = SlidingBlockConstants;
  const RigidBlock r = rigid_solution(0.2, 0.2, 0.0, 0.0);
  const double Q = r.friction_work(C::t_final());
  const SlidingHistory ref = run_angle(0.0, true);
  const double ref_rigid = rigid_gap(ref, r);
  std::printf("[angled  0°] mass ratio %.4f, max |v − v_rigid|/v_max = %.4f, final v %.3f m/s "
              "(rigid %.3f), work %.5g J (rigid %.5g)\n",
              ref.mass_ratio, ref_rigid, ref.velocity.back(), r.velocity(C::t_final()), ref.work_second.back(), Q);
  // The same bound as the axis-aligned sliding block (2 % of v_max, test_sliding_block.cpp): the
  // rotated variant only changes how the loads and the base are modelled.
  EXPECT_LT(ref_rigid, 0.02);
  for (double deg : {15.0, 30.0, 45.0}) {
    const SlidingHistory h = run_angle(deg, true);
    const double gap = max_gap(h, ref), to_rigid = rigid_gap(h, r);
    // Mass-scaled loads scale the friction force with the mass, the sliding distance is unchanged:
    // the expected work is Q times the mass ratio.
    const double work_error = std::fabs(h.work_second.back() - h.mass_ratio * Q) / (h.mass_ratio * Q);
    std::printf("[angled %2.0f°] mass ratio %.4f, max |v − v_0°|/v_max = %.4f, max |v − v_rigid|/v_max = %.4f, "
                "final v %.3f m/s, work %.5g J (%.2f %% from the rigid %.5g J)\n",
                deg, h.mass_ratio, gap, to_rigid, h.velocity.back(), h.work_second.back(), 100.0 * work_error,
                h.mass_ratio * Q);
    // The bound: the same velocity history within 3 % of v_max at every angle, and each
    // matches the rigid block (3 % as well: the staircase of particles along the tilted surface is
    // the only difference from the 0° case). Work: the 3 % of the sliding-block test.
    EXPECT_LT(gap, 0.03) << deg << "°";
    EXPECT_LT(to_rigid, 0.03) << deg << "°";
    EXPECT_LT(work_error, 0.03) << deg << "°";
  }
}

TEST(AngledSurfaces, UnscaledLoadsDifferOnlyByTheMassDeficit) {
  // With the paper's total forces F = N l b on m = ratio ρ l h b, every acceleration scales by
  // 1/ratio, so the rigid solution for the block as discretized is v_rigid(t)/ratio.
  const RigidBlock r = rigid_solution(0.2, 0.2, 0.0, 0.0);
  for (double deg : {15.0, 45.0}) {
    const SlidingHistory h = run_angle(deg, false);
    const double raw = rigid_gap(h, r), scaled = rigid_gap(h, r, 1.0 / h.mass_ratio);
    std::printf("[angled %2.0f°, unscaled loads] mass ratio %.4f: max |v − v_rigid|/v_max = %.4f, "
                "against v_rigid/ratio %.4f; final v %.3f m/s\n",
                deg, h.mass_ratio, raw, scaled, h.velocity.back());
    EXPECT_LT(scaled, 0.03) << deg << "°";
  }
}

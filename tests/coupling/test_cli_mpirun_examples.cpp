// Every scene of examples/ under mpirun (issue 32, "every example decomposes"): each shortened with
// run.max_steps to 150 steps (pbx_3d, 85,184 particles: 10), a series row every step and every
// snapshot field (output.fields=null: the EBS scenes write four of them), run by
// `frictherm run` and by `mpirun -n 2` and `-n 4`. The decomposed result must hold every series column
// and every field of the last snapshot that the serial one holds, and agree with it, each quantity
// within 1e-9 of its own scale (the bound of test_cli_mpirun.cpp: the same arithmetic, sums over
// particles, nodes and ranks in another order), the scale being that of what its round-off comes from:
//   * the energy columns (kinetic, strain, total, external, rigid, damping, plastic, energy_lost,
//     numerical_dissipation, contact_normal_work, boundary_stop_work): terms of one balance, the
//     largest of its terms over the run;
//   * the momenta: √(2 M max KE), M the total particle mass (zero by symmetry in most scenes);
//   * a body's mean displacement or velocity: the largest of that body's components (x, y, z);
//   * temperatures (columns and the snapshot field): their rise, at least 1 mK; the mean of n values
//     near T carries n ε T, so 1e-12 T bounds it too; where a thermal solve runs the temperatures are
//     the integrator's (KLU against the decomposed PCG), equal to its tolerance rtol T + atol (/meta);
//   * thermal_energy_change, Σ C_i T_i at the end less at the start: ten times the serial run's own
//     |thermal_energy_change − heat_delivered|, the round-off of Σ C T its books show;
//   * counts (contact_nodes, sliding_nodes, hotspot_count): one, or 1 % of the count: a node counts as
//     sliding when its slide impulse exceeds 1e-12 of the stick one, and at that threshold round-off
//     decides (0.5 % of the PBX's sliding nodes);
//   * the stress field: its largest |value|, at least 1e-6 ρc² (ρc² the largest P-wave modulus the
//     validator reports): a body moving rigidly has stresses of ε ρc² only;
//   * every other field and column: its largest |value|;
//   * the heat books (/meta): heat delivered as the serial run's to 1e-9; Σ M ΔT and Σ m C ΔT_p close
//     on it within ten times the serial run's own book error (the round-off of Σ C T near 300 K).
// Every particle is held by exactly one rank. // Skipped when mpirun is not installed. Labels verification;mpi; one ctest per example.
#include <gtest/gtest.h>

#include "cli_test_support.hpp"
#include "h5_test_support.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace frictherm::test {
namespace {

struct ExampleCase {
  const char* name;
  int steps;
  const char* sets = "";            // further --set options (the scheme cases below)
  const char* label = nullptr;      // the test's name (default: the example's)
  std::array<int, 2> ranks{{2, 4}};  // the split runs' rank counts
};

std::string exe() { return std::string("'") + FRICTHERM_EXE + "'"; }

bool is_count(const std::string& c) { return c == "contact_nodes" || c == "sliding_nodes" || c == "hotspot_count"; }
bool is_energy(const std::string& c) {
  for (const char* e : {"kinetic_energy", "strain_energy", "total_energy", "external_work", "rigid_work", "damping_work",
                        "plastic_dissipation", "energy_lost", "numerical_dissipation", "contact_normal_work",
                        "boundary_stop_work", "stored_energy_lead"})
    if (c == e) return true;
  return false;
}
bool is_temperature(const std::string& c) { return c.find("temperature") != std::string::npos; }

double largest(const std::vector<double>& a) {
  double s = 0.0;
  for (double x : a)
    if (std::isfinite(x)) s = std::max(s, std::fabs(x));
  return s;
}

// The rise of a temperature column or field over its finite values, at least 1 mK.
double rise(const std::vector<double>& a) {
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (double x : a)
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  return std::max(hi > lo ? hi - lo : 0.0, 1e-3);
}

class MpirunExamples : public MpirunScratchTest, public ::testing::WithParamInterface<ExampleCase> {
 protected:
  MpirunExamples() : MpirunScratchTest("frictherm_mpirun_examples_") {}

  std::string run_command(const std::string& out) const {
    return exe() + " run '" + FRICTHERM_SOURCE_DIR + "/examples/" + GetParam().name + ".json' --set run.max_steps=" +
           std::to_string(GetParam().steps) + " " + GetParam().sets +
           " --set output.series_interval=0 --set output.fields=null -q --threads 1 --force -o '" + path(out) + "'";
  }

  std::vector<double> series(const std::string& file, const std::string& c) const {
    return read_doubles(path(file), "/series/" + c);
  }

  // The bound of a temperature column or field a (serial) against its split twin.
  double temperature_bound(const std::vector<double>& a) const {
    const double t_max = largest(a);
    double bound = std::max(1e-9 * rise(a), 1e-12 * t_max);
    const std::vector<double> rtol = read_doubles(path("serial.h5"), "/meta/thermal_rtol");
    const std::vector<double> atol = read_doubles(path("serial.h5"), "/meta/thermal_atol");
    if (!rtol.empty() && !atol.empty()) bound = std::max(bound, rtol[0] * t_max + atol[0]);
    return bound;
  }

  // The largest P-wave modulus ρc² of the scene's materials, as `frictherm validate` reports them.
  double wave_modulus() const {
    const Result v = shell(exe() + " validate '" + FRICTHERM_SOURCE_DIR + "/examples/" + GetParam().name + ".json' " +
                           GetParam().sets);
    double m = 0.0;
    std::size_t at = 0;
    while ((at = v.output.find("density ", at)) != std::string::npos) {
      const double rho = std::atof(v.output.c_str() + at + 8);
      const std::size_t c = v.output.find("wave speed ", at), eol = v.output.find('\n', at);
      if (c != std::string::npos && c < eol) {
        const double speed = std::atof(v.output.c_str() + c + 11);
        m = std::max(m, rho * speed * speed);
      }
      at = eol == std::string::npos ? v.output.size() : eol;
    }
    return m;
  }

  // The scale of serial column c (values a), by what its round-off comes from (the header).
  double series_scale(const std::string& c, const std::vector<double>& a) const {
    double scale = largest(a);
    if (is_energy(c))
      for (const std::string& e : names_in(path("serial.h5"), "/series"))
        if (is_energy(e)) scale = std::max(scale, largest(series("serial.h5", e)));
    if (c.rfind("momentum_", 0) == 0)
      scale = std::max(scale, std::sqrt(2.0 * total_mass() * largest(series("serial.h5", "kinetic_energy"))));
    for (const char* mean : {"mean_displacement_", "mean_velocity_"}) {
      const std::string m = mean;
      if (c.rfind(m, 0) == 0 && c.size() > m.size() + 2 && c[m.size() + 1] == '.')
        for (const char axis : {'x', 'y', 'z'}) {
          std::string other = c;
          other[m.size()] = axis;
          scale = std::max(scale, largest(series("serial.h5", other)));
        }
    }
    if (is_temperature(c)) scale = rise(a);
    return scale;
  }

  // The total particle mass of the serial run's last snapshot.
  double total_mass() const {
    const std::vector<std::string> snaps = names_in(path("serial.h5"), "/snapshots");
    if (snaps.empty()) return 0.0;
    double m = 0.0;
    for (double x : read_doubles(path("serial.h5"), "/snapshots/" + snaps.back() + "/mass")) m += x;
    return m;
  }

  void compare_series(const std::string& split) {
    const std::vector<std::string> have = names_in(path(split), "/series");
    double worst = 0.0;
    std::string worst_column;
    int compared = 0;
    for (const std::string& c : names_in(path("serial.h5"), "/series")) {
      if (std::find(have.begin(), have.end(), c) == have.end()) {
        ADD_FAILURE() << split << " lacks the serial series column " << c;
        continue;
      }
      const std::vector<double> a = series("serial.h5", c), b = series(split, c);
      ASSERT_EQ(a.size(), b.size()) << c;
      double diff = 0.0;
      for (std::size_t k = 0; k < a.size(); ++k) {
        if (std::isnan(a[k]) || std::isnan(b[k])) {
          EXPECT_EQ(std::isnan(a[k]), std::isnan(b[k])) << c << " row " << k;
          continue;
        }
        diff = std::max(diff, std::fabs(a[k] - b[k]));
      }
      const double scale = series_scale(c, a);
      if (is_count(c)) {
        EXPECT_LE(diff, std::max(1.0, 0.01 * scale)) << c;
        continue;
      }
      double bound = 1e-9 * scale;
      if (is_temperature(c)) bound = temperature_bound(a);
      if (c == "thermal_energy_change") {
        const std::vector<double> q = series("serial.h5", "heat_delivered");
        double book = 0.0;
        for (std::size_t k = 0; k < std::min(a.size(), q.size()); ++k) book = std::max(book, std::fabs(a[k] - q[k]));
        bound = std::max(bound, 10.0 * book);
      }
      EXPECT_LE(diff, bound) << c << " (scale " << scale << ")";
      const double rel = scale > 0.0 ? diff / scale : diff;
      if (rel > worst) worst = rel, worst_column = c;
      ++compared;
    }
    std::printf("  %s: %d series columns, largest difference %.3g of its scale (%s)\n", split.c_str(), compared, worst,
                worst_column.c_str());
  }

  // The heat books (/meta): the heat delivered equals the serial run's to 1e-9 (the mechanics' work,
  // sums in another order); the nodal and particle energy changes, Σ M ΔT and Σ m C ΔT_p, close on it
  // as well as the serial run's own books do: within ten times its own error (the round-off of Σ C T,
  // the temperatures being near 300 K), at least 1e-9 of the heat.
  void compare_books(const std::string& split) {
    const auto meta = [&](const std::string& file, const char* key) {
      const std::vector<double> v = read_doubles(path(file), std::string("/meta/") + key);
      return v.empty() ? std::nan("") : v[0];
    };
    const double q_serial = meta("serial.h5", "heat_delivered"), q = meta(split, "heat_delivered");
    if (!(q_serial > 0.0)) return;  // no heat: no books
    EXPECT_NEAR(q, q_serial, 1e-9 * q_serial) << "heat_delivered";
    for (const char* change : {"nodal_energy_change", "particle_energy_change"}) {
      const double own = std::fabs(meta("serial.h5", change) - q_serial);
      const double book = std::fabs(meta(split, change) - q);
      EXPECT_LE(book, std::max(1e-9 * q_serial, 10.0 * own)) << change;
      std::printf("  %s: %s closes on the heat to %.3g of it (serial run: %.3g)\n", split.c_str(), change, book / q,
                  own / q_serial);
    }
  }

  // The last snapshot's fields by particle id over the rank files of `split` (K ranks).
  void compare_snapshot(const std::string& split, int ranks) {
    const std::vector<std::string> snaps = names_in(path("serial.h5"), "/snapshots");
    ASSERT_FALSE(snaps.empty());
    const std::string snap = "/snapshots/" + snaps.back() + "/";
    const std::string stem = split.substr(0, split.size() - 3);
    std::vector<std::vector<double>> ids(static_cast<std::size_t>(ranks));
    for (int r = 0; r < ranks; ++r)
      ids[static_cast<std::size_t>(r)] = read_doubles(path(stem + ".rank" + std::to_string(r) + ".h5"), snap + "id");
    const std::size_t n = read_doubles(path("serial.h5"), snap + "mass").size();
    ASSERT_GT(n, 0u);
    std::vector<int> seen(n, 0);
    for (const auto& v : ids)
      for (double id : v) {
        ASSERT_LT(static_cast<std::size_t>(id), n);
        ++seen[static_cast<std::size_t>(id)];
      }
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<long>(n)) << "every particle on one rank";
    const double modulus = wave_modulus();
    double worst = 0.0;
    std::string worst_field;
    int fields = 0;
    for (const std::string& f : names_in(path("serial.h5"), snap)) {
      const std::vector<double> a = read_doubles(path("serial.h5"), snap + f);
      if (a.empty() || a.size() % n != 0) continue;  // per-particle fields only
      const std::size_t width = a.size() / n;
      double scale = is_temperature(f) ? rise(a) : std::max(largest(a), 1e-300);
      if (f == "stress") scale = std::max(scale, 1e-6 * modulus);
      const double bound = is_temperature(f) ? temperature_bound(a) : 1e-9 * scale;
      double diff = 0.0;
      for (int r = 0; r < ranks; ++r) {
        const std::string file = stem + ".rank" + std::to_string(r) + ".h5";
        const std::vector<double> b = read_doubles(path(file), snap + f);
        const auto& id = ids[static_cast<std::size_t>(r)];
        if (b.size() != id.size() * width) {
          ADD_FAILURE() << file << snap << f << ": " << b.size() << " values for " << id.size() << " particles";
          break;
        }
        for (std::size_t k = 0; k < id.size(); ++k)
          for (std::size_t j = 0; j < width; ++j)
            diff = std::max(diff, std::fabs(b[k * width + j] - a[static_cast<std::size_t>(id[k]) * width + j]));
      }
      EXPECT_LE(diff, bound) << f;
      if (diff / scale > worst) worst = diff / scale, worst_field = f;
      ++fields;
    }
    std::printf("  %s: %d snapshot fields of %zu particles, largest difference %.3g of its scale (%s)\n", split.c_str(),
                fields, n, worst, worst_field.c_str());
  }
};

TEST_P(MpirunExamples, SplitRunsMatchTheSerialRun) {
  const Result s = shell(run_command("serial.h5"));
  ASSERT_EQ(s.code, 0) << s.output;
  for (int ranks : GetParam().ranks) {
    const std::string split = "split" + std::to_string(ranks) + ".h5";
    const Result d = shell(mpirun_command(ranks) + " " + run_command(split));
    ASSERT_EQ(d.code, 0) << d.output;
    compare_series(split);
    compare_snapshot(split, ranks);
    compare_books(split);
  }
}

const ExampleCase kExamples[] = {
    {"bar_vibration", 150},      {"bars_impact", 150},         {"granular_waves", 150},
    {"half_disk_plane", 150},    {"hertz_disks", 150},         {"image_body", 150},
    {"neo_hookean_rings", 150},  {"oscillating_block", 150},   {"pbx_3d", 10},
    {"pbx_compaction", 150},     {"pbx_microstructure_small", 150}, {"pressed_block", 150},
    {"rigid_push", 150},         {"sliding_block", 150},       {"sliding_block_expression", 150},
    {"sliding_block_heating", 150}, {"sphere_3d", 150},
};

INSTANTIATE_TEST_SUITE_P(Examples, MpirunExamples, ::testing::ValuesIn(kExamples),
                         [](const ::testing::TestParamInfo<ExampleCase>& p) { return std::string(p.param.name); });

// The update schemes and grid-to-particle transfers no example uses, on examples that exercise what
// they meet (issue 32): the same comparison on 2 and 3 ranks (3: a split along one axis into unequal
// parts). USF (the stress update from the extrapolated velocities after their ghost update, the forces
// and their exchange after it: mechanics/src/distributed/phase_lists.cpp) with multimaterial contact,
// frictional heating and tractions (sliding_block_heating), rigid contact partners and damping
// (oscillating_block), rigid walls and a fixed face (rigid_push), penalty contact with extended
// B-splines (hertz_disks), 3D (sphere_3d) and the PBX grains (pbx_microstructure_small). XPIC(3) and
// FMPM(3) (two round trips of the filters' series, each with its exchanges:
// mechanics/src/distributed/velocity_filter.cpp) on the same kinds of scene: per-material entries at
// multi-material nodes (the contact scenes, the PBX grains), velocity conditions in the series (fixed
// faces, rigid drives, rigid partners keeping w0), penalty contact, 3D, one shared field (bars_impact,
// MUSL), and XPIC under USF.
const ExampleCase kSchemes[] = {
    {"sliding_block_heating", 150, "--set solver.scheme=usf", "usf_sliding_block_heating", {{2, 3}}},
    {"oscillating_block", 150, "--set solver.scheme=usf", "usf_oscillating_block", {{2, 3}}},
    {"rigid_push", 150, "--set solver.scheme=usf", "usf_rigid_push", {{2, 3}}},
    {"hertz_disks", 150, "--set solver.scheme=usf", "usf_hertz_disks", {{2, 3}}},
    {"sphere_3d", 150, "--set solver.scheme=usf", "usf_sphere_3d", {{2, 3}}},
    {"pbx_microstructure_small", 150, "--set solver.scheme=usf", "usf_pbx_microstructure_small", {{2, 3}}},
    {"sliding_block_heating", 150, R"(--set 'solver.particle_update={"type":"xpic","order":3}')",
     "xpic_sliding_block_heating", {{2, 3}}},
    {"oscillating_block", 150, R"(--set 'solver.particle_update={"type":"xpic","order":3}')", "xpic_oscillating_block",
     {{2, 3}}},
    {"sphere_3d", 150, R"(--set 'solver.particle_update={"type":"xpic","order":3}')", "xpic_sphere_3d", {{2, 3}}},
    {"sliding_block", 150, R"(--set solver.scheme=usf --set 'solver.particle_update={"type":"xpic","order":3}')",
     "xpic_usf_sliding_block", {{2, 3}}},
    {"rigid_push", 150, R"(--set 'solver.particle_update={"type":"fmpm","order":3}')", "fmpm_rigid_push", {{2, 3}}},
    {"hertz_disks", 150, R"(--set 'solver.particle_update={"type":"fmpm","order":3}')", "fmpm_hertz_disks", {{2, 3}}},
    {"bars_impact", 150, R"(--set 'solver.particle_update={"type":"fmpm","order":3}')", "fmpm_bars_impact", {{2, 3}}},
    {"pbx_microstructure_small", 150,
     R"(--set solver.pic_relaxation_time=null --set 'solver.particle_update={"type":"fmpm","order":3}')",
     "fmpm_pbx_microstructure_small", {{2, 3}}},
};

INSTANTIATE_TEST_SUITE_P(Schemes, MpirunExamples, ::testing::ValuesIn(kSchemes),
                         [](const ::testing::TestParamInfo<ExampleCase>& p) { return std::string(p.param.label); });

}  // namespace
}  // namespace frictherm::test

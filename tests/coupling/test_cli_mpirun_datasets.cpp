// The decomposed result holds the serial result's datasets (issue 32, "the decomposed result holds
// the same datasets and series columns as the serial one"): `mpirun -n 2 frictherm run` against
// `frictherm run` on the main example (sliding_block_heating, 200 steps: one window with frictional
// heat) and the PBX specimen (pbx_microstructure_small, 50 steps: one window), shortened.
//
//   * every dataset path of the serial OUT.h5 exists in the decomposed OUT.h5 or its rank files
//     OUT.rank<r>.h5, the six-digit snapshot numbers under /snapshots and /nodes aside, and /xdmf
//     aside (the serial XDMF's polyvertex lists; each rank group holds its own connectivity). Also
//     aside: the serial step's phase timers time_time_step, time_shape_functions, time_contact and
//     time_grid_update, wall-clock seconds of phases the decomposed step's phase list
//     (mechanics/src/distributed/phase_lists.cpp) does not have: it times its own phases (contact as
//     find_contact_nodes, contact_extrapolated and contact_updated, ...) under their own time_* keys;
//   * /nodes: the thermal unknowns of each snapshot, each written once (on its owner rank), at the
//     serial run's positions, with the serial run's temperatures within 1e-9 of their scale
//     max |T_i − 300 K|, at least 1e-12 T (sums over particles in another order; a few ε T near a
//     uniform T), and units as the serial datasets'. The main example integrates its window with
//     cvode_bdf at rtol = atol = 1e-9 on a heat of 7e-12 J (measured 2.3e-13 K, 3.3e-14 of the
//     scale); the PBX specimen with forward Euler (the same matrix-free arithmetic in both runs:
//     3.3e-14). With the PBX specimen's own integrator (cvode_bdf at 1e-6, assembled windows: KLU in
//     the serial run, PCG with a Jacobi preconditioner in the decomposed one) the nodal temperatures
//     are each integrator's answer, equal to its tolerance rtol T + atol (/meta; measured 9e-5 K at
//     nodes whose M_i is 1e-9 of the largest, 1.3e-5 of the scale above);
//   * OUT_nodes.xdmf joins the rank files' /nodes as RUN_nodes.xdmf does the serial file's.
// Labels verification;mpi. Skipped when mpirun is not installed.
#include <gtest/gtest.h>

#include "cli_test_support.hpp"
#include "h5_test_support.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace frictherm::test {
namespace {

struct DatasetCase {
  const char* label;
  const char* example;
  int steps;
  const char* sets;         // further --set options
  bool integrator_bound;    // the nodal temperatures agree to the integrator's tolerance only
};

std::string exe() { return std::string("'") + FRICTHERM_EXE + "'"; }

// Every dataset of `file` by its path ("/meta/cfl", "/nodes/000001/temperature").
std::vector<std::string> dataset_paths(const std::string& file) {
  std::vector<std::string> paths;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return paths;
  auto add = [](hid_t, const char* name, const H5O_info_t* info, void* out) -> herr_t {
    if (info->type == H5O_TYPE_DATASET) static_cast<std::vector<std::string>*>(out)->push_back(std::string("/") + name);
    return 0;
  };
  H5Ovisit2(f, H5_INDEX_NAME, H5_ITER_INC, add, &paths, H5O_INFO_BASIC);
  H5Fclose(f);
  return paths;
}

// A path with the snapshot number under /snapshots and /nodes written as "#"; "" for paths aside.
std::string normalized(const std::string& path) {
  if (path.rfind("/xdmf/", 0) == 0) return "";
  for (const char* timer : {"/meta/time_time_step", "/meta/time_shape_functions", "/meta/time_contact",
                            "/meta/time_grid_update"})
    if (path == timer) return "";
  for (const char* group : {"/snapshots/", "/nodes/"}) {
    const std::string g = group;
    if (path.rfind(g, 0) == 0 && path.size() > g.size() + 6 && path[g.size() + 6] == '/')
      return g + "#" + path.substr(g.size() + 6);
  }
  return path;
}

// A string attribute (units, long_name) of a dataset, "" when absent.
std::string attribute(const std::string& file, const std::string& path, const char* name) {
  std::string s;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return s;
  if (H5Aexists_by_name(f, path.c_str(), name, H5P_DEFAULT) > 0) {
    const hid_t a = H5Aopen_by_name(f, path.c_str(), name, H5P_DEFAULT, H5P_DEFAULT);
    const hid_t t = H5Aget_type(a);
    if (H5Tget_class(t) == H5T_STRING && H5Tis_variable_str(t) <= 0) {
      s.assign(H5Tget_size(t), '\0');
      H5Aread(a, t, s.data());
      s.resize(s.find('\0') == std::string::npos ? s.size() : s.find('\0'));
    }
    H5Tclose(t);
    H5Aclose(a);
  }
  H5Fclose(f);
  return s;
}

class MpirunDatasets : public MpirunScratchTest, public ::testing::WithParamInterface<DatasetCase> {
 protected:
  MpirunDatasets() : MpirunScratchTest("frictherm_mpirun_datasets_") {}
  static constexpr int kRanks = 2;

  std::string run_command(const std::string& out) const {
    return exe() + " run '" + FRICTHERM_SOURCE_DIR + "/examples/" + GetParam().example + ".json' --set run.max_steps=" +
           std::to_string(GetParam().steps) + " " + GetParam().sets + " -q --threads 1 --force -o '" + path(out) + "'";
  }
  std::string rank_file(int r) const { return path("split.rank" + std::to_string(r) + ".h5"); }

  // The serial nodes of one snapshot against the rank files' (matched by position).
  void compare_nodes(const std::string& group) {
    const std::string serial = path("serial.h5");
    const std::vector<double> x = read_doubles(serial, group + "/position"), T = read_doubles(serial, group + "/temperature");
    const std::size_t n = T.size();
    ASSERT_GT(n, 0u) << group;
    const std::size_t dim = x.size() / n;
    std::map<std::vector<double>, std::size_t> at;  // serial node by position
    for (std::size_t k = 0; k < n; ++k) at[std::vector<double>(x.begin() + k * dim, x.begin() + (k + 1) * dim)] = k;
    ASSERT_EQ(at.size(), n) << group << ": serial nodes at distinct positions";
    double scale = 0.0, t_max = 0.0;
    for (double t : T) scale = std::max(scale, std::fabs(t - 300.0)), t_max = std::max(t_max, std::fabs(t));
    // At least 1e-12 T: T_i = Σ m C T S / Σ m C S near a uniform T carries a few ε T whatever the
    // order of the sums (pbx_3d at its start, 300 K everywhere: 4e-13 K).
    double bound = std::max(1e-9 * scale, 1e-12 * t_max);
    if (GetParam().integrator_bound)
      bound = read_doubles(serial, "/meta/thermal_rtol")[0] * t_max + read_doubles(serial, "/meta/thermal_atol")[0];
    std::vector<int> seen(n, 0);
    double diff = 0.0;
    for (int r = 0; r < kRanks; ++r) {
      const std::vector<double> xr = read_doubles(rank_file(r), group + "/position");
      const std::vector<double> Tr = read_doubles(rank_file(r), group + "/temperature");
      ASSERT_EQ(xr.size(), Tr.size() * dim) << rank_file(r) << group;
      for (std::size_t k = 0; k < Tr.size(); ++k) {
        const auto it = at.find(std::vector<double>(xr.begin() + k * dim, xr.begin() + (k + 1) * dim));
        ASSERT_NE(it, at.end()) << rank_file(r) << group << ": node " << k << " is not a serial node";
        ++seen[it->second];
        diff = std::max(diff, std::fabs(Tr[k] - T[it->second]));
      }
    }
    EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<long>(n)) << group << ": every node written once";
    EXPECT_LE(diff, bound) << group << " temperature (scale " << scale << " K)";
    std::printf("  %s: %zu nodes, largest temperature difference %.3g K (%.3g of the scale %.3g K)\n", group.c_str(), n,
                diff, scale > 0.0 ? diff / scale : diff, scale);
  }
};

TEST_P(MpirunDatasets, DecomposedResultHoldsTheSerialDatasets) {
  const Result s = shell(run_command("serial.h5"));
  ASSERT_EQ(s.code, 0) << s.output;
  const Result d = shell(mpirun_command(kRanks) + " " + run_command("split.h5"));
  ASSERT_EQ(d.code, 0) << d.output;

  std::set<std::string> have;
  for (const std::string& p : dataset_paths(path("split.h5"))) have.insert(normalized(p));
  for (int r = 0; r < kRanks; ++r)
    for (const std::string& p : dataset_paths(rank_file(r))) have.insert(normalized(p));
  int checked = 0;
  std::set<std::string> serial;
  for (const std::string& p : dataset_paths(path("serial.h5"))) {
    const std::string q = normalized(p);
    if (q.empty() || !serial.insert(q).second) continue;
    EXPECT_TRUE(have.count(q)) << "the decomposed result lacks the serial dataset " << q;
    ++checked;
  }
  EXPECT_GT(serial.count("/nodes/#/temperature"), 0u);
  EXPECT_GT(serial.count("/meta/grid_cells"), 0u);
  std::printf("  %d serial dataset paths, all in the decomposed result\n", checked);

  // /nodes: every snapshot's, and their units and long names as the serial file's.
  const std::vector<std::string> groups = names_in(path("serial.h5"), "/nodes");
  ASSERT_FALSE(groups.empty());
  EXPECT_EQ(names_in(rank_file(0), "/nodes"), groups);
  for (const std::string& g : groups) compare_nodes("/nodes/" + g);
  for (const char* f : {"position", "temperature", "heat_capacity", "lattice"})
    for (const char* a : {"units", "long_name"}) {
      const std::string want = attribute(path("serial.h5"), "/nodes/" + groups[0] + "/" + f, a);
      EXPECT_FALSE(want.empty()) << f << " " << a;
      EXPECT_EQ(attribute(rank_file(1), "/nodes/" + groups[0] + "/" + f, a), want) << f << " " << a;
    }

  // OUT_nodes.xdmf: one temporal collection of the snapshots, each a spatial collection of the ranks'.
  std::ifstream in(path("split_nodes.xdmf"));
  ASSERT_TRUE(in.good()) << "split_nodes.xdmf beside split.h5";
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("thermal_nodes"), std::string::npos);
  for (int r = 0; r < kRanks; ++r)
    EXPECT_NE(text.str().find("split.rank" + std::to_string(r) + ".h5:/nodes/" + groups.back() + "/temperature"),
              std::string::npos)
        << "rank " << r;
}

const DatasetCase kCases[] = {
    {"sliding_block_heating", "sliding_block_heating", 200, "", false},
    {"pbx_forward_euler", "pbx_microstructure_small", 50, "--set thermal.integrator=forward_euler", false},
    {"pbx_cvode_bdf", "pbx_microstructure_small", 50, "", true},
};

INSTANTIATE_TEST_SUITE_P(Examples, MpirunDatasets, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<DatasetCase>& p) { return std::string(p.param.label); });

}  // namespace
}  // namespace frictherm::test

// Output: HDF5 snapshots/series/metadata round trips (read back with the HDF5 C API), CSV export,
// XDMF content, crash safety (a child killed with SIGKILL mid-snapshot), error messages, and the
// plotting script on a generated file.
#include <frictherm/coupling/csv_export.hpp>
#include <frictherm/coupling/h5_output.hpp>
#include <frictherm/coupling/xdmf.hpp>

#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using frictherm::coupling::H5Output;
using frictherm::coupling::H5OutputOptions;

namespace {

// A fresh directory per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("frictherm_output_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }

 private:
  fs::path dir_;
};

struct File {
  hid_t id;
  explicit File(const std::string& path) : id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT)) {}
  ~File() {
    if (id >= 0) H5Fclose(id);
  }
};

std::vector<hsize_t> shape(hid_t file, const std::string& path) {
  const hid_t d = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  if (d < 0) return {};
  const hid_t s = H5Dget_space(d);
  std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(s)));
  H5Sget_simple_extent_dims(s, dims.data(), nullptr);
  H5Sclose(s);
  H5Dclose(d);
  return dims;
}

template <typename T>
std::vector<T> read_all(hid_t file, const std::string& path, hid_t mem_type) {
  std::size_t n = 1;
  for (const auto d : shape(file, path)) n *= d;
  std::vector<T> out(n);
  const hid_t d = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(d, 0) << path;
  if (n > 0) {
    EXPECT_GE(H5Dread(d, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0) << path;
  }
  H5Dclose(d);
  return out;
}
std::vector<double> read_doubles(hid_t f, const std::string& p) { return read_all<double>(f, p, H5T_NATIVE_DOUBLE); }

template <typename T>
T read_attr(hid_t file, const std::string& obj, const std::string& name, hid_t mem_type) {
  T value{};
  const hid_t a = H5Aopen_by_name(file, obj.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(a, 0) << obj << " @" << name;
  EXPECT_GE(H5Aread(a, mem_type, &value), 0);
  H5Aclose(a);
  return value;
}

// A fixed-length string stored in a scalar dataset (/meta) or attribute.
std::string read_string(hid_t file, const std::string& obj, const std::string& attr = "") {
  const bool is_attr = !attr.empty();
  const hid_t o = is_attr ? H5Aopen_by_name(file, obj.c_str(), attr.c_str(), H5P_DEFAULT, H5P_DEFAULT)
                          : H5Dopen2(file, obj.c_str(), H5P_DEFAULT);
  if (o < 0) return "<missing>";
  const hid_t t = is_attr ? H5Aget_type(o) : H5Dget_type(o);
  std::string value(H5Tget_size(t), '\0');
  if (is_attr) H5Aread(o, t, value.data()); else H5Dread(o, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, value.data());
  H5Tclose(t);
  is_attr ? H5Aclose(o) : H5Dclose(o);
  value.resize(std::min(value.size(), value.find('\0')));
  return value;
}

std::vector<std::string> links(hid_t file, const std::string& group) {
  std::vector<std::string> names;
  hsize_t idx = 0;
  H5Literate_by_name(file, group.c_str(), H5_INDEX_NAME, H5_ITER_INC, &idx,
                     [](hid_t, const char* name, const H5L_info_t*, void* out) -> herr_t {
                       static_cast<std::vector<std::string>*>(out)->emplace_back(name);
                       return 0;
                     },
                     &names, H5P_DEFAULT);
  return names;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// Deterministic particle data for snapshot k of n particles.
struct Particles {
  std::vector<double> position, velocity, stress, temperature, volume;
  std::vector<std::int32_t> material;
  Particles(std::size_t n, int dim, int k) {
    for (std::size_t p = 0; p < n; ++p) {
      for (int c = 0; c < dim; ++c) position.push_back(0.01 * static_cast<double>(p % 10) + 0.001 * c + 0.1 * k);
      // Vectors and tensors in the runner's shapes (3 and 9 components also in 2D, z padded with 0).
      for (int c = 0; c < 3; ++c) velocity.push_back(c < dim ? std::sin(static_cast<double>(p + c + k)) : 0.0);
      for (int c = 0; c < 9; ++c) stress.push_back(1e6 * (p + 1) + c + k);
      temperature.push_back(300.0 + static_cast<double>(p) + k);
      volume.push_back(1e-4);
      material.push_back(static_cast<std::int32_t>(p % 3));
    }
  }
  void write(H5Output& out, std::size_t n, int dim) const {
    out.snapshot_field("position", position.data(), n, dim);
    out.snapshot_field("velocity", velocity.data(), n, 3);
    out.snapshot_field("stress", stress.data(), n, 9);
    out.snapshot_field("temperature", temperature.data(), n, 1);
    out.snapshot_field("volume", volume.data(), n, 1);
    out.snapshot_field("material", material.data(), n);
  }
};

void expect_snapshot(hid_t f, const std::string& group, std::size_t n, int dim, int k, long step, double time) {
  const Particles ref(n, dim, k);
  EXPECT_EQ(read_attr<std::int64_t>(f, group, "step", H5T_NATIVE_INT64), step);
  EXPECT_EQ(read_attr<double>(f, group, "time", H5T_NATIVE_DOUBLE), time);
  EXPECT_EQ(shape(f, group + "/position"), (std::vector<hsize_t>{n, hsize_t(dim)}));
  EXPECT_EQ(shape(f, group + "/velocity"), (std::vector<hsize_t>{n, 3}));
  EXPECT_EQ(shape(f, group + "/stress"), (std::vector<hsize_t>{n, 9}));
  EXPECT_EQ(shape(f, group + "/temperature"), (std::vector<hsize_t>{n}));
  EXPECT_EQ(read_doubles(f, group + "/position"), ref.position);
  EXPECT_EQ(read_doubles(f, group + "/velocity"), ref.velocity);
  EXPECT_EQ(read_doubles(f, group + "/stress"), ref.stress);
  EXPECT_EQ(read_doubles(f, group + "/temperature"), ref.temperature);
  EXPECT_EQ(read_all<std::int32_t>(f, group + "/material", H5T_NATIVE_INT32), ref.material);
}

}  // namespace

TEST(Output, SnapshotsRoundTrip) {
  const TempDir tmp;
  const std::string path = tmp.file("run.h5");
  for (const int dim : {2, 3}) {
    const std::size_t n = 7;
    {
      H5Output out(path, dim);
      for (int k = 0; k < 3; ++k) {
        out.begin_snapshot(100L * k, 0.5 * k);
        EXPECT_TRUE(out.in_snapshot());
        Particles(n, dim, k).write(out, n, dim);
        out.end_snapshot();
        EXPECT_EQ(out.snapshot_count(), static_cast<std::size_t>(k + 1));
      }
    }
    const File f(path);
    ASSERT_GE(f.id, 0);
    EXPECT_EQ(read_attr<std::int32_t>(f.id, "/", "dim", H5T_NATIVE_INT32), dim);
    EXPECT_EQ(read_string(f.id, "/", "format"), "frictherm-output");
    EXPECT_EQ(links(f.id, "/snapshots"), (std::vector<std::string>{"000000", "000001", "000002"}));
    for (int k = 0; k < 3; ++k) {
      expect_snapshot(f.id, "/snapshots/00000" + std::to_string(k), n, dim, k, 100L * k, 0.5 * k);
    }
    EXPECT_EQ(H5Lexists(f.id, "failure", H5P_DEFAULT), 0);
  }
}

TEST(Output, SeriesRoundTripAndBatching) {
  const TempDir tmp;
  const std::string path = tmp.file("series.h5");
  {
    H5OutputOptions options;
    options.series_batch_rows = 4;
    H5Output out(path, 2, options);
    out.declare_series({"time", "kinetic_energy", "max_temperature"});
    for (int r = 0; r < 10; ++r) out.append_series({1e-6 * r, 0.5 * r * r, 300.0 + r});
    EXPECT_EQ(out.series_rows(), 10u);
  }  // the destructor writes the two buffered rows
  const File f(path);
  ASSERT_GE(f.id, 0);
  for (const auto* name : {"time", "kinetic_energy", "max_temperature"}) {
    EXPECT_EQ(shape(f.id, std::string("/series/") + name), (std::vector<hsize_t>{10}));
  }
  const auto ke = read_doubles(f.id, "/series/kinetic_energy");
  for (int r = 0; r < 10; ++r) EXPECT_EQ(ke[r], 0.5 * r * r);
  EXPECT_EQ(read_doubles(f.id, "/series/time")[9], 9e-6);

  const auto table = frictherm::coupling::read_series(path);
  EXPECT_EQ(table.names, (std::vector<std::string>{"time", "kinetic_energy", "max_temperature"}));
  EXPECT_EQ(table.rows(), 10u);
}

TEST(Output, SeriesRowsBecomeVisibleAtFlush) {
  const TempDir tmp;
  const std::string path = tmp.file("flush.h5");
  H5Output out(path, 2);
  out.declare_series({"time", "e"});
  for (int r = 0; r < 3; ++r) out.append_series({double(r), 2.0 * r});
  out.flush();
  EXPECT_EQ(frictherm::coupling::read_series(path).rows(), 3u);
  EXPECT_THROW(out.append_series({1.0}), std::invalid_argument);
  EXPECT_THROW(out.declare_series({"time"}), std::logic_error);
}

TEST(Output, MetadataStringsAndNumbers) {
  const TempDir tmp;
  const std::string path = tmp.file("meta.h5");
  const std::string scene = "{\n  // a comment\n  \"grid\": {\"cells\": [10, 10]}\n}\n";
  const std::string big(100000, 'x');  // larger than a compact dataset can hold
  {
    H5Output out(path, 3);
    out.write_metadata("scene", scene);
    out.write_metadata("version", "0.0.0");
    out.write_metadata("version", "0.1.0");  // overwrite
    out.write_metadata("command_line", "frictherm run scène.json -o out.h5");
    out.write_metadata("empty", "");
    out.write_metadata("big", big);
    out.write_metadata("wall_time", 1.5);
    out.write_metadata("wall_time", 2.25);
    EXPECT_THROW(out.write_metadata("a/b", 1.0), std::invalid_argument);
    EXPECT_THROW(out.write_metadata("", 1.0), std::invalid_argument);
  }
  const File f(path);
  ASSERT_GE(f.id, 0);
  EXPECT_EQ(read_string(f.id, "/meta/scene"), scene);
  EXPECT_EQ(read_string(f.id, "/meta/version"), "0.1.0");
  EXPECT_EQ(read_string(f.id, "/meta/command_line"), "frictherm run scène.json -o out.h5");
  EXPECT_EQ(read_string(f.id, "/meta/empty"), "");
  EXPECT_EQ(read_string(f.id, "/meta/big"), big);
  EXPECT_EQ(read_doubles(f.id, "/meta/wall_time"), std::vector<double>{2.25});
}

TEST(Output, CsvExport) {
  const TempDir tmp;
  const std::string path = tmp.file("csv.h5");
  {
    H5Output out(path, 2);
    out.declare_series({"time", "kinetic_energy", "heat, delivered"});
    out.append_series({0.0, 0.1, 1e-300});
    out.append_series({2.5e-7, -3.0, std::nan("")});
    out.append_series({5e-7, 1.0 / 3.0, INFINITY});
  }
  std::ostringstream csv;
  frictherm::coupling::export_series_csv(path, csv);
  EXPECT_EQ(csv.str(),
            "time,kinetic_energy,\"heat, delivered\"\n"
            "0,0.1,1e-300\n"
            "2.5e-07,-3,nan\n"
            "5e-07,0.3333333333333333,inf\n");

  std::ostringstream empty;  // a run without series writes nothing
  { H5Output out(tmp.file("none.h5"), 2); }
  frictherm::coupling::export_series_csv(tmp.file("none.h5"), empty);
  EXPECT_EQ(empty.str(), "");
  EXPECT_THROW(frictherm::coupling::export_series_csv(tmp.file("missing.h5"), empty), std::runtime_error);
}

TEST(Output, XdmfListsEverySnapshotAndField) {
  const TempDir tmp;
  const std::string path = tmp.file("view.h5");
  const std::size_t n = 5;
  H5Output out(path, 2);
  EXPECT_EQ(out.xdmf_path(), tmp.file("view.xdmf"));
  for (int k = 0; k < 3; ++k) {
    out.begin_snapshot(k, 1e-6 * k);
    Particles(n, 2, k).write(out, n, 2);
    out.end_snapshot();
    const std::string xml = slurp(out.xdmf_path());  // rewritten after every snapshot
    EXPECT_EQ(count_of(xml, "GridType=\"Uniform\""), static_cast<std::size_t>(k + 1));
  }
  out.begin_failure(3, 3e-6, "NaN velocity at particle 2");
  Particles(n, 2, 3).write(out, n, 2);
  out.end_snapshot();
  EXPECT_EQ(out.snapshot_count(), 3u);

  const std::string xml = slurp(out.xdmf_path());
  EXPECT_NE(xml.find("CollectionType=\"Temporal\""), std::string::npos);
  for (const auto* g : {"000000", "000001", "000002"}) {
    EXPECT_NE(xml.find(std::string("<Grid Name=\"") + g + "\""), std::string::npos) << g;
    EXPECT_NE(xml.find(std::string("view.h5:/snapshots/") + g + "/position"), std::string::npos) << g;
  }
  EXPECT_NE(xml.find("<Grid Name=\"failure\""), std::string::npos);
  EXPECT_NE(xml.find("<Time Value=\"1e-06\"/>"), std::string::npos);
  EXPECT_EQ(count_of(xml, "TopologyType=\"Polyvertex\" NumberOfElements=\"5\""), 4u);
  EXPECT_EQ(count_of(xml, "GeometryType=\"XY\""), 4u);
  EXPECT_EQ(count_of(xml, "<Attribute Name=\"velocity\" AttributeType=\"Vector\""), 4u);
  EXPECT_EQ(count_of(xml, "<Attribute Name=\"stress\" AttributeType=\"Tensor\""), 4u);
  EXPECT_EQ(count_of(xml, "<Attribute Name=\"temperature\" AttributeType=\"Scalar\""), 4u);
  EXPECT_EQ(count_of(xml, "<Attribute Name=\"material\" AttributeType=\"Scalar\""), 4u);
  EXPECT_EQ(count_of(xml, "<DataItem Dimensions=\"5 9\" NumberType=\"Float\""), 4u);
  EXPECT_EQ(count_of(xml, "<DataItem Dimensions=\"5 3\" NumberType=\"Float\""), 4u);
  EXPECT_EQ(count_of(xml, "NumberType=\"Int\" Precision=\"4\""), 8u);  // connectivity + material
  EXPECT_FALSE(fs::exists(out.xdmf_path() + "." + std::to_string(::getpid()) + ".tmp"));  // renamed away
  out.close();

  const File f(path);  // the connectivity the XDMF points at
  EXPECT_EQ(read_all<std::int32_t>(f.id, "/xdmf/polyvertex_5", H5T_NATIVE_INT32),
            (std::vector<std::int32_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(read_string(f.id, "/failure", "message"), "NaN velocity at particle 2");
  EXPECT_EQ(read_attr<std::int64_t>(f.id, "/failure", "step", H5T_NATIVE_INT64), 3);
  expect_snapshot(f.id, "/failure", n, 2, 3, 3, 3e-6);
}

TEST(Output, XdmfAttributeTypes) {
  using frictherm::coupling::xdmf_attribute_type;
  EXPECT_EQ(xdmf_attribute_type(1), "Scalar");
  EXPECT_EQ(xdmf_attribute_type(2), "Matrix");  // VTK's vector filters assert 3 components
  EXPECT_EQ(xdmf_attribute_type(4), "Matrix");
  EXPECT_EQ(xdmf_attribute_type(3), "Vector");
  EXPECT_EQ(xdmf_attribute_type(9), "Tensor");
  EXPECT_EQ(xdmf_attribute_type(6), "Tensor6");
  EXPECT_EQ(frictherm::coupling::xdmf_path_for("out/run.h5"), "out/run.xdmf");
  EXPECT_EQ(frictherm::coupling::xdmf_path_for("run"), "run.xdmf");
  EXPECT_EQ(frictherm::coupling::xml_escape("a<b&\"c\""), "a&lt;b&amp;&quot;c&quot;");
}

TEST(Output, FailureDiscardsUnfinishedSnapshotAndMisuseIsReported) {
  const TempDir tmp;
  const std::string path = tmp.file("misuse.h5");
  {
    H5Output out(path, 2);
    const std::vector<double> x(6, 1.0);
    EXPECT_THROW(out.snapshot_field("x", x.data(), 3, 1), std::logic_error);
    EXPECT_THROW(out.end_snapshot(), std::logic_error);
    out.begin_snapshot(0, 0.0);
    EXPECT_THROW(out.begin_snapshot(1, 0.0), std::logic_error);
    EXPECT_THROW(out.snapshot_field("position", x.data(), 2, 3), std::invalid_argument);
    out.snapshot_field("mass", x.data(), 3, 1);
    EXPECT_THROW(out.snapshot_field("volume", x.data(), 2, 1), std::invalid_argument);
    EXPECT_THROW(out.snapshot_field("bad/name", x.data(), 3, 1), std::invalid_argument);
    out.begin_failure(5, 1.0, "stopped");  // discards the unfinished snapshot
    out.snapshot_field("position", x.data(), 3, 2);
    out.end_snapshot();
    EXPECT_EQ(out.snapshot_count(), 0u);
    EXPECT_THROW(out.declare_series({"energy", "time"}), std::invalid_argument);
    EXPECT_THROW(out.append_series({1.0}), std::logic_error);
    out.close();
    EXPECT_THROW(out.flush(), std::logic_error);
  }
  const File f(path);
  EXPECT_TRUE(links(f.id, "/snapshots").empty());
  EXPECT_EQ(shape(f.id, "/failure/position"), (std::vector<hsize_t>{3, 2}));
}

// The thermal grid's nodes (node_field): /nodes/<the snapshot's number> with step and time, only with an
// ended snapshot (an unfinished one leaves neither), refused for the failure state and for mismatched
// rows, and drawn by RUN_nodes.xdmf (its own file: RUN.xdmf keeps only the particles).
TEST(Output, NodeFieldsFollowTheirSnapshot) {
  const TempDir tmp;
  const std::string path = tmp.file("nodes.h5");
  const std::size_t n = 4, m = 5;  // particles, nodes
  const std::vector<double> x(3 * m, 0.25), t{300.0, 301.0, 302.0, 303.0, 304.0};
  const std::vector<std::int32_t> lattice(2 * m, 1);
  {
    H5Output out(path, 2);
    for (int k = 0; k < 2; ++k) {
      out.begin_snapshot(10L * k, 0.5 * k);
      Particles(n, 2, k).write(out, n, 2);
      if (k == 1) {  // the first snapshot has no nodes
        out.node_field("position", x.data(), m, 2);
        out.node_field("temperature", t.data(), m, 1);
        out.node_field("lattice", lattice.data(), m, 2);
        EXPECT_THROW(out.node_field("heat_capacity", t.data(), m - 1, 1), std::invalid_argument);
        EXPECT_THROW(out.node_field("position", x.data(), m, 3), std::invalid_argument);
      }
      out.end_snapshot();
    }
    out.begin_snapshot(30, 1.5);  // never ended: its nodes must not appear
    out.node_field("temperature", t.data(), m, 1);
    out.begin_failure(31, 1.6, "stopped");
    EXPECT_THROW(out.node_field("temperature", t.data(), m, 1), std::logic_error);
    out.end_snapshot();
  }
  const File f(path);
  EXPECT_EQ(links(f.id, "/nodes"), (std::vector<std::string>{"000001"}));
  EXPECT_EQ(shape(f.id, "/nodes/000001/position"), (std::vector<hsize_t>{m, 2}));
  EXPECT_EQ(shape(f.id, "/nodes/000001/lattice"), (std::vector<hsize_t>{m, 2}));
  EXPECT_EQ(read_attr<std::int64_t>(f.id, "/nodes/000001", "step", H5T_NATIVE_INT64), 10);
  EXPECT_EQ(read_attr<double>(f.id, "/nodes/000001", "time", H5T_NATIVE_DOUBLE), 0.5);
  EXPECT_EQ(read_string(f.id, "/nodes/000001/temperature", "units"), "K");
  std::ifstream nodes(frictherm::coupling::xdmf_nodes_path_for(path));
  const std::string text((std::istreambuf_iterator<char>(nodes)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("nodes.h5:/nodes/000001/temperature"), std::string::npos) << text;
  EXPECT_NE(text.find("Dimensions=\"5\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">nodes.h5:/xdmf/polyvertex_5"),
            std::string::npos) << text;
  std::ifstream particles(frictherm::coupling::xdmf_path_for(path));
  const std::string ptext((std::istreambuf_iterator<char>(particles)), std::istreambuf_iterator<char>());
  EXPECT_EQ(ptext.find("/nodes/"), std::string::npos);
}

TEST(Output, UnwritablePathGivesClearError) {
  const std::string path = "/nonexistent-frictherm-dir/sub/run.h5";
  try {
    H5Output out(path, 2);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("cannot create the file"), std::string::npos) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
  }
  EXPECT_THROW(H5Output("x.h5", 4), std::invalid_argument);
}

// A child process writes three snapshots, metadata and series, starts a fourth snapshot with many
// fields (enough metadata to overflow the metadata cache), buffers more series rows and is then
// killed with SIGKILL. Everything ended before the kill must be readable; nothing of the fourth.
TEST(Output, SurvivesKillDuringSnapshot) {
  const TempDir tmp;
  const std::string path = tmp.file("crash.h5");
  const std::size_t n = 50;
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    H5Output out(path, 3);
    out.write_metadata("scene", "{\"run\": {}}");
    out.declare_series({"time", "energy"});
    for (int k = 0; k < 3; ++k) {
      for (int r = 0; r < 50; ++r) out.append_series({k * 50.0 + r, 1.0});
      out.begin_snapshot(k, k * 50.0);
      Particles(n, 3, k).write(out, n, 3);
      out.end_snapshot();
    }
    for (int r = 0; r < 30; ++r) out.append_series({1000.0 + r, 2.0});  // never flushed
    out.begin_snapshot(3, 150.0);
    Particles(n, 3, 3).write(out, n, 3);
    const std::vector<double> v(n, 1.0);
    for (int i = 0; i < 4000; ++i) out.snapshot_field("extra_" + std::to_string(i), v.data(), n, 1);
    ::kill(::getpid(), SIGKILL);
    ::_exit(3);  // not reached
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status)) << "child exited normally with " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), SIGKILL);

  const File f(path);
  ASSERT_GE(f.id, 0) << "the killed run's file does not open";
  EXPECT_EQ(links(f.id, "/snapshots"), (std::vector<std::string>{"000000", "000001", "000002"}));
  for (int k = 0; k < 3; ++k) expect_snapshot(f.id, "/snapshots/00000" + std::to_string(k), n, 3, k, k, k * 50.0);
  EXPECT_EQ(read_string(f.id, "/meta/scene"), "{\"run\": {}}");
  const auto table = frictherm::coupling::read_series(path);
  ASSERT_EQ(table.rows(), 150u);  // rows up to the last ended snapshot
  EXPECT_EQ(table.columns[0].back(), 149.0);
  const std::string xml = slurp(tmp.file("crash.xdmf"));
  EXPECT_EQ(count_of(xml, "GridType=\"Uniform\""), 3u);
  EXPECT_NE(xml.find("</Xdmf>"), std::string::npos);
}

// examples/plot_run.py (Debian python3-h5py + python3-matplotlib) on a small generated run.
TEST(Output, PlotScriptDrawsGeneratedRun) {
  // scripts/install_deps.sh installs these packages, so their absence is a failure, not a skip.
  ASSERT_EQ(std::system("/usr/bin/python3 -c 'import h5py, matplotlib, numpy' >/dev/null 2>&1"), 0)
      << "/usr/bin/python3 with h5py, matplotlib and numpy is not available (run scripts/install_deps.sh)";
  const TempDir tmp;
  const std::string path = tmp.file("plot.h5");
  for (const int dim : {2, 3}) {
    {
      const std::size_t n = 60;
      H5Output out(path, dim);
      out.declare_series({"time", "kinetic_energy", "strain_energy"});
      for (int k = 0; k < 2; ++k) {
        out.append_series({1e-6 * k, 1.0 + k, 2.0 - k});
        out.begin_snapshot(k, 1e-6 * k);
        Particles(n, dim, k).write(out, n, dim);
        out.end_snapshot();
      }
    }
    const std::string script = std::string(FRICTHERM_SOURCE_DIR) + "/examples/plot_run.py";
    const std::string prefix = tmp.file("fig" + std::to_string(dim));
    const std::string cmd = "/usr/bin/python3 " + script + " " + path + " --field von_mises -o " + prefix +
                            " >" + prefix + ".log 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp(prefix + ".log");
    EXPECT_GT(fs::file_size(prefix + "_particles.png"), 1000u);
    EXPECT_GT(fs::file_size(prefix + "_series.png"), 1000u);
    const std::string list = "/usr/bin/python3 " + script + " " + path + " --list >" + prefix + ".txt 2>&1";
    EXPECT_EQ(std::system(list.c_str()), 0) << slurp(prefix + ".txt");
    EXPECT_NE(slurp(prefix + ".txt").find("kinetic_energy"), std::string::npos);
  }
}

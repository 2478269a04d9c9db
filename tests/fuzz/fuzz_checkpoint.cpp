// libFuzzer target (issue 34): the checks `frictherm resume` applies to a checkpoint before its first
// step (checkpoint_ranks, checkpoint_scene, checkpoint_marks, then restore_checkpoint: the simulation
// and thermal run built from the stored scene, the state checked and restored), on damaged copies of
// a valid checkpoint. Structure-aware: the seed checkpoint is written once per process by a short run
// of a small heated penalty-contact scene (tests/fuzz/checkpoint_seed_scene.json, shared with
// tests/robustness/damaged_checkpoints.py: hot
// spots, a reaction, slip histories), stopped at step 60 of 80; the input is a list of mutations of
// it, 12 bytes each:
//   byte 0: which dataset (modulo their count); byte 1: what (modulo 8):
//     0 delete it                     1 resize it to (bytes 2-3) modulo 2n + 3 items (padding repeats)
//     2 set value (bytes 2-3) to the double / int64 in bytes 4-11
//     3 store it as another type (byte 2: f32 f64 i8 i16 i32 i64 u8 u64)
//     4 change its rank (n -> n x 1, n x c -> n c)
//     5 a root attribute (byte 2: format, dimension, ranks) set to the int32 in bytes 4-7, or deleted
//       (byte 3 odd)
//     6 flip the bits of byte 6 | 1 at file offset (bytes 2-5) modulo the size (after the others)
//     7 replace it by a group
// Every refusal must be an OutputError (what resume reports with exit code 2, naming the file and
// the dataset) or a SceneError (the stored scene); anything else escapes to libFuzzer as a finding,
// as do crashes, sanitizer reports, leaks, -rss_limit_mb and -timeout.
#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/restore_checkpoint.hpp>
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>

#include <hdf5.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace {

using namespace frictherm::coupling;



struct Seed {
  std::string dir, checkpoint, bytes;
  std::vector<std::string> datasets;
  Seed() = default;
  Seed(const Seed&) = delete;
  Seed(Seed&& o) noexcept : dir(std::move(o.dir)), checkpoint(std::move(o.checkpoint)), bytes(std::move(o.bytes)),
                            datasets(std::move(o.datasets)) {
    o.dir.clear();
  }
  ~Seed() {  // the folder of the seed run and of the damaged copies
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
};

herr_t collect(hid_t group, const char* name, const H5L_info_t*, void* out) {
  const hid_t obj = H5Oopen(group, name, H5P_DEFAULT);
  if (obj >= 0) {
    if (H5Iget_type(obj) == H5I_DATASET) static_cast<std::vector<std::string>*>(out)->push_back(name);
    H5Oclose(obj);
  }
  return 0;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

const Seed& seed() {
  static const Seed seed_checkpoint = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    Seed s;
    char dir[] = "/tmp/fuzz_checkpoint_XXXXXX";
    if (mkdtemp(dir) == nullptr) throw std::runtime_error("fuzz_checkpoint: cannot create a folder in /tmp");
    s.dir = dir;
    const std::string scene_file = FRICTHERM_SOURCE_DIR "/tests/fuzz/checkpoint_seed_scene.json";
    const Scene scene =
        parse_scene(read_file(scene_file), scene_file, s.dir, "fuzz", {{"run.threads", "1"}, {"run.max_steps", "60"}});
    RunOptions o;
    o.output = s.dir + "/seed.h5";
    o.quiet = true;
    o.threads = 1;
    run_scene(scene, o);
    s.checkpoint = checkpoint_path(o.output);
    s.bytes = read_file(s.checkpoint);
    const hid_t f = H5Fopen(s.checkpoint.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    H5Lvisit(f, H5_INDEX_NAME, H5_ITER_INC, collect, &s.datasets);
    H5Fclose(f);
    if (s.datasets.empty()) throw std::runtime_error("fuzz_checkpoint: the seed checkpoint has no dataset");
    return s;
  }();
  return seed_checkpoint;
}

template <class T> T take(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// Rewrites dataset `name` of `f` with `values` (as doubles), `dims` and file type `type`.
void rewrite(hid_t f, const std::string& name, const std::vector<double>& values, int rank, const hsize_t* dims,
             hid_t type) {
  H5Ldelete(f, name.c_str(), H5P_DEFAULT);
  const hid_t space = H5Screate_simple(rank, dims, nullptr);
  const hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(lcpl, 1);
  // With a Fletcher32 checksum as checkpoints hold them (format 3), so the mutation is what is checked.
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  if (H5Sget_simple_extent_npoints(space) > 0) {
    H5Pset_chunk(dcpl, rank, dims);
    H5Pset_fletcher32(dcpl);
  }
  const hid_t d = H5Dcreate2(f, name.c_str(), type, space, lcpl, dcpl, H5P_DEFAULT);
  H5Pclose(dcpl);
  if (d >= 0 && !values.empty()) H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  if (d >= 0) H5Dclose(d);
  H5Pclose(lcpl);
  H5Sclose(space);
}

void mutate(hid_t f, const Seed& s, const std::uint8_t* m, std::vector<std::pair<std::size_t, std::uint8_t>>& flips) {
  const std::string name = s.datasets[m[0] % s.datasets.size()];
  const int what = m[1] % 8;
  if (what == 5) {
    static const char* const kAttributes[] = {"format", "dimension", "ranks"};
    const char* a = kAttributes[m[2] % 3];
    if (H5Aexists(f, a) > 0) H5Adelete(f, a);
    if (m[3] % 2 == 0) {
      const std::int32_t v = take<std::int32_t>(m + 4);
      const hid_t space = H5Screate(H5S_SCALAR);
      const hid_t attr = H5Acreate2(f, a, H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT);
      if (attr >= 0) {
        H5Awrite(attr, H5T_NATIVE_INT32, &v);
        H5Aclose(attr);
      }
      H5Sclose(space);
    }
    return;
  }
  if (what == 6) {
    flips.emplace_back(take<std::uint32_t>(m + 2), static_cast<std::uint8_t>(m[6] | 1));
    return;
  }
  if (H5Lexists(f, name.c_str(), H5P_DEFAULT) <= 0) return;  // deleted by an earlier mutation
  const hid_t d = H5Dopen2(f, name.c_str(), H5P_DEFAULT);
  if (d < 0) return;  // a group by now
  const hid_t space = H5Dget_space(d), file_type = H5Dget_type(d);
  hsize_t dims[2] = {0, 1};
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank >= 1 && rank <= 2) H5Sget_simple_extent_dims(space, dims, nullptr);
  const bool is_float = H5Tget_class(file_type) == H5T_FLOAT;
  const hid_t type = H5Tcopy(file_type);
  std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
  if (!v.empty()) H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Tclose(file_type);
  H5Sclose(space);
  H5Dclose(d);
  const hsize_t c = rank == 2 ? dims[1] : 1;
  if (rank < 1 || rank > 2 || c == 0) {
    H5Tclose(type);
    return;
  }
  switch (what) {
    case 0: H5Ldelete(f, name.c_str(), H5P_DEFAULT); break;
    case 1: {
      const hsize_t n = take<std::uint16_t>(m + 2) % (2 * dims[0] + 3);
      std::vector<double> w(static_cast<std::size_t>(n * c), v.empty() ? 0.0 : v.back());
      std::copy(v.begin(), v.begin() + static_cast<long>(std::min(v.size(), w.size())), w.begin());
      const hsize_t nd[2] = {n, c};
      rewrite(f, name, w, rank, nd, type);
      break;
    }
    case 2:
      if (!v.empty()) {
        v[take<std::uint16_t>(m + 2) % v.size()] =
            is_float ? take<double>(m + 4) : static_cast<double>(take<std::int64_t>(m + 4));
        rewrite(f, name, v, rank, dims, type);
      }
      break;
    case 3: {
      const hid_t types[] = {H5T_IEEE_F32LE, H5T_IEEE_F64LE, H5T_STD_I8LE, H5T_STD_I16LE,
                             H5T_STD_I32LE,  H5T_STD_I64LE,  H5T_STD_U8LE, H5T_STD_U64LE};
      rewrite(f, name, v, rank, dims, types[m[2] % 8]);
      break;
    }
    case 4: {
      const hsize_t nd[2] = {rank == 2 ? dims[0] * dims[1] : dims[0], 1};
      rewrite(f, name, v, rank == 2 ? 1 : 2, nd, type);
      break;
    }
    case 7:
      H5Ldelete(f, name.c_str(), H5P_DEFAULT);
      if (const hid_t g = H5Gcreate2(f, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT); g >= 0) H5Gclose(g);
      break;
    default: break;
  }
  H5Tclose(type);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Seed& s = seed();
  const std::string path = s.dir + "/in.h5.checkpoint";
  write_file(path, s.bytes);
  std::vector<std::pair<std::size_t, std::uint8_t>> flips;
  if (const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT); f >= 0) {
    for (std::size_t at = 0; at + 12 <= size && at < 12 * 8; at += 12) mutate(f, s, data + at, flips);
    H5Fclose(f);
  }
  if (!flips.empty()) {
    std::string bytes = read_file(path);
    for (const auto& [offset, mask] : flips)
      if (!bytes.empty()) bytes[offset % bytes.size()] = static_cast<char>(bytes[offset % bytes.size()] ^ mask);
    write_file(path, bytes);
  }
  try {
    if (checkpoint_ranks(path) > 0) return 0;  // resume refuses a decomposed run's checkpoint (exit code 2)
    // The memory bound of the scene fuzzer: a damaged /scene that builds a huge simulation is refused.
    const Scene scene = checkpoint_scene(path, {{"run.max_memory", "64e6"}});
    checkpoint_marks(path);
    restore_checkpoint(scene, path);
  } catch (const OutputError&) {
    // A clear refusal: what resume reports with exit code 2, naming the file and the dataset.
  } catch (const SceneError&) {
    // The stored scene refused by its key (exit code 2).
  }
  return 0;
}

// libFuzzer target (issue 15): scene parsing and validation, the path `frictherm validate` takes
// (parse_scene with --set overrides, then describe_scene, which builds the simulation), without
// running steps and without writing files.
//
// Input: the scene text, optionally followed by NUL-separated --set assignments
//   {"dimension": 2, ...}\0solver.cfl=0.3\0bodies[0].velocity=[1,0]
// Every refusal must be a SceneError (what `validate` reports with exit code 2 and the key path);
// any other exception, a crash, a sanitizer report, a leak, more than -rss_limit_mb or more than
// -timeout seconds is a finding. run.max_memory is forced to kFuzzMemoryLimit (overriding the
// input's), so accepted scenes stay small enough to build inside the fuzzer's memory limit; the
// cost estimate (scene_cost.cpp) must hold that bound, or the fuzzer reports the overrun.
// Relative image paths resolve against examples/ (FRICTHERM_FUZZ_BASE_DIR overrides it).
#include <frictherm/coupling/scene.hpp>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <ostream>
#include <streambuf>
#include <string>
#include <vector>

namespace {

constexpr const char* kFuzzMemoryLimit = "64e6";  // bytes: run.max_memory of every fuzzed scene

// An ostream that discards what describe_scene prints.
class NullBuffer : public std::streambuf {
 protected:
  int overflow(int c) override { return c; }
  std::streamsize xsputn(const char*, std::streamsize n) override { return n; }
};

std::string base_dir() {
  const char* env = std::getenv("FRICTHERM_FUZZ_BASE_DIR");
  return env ? env : FRICTHERM_SOURCE_DIR "/examples";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace frictherm::coupling;
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::size_t first_nul = input.find('\0');
  const std::string text = input.substr(0, first_nul);
  static const std::string dir = base_dir();
  try {
    std::vector<SceneOverride> overrides;
    for (std::size_t at = first_nul; at != std::string::npos && at < input.size();) {
      const std::size_t next = input.find('\0', at + 1);
      const std::string assignment = input.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1);
      if (!assignment.empty()) overrides.push_back(parse_override(assignment));
      at = next;
    }
    overrides.push_back({"run.max_memory", kFuzzMemoryLimit});
    const Scene scene = parse_scene(text, "<fuzz>", dir, "fuzz", overrides);
    NullBuffer discard;
    std::ostream out(&discard);
    describe_scene(scene, out);
  } catch (const SceneError&) {
    // A clear refusal: what `frictherm validate` reports with exit code 2.
  }
  // Anything else (std::bad_alloc, std::runtime_error without a key path, ...) escapes to libFuzzer,
  // which reports it as a crash: validate would answer with exit code 1 and no key path.
  return 0;
}

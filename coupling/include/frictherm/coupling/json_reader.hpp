#pragma once
// A validating reader over nlohmann::json that remembers where it is in the document.
//
// Every reader holds one JSON value and its key path (e.g. `bodies[1].shape.radius`). Getters check
// presence, type and range, and every mistake becomes one SceneError whose message starts with the
// key path and says what was expected and what was found:
//   materials.steel.poisson_ratio: expected a number in (-1, 0.5), got 0.7
// Object readers remember each key they were asked about (present or not); finish() then rejects any
// other key, listing the keys allowed at that place.
#include <nlohmann/json.hpp>

#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace frictherm::coupling {

/// The JSON type scenes are read into (objects keep the file's key order).
using Json = nlohmann::ordered_json;

/// `text` with control characters (other than newline and tab) written as JSON escapes, \u0000:
/// a key holding "\u0000" had cut the message at the NUL (issue 34).
inline std::string escape_control_characters(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\n' && c != '\t') || u == 0x7f) {
      static const char* const hex = "0123456789abcdef";
      out += "\\u00";
      out += hex[u >> 4];
      out += hex[u & 15];
    } else {
      out += c;
    }
  }
  return out;
}

/// Any mistake in a scene: malformed JSON, unknown key, wrong type, value out of range, ... The
/// message's control characters are escaped (escape_control_characters).
class SceneError : public std::runtime_error {
 public:
  explicit SceneError(const std::string& message) : std::runtime_error(escape_control_characters(message)) {}
  explicit SceneError(const char* message) : SceneError(std::string(message)) {}
  /// A scene the heat hand-off refused when it started (std::invalid_argument of the coupler):
  /// under `key` (e.g. "thermal.materials"), unless the message names its own key path already.
  static SceneError at_key(const std::string& key, const std::string& message) {
    for (const char* section : {"thermal.", "coupling.", "contact.", "grid.", "bodies", "materials."})
      if (message.rfind(section, 0) == 0) return SceneError(message);
    return SceneError(key + ": " + message);
  }
};

/// A closed, open or half-open interval of allowed numbers.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  static Range any() { return {}; }
  static Range positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
  static Range non_negative() { return {0.0, std::numeric_limits<double>::infinity(), false, false}; }
  static Range open(double a, double b) { return {a, b, true, true}; }          // (a, b)
  static Range left_open(double a, double b) { return {a, b, true, false}; }    // (a, b]
  static Range closed(double a, double b) { return {a, b, false, false}; }      // [a, b]

  bool contains(double x) const;
  /// "a number", "a number > 0", "a number >= 0", "a number in (-1, 0.5)", ...
  std::string describe() const;
};

/// Short description of a JSON value for messages: 0.7, "text", true, null, an array of 3 elements, an object.
std::string describe_json(const Json& value);

/// Formats a number for messages (shortest of %g with up to 10 significant digits).
std::string format_number(double x);

class JsonReader {
 public:
  /// `path` is the key path of `value` ("" for the document root).
  JsonReader(const Json& value, std::string path);

  const Json& json() const { return *value_; }
  const std::string& path() const { return path_; }
  /// Path of a member: "grid" + "lo" -> "grid.lo"; the root + "grid" -> "grid".
  std::string member_path(const std::string& key) const;

  // ---- errors --------------------------------------------------------------------------------------
  /// Throws SceneError("<path>: <message>").
  [[noreturn]] void fail(const std::string& message) const;
  /// Throws SceneError("<path>: expected <what>, got <this value>").
  [[noreturn]] void expected(const std::string& what) const;

  // ---- this value -----------------------------------------------------------------------------------
  bool is_object() const { return value_->is_object(); }
  bool is_array() const { return value_->is_array(); }
  bool is_number() const { return value_->is_number(); }
  bool is_string() const { return value_->is_string(); }

  double as_number(const Range& range = Range::any()) const;
  /// An integer (a JSON number with no fractional part, 1e3 included) in [min, max].
  long as_integer(long min = std::numeric_limits<long>::min(), long max = std::numeric_limits<long>::max()) const;
  std::string as_string() const;
  bool as_bool() const;
  /// A string equal to one of `choices`.
  std::string as_choice(const std::vector<std::string>& choices) const;
  /// An array of exactly `n` numbers, each in `range`.
  std::vector<double> as_vector(std::size_t n, const Range& range = Range::any()) const;
  /// An array of numbers of any length >= min_size.
  std::vector<double> as_number_list(std::size_t min_size = 0, const Range& range = Range::any()) const;

  /// Requires an array (of at least min_size elements) and returns a reader per element, path `p[i]`.
  std::vector<JsonReader> elements(std::size_t min_size = 0) const;
  /// Requires an object and returns its keys in file order (for maps such as `materials`). Every key
  /// counts as known.
  std::vector<std::string> keys() const;
  /// keys() with a reader per member, in file order, without looking each key up (a lookup in an
  /// ordered object is a linear search: 50,000 materials had taken 12 s, issue 34).
  std::vector<std::pair<std::string, JsonReader>> members() const;

  // ---- members of an object (the value must be an object: checked on construction of the first query)
  /// Marks `key` as known and says whether it is present.
  bool has(const std::string& key) const;
  /// A required member; `what` describes it in the "missing" message.
  JsonReader at(const std::string& key, const std::string& what = "") const;
  /// An optional member.
  std::optional<JsonReader> find(const std::string& key) const;

  double number(const std::string& key, const Range& range = Range::any()) const;
  double number(const std::string& key, double default_value, const Range& range) const;
  long integer(const std::string& key, long min, long max) const;
  long integer(const std::string& key, long default_value, long min, long max) const;
  std::string string(const std::string& key) const;
  std::string string(const std::string& key, const std::string& default_value) const;
  std::string choice(const std::string& key, const std::vector<std::string>& choices) const;
  std::string choice(const std::string& key, const std::vector<std::string>& choices,
                     const std::string& default_value) const;
  std::vector<double> vector(const std::string& key, std::size_t n, const Range& range = Range::any()) const;

  /// Rejects members that no query asked about: "<path>.<key>: unknown key (allowed here: a, b, c)",
  /// followed by "; did you mean 'k'?" when an allowed key k is near the unknown one (nearest_key).
  void finish() const;
  /// The keys asked about so far, in query order: the keys allowed at this place (what finish() checks).
  const std::vector<std::string>& known_keys() const { return known_; }

  /// The validator's key tables: when set, every finish() reports its object's key path, the keys
  /// allowed there and whether the object is a map of user names (keys(), e.g. `materials`). The
  /// scene schema test (tests/coupling/test_scene_schema.cpp) builds docs/scene.schema.json from
  /// these. One observer for the whole process, not thread-safe: for tools and tests only.
  using KeyTableObserver =
      std::function<void(const std::string& path, const std::vector<std::string>& allowed, bool is_map)>;
  static void set_key_table_observer(KeyTableObserver observer);

 private:
  void require_object() const;
  void mark(const std::string& key) const;

  const Json* value_;
  std::string path_;
  mutable std::vector<std::string> known_;  // keys asked about, in query order
  mutable bool map_ = false;                 // keys() was asked: the keys are user names
};

/// Levenshtein distance: the fewest single-character insertions, deletions and substitutions that
/// turn a into b.
std::size_t edit_distance(const std::string& a, const std::string& b);
/// The allowed key nearest to a mistyped one (gird -> grid), or "" when none is near: distance at
/// most 1 for keys of up to 3 characters, else at most max(2, length / 3), and shorter than both
/// keys (x is not "near" a); ties go to the first key.
std::string nearest_key(const std::string& typo, const std::vector<std::string>& allowed);

/// Malformed JSON (a syntax error; json_text.cpp). A --set value that is not JSON is a bare word.
class JsonSyntaxError : public SceneError {
 public:
  using SceneError::SceneError;
};

/// Limits on scene text (json_text.cpp), each refused with the key path, line and column.
constexpr std::size_t kMaxJsonDepth = 64;           // objects and arrays inside each other
constexpr std::size_t kMaxKeyLength = 256;          // characters of an object key
constexpr std::size_t kMaxStringLength = 1 << 20;   // characters of a string value
constexpr std::size_t kMaxSceneBytes = 8u << 20;    // a scene file (scene_parse.cpp: load_scene)

/// Parses scene text (comments allowed; json_text.cpp). Malformed JSON becomes a JsonSyntaxError
/// "malformed JSON at line L, column C: <detail> (in PATH)"; duplicate keys, numbers beyond a double
/// and the limits above a SceneError "PATH: ... at line L, column C; expected ...". `root_path`
/// prefixes the key paths (a --set value: its key).
Json parse_json_text(const std::string& text, const std::string& root_path = "");

}  // namespace frictherm::coupling

#include <set>
#include <vector>
#include <frictherm/coupling/json_reader.hpp>
#include <frictherm/coupling/scene_value_observer.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace frictherm::coupling {

bool Range::contains(double x) const {
  if (!std::isfinite(x)) return false;
  const bool above = lo_open ? x > lo : x >= lo;
  const bool below = hi_open ? x < hi : x <= hi;
  return above && below;
}

std::string Range::describe() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (!has_lo && !has_hi) return "a number";
  if (has_lo && !has_hi) return std::string("a number ") + (lo_open ? "> " : ">= ") + format_number(lo);
  if (!has_lo) return std::string("a number ") + (hi_open ? "< " : "<= ") + format_number(hi);
  return std::string("a number in ") + (lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) +
         (hi_open ? ")" : "]");
}

std::string format_number(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", x);
  return buf;
}

std::string describe_json(const Json& v) {
  switch (v.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::boolean: return v.get<bool>() ? "true" : "false";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned: return v.dump();
    case Json::value_t::number_float: return format_number(v.get<double>());
    case Json::value_t::string: {
      std::string s = v.get<std::string>();
      if (s.size() > 40) s = s.substr(0, 37) + "...";
      return "\"" + s + "\"";
    }
    case Json::value_t::array: {
      const std::size_t n = v.size();
      // A short array of numbers (a point, a box corner, a range) is shown as its values.
      if (n > 0 && n <= 4 && std::all_of(v.begin(), v.end(), [](const Json& e) { return e.is_number(); })) {
        std::string list = "[";
        for (std::size_t i = 0; i < n; ++i) list += (i ? ", " : "") + describe_json(v[i]);
        return list + "]";
      }
      return n == 1 ? "an array of 1 element" : "an array of " + std::to_string(n) + " elements";
    }
    case Json::value_t::object: return "an object";
    default: return "a value of unsupported type";
  }
}

JsonReader::JsonReader(const Json& value, std::string path) : value_(&value), path_(std::move(path)) {}

std::string JsonReader::member_path(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void JsonReader::fail(const std::string& message) const {
  throw SceneError((path_.empty() ? std::string("scene") : path_) + ": " + message);
}

void JsonReader::expected(const std::string& what) const {
  fail("expected " + what + ", got " + describe_json(*value_));
}

namespace {
SceneValueObserver& value_observer() {
  static SceneValueObserver observer;
  return observer;
}
void report(const std::string& path, const std::string& what, const std::vector<std::string>& choices = {}) {
  if (value_observer()) value_observer()(path, what, choices);
}
// The same, with the description built only when an observer listens (a scene of 50,000 materials
// spent a quarter of its validation formatting range descriptions nobody read).
template <class Describe>
void report_lazily(const std::string& path, const Describe& describe) {
  if (value_observer()) value_observer()(path, describe(), {});
}
}  // namespace

void set_scene_value_observer(SceneValueObserver observer) { value_observer() = std::move(observer); }

double JsonReader::as_number(const Range& range) const {
  report_lazily(path_, [&] { return range.describe(); });
  if (!value_->is_number()) expected(range.describe());
  const double x = value_->get<double>();
  if (!range.contains(x)) expected(range.describe());
  return x;
}

long JsonReader::as_integer(long min, long max) const {
  std::string what = "an integer";
  if (min != std::numeric_limits<long>::min() && max != std::numeric_limits<long>::max())
    what += " in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  else if (min != std::numeric_limits<long>::min())
    what += " >= " + std::to_string(min);
  else if (max != std::numeric_limits<long>::max())
    what += " <= " + std::to_string(max);
  report(path_, what);
  if (!value_->is_number()) expected(what);
  // Compare in the integer domain: 2^63 written as a float equals double(LONG_MAX) after rounding,
  // so a float is first bounded by the exact powers of two before any cast (a cast out of range is UB).
  if (value_->is_number_unsigned()) {
    const auto u = value_->get<unsigned long long>();
    if (u > static_cast<unsigned long long>(std::numeric_limits<long>::max())) expected(what);
  }
  const double x = value_->get<double>();
  constexpr double two63 = 9223372036854775808.0;  // 2^63, exact in double
  if (!std::isfinite(x) || std::floor(x) != x || x < -two63 || x >= two63) expected(what);
  const long v = value_->is_number_float() ? static_cast<long>(x) : value_->get<long>();
  if (v < min || v > max) expected(what);
  return v;
}

std::string JsonReader::as_string() const {
  report(path_, "a string");
  if (!value_->is_string()) expected("a string");
  return value_->get<std::string>();
}

bool JsonReader::as_bool() const {
  report(path_, "true or false");
  if (!value_->is_boolean()) expected("true or false");
  return value_->get<bool>();
}

std::string JsonReader::as_choice(const std::vector<std::string>& choices) const {
  std::string what = choices.size() == 1 ? "\"" + choices[0] + "\"" : "one of ";
  if (choices.size() > 1)
    for (std::size_t k = 0; k < choices.size(); ++k) what += (k ? ", \"" : "\"") + choices[k] + "\"";
  report(path_, what, choices);
  if (!value_->is_string()) expected(what);
  const std::string s = value_->get<std::string>();
  if (std::find(choices.begin(), choices.end(), s) == choices.end()) expected(what);
  return s;
}

std::vector<double> JsonReader::as_vector(std::size_t n, const Range& range) const {
  const std::string what =
      "an array of " + std::to_string(n) + (n == 1 ? " number" : " numbers") + " (one per dimension)";
  report_lazily(path_, [&] { return what + ", each " + range.describe(); });
  if (!value_->is_array() || value_->size() != n) expected(what);
  std::vector<double> out;
  out.reserve(n);
  for (const JsonReader& e : elements()) out.push_back(e.as_number(range));
  return out;
}

std::vector<double> JsonReader::as_number_list(std::size_t min_size, const Range& range) const {
  report_lazily(path_, [&] {
    return "an array of " + (min_size > 0 ? "at least " + std::to_string(min_size) + " " : std::string()) +
           "numbers, each " + range.describe();
  });
  if (!value_->is_array() || value_->size() < min_size)
    expected("an array of " + (min_size > 0 ? "at least " + std::to_string(min_size) + " " : std::string()) +
             "numbers");
  std::vector<double> out;
  out.reserve(value_->size());
  for (const JsonReader& e : elements()) out.push_back(e.as_number(range));
  return out;
}

std::vector<JsonReader> JsonReader::elements(std::size_t min_size) const {
  if (!value_->is_array() || value_->size() < min_size)
    expected(min_size > 0 ? "an array of at least " + std::to_string(min_size) +
                                (min_size == 1 ? " element" : " elements")
                          : std::string("an array"));
  std::vector<JsonReader> out;
  out.reserve(value_->size());
  for (std::size_t i = 0; i < value_->size(); ++i)
    out.emplace_back((*value_)[i], path_ + "[" + std::to_string(i) + "]");
  return out;
}

namespace {
JsonReader::KeyTableObserver& key_table_observer() {
  static JsonReader::KeyTableObserver observer;
  return observer;
}
}  // namespace

void JsonReader::set_key_table_observer(KeyTableObserver observer) { key_table_observer() = std::move(observer); }

std::vector<std::string> JsonReader::keys() const {
  require_object();
  std::vector<std::string> out;
  for (auto it = value_->begin(); it != value_->end(); ++it) out.push_back(it.key());
  // Every key counts as known. Keys of an object are unique (json_text refuses duplicates): once
  // per key, not a search of the known keys per key (issue 34: 50,000 materials took 12 s).
  if (known_.empty() && !map_) {
    known_ = out;
  } else {
    for (const std::string& k : out) mark(k);
  }
  map_ = true;
  return out;
}

std::vector<std::pair<std::string, JsonReader>> JsonReader::members() const {
  const std::vector<std::string> names = keys();
  std::vector<std::pair<std::string, JsonReader>> out;
  out.reserve(names.size());
  std::size_t k = 0;
  for (auto it = value_->begin(); it != value_->end(); ++it, ++k) out.emplace_back(names[k], JsonReader(it.value(), member_path(names[k])));
  return out;
}

void JsonReader::require_object() const {
  if (!value_->is_object()) expected("an object");
}

void JsonReader::mark(const std::string& key) const {
  if (map_) return;  // keys() made every key known; finish() checks none
  if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.push_back(key);
}

bool JsonReader::has(const std::string& key) const {
  require_object();
  mark(key);
  return value_->contains(key);
}

JsonReader JsonReader::at(const std::string& key, const std::string& what) const {
  if (!has(key)) {
    const std::string p = member_path(key);
    std::vector<std::string> present;  // a misspelt required key: name the key that is probably it
    for (auto it = value_->begin(); it != value_->end(); ++it) present.push_back(it.key());
    const std::string near = nearest_key(key, present);
    throw SceneError(p + ": required key missing" + (what.empty() ? std::string() : " (expected " + what + ")") +
                     (near.empty() ? std::string() : "; is '" + near + "' a misspelling of it?"));
  }
  return JsonReader(value_->at(key), member_path(key));
}

std::optional<JsonReader> JsonReader::find(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return JsonReader(value_->at(key), member_path(key));
}

double JsonReader::number(const std::string& key, const Range& range) const {
  const auto v = find(key);
  if (!v) at(key, range.describe());  // throws: the required key is missing
  return v->as_number(range);
}

double JsonReader::number(const std::string& key, double default_value, const Range& range) const {
  const auto v = find(key);
  return v ? v->as_number(range) : default_value;
}

long JsonReader::integer(const std::string& key, long min, long max) const {
  return at(key, "an integer").as_integer(min, max);
}

long JsonReader::integer(const std::string& key, long default_value, long min, long max) const {
  const auto v = find(key);
  return v ? v->as_integer(min, max) : default_value;
}

std::string JsonReader::string(const std::string& key) const { return at(key, "a string").as_string(); }

std::string JsonReader::string(const std::string& key, const std::string& default_value) const {
  const auto v = find(key);
  return v ? v->as_string() : default_value;
}

std::string JsonReader::choice(const std::string& key, const std::vector<std::string>& choices) const {
  return at(key, "a string").as_choice(choices);
}

std::string JsonReader::choice(const std::string& key, const std::vector<std::string>& choices,
                               const std::string& default_value) const {
  const auto v = find(key);
  return v ? v->as_choice(choices) : default_value;
}

std::vector<double> JsonReader::vector(const std::string& key, std::size_t n, const Range& range) const {
  return at(key, "an array of " + std::to_string(n) + " numbers").as_vector(n, range);
}

void JsonReader::finish() const {
  require_object();
  if (key_table_observer()) key_table_observer()(path_, known_, map_);
  if (map_) return;  // keys() made every key known
  for (auto it = value_->begin(); it != value_->end(); ++it) {
    if (std::find(known_.begin(), known_.end(), it.key()) != known_.end()) continue;
    std::string allowed;
    for (const std::string& k : known_) allowed += (allowed.empty() ? "" : ", ") + k;
    const std::string near = nearest_key(it.key(), known_);
    throw SceneError(member_path(it.key()) + ": unknown key" +
                     (allowed.empty() ? std::string(" (no keys are allowed here)")
                                      : " (allowed here: " + allowed + ")") +
                     (near.empty() ? std::string() : "; did you mean '" + near + "'?"));
  }
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);  // row[j]: distance of a[0, i) to b[0, j)
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string nearest_key(const std::string& typo, const std::vector<std::string>& allowed) {
  const std::size_t limit = typo.size() <= 3 ? 1 : std::max<std::size_t>(2, typo.size() / 3);
  std::string best;
  std::size_t best_distance = limit + 1;
  for (const std::string& k : allowed) {
    const std::size_t d = edit_distance(typo, k);
    if (d < best_distance && d < typo.size() && d < k.size()) best = k, best_distance = d;  // not a whole new word
  }
  return best;
}


}  // namespace frictherm::coupling

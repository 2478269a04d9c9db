// Scene text to JSON (json_reader.hpp: parse_json_text), with the limits of issue 15 item 3.
//
// A SAX handler over nlohmann's DOM builder follows the key path of every value, so each refusal
// names it, with the line and column: duplicate keys (nlohmann keeps the last one silently), numbers
// beyond a double (1e999), nesting deeper than kMaxJsonDepth (a 100000-deep array would overflow the
// stack of the recursive copies and destructors later), keys longer than kMaxKeyLength and strings
// longer than kMaxStringLength (messages repeat them).
#include <frictherm/coupling/json_reader.hpp>

#include <algorithm>
#include <cstddef>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace frictherm::coupling {

namespace {

// An input iterator over the text that records the furthest byte read: the position of the parser
// when the SAX handler is called (nlohmann hands positions to parse_error only).
class CountingIterator {
 public:
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;

  CountingIterator(const char* p, const char** furthest) : p_(p), furthest_(furthest) {}
  reference operator*() const { return *p_; }
  CountingIterator& operator++() {
    ++p_;
    if (p_ > *furthest_) *furthest_ = p_;
    return *this;
  }
  CountingIterator operator++(int) {
    CountingIterator old = *this;
    ++*this;
    return old;
  }
  bool operator==(const CountingIterator& o) const { return p_ == o.p_; }
  bool operator!=(const CountingIterator& o) const { return p_ != o.p_; }

 private:
  const char* p_;
  const char** furthest_;
};

// "line L, column C" of byte offset `end` (0-based, exclusive) of `text`.
std::string line_column(const std::string& text, std::size_t end) {
  end = std::min(end, text.size());
  std::size_t line = 1, column = 1;
  for (std::size_t k = 0; k < end; ++k) {
    if (text[k] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(column);
}

// Builds the document itself rather than through nlohmann's json_sax_dom_parser, whose key() looks
// the key up in the ordered object (a linear search: 50,000 materials took 12 s, issue 34); the
// duplicate check below is a set lookup, so a key is appended without a search.
class SceneSax {
 public:
  using number_integer_t = Json::number_integer_t;
  using number_unsigned_t = Json::number_unsigned_t;
  using number_float_t = Json::number_float_t;
  using string_t = Json::string_t;
  using binary_t = Json::binary_t;

  SceneSax(Json& document, const std::string& text, const char** furthest, std::string root_path)
      : root_(document), text_(text), furthest_(furthest), root_path_(std::move(root_path)) {}

  bool null() { return value(), put(Json(nullptr)); }
  bool boolean(bool v) { return value(), put(Json(v)); }
  bool number_integer(number_integer_t v) { return value(), put(Json(v)); }
  bool number_unsigned(number_unsigned_t v) { return value(), put(Json(v)); }
  bool number_float(number_float_t v, const string_t&) { return value(), put(Json(v)); }
  bool string(string_t& v) {
    value();
    if (v.size() > kMaxStringLength)
      fail(named_path() + ": a string of " + std::to_string(v.size()) + " characters at " + here() + "; expected at most " +
           std::to_string(kMaxStringLength));
    return put(Json(std::move(v)));
  }
  bool binary(binary_t&) { return false; }  // not in JSON text
  bool start_object(std::size_t) {
    open(true);
    stack_.push_back(place(Json(Json::value_t::object)));
    return true;
  }
  bool key(string_t& k) {
    Frame& f = frames_.back();
    f.key.clear();  // the path of the object itself until the key is accepted
    if (k.size() > kMaxKeyLength)
      fail(named_path() + ": a key of " + std::to_string(k.size()) + " characters at " + here() + "; expected at most " +
           std::to_string(kMaxKeyLength));
    f.key = k;
    if (!f.keys.insert(k).second)
      fail(path() + ": duplicate key '" + k + "' at " + here() + " (a key may appear once in an object)");
    auto& members = static_cast<Json::object_t::Container&>(stack_.back()->get_ref<Json::object_t&>());
    if (members.size() == members.capacity()) grow(members);
    members.emplace_back(k, Json());
    member_ = &members.back().second;
    return true;
  }
  bool end_object() {
    frames_.pop_back();
    stack_.pop_back();
    return true;
  }
  bool start_array(std::size_t) {
    open(false);
    stack_.push_back(place(Json(Json::value_t::array)));
    return true;
  }
  bool end_array() {
    frames_.pop_back();
    stack_.pop_back();
    return true;
  }
  template <class Exception>
  bool parse_error(std::size_t position, const std::string& token, const Exception& ex) {
    const std::string where = line_column(text_, position == 0 ? 0 : position - 1);
    if (ex.id == 406) {  // out_of_range.406: a number beyond a double (the value nlohmann refused)
      value();
      fail(named_path() + ": the number " + token + " at " + where + " is out of range; expected a finite number");
    }
    // nlohmann's message: "[json.exception.parse_error.101] parse error at line 3, column 5: detail".
    std::string detail = ex.what();
    const std::size_t colon = detail.find(": ", detail.find("parse error"));
    if (colon != std::string::npos) detail = detail.substr(colon + 2);
    const std::string p = path();
    throw JsonSyntaxError("malformed JSON at " + where + ": " + detail + (p.empty() ? "" : " (in " + p + ")"));
  }

 private:
  struct Frame {
    bool object = false;
    std::string key;        // objects: the key of the value being read
    long index = -1;        // arrays: the index of the value being read
    std::set<std::string> keys;  // objects: the keys seen
  };

  // Every value (scalars, objects, arrays) advances the index of the array holding it.
  void value() {
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
  }
  void open(bool object) {
    value();
    if (frames_.size() >= kMaxJsonDepth)
      fail(outer_path() + ": objects and arrays nested deeper than " +
           std::to_string(kMaxJsonDepth) + " levels at " + here() + "; expected at most " + std::to_string(kMaxJsonDepth));
    frames_.push_back(Frame{object, {}, -1, {}});
  }
  std::string path() const {
    std::string p = root_path_;
    for (const Frame& f : frames_) {
      if (f.object && !f.key.empty()) p += (p.empty() ? "" : ".") + f.key;
      if (!f.object && f.index >= 0) p += "[" + std::to_string(f.index) + "]";
    }
    return p;
  }
  // The key path down to the first array below the top level ("description" for a deep array in
  // it; "scene" when the document itself is the deep array): a deep path would fill the message.
  std::string outer_path() const {
    std::string p = root_path_;
    for (const Frame& f : frames_) {
      if (!f.object || f.key.empty()) break;
      p += (p.empty() ? "" : ".") + f.key;
    }
    return p.empty() ? std::string("scene") : p;
  }
  std::string named_path() const {  // "scene" for the document itself
    const std::string p = path();
    return p.empty() ? std::string("scene") : p;
  }
  // The last character read: the '[' or '{' that opened too deep, the closing quote of a key or string.
  std::string here() const {
    const auto read = static_cast<std::size_t>(*furthest_ - text_.data());
    return line_column(text_, read == 0 ? 0 : read - 1);
  }
  [[noreturn]] void fail(const std::string& message) const { throw SceneError(message); }

  // Doubles the room of an object's members, moving the values: the vector's own growth copies
  // them (a pair with a const key has no noexcept move), a deep copy of every member read so far.
  static void grow(Json::object_t::Container& members) {
    Json::object_t::Container larger;
    larger.reserve(std::max<std::size_t>(8, 2 * members.capacity()));
    for (auto& m : members)
      larger.emplace_back(std::piecewise_construct, std::forward_as_tuple(m.first),
                          std::forward_as_tuple(std::move(m.second)));
    members.swap(larger);
  }

  // The new value: the document, the next element of the open array or the member of the last key.
  Json* place(Json&& v) {
    if (stack_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    Json& top = *stack_.back();
    if (top.is_array()) {
      auto& elements = top.get_ref<Json::array_t&>();
      elements.push_back(std::move(v));
      return &elements.back();
    }
    *member_ = std::move(v);
    return member_;
  }
  bool put(Json&& v) {
    place(std::move(v));
    return true;
  }

  Json& root_;
  std::vector<Json*> stack_;  // the open objects and arrays
  Json* member_ = nullptr;    // the value of the last key
  const std::string& text_;
  const char** furthest_;
  std::string root_path_;
  std::vector<Frame> frames_;
};

}  // namespace

Json parse_json_text(const std::string& text, const std::string& root_path) {
  Json doc;
  const char* furthest = text.data();
  SceneSax sax(doc, text, &furthest, root_path);
  const CountingIterator first(text.data(), &furthest), last(text.data() + text.size(), &furthest);
  Json::sax_parse(first, last, &sax, nlohmann::detail::input_format_t::json, /*strict=*/true, /*ignore_comments=*/true);
  return doc;
}

}  // namespace frictherm::coupling

// docs/scene.schema.json against the validator's own key tables (issue 14 item 9). Every example scene
// is validated with a key-table observer (JsonReader::set_key_table_observer): each object reports its
// key path and the keys the validator allows there. The schema is built from those tables; the test
// fails when docs/scene.schema.json differs, so schema and validator cannot drift apart. Regenerate:
//   FRICTHERM_SCHEMA_OUT=docs/scene.schema.json build/tests/coupling/test_scene_schema
// Also: `frictherm validate` suggests the nearest allowed key for a typo (Levenshtein distance).
#include <frictherm/coupling.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>

namespace fc = frictherm::coupling;
namespace fs = std::filesystem;
using ::testing::HasSubstr;

namespace {

struct KeyTable {
  std::vector<std::string> keys;  // the union over every time the place was seen, in first-seen order
  bool constant = true;           // the same keys every time (else they depend on a variant, e.g. a shape's type)
  std::set<std::string> first;
  bool is_map = false;
  std::vector<std::string> expected;  // what the validator expects of a value here (set_scene_value_observer)
  std::vector<std::string> choices;   // the allowed strings of a choice
};

void add_unique(std::vector<std::string>& to, const std::string& x) {
  if (std::find(to.begin(), to.end(), x) == to.end()) to.push_back(x);
}

// Key paths as patterns: bodies[3].shape -> bodies[].shape, materials.steel -> materials.* .
std::map<std::string, KeyTable> record_key_tables(std::vector<std::string>& scenes) {
  std::vector<std::tuple<std::string, std::vector<std::string>, bool>> raw;
  std::vector<std::tuple<std::string, std::string, std::vector<std::string>>> values;
  fc::JsonReader::set_key_table_observer(
      [&raw](const std::string& path, const std::vector<std::string>& keys, bool is_map) {
        raw.emplace_back(path, keys, is_map);
      });
  fc::set_scene_value_observer(
      [&values](const std::string& path, const std::string& expected, const std::vector<std::string>& choices) {
        values.emplace_back(path, expected, choices);
      });
  for (const auto& e : fs::directory_iterator(fs::path(FRICTHERM_SOURCE_DIR) / "examples"))
    if (e.path().extension() == ".json") scenes.push_back(e.path().string());
  std::sort(scenes.begin(), scenes.end());
  for (const auto& s : scenes) {
    try {
      fc::load_scene(s);
    } catch (const std::exception& e) {
      ADD_FAILURE() << s << ": " << e.what();
    }
  }
  fc::JsonReader::set_key_table_observer(nullptr);
  fc::set_scene_value_observer(nullptr);
  const std::regex index(R"(\[[0-9]+\])");
  std::vector<std::string> maps;  // patterns of maps of user names
  auto pattern = [&](std::string p) {
    p = std::regex_replace(p, index, "[]");
    for (const auto& m : maps) {
      const std::string prefix = m.empty() ? "" : m + ".";
      if (p.size() > prefix.size() && p.compare(0, prefix.size(), prefix) == 0) {
        const std::size_t end = p.find_first_of(".[", prefix.size());
        p = prefix + "*" + (end == std::string::npos ? "" : p.substr(end));
      }
    }
    return p;
  };
  for (auto& [path, keys, is_map] : raw)  // maps first, shortest first, so nested maps normalise too
    if (is_map) maps.push_back(std::regex_replace(path, index, "[]"));
  std::sort(maps.begin(), maps.end(), [](const auto& a, const auto& b) { return a.size() < b.size(); });
  for (auto& m : maps) m = pattern(m);
  std::map<std::string, KeyTable> tables;
  for (const auto& [path, keys, is_map] : raw) {
    const std::string p = pattern(path);
    auto [it, fresh] = tables.try_emplace(p);
    KeyTable& t = it->second;
    t.is_map = t.is_map || is_map;
    const std::set<std::string> now(keys.begin(), keys.end());
    if (fresh) t.first = now;
    else if (now != t.first) t.constant = false;
    for (const auto& k : keys) add_unique(t.keys, k);
  }
  for (const auto& [path, expected, choices] : values) {  // leaves get an entry of their own
    KeyTable& t = tables[pattern(path)];
    add_unique(t.expected, expected);
    for (const auto& c : choices) add_unique(t.choices, c);
  }
  return tables;
}

fc::Json object_schema(const std::string& p, const std::map<std::string, KeyTable>& tables);

// The schema of the value at pattern p: an object's keys, an array's items, a map's values, else any.
fc::Json value_schema(const std::string& p, const std::map<std::string, KeyTable>& tables) {
  fc::Json s = fc::Json::object();
  const auto obj = tables.find(p);
  if (obj != tables.end() && obj->second.is_map) {
    s["type"] = "object";
    if (tables.count(p + ".*")) s["additionalProperties"] = value_schema(p + ".*", tables);
  } else if (obj != tables.end() && (!obj->second.keys.empty() || obj->second.expected.empty())) {
    s = object_schema(p, tables);
  }
  if (obj != tables.end() && !obj->second.expected.empty()) {  // annotations only: they never reject a value
    std::string d;
    for (const auto& e : obj->second.expected) d += (d.empty() ? "" : ", or ") + e;
    s["description"] = "expected " + d;
    if (!obj->second.choices.empty()) s["examples"] = obj->second.choices;
  }
  if (tables.count(p + "[]")) s["items"] = value_schema(p + "[]", tables);  // also an array of such objects
  return s;
}

fc::Json object_schema(const std::string& p, const std::map<std::string, KeyTable>& tables) {
  const KeyTable& t = tables.at(p);
  fc::Json s = fc::Json::object();
  fc::Json props = fc::Json::object();
  for (const auto& k : t.keys) props[k] = value_schema(p.empty() ? k : p + "." + k, tables);
  s["properties"] = props;
  if (t.constant) s["additionalProperties"] = false;  // where the allowed keys do not depend on a variant
  return s;
}

fc::Json build_schema(const std::map<std::string, KeyTable>& tables, const std::vector<std::string>& scenes) {
  fc::Json s = fc::Json::object();
  s["$schema"] = "https://json-schema.org/draft/2020-12/schema";
  s["$id"] = "https://frictherm/scene.schema.json";
  s["title"] = "frictherm scene";
  s["description"] =
      "Keys of a frictherm scene (docs/scenes.md), generated from the validator's key tables over the " +
      std::to_string(scenes.size()) +
      " scenes in examples/ by tests/coupling/test_scene_schema.cpp; do not edit by hand. Objects whose keys "
      "depend on a variant (a shape's or law's type) list every key seen and leave others to `frictherm validate`.";
  s["type"] = "object";
  const fc::Json root = object_schema("", tables);
  for (auto it = root.begin(); it != root.end(); ++it) s[it.key()] = it.value();
  return s;
}

std::string run(const std::string& args) {
  const std::string cmd = std::string("'") + FRICTHERM_EXE + "' " + args + " 2>&1";
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int status = pclose(p);
  return "exit " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ": " + out;
}

}  // namespace

TEST(SceneSchema, MatchesTheValidatorKeyTables) {
  std::vector<std::string> scenes;
  const auto tables = record_key_tables(scenes);
  ASSERT_GE(scenes.size(), 10u);
  ASSERT_TRUE(tables.count(""));
  const fc::Json generated = build_schema(tables, scenes);
  const fs::path doc = fs::path(FRICTHERM_SOURCE_DIR) / "docs" / "scene.schema.json";
  if (const char* out = std::getenv("FRICTHERM_SCHEMA_OUT")) {
    std::ofstream(out) << generated.dump(2) << '\n';
    GTEST_SKIP() << "wrote " << out;
  }
  std::ifstream in(doc);
  ASSERT_TRUE(in) << doc;
  const fc::Json stored = fc::Json::parse(in);
  EXPECT_EQ(stored, generated) << "docs/scene.schema.json is out of date with the validator; regenerate it:\n"
                               << "  FRICTHERM_SCHEMA_OUT=docs/scene.schema.json build/tests/coupling/test_scene_schema";
  // Every top-level key the validator knows is in the schema, with no others allowed.
  EXPECT_EQ(stored["additionalProperties"], false);
  for (const char* k : {"units", "dimension", "grid", "materials", "bodies", "contact", "thermal", "coupling", "solver",
                        "run", "output"})
    EXPECT_TRUE(stored["properties"].contains(k)) << k;
  // What the validator expects of values shows as descriptions, a choice's strings as examples.
  EXPECT_EQ(stored["properties"]["solver"]["properties"]["cfl"]["description"], "expected a number in (0, 1]");
  EXPECT_TRUE(stored["properties"]["solver"]["properties"]["shape_function"]["examples"].size() >= 4u);
  // A map of user names: material definitions are checked under additionalProperties.
  EXPECT_TRUE(stored["properties"]["materials"]["additionalProperties"]["properties"].contains("density"));
  EXPECT_TRUE(stored["properties"]["bodies"]["items"]["properties"].contains("shape"));
}

TEST(SceneSchema, EditDistanceAndNearestKey) {
  EXPECT_EQ(fc::edit_distance("gird", "grid"), 2u);  // a transposition is two substitutions
  EXPECT_EQ(fc::edit_distance("", "abc"), 3u);
  EXPECT_EQ(fc::edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(fc::edit_distance("density", "density"), 0u);
  const std::vector<std::string> top{"units", "dimension", "grid", "materials", "bodies", "run", "output"};
  EXPECT_EQ(fc::nearest_key("gird", top), "grid");
  EXPECT_EQ(fc::nearest_key("materails", top), "materials");
  EXPECT_EQ(fc::nearest_key("dimensions", top), "dimension");
  EXPECT_EQ(fc::nearest_key("rn", top), "run");
  EXPECT_EQ(fc::nearest_key("temperature", top), "");  // nothing near: no suggestion
  EXPECT_EQ(fc::nearest_key("xyz", top), "");
  EXPECT_EQ(fc::nearest_key("x", {"a"}), "");  // one letter for another is no typo of it
}

TEST(SceneSchema, ValidateSuggestsTheNearestKey) {
  // Per process: two test runs at once (two build folders) must not share it.
  const fs::path dir = fs::temp_directory_path() / ("frictherm_test_scene_schema_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string scene = (dir / "typo.json").string();
  std::ifstream src(fs::path(FRICTHERM_SOURCE_DIR) / "examples" / "bar_vibration.json");
  std::string text((std::istreambuf_iterator<char>(src)), std::istreambuf_iterator<char>());
  text.replace(text.find("\"grid\""), 6, "\"gird\"");
  std::ofstream(scene) << text;
  const std::string out = run("validate '" + scene + "'");
  EXPECT_THAT(out, HasSubstr("exit 2: "));
  EXPECT_THAT(out, HasSubstr("gird: unknown key"));
  EXPECT_THAT(out, HasSubstr("did you mean 'grid'?"));
  // Deeper down, an optional key: bodies[0].velocity.
  text.replace(text.find("\"gird\""), 6, "\"grid\"");
  text.replace(text.find("\"velocity\""), 10, "\"velocty\"");
  std::ofstream(scene) << text;
  const std::string body = run("validate '" + scene + "'");
  EXPECT_THAT(body, HasSubstr("bodies[0].velocty: unknown key"));
  EXPECT_THAT(body, HasSubstr("did you mean 'velocity'?"));
  // A misspelt required key is reported as missing first: the message names the misspelling.
  text.replace(text.find("\"velocty\""), 9, "\"velocity\"");
  text.replace(text.find("\"density\""), 9, "\"desnity\"");
  std::ofstream(scene) << text;
  EXPECT_THAT(run("validate '" + scene + "'"),
              HasSubstr("materials.aluminium.density: required key missing (expected a number > 0); is 'desnity' a "
                        "misspelling of it?"));
}

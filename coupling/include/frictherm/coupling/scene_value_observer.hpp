#pragma once
// The validator's value expectations, for tools: when set, every value a scene reader checks
// (JsonReader::as_number, as_integer, as_string, as_bool, as_choice, as_vector, as_number_list)
// reports its key path, what it expects ("a number > 0", "one of \"linear\", \"ugimp\"") and, for a
// choice, the choices. tests/coupling/test_scene_schema.cpp puts these into docs/scene.schema.json
// as descriptions and completion examples. One observer for the whole process, not thread-safe.
#include <functional>
#include <string>
#include <vector>

namespace frictherm::coupling {

using SceneValueObserver =
    std::function<void(const std::string& path, const std::string& expected, const std::vector<std::string>& choices)>;
void set_scene_value_observer(SceneValueObserver observer);

}  // namespace frictherm::coupling

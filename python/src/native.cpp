// frictherm._native: the library's scene parser and run loop for Python (pybind11, Debian
// pybind11-dev). The Python face is python/frictherm/native.py (load_scene, Scene.set, validate,
// run); this module only passes a scene's text and overrides to coupling::parse_scene / run_scene.
//   * The run releases the GIL; the observer takes it back once per mechanics step. An exception the
//     observer raises ends the run and reaches the caller (the file written so far stays, runner.hpp).
//   * Ctrl-C: the run takes SIGINT/SIGTERM over while it lasts (RunOptions::handle_signals, as the
//     program does): the first ends it after the current step with its series, a last snapshot and
//     status `interrupted`, and native.py then raises KeyboardInterrupt; the handlers are restored after.
//   * Particle arrays handed to the observer are NumPy views of the simulation's own arrays,
//     read-only and valid only during that call (copy them to keep them).
#include <frictherm/coupling/h5_output.hpp>
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace py = pybind11;
using namespace frictherm;

namespace {

std::vector<coupling::SceneOverride> overrides_of(const std::vector<std::pair<std::string, std::string>>& sets) {
  std::vector<coupling::SceneOverride> o;
  for (const auto& [path, value] : sets) o.push_back({path, value});
  return o;
}

coupling::Scene parse(const std::string& text, const std::string& source, const std::string& base_dir,
                      const std::string& name, const std::vector<std::pair<std::string, std::string>>& sets) {
  return coupling::parse_scene(text, source, base_dir, name, overrides_of(sets));
}

// A read-only (n, components) or (n,) NumPy view of `data`, kept alive by `owner` (the observer's step).
template <class T>
py::array view(const T* data, std::size_t n, std::size_t components, py::handle owner) {
  std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(n)};
  std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(components * sizeof(T))};
  if (components > 1) {
    shape.push_back(static_cast<py::ssize_t>(components));
    strides.push_back(sizeof(T));
  }
  py::array a(py::dtype::of<T>(), shape, strides, data, owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

template <int Dim>
py::dict particle_views(const mechanics::Simulation<Dim>& sim, py::handle owner) {
  const auto& p = sim.particles();
  const std::size_t n = p.size();
  py::dict d;
  d["position"] = view(n ? p.position[0].data() : nullptr, n, Dim, owner);
  d["velocity"] = view(n ? p.velocity[0].data() : nullptr, n, Dim, owner);
  d["temperature"] = view(p.temperature.data(), n, 1, owner);
  d["mass"] = view(p.mass.data(), n, 1, owner);
  d["material"] = view(p.material.data(), n, 1, owner);
  return d;
}

// What the Python observer receives each step.
struct Step {
  long step;
  double time, dt, kinetic_energy, strain_energy;
  py::dict series;  // the latest /series row, column -> value (int for count columns, as in the file)
  bool series_new;  // this step wrote it
  const coupling::StepView* view;
};

// StepView::series_row as a dict in column order; count columns (stored as int64) as Python ints.
py::dict series_dict(const coupling::StepView& v) {
  py::dict d;
  const auto& names = v.series_columns();
  const auto& row = v.series_row();
  if (row.size() != names.size()) return d;  // no row yet (a resumed run before its first one)
  for (std::size_t j = 0; j < names.size(); ++j) {
    if (coupling::H5Output::is_count_column(names[j]))
      d[py::str(names[j])] = py::int_(static_cast<long long>(std::llround(row[j])));
    else
      d[py::str(names[j])] = py::float_(row[j]);
  }
  return d;
}

}  // namespace

PYBIND11_MODULE(_native, m) {
  m.doc() = "frictherm's scene parser and run loop (use the frictherm package: frictherm.run, frictherm.load_scene)";
  py::register_exception<coupling::SceneError>(m, "SceneError", PyExc_ValueError);

  py::class_<Step>(m, "Step")
      .def_readonly("step", &Step::step)
      .def_readonly("time", &Step::time)
      .def_readonly("dt", &Step::dt)
      .def_readonly("kinetic_energy", &Step::kinetic_energy)
      .def_readonly("strain_energy", &Step::strain_energy)
      .def_readonly("series", &Step::series,
                    "the latest series row as {column: value}, the row written to the file's /series "
                    "(units: frictherm.open(...).unit_of(column)); empty before a resumed run's first row")
      .def_readonly("series_new", &Step::series_new, "True when this step wrote `series` (rows come every "
                    "output.series_interval)")
      .def(
          "particles",
          [](py::object self) {
            const Step& s = self.cast<const Step&>();
            if (s.view == nullptr) throw std::runtime_error("Step.particles(): only during the observer call");
            return s.view->dim() == 2 ? particle_views(s.view->simulation<2>(), self)
                                      : particle_views(s.view->simulation<3>(), self);
          },
          "position, velocity (n, dim), temperature, mass, material (n,): read-only NumPy views of the "
          "simulation's arrays, valid during this call only");

  // Parses and validates; returns the scene as run (plain JSON text) and a few facts.
  m.def("validate", [](const std::string& text, const std::string& source, const std::string& base_dir,
                       const std::string& name, const std::vector<std::pair<std::string, std::string>>& sets) {
    const coupling::Scene s = parse(text, source, base_dir, name, sets);
    py::dict d;
    d["json"] = s.json;
    d["dimension"] = s.dimension;
    d["end_time"] = s.end_time;
    d["name"] = s.name;
    d["notes"] = s.notes;  // settings known to fail or mislead, naming the key (Scene::notes)
    return d;
  });

  m.def("run", [](const std::string& text, const std::string& source, const std::string& base_dir,
                  const std::string& name, const std::vector<std::pair<std::string, std::string>>& sets,
                  const std::string& output, int threads, bool overwrite, py::object observer, long every) {
    const coupling::Scene scene = parse(text, source, base_dir, name, sets);
    coupling::RunOptions o;
    o.output = output;
    o.threads = threads;
    o.overwrite = overwrite;
    o.quiet = true;
    o.progress = coupling::RunOptions::Progress::never;
    o.command_line = "python: frictherm.run";
    o.handle_signals = true;  // Ctrl-C: status interrupted, then KeyboardInterrupt (native.py)
    const bool has_observer = !observer.is_none();
    o.observer = [&observer, has_observer, every](const coupling::StepView& v) {
      if (every > 1 && v.step() % every != 0) return;
      if (!has_observer) return;
      py::gil_scoped_acquire gil;
      py::object step = py::cast(Step{v.step(), v.time(), v.dt(), v.kinetic_energy(), v.strain_energy(),
                                      series_dict(v), v.series_row_is_new(), &v});
      observer(step);
      step.cast<Step&>().view = nullptr;  // a kept Step object no longer reaches the simulation
    };
    coupling::RunResult r;
    {
      py::gil_scoped_release release;
      r = coupling::run_scene(scene, o);
    }
    const char* status[] = {"completed", "stopped_at_max_steps", "failed", "interrupted"};
    py::dict d;
    d["status"] = status[static_cast<int>(r.status)];
    d["output"] = r.output;
    d["steps"] = r.steps;
    d["time"] = r.time;
    d["wall_time"] = r.wall_time;
    d["snapshots"] = r.snapshots;
    d["series_rows"] = r.series_rows;
    d["particles"] = r.particles;
    d["message"] = r.message;
    d["notes"] = scene.notes;
    return d;
  });
}

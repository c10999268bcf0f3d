// Run control for Python: an Engine (run/engine.hpp, the code `cairn run` runs) stepped with
// the GIL released, Ctrl-C turned into KeyboardInterrupt between steps, checkpoints on demand.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <chrono>
#include <limits>
#include <memory>
#include <utility>

#include "arrays.hpp"
#include "bindings.hpp"
#include "cairn/run/engine.hpp"

namespace cairn::python {
namespace {

using Clock = std::chrono::steady_clock;

/// One run, as the Python class cairn.Simulation holds it.
class PyEngine {
 public:
  explicit PyEngine(const Config& config) : engine_(make_engine(config, RunOptions{.quiet = true})) {}
  explicit PyEngine(std::unique_ptr<Engine> engine) : engine_(std::move(engine)) {}

  /// Steps until `max_steps` are taken, the time reaches `until`, the run is finished or
  /// `wall_seconds` have passed (0: no limit); at least one step unless one of the first three
  /// holds already. The GIL is released during each step; a signal (Ctrl-C) raises its Python
  /// exception after the step it arrived in, with the history flushed and the state intact.
  long long advance(long long max_steps, double until, double wall_seconds) {
    refuse_finished();
    const auto start = Clock::now();
    long long taken = 0;
    while (taken < max_steps && !engine_->finished() && engine_->time() < until) {
      {
        py::gil_scoped_release release;
        engine_->step();
      }
      ++taken;
      if (PyErr_CheckSignals() != 0) {
        engine_->flush();
        throw py::error_already_set();
      }
      if (wall_seconds > 0.0 && std::chrono::duration<double>(Clock::now() - start).count() >= wall_seconds) break;
    }
    return taken;
  }

  /// The final outputs and checkpoint (once); the summary as a dict.
  py::dict finish() {
    refuse_finished();
    RunSummary s;
    {
      py::gil_scoped_release release;
      s = engine_->finish();
    }
    finished_ = true;
    py::dict d;
    d["steps"] = s.steps;
    d["end_time"] = s.end_time;
    d["wall_seconds"] = s.wall_seconds;
    d["particle_steps_per_second"] = s.particle_steps_per_second;
    d["items"] = s.n_particles;
    d["output_directory"] = s.output_directory;
    d["last_checkpoint"] = s.last_checkpoint;
    d["stage_seconds"] = s.stage_seconds;
    return d;
  }

  Engine& engine() { return *engine_; }
  [[nodiscard]] bool closed() const { return finished_; }

 private:
  void refuse_finished() const {
    if (finished_)
      throw std::logic_error("this run has finished (its final outputs are written); make a new Simulation, or "
                             "continue from its last checkpoint with cairn restart");
  }

  std::unique_ptr<Engine> engine_;
  bool finished_ = false;
};

}  // namespace

void bind_engine(py::module_& m) {
  py::register_exception<RunFailure>(m, "RunFailure", PyExc_RuntimeError);
  py::class_<PyEngine>(m, "Engine", "One run of one engine (run/engine.hpp); use cairn.Simulation.")
      .def(py::init<const Config&>(), py::arg("config"))
      .def_static(
          "restore",
          [](const std::filesystem::path& checkpoint, const std::vector<std::string>& overrides) {
            return std::make_unique<PyEngine>(restore_engine(checkpoint, overrides, RunOptions{.quiet = true}));
          },
          py::arg("checkpoint"), py::arg("overrides"), "Continue from a checkpoint, as `cairn restart`.")
      .def("advance", &PyEngine::advance, py::arg("max_steps") = 1,
           py::arg("until") = std::numeric_limits<double>::infinity(), py::arg("wall_seconds") = 0.0)
      .def("start", [](PyEngine& e) { e.engine().start(); })
      .def("finish", &PyEngine::finish)
      .def_property_readonly("finished", [](PyEngine& e) { return e.closed() || e.engine().finished(); })
      .def_property_readonly("closed", &PyEngine::closed)
      .def_property_readonly("name", [](PyEngine& e) { return e.engine().name(); })
      .def_property_readonly("dimension", [](PyEngine& e) { return e.engine().config().simulation.dimension; })
      .def_property_readonly("time", [](PyEngine& e) { return e.engine().time(); })
      .def_property_readonly("steps", [](PyEngine& e) { return e.engine().step_count(); })
      .def_property_readonly("end_time", [](PyEngine& e) { return e.engine().config().simulation.end_time; })
      .def_property_readonly("items", [](PyEngine& e) { return e.engine().items(); })
      .def_property_readonly("config", [](PyEngine& e) -> const Config& { return e.engine().config(); },
                             py::return_value_policy::reference_internal)
      .def("flush", [](PyEngine& e) { e.engine().flush(); })
      .def(
          "write_checkpoint",
          [](PyEngine& e, bool autosave) {
            py::gil_scoped_release release;
            return e.engine().write_checkpoint(autosave);
          },
          py::arg("autosave") = false)
      .def(
          "particle_array",
          [](py::object self, const std::string& name, bool writable) {
            return particle_array(self.cast<PyEngine&>().engine().state(), self, name, writable);
          },
          py::arg("name"), py::arg("writable") = false)
      .def("particle_fields", [](PyEngine& e) { return particle_fields(e.engine().state()); })
      .def("grid_fields", [](PyEngine& e) { return grid_fields(e.engine().state()); })
      .def("material_names", [](PyEngine& e) { return material_names(e.engine().state()); });
}

}  // namespace cairn::python

// The Python module `immerse`: configurations (a scenario file or a dict, with `set` keys), simulations stepped or
// run from Python, diagnostics and node positions/velocities as numpy arrays. Usage and a parameter sweep:
// docs/python.md and python/examples/sweep_G.py; tested by tests/python/test_module.py.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <toml++/toml.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "immerse/core/Error.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/run/Diagnostics.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/scenario/ScenarioRun.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/simulation/Simulation.hpp"
#include "immerse/timestep/PetscSession.hpp"

namespace py = pybind11;
using namespace immerse;

namespace {

/// PETSc (and MPI), started by the first Simulation and finalized when the interpreter exits and every Simulation
/// is gone (each holds the session).
std::shared_ptr<PetscSession> petsc_session() {
  static std::shared_ptr<PetscSession> session;
  if (!session) {
    session = std::make_shared<PetscSession>();
    py::module_::import("atexit").attr("register")(py::cpp_function([] { session.reset(); }));
  }
  return session;
}

toml::table to_table(const py::dict& d, const std::string& where);
toml::array to_array(const py::handle& seq, const std::string& where);

/// Calls f with the TOML value of a Python value: bool, int, float (numpy scalars too), str, dict (a table), list,
/// tuple or numpy array (an array; a list of dicts is an array of tables such as [[membrane]]).
template <class F>
void with_toml_value(const py::handle& v, const std::string& where, F&& f) {
  if (py::isinstance<py::bool_>(v))
    f(v.cast<bool>());
  else if (py::isinstance<py::int_>(v))
    f(v.cast<std::int64_t>());
  else if (py::isinstance<py::float_>(v))
    f(v.cast<double>());
  else if (py::isinstance<py::str>(v))
    f(v.cast<std::string>());
  else if (py::isinstance<py::dict>(v))
    f(to_table(v.cast<py::dict>(), where));
  else if (py::isinstance<py::array>(v))
    f(to_array(v.attr("tolist")(), where));
  else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v))
    f(to_array(v, where));
  else if (py::hasattr(v, "__index__"))
    f(py::int_(py::reinterpret_borrow<py::object>(v)).cast<std::int64_t>());
  else if (py::hasattr(v, "__float__"))
    f(py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>());
  else
    throw InputError(where + ": a value of Python type " + py::str(py::type::of(v).attr("__name__")).cast<std::string>() +
                     " (allowed: bool, int, float, str, dict, list, tuple, numpy array)");
}

toml::table to_table(const py::dict& d, const std::string& where) {
  toml::table t;
  for (const auto& [k, v] : d) {
    const std::string key = py::str(k).cast<std::string>();
    const std::string at = where.empty() ? key : where + "." + key;
    with_toml_value(v, at, [&](auto&& x) { t.insert_or_assign(key, std::forward<decltype(x)>(x)); });
  }
  return t;
}

toml::array to_array(const py::handle& seq, const std::string& where) {
  toml::array a;
  std::size_t i = 0;
  for (const auto& v : seq)
    with_toml_value(v, where + "[" + std::to_string(i++) + "]", [&](auto&& x) { a.push_back(std::forward<decltype(x)>(x)); });
  return a;
}

/// `set` keys as the command line's --set KEY=VALUE: a dict {key: value} (values as TOML) or a list of
/// "KEY=VALUE" strings.
std::vector<std::string> overrides(const py::object& set) {
  std::vector<std::string> out;
  if (set.is_none()) return out;
  if (py::isinstance<py::dict>(set)) {
    for (const auto& [k, v] : set.cast<py::dict>()) {
      const std::string key = py::str(k).cast<std::string>();
      std::string value;
      if (py::isinstance<py::str>(v)) {
        value = v.cast<std::string>();
      } else {
        toml::table t;
        with_toml_value(v, key, [&](auto&& x) { t.insert_or_assign("v", std::forward<decltype(x)>(x)); });
        std::ostringstream s;
        s << t;
        value = s.str().substr(s.str().find('=') + 1);
        value.erase(0, value.find_first_not_of(' '));
      }
      out.push_back(key + "=" + value);
    }
    return out;
  }
  for (const auto& v : set) out.push_back(py::str(v).cast<std::string>());
  return out;
}

/// A configuration through the schema and the scenario kind, as `immerse run` reads it.
io::Config load(const py::object& source, const py::object& set) {
  const io::ConfigSchema schema = run_schema();
  const auto sets = overrides(set);
  if (py::isinstance<py::dict>(source)) {
    std::ostringstream text;
    text << to_table(source.cast<py::dict>(), "");
    return apply_scenario(schema.parse_string(text.str(), "<dict>", sets));
  }
  return apply_scenario(schema.parse_file(py::str(source).cast<std::string>(), sets));
}

py::array_t<double> nodes_array(const std::vector<Vec3>& v) {
  py::array_t<double> a({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  auto r = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int d = 0; d < 3; ++d) r(static_cast<py::ssize_t>(i), d) = v[i][d];
  return a;
}

/// A simulation and the diagnostics rows of the steps taken through this object.
class PySimulation {
 public:
  explicit PySimulation(const io::Config& config) : petsc_(petsc_session()) {
    sim_ = std::make_unique<Simulation>(config);
    scenario_ = make_scenario_run(sim_->config());
    diagnostics_.emplace(sim_->config(), sim_->num_membranes(), *scenario_);
    columns_ = column_names(diagnostics_->columns());
  }

  py::dict step() {
    StepRecord r;
    {
      py::gil_scoped_release release;
      r = sim_->advance([](const std::string& message) {
        py::gil_scoped_acquire acquire;
        py::print("immerse:", message, py::arg("file") = py::module_::import("sys").attr("stderr"));
      });
    }
    const auto row = diagnostics_->row(*sim_, r);
    py::dict d;
    for (std::size_t c = 0; c < columns_.size(); ++c) d[py::str(columns_[c])] = row[c];
    d["rejected"] = r.rejected;
    return d;
  }

  /// Steps until `steps` more steps are taken, the time reaches `until`, or the run's time.end; the rows as
  /// {column: numpy array}.
  py::dict run(std::optional<long> steps, std::optional<double> until) {
    std::vector<std::vector<double>> rows;
    const long first = sim_->step();
    while (!sim_->finished() && (!steps || sim_->step() - first < *steps) && (!until || sim_->time() < *until)) {
      const py::dict d = step();
      std::vector<double> row;
      for (const auto& c : columns_) row.push_back(d[py::str(c)].cast<double>());
      rows.push_back(std::move(row));
    }
    py::dict out;
    for (std::size_t c = 0; c < columns_.size(); ++c) {
      py::array_t<double> a(static_cast<py::ssize_t>(rows.size()));
      auto w = a.mutable_unchecked<1>();
      for (std::size_t i = 0; i < rows.size(); ++i) w(static_cast<py::ssize_t>(i)) = rows[i][c];
      out[py::str(columns_[c])] = a;
    }
    return out;
  }

  const Simulation& sim() const { return *sim_; }
  Simulation& sim() { return *sim_; }
  const std::vector<std::string>& columns() const { return columns_; }
  const Diagnostics& diagnostics() const { return *diagnostics_; }

  void check_membrane(std::size_t m) const {
    if (m >= sim_->num_membranes())
      throw py::index_error("membrane " + std::to_string(m) + ": this run has " +
                            std::to_string(sim_->num_membranes()) + " membrane(s)");
  }

 private:
  std::shared_ptr<PetscSession> petsc_;  // declared first: destroyed after the simulation's PETSc objects
  std::unique_ptr<Simulation> sim_;
  std::unique_ptr<ScenarioRun> scenario_;  // the columns the scenario kind adds
  std::optional<Diagnostics> diagnostics_;
  std::vector<std::string> columns_;
};

}  // namespace

PYBIND11_MODULE(immerse, m) {
  m.doc() = "immerse: implicit immersed-boundary simulation of elastic membranes in 3D incompressible flow";
  m.attr("__version__") = IMMERSE_VERSION;
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError);
  py::register_exception<SimulationError>(m, "SimulationError", PyExc_RuntimeError);

  py::class_<io::Config>(m, "Config", "A resolved configuration (every key, scenario values derived).")
      .def("to_toml", &io::Config::to_toml_string, "The configuration as TOML (what config.resolved.toml holds).")
      .def(
          "to_dict", [](const io::Config& c) { return py::module_::import("tomllib").attr("loads")(c.to_toml_string()); },
          "The configuration as nested dicts.")
      .def("save", [](const io::Config& c, const std::filesystem::path& p) { c.save(p); }, py::arg("path"));

  m.def("load", &load, py::arg("source"), py::arg("set") = py::none(),
        R"(A configuration from a scenario file (a path) or a dict of tables, with `set` keys applied as the command
line's --set: a dict {"scenario.G": 0.1, ...} or a list of "KEY=VALUE" strings. Raises immerse.InputError
(a ValueError) naming the key on bad input.)");

  py::class_<PySimulation>(m, "Simulation", "One run, built from a Config; stepped or run from Python.")
      .def(py::init<const io::Config&>(), py::arg("config"))
      .def("step", &PySimulation::step,
           "Advances one accepted step; returns its diagnostics row as a dict (the columns of diagnostics.csv, "
           "plus 'rejected'). Raises immerse.SimulationError when the run becomes unstable.")
      .def("run", &PySimulation::run, py::arg("steps") = py::none(), py::arg("until") = py::none(),
           "Steps until `steps` more steps, time `until` or time.end; returns {column: numpy array}.")
      .def_property_readonly("columns", &PySimulation::columns)
      .def_property_readonly(
          "units",
          [](const PySimulation& s) {
            py::dict units;
            for (const auto& c : s.diagnostics().columns())
              units[py::str(c.name)] = c.unit;
            return units;
          },
          "{column: unit} of the diagnostics (UDUNITS form; \"1\" for a pure number), as diagnostics.columns.csv.")
      .def_property_readonly("time", [](const PySimulation& s) { return s.sim().time(); })
      .def_property_readonly("steps", [](const PySimulation& s) { return s.sim().step(); })
      .def_property_readonly("finished", [](const PySimulation& s) { return s.sim().finished(); })
      .def_property_readonly("num_membranes", [](const PySimulation& s) { return s.sim().num_membranes(); })
      .def_property_readonly("config", [](const PySimulation& s) { return s.sim().config(); })
      .def(
          "positions",
          [](const PySimulation& s, std::size_t i) {
            s.check_membrane(i);
            return nodes_array(s.sim().op().membrane_positions(i));
          },
          py::arg("membrane") = 0, "Node positions of a membrane (m), an (N, 3) numpy array.")
      .def(
          "elements",
          [](const PySimulation& s, std::size_t i) {
            s.check_membrane(i);
            const auto& el = s.sim().mesh(i).elements;
            py::array_t<int> a({static_cast<py::ssize_t>(el.size()), py::ssize_t{6}});
            auto r = a.mutable_unchecked<2>();
            for (std::size_t e = 0; e < el.size(); ++e)
              for (int k = 0; k < 6; ++k) r(static_cast<py::ssize_t>(e), k) = el[e][k];
            return a;
          },
          py::arg("membrane") = 0,
          "Node indices of a membrane's six-node elements, an (E, 6) numpy array: vertices v0 v1 v2 "
          "(counter-clockwise seen from outside), then the mid-side nodes of edges 0-1, 1-2, 2-0.")
      .def(
          "velocities",
          [](const PySimulation& s, std::size_t i) {
            s.check_membrane(i);
            return nodes_array(s.sim().op().membrane_velocities(i));
          },
          py::arg("membrane") = 0, "Node velocities of a membrane (m/s), an (N, 3) numpy array.")
      .def(
          "set_applied_forces",
          [](PySimulation& s, std::size_t i, const py::array_t<double, py::array::c_style | py::array::forcecast>& F) {
            s.check_membrane(i);
            const std::size_t n = s.sim().mesh(i).nodes.size();
            if (F.ndim() != 2 || F.shape(1) != 3 || static_cast<std::size_t>(F.shape(0)) != n)
              throw InputError("set_applied_forces: forces must be an (" + std::to_string(n) + ", 3) array");
            std::vector<Vec3> v(n);
            auto r = F.unchecked<2>();
            for (std::size_t k = 0; k < n; ++k) v[k] = {r(k, 0), r(k, 1), r(k, 2)};
            s.sim().set_applied_forces(i, v);
          },
          py::arg("membrane"), py::arg("forces"), "External nodal forces (N) on a membrane from now on.");
}

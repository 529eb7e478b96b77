// The C++ extension `hybrid._hybrid` behind the Python package `hybrid` (python/hybrid/,
// docs/python.md): the finger's closed form, vectorised, and models read, drawn, simulated and
// checked in-process. JSON-shaped results travel as JSON text (the same documents as the command
// line's --json); python/hybrid/__init__.py turns them into Python values.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "automaton/dot_writer.h"
#include "automaton/parser.h"
#include "automaton/spaceex/spaceex_import.h"
#include "gripper/finger_closed_form.h"
#include "gripper/finger_parameters.h"
#include "gripper/measured_data.h"
#include "solvers/simulation/simulator.h"
#include "tools/bundled_files.h"
#include "tools/check_command.h"
#include "tools/diagnose_command.h"
#include "tools/gripper_command.h"
#include "tools/info_command.h"
#include "tools/options.h"
#include "tools/simulate_command.h"

namespace py = pybind11;

namespace hybrid::python {
namespace {

using gripper::FingerClosedForm;
using gripper::FingerContacts;
using gripper::FingerParameters;

// `value` as a motor position of argument `name`; throws ValueError outside [0, 255].
double MotorPosition(const std::string& name, double value) {
  if (!(value >= 0.0 && value <= 255.0)) {
    throw py::value_error(name + " must be a motor position in [0, 255] (got " +
                          std::to_string(value) + ")");
  }
  return value;
}

// The closed form's constants of the finger model at `path` (spec/finger.ha or one like it).
FingerParameters ParametersOfModel(const std::string& path) {
  const System model = spaceex::ReadModelFile(path);
  if (model.components().size() != 1) {
    throw py::value_error(path + ": not a finger model like spec/finger.ha (it has " +
                          std::to_string(model.components().size()) + " components)");
  }
  try {
    const FingerParameters p = gripper::FingerParametersOf(model.components()[0].automaton);
    FingerClosedForm check({}, p);  // the closed form's own conditions on its constants
    return p;
  } catch (const std::invalid_argument& e) {
    throw py::value_error(path + ": " + e.what());
  }
}

// finger_angles: theta1..3 (degrees) at every g, shape (n, 3), computed without the GIL, in two
// halves on two threads for large batches (the closed form is read-only, so they share it).
py::array_t<double> FingerAngles(
    const py::array_t<double, py::array::c_style | py::array::forcecast>& g,
    std::optional<double> gob1, std::optional<double> gob2, std::optional<double> gob3,
    const std::optional<std::string>& model) {
  FingerContacts contacts;
  const std::array<std::optional<double>, 3> gob = {gob1, gob2, gob3};
  for (int i = 0; i < 3; ++i) {
    if (gob[i]) contacts.gob[i] = MotorPosition("gob" + std::to_string(i + 1), *gob[i]);
  }
  const FingerClosedForm closed(contacts, model ? ParametersOfModel(*model) : FingerParameters{});
  const size_t n = static_cast<size_t>(g.size());
  const std::span<const double> in(g.data(), n);
  py::array_t<double> out({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(3)});
  const std::span<double> theta(out.mutable_data(), 3 * n);
  bool out_of_range = false;  // the kernel checks the range in the same pass
  {
    py::gil_scoped_release release;
    const auto angles = [&closed](std::span<const double> part, std::span<double> to,
                                  bool* failed) {
      try {
        closed.AnglesAt(part, to);
      } catch (const std::out_of_range&) {
        *failed = true;
      }
    };
    constexpr size_t kThreadBatch = 1 << 16;  // below this a thread costs more than it saves
    if (n < kThreadBatch) {
      angles(in, theta, &out_of_range);
    } else {
      const size_t half = n / 2;
      bool first_failed = false;
      std::thread first(angles, in.first(half), theta.first(3 * half), &first_failed);
      angles(in.subspan(half), theta.subspan(3 * half), &out_of_range);
      first.join();
      out_of_range = out_of_range || first_failed;
    }
  }
  if (out_of_range) {
    for (const double x : in) MotorPosition("g", x);  // throws, naming the first one outside
  }
  return out;
}

// An input's signal from Python: a number (constant), a list of (time, value) pairs (steps), or
// a signal in the language's syntax ("step(0: 0, 1: 0.5)", docs/language.md).
using SignalValue = std::variant<double, std::vector<std::pair<double, double>>, std::string>;

InputSignal SignalOf(const std::string& name, const SignalValue& value) {
  InputSignal s;
  if (const double* c = std::get_if<double>(&value)) {
    s.points = {{0.0, *c}};
  } else if (const auto* points = std::get_if<std::vector<std::pair<double, double>>>(&value)) {
    if (points->empty()) throw py::value_error("inputs['" + name + "']: no points");
    s.points = *points;
  } else {
    s = ParseSignal(std::get<std::string>(value), "inputs['" + name + "']");
  }
  return s;
}

// A model read from a file (.ha or SpaceEx .xml), with the operations of the command line.
class Model {
 public:
  explicit Model(std::string path)
      : path_(std::move(path)), system_(spaceex::ReadModelFile(path_)) {}

  const std::string& path() const { return path_; }
  const std::string& name() const { return system_.name(); }
  std::string InfoJsonText() const { return cli::InfoJson(system_, path_).dump(); }
  std::string Dot(bool product) const {
    DotOptions options;
    options.product = product;
    return WriteDot(system_, options);
  }

  std::string CheckJsonText(const std::vector<std::string>& properties, const std::string& method,
                            double budget, int depth) const {
    cli::CheckArgs args;
    args.model = path_;
    args.properties = properties;
    args.method = method;
    args.budget = budget;
    args.depth = depth;
    py::gil_scoped_release release;
    return cli::CheckReport(args, system_, nullptr).dump();
  }

  py::dict Simulate(std::optional<double> until, const std::map<std::string, SignalValue>& inputs,
                    std::optional<double> sample,
                    const std::map<std::string, double>& parameters) const;

 private:
  std::vector<InputSignal> Signals(const std::map<std::string, SignalValue>& inputs) const;

  std::string path_;
  System system_;
};

std::vector<InputSignal> Model::Signals(const std::map<std::string, SignalValue>& inputs) const {
  std::vector<InputSignal> signals;
  for (const auto& [name, value] : inputs) {
    const auto slot = system_.symbols().Find(name);
    if (!slot || system_.symbols()[*slot].kind != SymbolKind::kInput) {
      throw py::key_error("'" + name + "' is not an input of the model");
    }
    InputSignal s = SignalOf(name, value);
    s.slot = *slot;
    signals.push_back(std::move(s));
  }
  return signals;
}

py::dict Model::Simulate(std::optional<double> until,
                         const std::map<std::string, SignalValue>& inputs,
                         std::optional<double> sample,
                         const std::map<std::string, double>& parameters) const {
  SimulationOptions options;
  options.until = until;
  if (sample) options.sample_step = *sample;
  for (const auto& [name, value] : parameters) options.parameters.emplace_back(name, value);
  const std::vector<InputSignal> signals = Signals(inputs);
  const Simulator sim(system_);
  SimulationResult r;
  {
    py::gil_scoped_release release;
    r = sim.Run(options, signals);
  }
  const py::ssize_t n = static_cast<py::ssize_t>(r.samples.size());
  py::array_t<double> time(n);
  std::vector<py::array_t<double>> columns;
  for (size_t v = 0; v < sim.variable_names().size(); ++v) columns.emplace_back(n);
  py::list modes;
  for (py::ssize_t k = 0; k < n; ++k) {
    const StateSample& s = r.samples[static_cast<size_t>(k)];
    time.mutable_at(k) = s.time;
    for (size_t v = 0; v < columns.size(); ++v) columns[v].mutable_at(k) = s.x[v];
    modes.append(sim.ModeLabel(s.modes));
  }
  py::dict states;
  for (size_t v = 0; v < columns.size(); ++v) states[py::str(sim.variable_names()[v])] = columns[v];
  py::dict out;
  out["status"] = std::string(StatusName(r.status));
  out["message"] = r.message;
  out["time"] = time;
  out["states"] = states;
  out["modes"] = modes;
  // final, events, steps, until (and zeno): the command's JSON, parsed by the package.
  const double horizon = until ? *until : system_.scenario() ? system_.scenario()->until : 0.0;
  out["report_json"] = cli::SimulationReport(sim, r, horizon).dump();
  return out;
}

// `hybrid hand --json` (without --simulate): the report as JSON text.
std::string HandJsonText(const std::vector<std::string>& objects, const std::string& mode,
                         std::optional<double> spread, double g, std::optional<double> g_a,
                         std::optional<double> g_b, std::optional<double> g_c) {
  cli::HandArgs args;
  args.objects = objects;
  args.mode = mode;
  args.spread = spread;
  args.g = g;
  args.g_a = g_a;
  args.g_b = g_b;
  args.g_c = g_c;
  py::gil_scoped_release release;
  return cli::HandReport(args).dump();
}

// `hybrid diagnose DATA --json`: the report as JSON text (the bundled finger without a model).
std::string DiagnoseJsonText(const std::string& data, const std::optional<std::string>& model,
                             double significance, int threads) {
  cli::DiagnoseArgs args;
  args.data = data;
  args.model = model ? *model : cli::BundledFile("spec/finger.ha").string();
  args.significance = significance;
  args.threads = threads;
  py::gil_scoped_release release;
  return cli::DiagnoseReport(args).dump();
}

}  // namespace
}  // namespace hybrid::python

PYBIND11_MODULE(_hybrid, m) {
  using namespace hybrid::python;
  m.doc() = "C++ core of the hybrid package (see the package docstrings; docs/python.md).";
  static py::exception<hybrid::ParseError> model_error(m, "ModelError", PyExc_ValueError);
  static py::exception<hybrid::DataError> data_error(m, "DataError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const hybrid::ParseError& e) {
      model_error(e.what());
    } catch (const std::invalid_argument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const hybrid::DataError& e) {
      data_error(e.what());
    } catch (const hybrid::cli::UsageError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const hybrid::cli::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const std::out_of_range& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  m.def("finger_angles", &FingerAngles, py::arg("g"), py::arg("gob1") = py::none(),
        py::arg("gob2") = py::none(), py::arg("gob3") = py::none(), py::arg("model") = py::none());
  m.def("hand_json", &HandJsonText, py::arg("objects"), py::arg("mode"), py::arg("spread"),
        py::arg("g"), py::arg("g_a"), py::arg("g_b"), py::arg("g_c"));
  m.def("diagnose_json", &DiagnoseJsonText, py::arg("data"), py::arg("model"),
        py::arg("significance"), py::arg("threads"));
  py::class_<Model>(m, "Model")
      .def(py::init<std::string>(), py::arg("path"))
      .def_property_readonly("path", &Model::path)
      .def_property_readonly("name", &Model::name)
      .def("info_json", &Model::InfoJsonText)
      .def("dot", &Model::Dot, py::arg("product") = false)
      .def("check_json", &Model::CheckJsonText, py::arg("properties"), py::arg("method"),
           py::arg("budget"), py::arg("depth"))
      .def("simulate", &Model::Simulate, py::arg("until") = py::none(),
           py::arg("inputs") = std::map<std::string, SignalValue>{}, py::arg("sample") = py::none(),
           py::arg("parameters") = std::map<std::string, double>{});
}

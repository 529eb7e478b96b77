#include "gripper/commands/gripper_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string_view>

#include "commands/command_error.h"
#include "commands/output.h"
#include "gripper/commands/finger_batch.h"
#include "hybrid/automaton/expression.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/gripper/finger_closed_form.h"
#include "hybrid/gripper/finger_parameters.h"
#include "hybrid/gripper/geometric_finger.h"
#include "hybrid/gripper/hand.h"
#include "hybrid/gripper/measured_data.h"
#include "hybrid/gripper/robot_frames.h"
#include "hybrid/gripper/svg_figures.h"
#include "hybrid/simulation/simulator.h"

namespace hybrid::cli {
namespace {

using gripper::FingerClosedForm;
using gripper::FingerConfiguration;
using gripper::FingerContacts;
using gripper::FingerGeometry;
using gripper::FingerParameters;
using gripper::GeometricFinger;
using gripper::Obstacle;
using json = nlohmann::ordered_json;

// Most motor positions one batch (--queries, --g-range) answers: its output stays under about
// 100 MB (CSV) or 150 MB (JSON).
constexpr std::size_t kMaxBatchQueries = 1000000;
constexpr double kAgreement = 1e-6;  // degrees: simulation against the closed form

std::vector<Obstacle> ParseObjects(const std::vector<std::string>& texts) {
  std::vector<Obstacle> out;
  for (const std::string& text : texts) {
    try {
      out.push_back(Obstacle::Parse(text));
    } catch (const gripper::ObstacleParseError& e) {
      throw OptionError("objects", Arg("objects") + " '" + text + "': column " +
                                       std::to_string(e.column()) + ": " + e.what());
    } catch (const std::invalid_argument& e) {
      throw OptionError("objects", Arg("objects") + " '" + text + "': " + e.what());
    }
  }
  return out;
}

// Throws OptionError about `argument` unless `g` is a motor position (the spread motor has the
// same range).
void CheckMotor(const std::string& argument, double g) {
  if (!(g >= 0.0 && g <= 255.0)) {
    const std::string value =
        std::isnan(g) ? "nan" : (std::isinf(g) ? (g > 0 ? "inf" : "-inf") : FormatNumber(g));
    throw OptionError(argument,
                      Arg(argument) + " must be a motor position in [0, 255] (got " + value + ")",
                      OptionError::Scope::kCommand);
  }
}

json ConfigurationJson(double g, const FingerConfiguration& q) {
  return {{"g", g},
          {"motor", q.motor},
          {"theta1", q.theta[0]},
          {"theta2", q.theta[1]},
          {"theta3", q.theta[2]},
          {"phase", gripper::PhaseName(q.phase)},
          {"mode", gripper::FingerModeName(q)},
          {"discrete",
           {{"c1", q.c[0]},
            {"c2", q.c[1]},
            {"c3", q.c[2]},
            {"l1", q.l[0]},
            {"l2", q.l[1]},
            {"l3", q.l[2]}}}};
}

std::string Fixed(double v, int digits = 6) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

// Who blocks link i: "object K" (1-based), "palm", "finger X" or "gob" for a given position.
std::string BlockerName(const std::optional<int>& by, const std::string& imposed_name) {
  if (!by) return "given";
  if (*by == GeometricFinger::kPalm) return "palm";
  if (*by == GeometricFinger::kImposed) return imposed_name;
  return "object " + std::to_string(*by + 1);
}

// The contacts that take effect while closing (a given contact position beyond where a link
// stops moving, e.g. --gob1 200 with link 1 at its limit since 140, does not).
std::vector<HandFinger::Contact> EffectiveContacts(
    const FingerClosedForm& closed, const std::array<std::optional<int>, 3>& by,
    const std::array<std::string, 3>& imposed_names) {
  const FingerContacts& contacts = closed.contacts();
  std::vector<HandFinger::Contact> out;
  for (int i = 0; i < 3; ++i) {
    if (contacts.gob[i] > 255.0 || closed.pieces().back().c[i] != 1) continue;
    out.push_back({i + 1, contacts.gob[i], BlockerName(by[i], imposed_names[i])});
  }
  return out;
}

json ContactsJson(const std::vector<HandFinger::Contact>& contacts) {
  json out = json::array();
  for (const auto& c : contacts) out.push_back({{"link", c.link}, {"g", c.g}, {"by", c.by}});
  return out;
}

json StopJson(double stop) { return std::isfinite(stop) ? json(stop) : json(nullptr); }

// The closing of the fingers of `system` (instance prefixes "A.", ... or "" for one finger),
// each driven at u = 1 until its command (`commands`: input name and command), compared at
// every recorded state with the closed form: joint angles with `expected(f, motor)`, and the
// motor position at time t with min(t, command, stops[f]) (where the closed form stops).
struct Comparison {
  SimulationStatus status;
  std::string message;
  double max_angle_difference = 0.0;
  double max_motor_difference = 0.0;
  json contacts = json::array();
};

template <typename Expected>
Comparison SimulateClosing(const System& system, const std::vector<std::string>& prefixes,
                           const std::vector<std::pair<std::string, double>>& commands,
                           const std::vector<double>& stops, Expected expected) {
  const Simulator sim(system);
  std::vector<InputSignal> signals;
  double until = 1.0;
  for (const auto& [input, command] : commands) {
    InputSignal s{*system.symbols().Find(input), InputSignal::Shape::kStep, {{0.0, 1.0}}};
    if (command > 0.0) s.points.push_back({command, 0.0});
    if (command == 0.0) s.points = {{0.0, 0.0}};
    signals.push_back(s);
    until = std::max(until, command + 1.0);
  }
  SimulationOptions o;
  o.until = until;
  o.sample_step = 0.5;
  const SimulationResult r = sim.Run(o, signals);
  Comparison out;
  out.status = r.status;
  out.message = r.message;
  const auto& names = sim.variable_names();
  auto index = [&](const std::string& n) {
    return static_cast<int>(std::find(names.begin(), names.end(), n) - names.begin());
  };
  for (size_t f = 0; f < prefixes.size(); ++f) {
    const std::string& p = prefixes[f];
    const int g = index(p + "g");
    const std::array<int, 3> th = {index(p + "theta1"), index(p + "theta2"), index(p + "theta3")};
    const double command = commands[std::min(f, commands.size() - 1)].second;
    for (const StateSample& s : r.samples) {
      const Eigen::Vector3d q = expected(static_cast<int>(f), std::clamp(s.x[g], 0.0, 255.0));
      for (int k = 0; k < 3; ++k) {
        out.max_angle_difference = std::max(out.max_angle_difference, std::abs(s.x[th[k]] - q[k]));
      }
      const double motor = std::min({s.time, command, stops[f]});
      out.max_motor_difference = std::max(out.max_motor_difference, std::abs(s.x[g] - motor));
    }
    const std::string contact = p + "contact";
    for (const EventRecord& e : r.events) {
      if (e.label.rfind(contact, 0) != 0) continue;
      json j = {{"link", std::stoi(e.label.substr(contact.size()))}, {"g", e.before[g]}};
      if (!p.empty()) j["finger"] = p.substr(0, p.size() - 1);
      out.contacts.push_back(j);
    }
  }
  return out;
}

bool Agrees(const Comparison& c) {
  return c.status == SimulationStatus::kCompleted && c.max_angle_difference <= kAgreement &&
         c.max_motor_difference <= kAgreement;
}

json SimulationJson(const Comparison& c) {
  json j = {{"status", std::string(StatusName(c.status))},
            {"contacts", c.contacts},
            {"max_angle_difference_deg", c.max_angle_difference},
            {"max_motor_difference", c.max_motor_difference},
            {"agrees", Agrees(c)}};
  if (!c.message.empty()) j["message"] = c.message;
  return j;
}

// `hybrid finger/hand` with `simulate` needs the finger automaton of spec/finger.ha: variables
// theta1..3 and g, input u, parameters gob1..3, contact transitions. Throws InputError (exit 1).
void CheckFingerModel(const Automaton& a, const std::string& file) {
  const std::vector<std::pair<std::string, SymbolKind>> needed = {
      {"theta1", SymbolKind::kVariable}, {"theta2", SymbolKind::kVariable},
      {"theta3", SymbolKind::kVariable}, {"g", SymbolKind::kVariable},
      {"u", SymbolKind::kInput},         {"gob1", SymbolKind::kParameter},
      {"gob2", SymbolKind::kParameter},  {"gob3", SymbolKind::kParameter}};
  for (const auto& [name, kind] : needed) {
    const auto slot = a.symbols().Find(name);
    if (!slot || a.symbols()[*slot].kind != kind) {
      throw InputError(file + ": not a finger model like spec/finger.ha (automaton '" + a.name() +
                       "' has no " + std::string(KindName(kind)) + " '" + name + "')");
    }
  }
}

std::vector<double> DefaultFrames(const std::vector<double>& at) {
  return at.empty() ? std::vector<double>{0, 30, 70, 110, 150, 180, 210, 255} : at;
}

// Names of the hand's fingers, by index.
constexpr std::string_view kFingerNames = "ABC";

// Whether any of gob1..3 is given.
bool AnyGob(const FingerArgs& args) {
  return std::any_of(args.gob.begin(), args.gob.end(),
                     [](const std::optional<double>& gob) { return gob.has_value(); });
}

// Validates the options of `hybrid finger` (throwing as RunFinger documents) and returns the
// contact positions given by --gob1..3 (the others at their default). Turns a --g of -0 into 0.
// The batch options (--queries, --g-range) and what they cannot be combined with.
void CheckBatchArgs(const FingerArgs& args) {
  if (args.queries.empty() && args.g_range.empty()) {
    if (!args.output.empty()) {
      throw OptionError("output",
                        Arg("output") + " needs " + Arg("queries") + " or " + Arg("g_range"));
    }
    return;
  }
  if (!args.queries.empty() && !args.g_range.empty()) {
    throw OptionError("g_range", Arg("queries") + " and " + Arg("g_range") +
                                     " cannot be combined (one batch at a time)");
  }
  const std::string batch = args.queries.empty() ? "g_range" : "queries";
  if (args.g || !args.requests.empty() || args.simulate || !args.draw.empty() ||
      !args.plot.empty()) {
    throw OptionError(batch, Arg(batch) + " cannot be combined with " + Arg("g") + ", " +
                                 Arg("requests") + ", " + Arg("simulate") + ", " + Arg("draw") +
                                 " or " + Arg("plot"));
  }
}

FingerContacts CheckFingerArgs(FingerArgs& args) {
  CheckBatchArgs(args);
  // Asked nothing else, the finger answers for the fully closing command, as `hand` does.
  if (!args.g && args.requests.empty() && args.draw.empty() && args.plot.empty() &&
      args.queries.empty() && args.g_range.empty()) {
    args.g = kDefaultMotorCommand;
  }
  const std::vector<NamedFile> outputs = {
      {"draw", args.draw}, {"plot", args.plot}, {"output", args.output}};
  std::vector<NamedFile> inputs;
  if (!args.model.empty()) inputs = ModelInputs("model", args.model);
  if (!args.data.empty()) inputs.push_back({"data", args.data});
  if (!args.queries.empty()) inputs.push_back({"queries", args.queries});
  CheckDistinctFiles(inputs, outputs);
  CheckOutputPlaces(outputs);
  if (args.g) {
    CheckMotor("g", *args.g);
    *args.g += 0.0;  // -0 -> 0
  }
  for (double g : args.draw_at) CheckMotor("draw_at", g);
  for (double& r : args.requests) {
    CheckMotor("requests", r);
    r += 0.0;  // -0 -> 0
  }
  FingerContacts contacts;
  for (int i = 0; i < 3; ++i) {
    if (!args.gob[i]) continue;
    CheckMotor("gob" + std::to_string(i + 1), *args.gob[i]);
    contacts.gob[i] = *args.gob[i];
  }
  if (AnyGob(args) && !args.objects.empty()) {
    throw OptionError("objects", Arg("gob1") + "..3 and " + Arg("objects") + " cannot be combined",
                      OptionError::Scope::kCommand);
  }
  if (!args.data.empty() && args.plot.empty()) {
    throw OptionError(
        "data", Arg("data") + " needs " + Arg("plot") + " (it overlays the runs on the plot)");
  }
  return contacts;
}

// The finger automaton of --model, if given. Throws InputError (exit 1) if the file holds more
// than one automaton.
std::optional<Automaton> FingerModel(const FingerArgs& args) {
  if (args.model.empty()) return std::nullopt;
  const System model = ParseModelFile(args.model);
  if (model.components().size() != 1) {
    throw InputError(args.model + ": not a finger model like spec/finger.ha (it has " +
                     std::to_string(model.components().size()) + " components)");
  }
  return model.components()[0].automaton;
}

// The closed form's constants of `model` (joint ranges, phase-3 fraction), or the report's
// without one. Throws InputError (exit 1) if it is not a finger automaton like spec/finger.ha.
FingerParameters ModelParameters(const std::optional<Automaton>& model, const std::string& file) {
  if (!model) return {};
  try {
    const FingerParameters p = gripper::FingerParametersOf(*model);
    FingerClosedForm check({}, p);  // the closed form's own conditions on its constants
    return p;
  } catch (const std::invalid_argument& e) {
    throw InputError(file + ": " + e.what());
  }
}

// The finger with `parameters` closing on `objects` (none without objects); throws InputError if
// the objects are invalid (a finger that cannot reach them is valid: FingerStatus).
std::optional<GeometricFinger> FingerOnObjects(const std::vector<Obstacle>& objects,
                                               const FingerParameters& parameters) {
  std::optional<GeometricFinger> geometric;
  if (objects.empty()) return geometric;
  try {
    geometric.emplace(objects, FingerGeometry(), parameters);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  return geometric;
}

}  // namespace

double FirstObjectContact(const GeometricFinger& finger) {
  double first = std::numeric_limits<double>::quiet_NaN();
  for (int i = 0; i < 3; ++i) {
    const auto& by = finger.blocked_by()[i];
    if (!by || *by < 0) continue;
    const double g = finger.contacts().gob[i];
    if (!(first <= g)) first = g;
  }
  return first;
}

std::string ContactStatus(double first_contact, double g) {
  if (std::isnan(first_contact)) return "out_of_reach";
  return first_contact <= g ? "contact" : "free";
}

namespace {

// The settled state after each request of --requests: the controller drives the motor to the
// request and stops it where the finger stalls (closed.stop()); it stays there until a request
// below the stop (docs/finger_model.md, "The controller"). The closed form has no hysteresis, so
// the angles are its configuration at the motor's position; the status is the firmware's (2:
// stopped while closing, 3: at the request).
json RequestHistoryJson(const std::vector<double>& requests, const FingerClosedForm& closed) {
  json out = json::array();
  for (const double r : requests) {
    json entry = ConfigurationJson(r, closed.At(r));
    entry.erase("g");
    entry["request"] = r;
    entry["status"] = r >= closed.stop() ? 2 : 3;
    out.push_back(std::move(entry));
  }
  return out;
}

// The report of `hybrid finger` before any simulation: the configuration at --g (if given), the
// settled states after --requests, the contacts that take effect, where the finger stops and the
// objects.
json FingerReport(const FingerArgs& args, const FingerClosedForm& closed,
                  const std::optional<GeometricFinger>& geometric,
                  const std::vector<Obstacle>& objects) {
  std::array<std::optional<int>, 3> by;
  if (geometric) by = geometric->blocked_by();
  json report;
  if (args.g) report = ConfigurationJson(*args.g, closed.At(*args.g));
  if (!args.requests.empty()) report["requests"] = RequestHistoryJson(args.requests, closed);
  report["contacts"] = ContactsJson(EffectiveContacts(closed, by, {"", "", ""}));
  report["stop"] = StopJson(closed.stop());
  if (geometric) {
    const double first = FirstObjectContact(*geometric);
    report["status"] = ContactStatus(first, args.g.value_or(255.0));
    report["first_contact"] = std::isnan(first) ? json(nullptr) : json(first);
  }
  if (!objects.empty()) {
    json list = json::array();
    for (const Obstacle& o : objects) list.push_back(o.ToString());
    report["objects"] = list;
  }
  return report;
}

// `hybrid finger --simulate`: `model`, the finger automaton of --model (with the geometric contact
// guards of `geometric`, else with the contact positions `contacts`) closing at u = 1 up to 255,
// compared with `closed`. Throws InputError if --model is not a finger model.
Comparison SimulateFinger(const FingerArgs& args, const Automaton& model,
                          const std::optional<GeometricFinger>& geometric,
                          const FingerContacts& contacts, const FingerClosedForm& closed) {
  CheckFingerModel(model, args.model);
  System system("finger");
  try {
    system = System::Of(geometric ? geometric->ContactAutomaton(model) : model);
  } catch (const std::invalid_argument& e) {
    throw InputError(args.model + ": " + e.what());
  }
  for (int i = 0; i < 3 && !geometric; ++i) {
    system.SetParameter("gob" + std::to_string(i + 1), std::min(contacts.gob[i], 256.0));
  }
  return SimulateClosing(system, {""}, {{"u", 255.0}}, {closed.stop()},
                         [&](int, double g) { return closed.At(g).theta; });
}

// The runs of --data whose object is the finger's: a run against link i at gob when only --gobi
// = gob is given, free runs when no --gobN is (none with --object). Throws InputError (exit 1)
// when no run matches; the file's errors are DataError (exit 1, with line and column).
std::vector<gripper::MeasuredSeries> OverlaidRuns(const FingerArgs& args,
                                                  const FingerContacts& contacts) {
  std::vector<gripper::MeasuredSeries> out;
  if (args.data.empty()) return out;
  const MeasuredData data = ReadMeasuredDataFile(args.data);
  std::string wanted = "free space";
  int given = 0, link = 0;
  for (int i = 0; i < 3; ++i) {
    if (!(contacts.gob[i] <= 255.0)) continue;
    ++given;
    link = i + 1;
    wanted = "gob" + std::to_string(link) + " = " + FormatNumber(contacts.gob[i]);
  }
  for (const MeasuredRun& run : data.runs) {
    const bool matches = args.objects.empty() &&
                         (given == 0 ? !run.contact_link
                                     : given == 1 && run.contact_link == link && run.gob &&
                                           std::abs(*run.gob - contacts.gob[link - 1]) <= 1e-9);
    if (matches) out.push_back({run.g, run.theta});
  }
  if (out.empty()) {
    throw InputError(args.data + ": no run has the finger's object (" +
                     (args.objects.empty() ? ArgumentMessage(wanted) : Arg("objects")) +
                     "): " + Arg("data") + " overlays the runs measured with it");
  }
  return out;
}

// The files of `hybrid finger`: --draw (the finger at the frames' motor positions) and --plot
// (the joint angles against g), as (path, SVG) pairs.
std::vector<std::pair<std::string, std::string>> FingerFiles(
    const FingerArgs& args, const FingerClosedForm& closed,
    const std::optional<GeometricFinger>& geometric, const std::vector<Obstacle>& objects,
    const FingerContacts& contacts) {
  std::vector<std::pair<std::string, std::string>> files;
  if (!args.draw.empty()) {
    std::vector<std::pair<double, FingerConfiguration>> frames;
    for (double g : DefaultFrames(args.draw_at)) frames.emplace_back(g, closed.At(g));
    files.emplace_back(args.draw, gripper::FingerDrawingSvg(
                                      geometric ? geometric->geometry() : gripper::FingerGeometry(),
                                      objects, frames));
  }
  if (!args.plot.empty()) {
    std::string title = "Robotiq finger, closed form";
    if (!objects.empty()) title += " against " + objects[0].ToString();
    for (int i = 0; i < 3 && AnyGob(args); ++i) {
      if (contacts.gob[i] <= 255.0) {
        title += ", gob" + std::to_string(i + 1) + " = " + FormatNumber(contacts.gob[i]);
      }
    }
    files.emplace_back(args.plot,
                       gripper::AnglePlotSvg(closed, title, OverlaidRuns(args, contacts)));
  }
  return files;
}

// The text output of `hybrid finger` from its `report`.
std::string FingerText(const FingerArgs& args, const FingerClosedForm& closed, const json& report) {
  std::ostringstream out;
  if (args.g) {
    const FingerConfiguration q = closed.At(*args.g);
    out << "g = " << FormatNumber(*args.g) << ": phase " << gripper::PhaseName(q.phase)
        << ", state " << gripper::FingerModeName(q) << ", motor at " << FormatNumber(q.motor)
        << "\n"
        << "theta1 = " << Fixed(q.theta[0]) << " deg\ntheta2 = " << Fixed(q.theta[1])
        << " deg\ntheta3 = " << Fixed(q.theta[2]) << " deg\n";
  }
  if (report.contains("requests")) {
    out << "request    motor  status     theta1     theta2     theta3  mode\n";
    for (const json& e : report.at("requests")) {
      char line[160];
      std::snprintf(line, sizeof line, "%7.2f  %7.2f  %6d  %9.4f  %9.4f  %9.4f  %s\n",
                    e["request"].get<double>(), e["motor"].get<double>(), e["status"].get<int>(),
                    e["theta1"].get<double>(), e["theta2"].get<double>(), e["theta3"].get<double>(),
                    e["mode"].get<std::string>().c_str());
      out << line;
    }
  }
  out << "contacts:";
  if (report.at("contacts").empty()) out << " none";
  for (const auto& c : report.at("contacts")) {
    out << " link " << c["link"].get<int>() << " at g = " << Fixed(c["g"].get<double>()) << " ("
        << c["by"].get<std::string>() << ");";
  }
  out << "\nthe finger stops at "
      << (std::isfinite(closed.stop()) ? "g = " + Fixed(closed.stop()) : "no g (still moving)")
      << "\n";
  if (args.simulate) {
    const json& s = report.at("simulation");
    out << "simulation (" << args.model << "): " << s["status"].get<std::string>()
        << ", max |theta difference| = " << s["max_angle_difference_deg"].get<double>()
        << " deg: " << (s["agrees"].get<bool>() ? "agrees" : "DISAGREES")
        << " with the closed form\n";
  }
  return out.str();
}

// The motor commands of fingers A, B and C: --g, or per finger --g-a, --g-b, --g-c (checked).
std::array<double, 3> HandCommands(const HandArgs& args) {
  std::array<double, 3> commands = {args.g, args.g, args.g};
  const std::array<std::optional<double>, 3> per = {args.g_a, args.g_b, args.g_c};
  for (int f = 0; f < 3; ++f) {
    if (per[f]) {
      CheckMotor(std::string("g_") + "abc"[f], *per[f]);
      commands[f] = *per[f];
    }
  }
  return commands;
}

// The spread motor position: --spread (checked), else the position of --mode.
double HandSpread(const HandArgs& args) {
  const gripper::SpreadMode mode = gripper::SpreadModeByName(args.mode);
  double spread = gripper::Hand::SpreadPosition(mode);
  if (args.spread) {
    CheckMotor("spread", *args.spread);
    spread = *args.spread;
  }
  return spread;
}

// The hand closing on `objects`; throws InputError if the hand cannot be built (an object that
// overlaps the palm or an open finger). A hand that does not reach the objects is valid: its
// status says so (HandOutcomeOf).
gripper::Hand HandOnObjects(const std::vector<Obstacle>& objects, double spread,
                            const std::array<double, 3>& commands) {
  try {
    return gripper::Hand(objects, spread, commands);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
}

// The first motor position at which a finger of `hand` touches an object (not the palm or
// another finger); NaN if none does before its command.
double FirstHandContact(const gripper::Hand& hand) {
  double first = std::numeric_limits<double>::quiet_NaN();
  for (int f = 0; f < 3; ++f) {
    const double g = FirstObjectContact(hand.finger(f));
    if (!(first <= g)) first = g;
  }
  return first;
}

}  // namespace

HandFinger HandFingerOf(const gripper::Hand& hand, int f) {
  const double command = hand.commands()[f];
  std::array<std::string, 3> imposed;
  for (const auto& t : hand.touches()) {
    if (t.finger_a == f) imposed[t.link_a] = std::string("finger ") + kFingerNames[t.finger_b];
    if (t.finger_b == f) imposed[t.link_b] = std::string("finger ") + kFingerNames[t.finger_a];
  }
  HandFinger out{command, hand.At(f, 255.0)};
  const FingerClosedForm& closed = hand.finger(f).closed_form();
  out.contacts = EffectiveContacts(closed, hand.finger(f).blocked_by(), imposed);
  // Where the finger stops by itself (phase 4), if before its command; else +inf.
  const double stop = closed.stop();
  out.stop = stop <= command ? stop : std::numeric_limits<double>::infinity();
  return out;
}

HandOutcome HandOutcomeOf(const gripper::Hand& hand, double spread) {
  HandOutcome out;
  out.first_contact = FirstHandContact(hand);
  if (!std::isnan(out.first_contact)) {
    out.status = "contact";
    return out;
  }
  if (hand.objects().empty()) {
    out.status = "free";
    return out;
  }
  // Not touched at these commands: where closing all the way would first touch.
  const gripper::Hand closed(hand.objects(), spread, {255.0, 255.0, 255.0}, hand.layout());
  out.first_contact = FirstHandContact(closed);
  out.status = std::isnan(out.first_contact) ? "out_of_reach" : "free";
  return out;
}

namespace {

// The "fingers" array of the hand report: per finger its command, its configuration at the end of
// the closing, the contacts that take effect (other fingers named) and where it stops by itself.
json HandFingersJson(const gripper::Hand& hand) {
  json fingers = json::array();
  for (int f = 0; f < 3; ++f) {
    const HandFinger finger = HandFingerOf(hand, f);
    json j = {{"finger", std::string(1, kFingerNames[f])}, {"command", finger.command}};
    j.update(ConfigurationJson(finger.command, finger.configuration));
    j.erase("g");
    j["contacts"] = ContactsJson(finger.contacts);
    j["stop"] = StopJson(finger.stop);
    fingers.push_back(j);
  }
  return fingers;
}

// The "finger_touches" array of the hand report.
json HandTouchesJson(const gripper::Hand& hand) {
  json touches = json::array();
  for (const auto& t : hand.touches()) {
    touches.push_back(
        {{"fingers",
          {std::string(1, kFingerNames[t.finger_a]), std::string(1, kFingerNames[t.finger_b])}},
         {"links", {t.link_a + 1, t.link_b + 1}},
         {"g", t.g}});
  }
  return touches;
}

// `hybrid hand --simulate`: the finger automata of --model composed as `hand` has them, driven
// by `commands` (one shared input u unless `per_finger`), compared with the closed form. Throws
// InputError if --model has no suitable finger automaton.
Comparison SimulateHand(const HandArgs& args, const gripper::Hand& hand,
                        const std::array<double, 3>& commands, bool per_finger) {
  const System model = ParseModelFile(args.model);
  System system("hand");
  try {
    for (const Component& c : model.components()) {
      if (c.source.name() == "finger") CheckFingerModel(c.source, args.model);
    }
    system = hand.ComposedAutomata(model, /*shared_command=*/!per_finger);
  } catch (const std::invalid_argument& e) {
    throw InputError(args.model + ": " + e.what());
  }
  std::vector<std::pair<std::string, double>> inputs;
  if (per_finger) {
    for (int f = 0; f < 3; ++f) {
      inputs.emplace_back(std::string(1, kFingerNames[f]) + ".u", commands[f]);
    }
  } else {
    inputs.emplace_back("u", args.g);
  }
  std::vector<double> stops;
  for (int f = 0; f < 3; ++f) stops.push_back(hand.finger(f).closed_form().stop());
  return SimulateClosing(system, {"A.", "B.", "C."}, inputs, stops, [&](int f, double g) {
    return hand.finger(f).At(std::min(g, commands[f])).theta;
  });
}

// The text output of `hybrid hand` from its `report` (spread position `spread`).
std::string HandText(const HandArgs& args, const gripper::Hand& hand, double spread,
                     const std::vector<Obstacle>& objects, const json& report) {
  std::ostringstream out;
  out << "hand, " << (args.spread ? "spread set by --spread" : args.mode + " mode")
      << " (spread s = " << FormatNumber(spread) << ", angle " << Fixed(hand.spread_angle(), 3)
      << " deg)";
  for (const Obstacle& o : objects) out << ", object " << o.ToString();
  out << "\n";
  for (const auto& j : report.at("fingers")) {
    out << "finger " << j["finger"].get<std::string>() << " (command "
        << FormatNumber(j["command"].get<double>()) << "): phase " << j["phase"].get<std::string>()
        << ", " << j["mode"].get<std::string>() << ", motor at "
        << Fixed(j["motor"].get<double>(), 3) << "; theta = ("
        << Fixed(j["theta1"].get<double>(), 4) << ", " << Fixed(j["theta2"].get<double>(), 4)
        << ", " << Fixed(j["theta3"].get<double>(), 4) << ") deg; contacts:";
    if (j["contacts"].empty()) out << " none";
    for (const auto& c : j["contacts"]) {
      out << " link " << c["link"].get<int>() << " at g = " << Fixed(c["g"].get<double>(), 4)
          << " (" << c["by"].get<std::string>() << ")";
    }
    out << "\n";
  }
  const std::string status = report.at("status").get<std::string>();
  if (status == "out_of_reach") {
    out << "out of reach: the fingers closing all the way touch no object\n";
  } else if (status == "free" && !objects.empty()) {
    out << "no finger touches an object at these commands; closing further, the first contact "
           "is at g = "
        << Fixed(report.at("first_contact").get<double>(), 4) << "\n";
  }
  for (const auto& t : report.at("finger_touches")) {
    out << "fingers " << t["fingers"][0].get<std::string>() << t["fingers"][1].get<std::string>()
        << " touch (links " << t["links"][0].get<int>() << ", " << t["links"][1].get<int>()
        << ") at g = " << Fixed(t["g"].get<double>(), 4) << "\n";
  }
  if (args.joint_state) {
    const json& js = report.at("joint_state");
    out << "joint state (ROS description, rad):";
    for (size_t k = 0; k < js["name"].size(); ++k) {
      out << (k % 4 == 0 ? "\n  " : "  ") << js["name"][k].get<std::string>() << " "
          << Fixed(js["position"][k].get<double>(), 4);
    }
    out << "\n";
    if (!js["clamped"].empty()) {
      out << "  clamped into the description's limits:";
      for (const auto& name : js["clamped"]) out << " " << name.get<std::string>();
      out << "\n";
    }
  }
  if (args.simulate) {
    const json& s = report.at("simulation");
    out << "simulation of the composed automata: " << s["status"].get<std::string>()
        << ", max |theta difference| = " << s["max_angle_difference_deg"].get<double>()
        << " deg: " << (s["agrees"].get<bool>() ? "agrees" : "DISAGREES")
        << " with the closed form\n";
  }
  return out.str();
}

// What `hybrid finger` works from: its checked arguments, the contact positions given, the
// objects, the model, the finger on the objects and its closed form.
struct FingerSetup {
  FingerArgs args;
  FingerContacts contacts;
  std::vector<Obstacle> objects;
  std::optional<Automaton> model;
  std::optional<GeometricFinger> geometric;
  FingerClosedForm closed;
};

FingerSetup SetUpFinger(const FingerArgs& args_in) {
  FingerArgs args = args_in;
  const FingerContacts contacts = CheckFingerArgs(args);
  std::vector<Obstacle> objects = ParseObjects(args.objects);
  std::optional<Automaton> model = FingerModel(args);
  const FingerParameters parameters = ModelParameters(model, args.model);
  std::optional<GeometricFinger> geometric = FingerOnObjects(objects, parameters);
  FingerClosedForm closed =
      geometric ? geometric->closed_form() : FingerClosedForm(contacts, parameters);
  return {std::move(args),      contacts,         std::move(objects), std::move(model),
          std::move(geometric), std::move(closed)};
}

}  // namespace

ExitCode RunFinger(const FingerArgs& args_in) {
  const FingerSetup setup = SetUpFinger(args_in);
  const auto& [args, contacts, objects, model, geometric, closed] = setup;
  if (!args.queries.empty() || !args.g_range.empty()) {
    const std::vector<double> g = args.queries.empty()
                                      ? MotorRange(args.g_range, kMaxBatchQueries)
                                      : ReadMotorPositions(args.queries, kMaxBatchQueries);
    WriteOutput(args.output, args.json ? BatchJson(closed, g) : BatchCsv(closed, g));
    return ExitCode::kOk;
  }
  json report = FingerReport(args, closed, geometric, objects);
  ExitCode code = ExitCode::kOk;
  if (args.simulate) {
    const Comparison c = SimulateFinger(args, *model, geometric, contacts, closed);
    report["simulation"] = SimulationJson(c);
    const bool agrees = Agrees(c);
    if (!agrees) code = ExitCode::kSimulationFailed;
  }
  WriteOutputs(FingerFiles(args, closed, geometric, objects, contacts));
  if (args.json) {
    WriteOutput("-", report.dump(2) + "\n");
    return code;
  }
  WriteOutput("-", FingerText(args, closed, report));
  return code;
}

namespace {

// The hand's configuration at the end of its closing as the ROS description's joint state.
json JointStateJson(const gripper::Hand& hand) {
  std::array<Eigen::Vector3d, 3> theta;
  for (int f = 0; f < 3; ++f) theta[f] = hand.At(f, 255.0).theta;
  const gripper::JointState state = gripper::RosJointState(theta, hand.spread_angle());
  return {{"name", state.name},
          {"position", state.position},
          {"model_position", state.model_position},
          {"clamped", state.clamped}};
}

// The report of `hybrid hand` before any simulation (the spread, each finger, their touches).
json HandJson(const HandArgs& args, const gripper::Hand& hand, double spread) {
  // With --spread the spread is set directly: no operating mode applies.
  const HandOutcome outcome = HandOutcomeOf(hand, spread);
  json report = {{"mode", args.spread ? json(nullptr) : json(args.mode)},
                 {"spread", spread},
                 {"spread_angle_deg", hand.spread_angle()},
                 {"status", outcome.status},
                 {"first_contact",
                  std::isnan(outcome.first_contact) ? json(nullptr) : json(outcome.first_contact)},
                 {"fingers", HandFingersJson(hand)},
                 {"finger_touches", HandTouchesJson(hand)}};
  if (args.joint_state) report["joint_state"] = JointStateJson(hand);
  return report;
}

}  // namespace

nlohmann::ordered_json FingerReportJson(const FingerArgs& args) {
  const FingerSetup s = SetUpFinger(args);
  return FingerReport(s.args, s.closed, s.geometric, s.objects);
}

HandSettings CheckedHandSettings(const HandArgs& args) {
  CheckMotor("g", args.g);
  HandSettings out;
  out.commands = HandCommands(args);
  out.spread = HandSpread(args);
  out.objects = ParseObjects(args.objects);
  return out;
}

void CheckMotorPosition(const std::string& argument, double g) { CheckMotor(argument, g); }

std::vector<gripper::Obstacle> ParseObjectList(const std::vector<std::string>& texts) {
  return ParseObjects(texts);
}

HandFinger FingerAt(const GeometricFinger& finger, double g) {
  const FingerClosedForm& closed = finger.closed_form();
  HandFinger out{g, closed.At(g)};
  out.contacts = EffectiveContacts(closed, finger.blocked_by(), {"", "", ""});
  out.stop = closed.stop();
  return out;
}

nlohmann::ordered_json HandReport(const HandArgs& args) {
  const HandSettings settings = CheckedHandSettings(args);
  const gripper::Hand hand = HandOnObjects(settings.objects, settings.spread, settings.commands);
  return HandJson(args, hand, settings.spread);
}

ExitCode RunHand(const HandArgs& args) {
  CheckDistinctFiles(args.simulate ? ModelInputs("model", args.model) : std::vector<NamedFile>{},
                     {{"draw", args.draw}});
  CheckOutputPlaces({{"draw", args.draw}});
  CheckMotor("g", args.g);
  const std::array<double, 3> commands = HandCommands(args);
  const bool per_finger = args.g_a || args.g_b || args.g_c;
  const double spread = HandSpread(args);
  for (double g : args.draw_at) CheckMotor("draw_at", g);
  const std::vector<Obstacle> objects = ParseObjects(args.objects);
  const gripper::Hand hand = HandOnObjects(objects, spread, commands);
  json report = HandJson(args, hand, spread);
  ExitCode code = ExitCode::kOk;
  if (args.simulate) {
    const Comparison c = SimulateHand(args, hand, commands, per_finger);
    const bool agrees = Agrees(c);
    report["simulation"] = SimulationJson(c);
    if (!agrees) code = ExitCode::kSimulationFailed;
  }
  if (!args.draw.empty()) {
    std::vector<gripper::HandFrame> frames;
    for (double g : DefaultFrames(args.draw_at)) {
      frames.push_back({g, {hand.At(0, g), hand.At(1, g), hand.At(2, g)}});
    }
    WriteOutput(args.draw, gripper::HandDrawingSvg(hand, frames));
  }
  if (args.json) {
    WriteOutput("-", report.dump(2) + "\n");
    return code;
  }
  WriteOutput("-", HandText(args, hand, spread, objects, report));
  return code;
}

}  // namespace hybrid::cli

#include "tools/gripper_command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "automaton/expression.h"
#include "automaton/parser.h"
#include "gripper/finger_closed_form.h"
#include "gripper/geometric_finger.h"
#include "gripper/hand.h"
#include "gripper/svg_figures.h"
#include "solvers/simulation/simulator.h"
#include "tools/options.h"
#include "tools/output.h"
#include "tools/user_message.h"

namespace hybrid::cli {
namespace {

using gripper::FingerClosedForm;
using gripper::FingerConfiguration;
using gripper::FingerContacts;
using gripper::GeometricFinger;
using gripper::Obstacle;
using json = nlohmann::ordered_json;

constexpr int kExitDisagrees = 5;
constexpr double kAgreement = 1e-6;  // degrees: simulation against the closed form

std::vector<Obstacle> ParseObjects(const std::vector<std::string>& texts) {
  std::vector<Obstacle> out;
  for (const std::string& text : texts) {
    try {
      out.push_back(Obstacle::Parse(text));
    } catch (const gripper::ObstacleParseError& e) {
      throw UsageError("--object '" + text + "': column " + std::to_string(e.column()) + ": " +
                       e.what());
    } catch (const std::invalid_argument& e) {
      throw UsageError("--object '" + text + "': " + UserMessage(e.what()));
    }
  }
  return out;
}

void CheckMotor(const std::string& option, double g) {
  if (!(g >= 0.0 && g <= 255.0)) {
    const std::string value =
        std::isnan(g) ? "nan" : (std::isinf(g) ? (g > 0 ? "inf" : "-inf") : FormatNumber(g));
    throw std::invalid_argument(option + " must be a motor position in [0, 255] (got " + value +
                                ")");  // the spread motor has the same range
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
          {"state",
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
json ContactsJson(const FingerClosedForm& closed, const std::array<std::optional<int>, 3>& by,
                  const std::array<std::string, 3>& imposed_names) {
  const FingerContacts& contacts = closed.contacts();
  json out = json::array();
  for (int i = 0; i < 3; ++i) {
    if (contacts.gob[i] > 255.0 || closed.pieces().back().c[i] != 1) continue;
    out.push_back(
        {{"link", i + 1}, {"g", contacts.gob[i]}, {"by", BlockerName(by[i], imposed_names[i])}});
  }
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

// `hybrid finger/hand --simulate` needs the finger automaton of spec/finger.ha: variables
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

}  // namespace

int RunFinger(const FingerArgs& args_in) {
  FingerArgs args = args_in;
  const std::vector<NamedFile> outputs = {{"--draw", args.draw}, {"--plot", args.plot}};
  CheckDistinctFiles(
      args.simulate ? std::vector<NamedFile>{{"--model", args.model}} : std::vector<NamedFile>{},
      outputs);
  CheckOutputPlaces(outputs);
  if (args.g) {
    CheckMotor("--g", *args.g);
    *args.g += 0.0;  // -0 -> 0
  }
  for (double g : args.draw_at) CheckMotor("--at", g);
  FingerContacts contacts;
  bool any_gob = false;
  for (int i = 0; i < 3; ++i) {
    if (!args.gob[i]) continue;
    CheckMotor("--gob" + std::to_string(i + 1), *args.gob[i]);
    contacts.gob[i] = *args.gob[i];
    any_gob = true;
  }
  if (any_gob && !args.objects.empty()) {
    throw std::invalid_argument("--gob1..3 and --object cannot be combined");
  }
  if (!args.g && args.draw.empty() && args.plot.empty()) {
    throw std::invalid_argument("nothing to do: give --g, --draw or --plot");
  }
  const std::vector<Obstacle> objects = ParseObjects(args.objects);
  std::optional<GeometricFinger> geometric;
  if (!objects.empty()) {
    try {
      geometric.emplace(objects);
    } catch (const std::invalid_argument& e) {
      throw InputError(UserMessage(e.what()));
    }
    if (!geometric->touches_object()) {
      throw InputError("the finger cannot reach the object(s): it closes to g = " +
                       FormatNumber(std::min(255.0, geometric->closed_form().stop())) +
                       " without touching " +
                       (objects.size() == 1 ? objects[0].ToString() : "any of them"));
    }
  }
  const FingerClosedForm closed = geometric ? geometric->closed_form() : FingerClosedForm(contacts);
  std::array<std::optional<int>, 3> by;
  if (geometric) by = geometric->blocked_by();
  json report;
  if (args.g) report = ConfigurationJson(*args.g, closed.At(*args.g));
  report["contacts"] = ContactsJson(closed, by, {"", "", ""});
  report["stop"] = StopJson(closed.stop());
  if (!objects.empty()) {
    json list = json::array();
    for (const Obstacle& o : objects) list.push_back(o.ToString());
    report["objects"] = list;
  }
  int code = 0;
  if (args.simulate) {
    const System model = ParseModelFile(args.model);
    if (model.components().size() != 1) {
      throw InputError(args.model + ": not a finger model like spec/finger.ha (it has " +
                       std::to_string(model.components().size()) + " components)");
    }
    CheckFingerModel(model.components()[0].automaton, args.model);
    System system("finger");
    try {
      system = System::Of(geometric ? geometric->ContactAutomaton(model.components()[0].automaton)
                                    : model.components()[0].automaton);
    } catch (const std::invalid_argument& e) {
      throw InputError(args.model + ": " + e.what());
    }
    for (int i = 0; i < 3 && !geometric; ++i) {
      system.SetParameter("gob" + std::to_string(i + 1), std::min(contacts.gob[i], 256.0));
    }
    const Comparison c = SimulateClosing(system, {""}, {{"u", 255.0}}, {closed.stop()},
                                         [&](int, double g) { return closed.At(g).theta; });
    report["simulation"] = SimulationJson(c);
    const bool agrees = Agrees(c);
    if (!agrees) code = kExitDisagrees;
  }
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
    for (int i = 0; i < 3 && any_gob; ++i) {
      if (contacts.gob[i] <= 255.0) {
        title += ", gob" + std::to_string(i + 1) + " = " + FormatNumber(contacts.gob[i]);
      }
    }
    files.emplace_back(args.plot, gripper::AnglePlotSvg(closed, title));
  }
  WriteOutputs(files);
  if (args.json) {
    WriteOutput("-", report.dump(2) + "\n");
    return code;
  }
  std::ostringstream out;
  if (args.g) {
    const FingerConfiguration q = closed.At(*args.g);
    out << "g = " << FormatNumber(*args.g) << ": phase " << gripper::PhaseName(q.phase)
        << ", state " << gripper::FingerModeName(q) << ", motor at " << FormatNumber(q.motor)
        << "\n"
        << "theta1 = " << Fixed(q.theta[0]) << " deg\ntheta2 = " << Fixed(q.theta[1])
        << " deg\ntheta3 = " << Fixed(q.theta[2]) << " deg\n";
  }
  out << "contacts:";
  if (report["contacts"].empty()) out << " none";
  for (const auto& c : report["contacts"]) {
    out << " link " << c["link"].get<int>() << " at g = " << Fixed(c["g"].get<double>()) << " ("
        << c["by"].get<std::string>() << ");";
  }
  out << "\nthe finger stops at "
      << (std::isfinite(closed.stop()) ? "g = " + Fixed(closed.stop()) : "no g (still moving)")
      << "\n";
  if (args.simulate) {
    const json& s = report["simulation"];
    out << "simulation (" << args.model << "): " << s["status"].get<std::string>()
        << ", max |theta difference| = " << s["max_angle_difference_deg"].get<double>()
        << " deg: " << (s["agrees"].get<bool>() ? "agrees" : "DISAGREES")
        << " with the closed form\n";
  }
  WriteOutput("-", out.str());
  return code;
}

int RunHand(const HandArgs& args) {
  CheckDistinctFiles(
      args.simulate ? std::vector<NamedFile>{{"--model", args.model}} : std::vector<NamedFile>{},
      {{"--draw", args.draw}});
  CheckOutputPlaces({{"--draw", args.draw}});
  CheckMotor("--g", args.g);
  std::array<double, 3> commands = {args.g, args.g, args.g};
  const std::array<std::optional<double>, 3> per = {args.g_a, args.g_b, args.g_c};
  const bool per_finger = args.g_a || args.g_b || args.g_c;
  for (int f = 0; f < 3; ++f) {
    if (per[f]) {
      CheckMotor(std::string("--g-") + "abc"[f], *per[f]);
      commands[f] = *per[f];
    }
  }
  const gripper::SpreadMode mode = gripper::SpreadModeByName(args.mode);
  double spread = gripper::Hand::SpreadPosition(mode);
  if (args.spread) {
    CheckMotor("--spread", *args.spread);
    spread = *args.spread;
  }
  for (double g : args.draw_at) CheckMotor("--at", g);
  const std::vector<Obstacle> objects = ParseObjects(args.objects);
  std::optional<gripper::Hand> hand;
  try {
    hand.emplace(objects, spread, commands);
  } catch (const std::invalid_argument& e) {
    throw InputError(UserMessage(e.what()));
  }
  bool touched = false;
  for (int f = 0; f < 3; ++f) touched |= hand->finger(f).touches_object();
  if (!objects.empty() && !touched) {
    throw InputError("no finger reaches the object(s): the hand closes without touching them");
  }
  const std::string names = "ABC";
  json fingers = json::array();
  for (int f = 0; f < 3; ++f) {
    std::array<std::string, 3> imposed;
    for (const auto& t : hand->touches()) {
      if (t.finger_a == f) imposed[t.link_a] = std::string("finger ") + names[t.finger_b];
      if (t.finger_b == f) imposed[t.link_b] = std::string("finger ") + names[t.finger_a];
    }
    json j = {{"finger", std::string(1, names[f])}, {"command", commands[f]}};
    j.update(ConfigurationJson(commands[f], hand->At(f, 255.0)));
    j.erase("g");
    j["contacts"] =
        ContactsJson(hand->finger(f).closed_form(), hand->finger(f).blocked_by(), imposed);
    // Where the finger stops by itself (phase 4), if before its command; else null.
    const double stop = hand->finger(f).closed_form().stop();
    j["stop"] = StopJson(stop <= commands[f] ? stop : std::numeric_limits<double>::infinity());
    fingers.push_back(j);
  }
  json touches = json::array();
  for (const auto& t : hand->touches()) {
    touches.push_back({{"fingers", std::string{names[t.finger_a], names[t.finger_b]}},
                       {"links", {t.link_a + 1, t.link_b + 1}},
                       {"g", t.g}});
  }
  json report = {{"mode", args.mode},
                 {"spread", spread},
                 {"spread_angle_deg", hand->spread_angle()},
                 {"fingers", fingers},
                 {"finger_touches", touches}};
  int code = 0;
  if (args.simulate) {
    const System model = ParseModelFile(args.model);
    System system("hand");
    try {
      for (const Component& c : model.components()) {
        if (c.source.name() == "finger") CheckFingerModel(c.source, args.model);
      }
      system = hand->ComposedAutomata(model, /*shared_command=*/!per_finger);
    } catch (const std::invalid_argument& e) {
      throw InputError(args.model + ": " + UserMessage(e.what()));
    }
    std::vector<std::pair<std::string, double>> inputs;
    if (per_finger) {
      for (int f = 0; f < 3; ++f) inputs.emplace_back(std::string(1, names[f]) + ".u", commands[f]);
    } else {
      inputs.emplace_back("u", args.g);
    }
    std::vector<double> stops;
    for (int f = 0; f < 3; ++f) stops.push_back(hand->finger(f).closed_form().stop());
    const Comparison c = SimulateClosing(
        system, {"A.", "B.", "C."}, inputs, stops,
        [&](int f, double g) { return hand->finger(f).At(std::min(g, commands[f])).theta; });
    const bool agrees = Agrees(c);
    report["simulation"] = SimulationJson(c);
    if (!agrees) code = kExitDisagrees;
  }
  if (!args.draw.empty()) {
    std::vector<gripper::HandFrame> frames;
    for (double g : DefaultFrames(args.draw_at)) {
      frames.push_back({g, {hand->At(0, g), hand->At(1, g), hand->At(2, g)}});
    }
    WriteOutput(args.draw, gripper::HandDrawingSvg(*hand, frames));
  }
  if (args.json) {
    WriteOutput("-", report.dump(2) + "\n");
    return code;
  }
  std::ostringstream out;
  out << "hand, " << args.mode << " mode (spread s = " << FormatNumber(spread) << ", angle "
      << Fixed(hand->spread_angle(), 3) << " deg)";
  for (const Obstacle& o : objects) out << ", object " << o.ToString();
  out << "\n";
  for (const auto& j : fingers) {
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
  for (const auto& t : touches) {
    out << "fingers " << t["fingers"].get<std::string>() << " touch (links "
        << t["links"][0].get<int>() << ", " << t["links"][1].get<int>()
        << ") at g = " << Fixed(t["g"].get<double>(), 4) << "\n";
  }
  if (args.simulate) {
    const json& s = report["simulation"];
    out << "simulation of the composed automata: " << s["status"].get<std::string>()
        << ", max |theta difference| = " << s["max_angle_difference_deg"].get<double>()
        << " deg: " << (s["agrees"].get<bool>() ? "agrees" : "DISAGREES")
        << " with the closed form\n";
  }
  WriteOutput("-", out.str());
  return code;
}

}  // namespace hybrid::cli

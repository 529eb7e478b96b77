#include "hybrid/gripper/gripper_emulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hybrid/simulation/simulator.h"

namespace hybrid::gripper {
namespace {

constexpr std::array<const char*, 4> kAxes = {"A", "B", "C", "S"};
constexpr std::array<const char*, 4> kControllers = {"ctlA", "ctlB", "ctlC", "ctlS"};
// A finger without an object contact: beyond the motor range (spec/driven_finger.ha).
constexpr double kNoContact = 256.0;

// Throws std::invalid_argument unless `value` of register `name` is in [lo, hi].
void CheckRegister(const std::string& name, int value, int lo, int hi) {
  if (value < lo || value > hi) {
    throw std::invalid_argument(name + " must be in " + std::to_string(lo) + ".." +
                                std::to_string(hi) + " (got " + std::to_string(value) + ")");
  }
}

// The scissor position of operating mode `mode` (rMOD): basic, pinch, wide; scissor mode starts
// with B and C apart (the wide position) and closes them by its request.
double ModePosition(int mode, const HandLayout& layout) {
  switch (mode) {
    case 1:
      return layout.s_pinch;
    case 2:
    case 3:
      return layout.s_wide;
    default:
      return layout.s_basic;
  }
}

// The discrete variable `name` of the mode component c is in.
int DiscreteValue(const System& system, int c, int mode, const std::string& name) {
  const Automaton& a = system.components()[c].automaton;
  const auto slot = a.symbols().Find(name);
  if (!slot) throw std::invalid_argument("the gripper model has no discrete variable " + name);
  return a.modes()[mode].DiscreteValueOf(*slot).value_or(0);
}

}  // namespace

int* GripperRegisters::Find(std::string_view name) {
  const std::array<std::pair<std::string_view, int*>, 7> flags = {{{"rACT", &rACT},
                                                                   {"rMOD", &rMOD},
                                                                   {"rGTO", &rGTO},
                                                                   {"rATR", &rATR},
                                                                   {"rGLV", &rGLV},
                                                                   {"rICF", &rICF},
                                                                   {"rICS", &rICS}}};
  for (const auto& [flag, field] : flags) {
    if (name == flag) return field;
  }
  if (name.size() != 4) return nullptr;
  const size_t axis = std::string_view("ABCS").find(name[3]);
  if (axis == std::string_view::npos) return nullptr;
  const std::string_view kind = name.substr(0, 3);
  if (kind == "rPR") return &rPR[axis];
  if (kind == "rSP") return &rSP[axis];
  if (kind == "rFR") return &rFR[axis];
  return nullptr;
}

GripperEmulator::GripperEmulator(System model, std::vector<Obstacle> objects,
                                 const HandLayout& layout)
    : system_(std::make_unique<System>(std::move(model))),
      objects_(std::move(objects)),
      layout_(layout) {
  for (const char* name : {"A", "B", "C", "S", "ctlA", "ctlB", "ctlC", "ctlS"}) {
    const auto& cs = system_->components();
    if (std::none_of(cs.begin(), cs.end(),
                     [&](const Component& c) { return c.instance == name; })) {
      throw std::invalid_argument("the gripper model '" + system_->name() +
                                  "' has no instance named " + name + " (see spec/gripper.ha)");
    }
  }
  simulator_ = std::make_unique<Simulator>(*system_);
  ResolveNames();
  gob_.fill(kNoContact);
  SetContacts(layout_.s_basic);  // checks the objects
  // The start state: the first sample of a run of no consequence (nothing is enabled at the
  // start of spec/gripper.ha with every request at 0).
  SimulationOptions options;
  options.until = 1e-9;
  const SimulationResult start = simulator_->Run(options);
  modes_ = start.samples.front().modes;
  x_ = start.samples.front().x;
  UpdateState();
}

GripperEmulator::~GripperEmulator() = default;
GripperEmulator::GripperEmulator(GripperEmulator&&) noexcept = default;
GripperEmulator& GripperEmulator::operator=(GripperEmulator&&) noexcept = default;

int GripperEmulator::Slot(const std::string& name) const {
  const auto slot = system_->symbols().Find(name);
  if (!slot) throw std::invalid_argument("the gripper model has no symbol " + name);
  return *slot;
}

int GripperEmulator::Index(const std::string& name) const {
  const auto& names = simulator_->variable_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw std::invalid_argument("the gripper model has no variable " + name);
  return static_cast<int>(it - names.begin());
}

void GripperEmulator::SetContacts(double spread) {
  if (spread == contacts_spread_) return;
  contacts_spread_ = spread;
  gob_.fill(kNoContact);
  if (objects_.empty()) return;
  const Hand hand(objects_, spread, {255.0, 255.0, 255.0}, layout_);
  for (int f = 0; f < 3; ++f) {
    for (int i = 0; i < 3; ++i) {
      const double g = hand.finger(f).contacts().gob[i];
      if (g <= 255.0) gob_[3 * f + i] = g;
    }
  }
}

void GripperEmulator::Command(const GripperRegisters& r) {
  for (const auto& [name, value] : {std::pair{"rACT", r.rACT},
                                    {"rGTO", r.rGTO},
                                    {"rATR", r.rATR},
                                    {"rGLV", r.rGLV},
                                    {"rICF", r.rICF},
                                    {"rICS", r.rICS}}) {
    CheckRegister(name, value, 0, 1);
  }
  CheckRegister("rMOD", r.rMOD, 0, 3);
  for (int k = 0; k < 4; ++k) {
    CheckRegister(std::string("rPR") + kAxes[k], r.rPR[k], 0, 255);
    CheckRegister(std::string("rSP") + kAxes[k], r.rSP[k], 0, 255);
    CheckRegister(std::string("rFR") + kAxes[k], r.rFR[k], 0, 255);
  }
  // Activation starts from reset, a mode change once activated: the scissor axis moves first.
  if (r.rACT == 1 && imc_ == 0) imc_ = 1;
  if (r.rACT == 1 && imc_ == 3 && r.rMOD != registers_.rMOD) imc_ = 2;
  if (r.rACT == 0) imc_ = 0;
  registers_ = r;
  ApplyRegisters();
}

void GripperEmulator::ApplyRegisters() {
  const GripperRegisters& r = registers_;
  // Hold: every motor's request is where it is.
  for (int k = 0; k < 3; ++k) request_[k] = state_.motor[k];
  request_[3] = state_.scissor;
  if (imc_ == 0) return;
  const double mode_position = ModePosition(r.rMOD, layout_);
  if (imc_ == 1 || imc_ == 2) {
    request_[3] = mode_position;
    speed_[3] = 255.0;
    SetContacts(mode_position);
    return;
  }
  if (r.rATR == 1) {  // automatic release: every finger opens, at the lowest speed
    for (int k = 0; k < 3; ++k) request_[k] = 0.0, speed_[k] = 0.0;
    return;
  }
  if (r.rGTO == 0) return;
  const int scissor_request = r.rICS ? r.rPR[3] : (r.rMOD == 3 ? r.rPR[0] : -1);
  request_[3] = scissor_request >= 0 ? scissor_request : mode_position;
  speed_[3] = r.rICS ? r.rSP[3] : r.rSP[0];
  if (r.rMOD != 3 || r.rICF) {
    for (int k = 0; k < 3; ++k) {
      request_[k] = r.rICF ? r.rPR[k] : r.rPR[0];
      speed_[k] = r.rICF ? r.rSP[k] : r.rSP[0];
    }
  }
  SetContacts(request_[3]);
}

const GripperState& GripperEmulator::Step(double dt) {
  if (!(dt > 0.0 && dt <= 10.0)) {
    throw std::invalid_argument("the step dt must be in (0, 10] seconds");
  }
  SimulationOptions options;
  options.until = dt;
  options.start_modes = modes_;
  options.start_x = x_;
  options.relative_tolerance = 1e-13;
  options.absolute_tolerance = 1e-15;
  for (int k = 0; k < 4; ++k) options.parameters.emplace_back(parameter_names_[k], speed_[k]);
  for (int j = 0; j < 9; ++j) options.parameters.emplace_back(parameter_names_[4 + j], gob_[j]);
  std::vector<InputSignal> signals;
  for (int k = 0; k < 4; ++k) {
    signals.push_back({request_slot_[k], InputSignal::Shape::kStep, {{0.0, request_[k]}}});
  }
  const SimulationResult r = simulator_->Run(options, signals);
  modes_ = r.samples.back().modes;
  x_ = r.samples.back().x;
  state_.time += r.samples.back().time;
  state_.simulation = std::string(StatusName(r.status));
  state_.message = r.message;
  UpdateState();
  // Activation and mode changes end when the scissor axis has arrived; the go-to then applies.
  if ((imc_ == 1 || imc_ == 2) && state_.status.gDT[3] == 3) {
    imc_ = 3;
    ApplyRegisters();
    UpdateState();
  }
  return state_;
}

void GripperEmulator::ResolveNames() {
  for (int k = 0; k < 4; ++k) {
    request_slot_[k] = Slot(std::string(kControllers[k]) + ".request");
    parameter_names_.push_back(std::string(kControllers[k]) + ".speed_setting");
  }
  for (int f = 0; f < 3; ++f) {
    for (int i = 0; i < 3; ++i) {
      parameter_names_.push_back(std::string(kAxes[f]) + ".gob" + std::to_string(i + 1));
      variable_index_[4 * f + i] = Index(std::string(kAxes[f]) + ".theta" + std::to_string(i + 1));
    }
    variable_index_[4 * f + 3] = Index(std::string(kAxes[f]) + ".g");
  }
  scissor_index_ = Index("S.s");
  const auto& components = system_->components();
  for (size_t c = 0; c < components.size(); ++c) {
    for (int k = 0; k < 4; ++k) {
      if (components[c].instance != kControllers[k]) continue;
      controller_[k] = static_cast<int>(c);
      for (int m = 0; m < components[c].automaton.num_modes(); ++m) {
        status_of_mode_[k].push_back(DiscreteValue(*system_, static_cast<int>(c), m,
                                                   std::string(kControllers[k]) + ".status"));
      }
    }
  }
}

void GripperEmulator::UpdateState() {
  GripperStatus& s = state_.status;
  for (int f = 0; f < 3; ++f) {
    for (int i = 0; i < 3; ++i) state_.theta[f][i] = x_[variable_index_[4 * f + i]];
    state_.motor[f] = x_[variable_index_[4 * f + 3]];
  }
  state_.scissor = x_[scissor_index_];
  state_.spread_angle =
      layout_.phi_min + (layout_.phi_max - layout_.phi_min) * state_.scissor / 255.0;
  state_.joints = RosJointState(state_.theta, state_.spread_angle);
  for (int k = 0; k < 4; ++k) s.gDT[k] = status_of_mode_[k][modes_[controller_[k]]];
  for (int k = 0; k < 4; ++k) {
    s.gPR[k] = static_cast<int>(std::lround(request_[k]));
    s.gPO[k] = static_cast<int>(std::lround(k < 3 ? state_.motor[k] : state_.scissor));
  }
  s.gACT = registers_.rACT;
  s.gMOD = registers_.rMOD;
  s.gGTO = registers_.rGTO;
  s.gIMC = imc_;
  const int arrived = static_cast<int>(std::count(s.gDT.begin(), s.gDT.begin() + 3, 3));
  const int moving = static_cast<int>(std::count(s.gDT.begin(), s.gDT.begin() + 3, 0));
  s.gSTA = moving > 0 ? 0 : arrived == 3 ? 3 : arrived == 0 ? 2 : 1;
}

}  // namespace hybrid::gripper

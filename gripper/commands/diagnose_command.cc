#include "gripper/commands/diagnose_command.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "commands/command_error.h"
#include "commands/diagnose_model_command.h"
#include "commands/output.h"
#include "commands/progress.h"
#include "gripper/commands/diagnosis_report.h"
#include "gripper/commands/gripper_command.h"
#include "hybrid/automaton/parser.h"
#include "hybrid/automaton/printer.h"
#include "hybrid/gripper/finger_diagnosis.h"
#include "hybrid/gripper/finger_predictor.h"
#include "hybrid/gripper/measured_data.h"
#include "hybrid/gripper/synthetic_data.h"

namespace hybrid::cli {
namespace {

using json = nlohmann::ordered_json;

const char* const kJoints[3] = {"theta1", "theta2", "theta3"};

// The finger automaton of `path`: an invalid model (ParseError) or one that is not the finger
// (InputError) exits 1.
FingerPredictor LoadPredictor(const std::string& path, FingerPredictor::Options options) {
  const System system = ParseModelFile(path);
  if (system.components().size() != 1) {
    throw InputError(path + ": expected one finger automaton (spec/finger.ha), got " +
                     std::to_string(system.components().size()) + " components");
  }
  try {
    return FingerPredictor(system.components()[0].automaton, options);
  } catch (const std::invalid_argument& e) {
    throw InputError(path + ": " + e.what());
  }
}

json PerJoint(const std::array<double, 3>& v) {
  json j = json::object();
  for (int i = 0; i < 3; ++i) j[kJoints[i]] = std::isfinite(v[i]) ? json(v[i]) : json(nullptr);
  return j;
}

std::string Direction(int d) { return d > 0 ? "closing" : "opening"; }

json Located(const std::optional<ResidualLocation>& w) {
  if (!w) return nullptr;
  return {{"joint", kJoints[w->channel]},         {"mode", w->mode},
          {"direction", Direction(w->direction)}, {"g_range", {w->input_min, w->input_max}},
          {"mean_residual", w->mean_residual},    {"excess", w->excess}};
}

json ToJson(const Diagnosis& d, const DiagnoseArgs& args, double seconds) {
  json out;
  out["data"] = {{"file", args.data},
                 {"runs", d.curves.size()},
                 {"samples", d.samples},
                 {"outliers_clamped",
                  {{"theta1", d.outliers.clamped[0]},
                   {"theta2", d.outliers.clamped[1]},
                   {"theta3", d.outliers.clamped[2]}}},
                 {"outlier_rule",
                  "report section 5.1: a change of more than 5 deg from the "
                  "previous inlier and the next sample is clamped to within 5 "
                  "deg of both"}};
  out["cause"] = d.cause;
  json params = json::object();
  for (const auto& [p, v] : d.parameters) params[ParameterName(p)] = v;
  out["parameters"] = params;
  json units = json::object();
  for (const auto& [p, v] : d.parameters) units[ParameterName(p)] = ParameterUnit(p);
  out["parameter_units"] = units;
  out["baseline_mse"] = PerJoint(d.baseline_mse);
  out["extended_mse"] = PerJoint(d.extended_mse);
  json noise = PerJoint(d.noise.variance);
  noise["method"] = d.noise.method;
  noise["dof"] = {
      {"theta1", d.noise.dof[0]}, {"theta2", d.noise.dof[1]}, {"theta3", d.noise.dof[2]}};
  out["noise_floor"] = noise;
  out["mse_unit"] = "deg^2";
  out["where"] = Located(d.where);
  out["explained_fraction"] = d.explained_fraction;
  out["remainder"] = Located(d.remainder);
  out["notes"] = d.notes;
  json candidates = json::array();
  for (const CandidateFit& c : d.candidates) {
    json names = json::array(), values = json::object();
    for (size_t i = 0; i < c.parameters.size(); ++i) {
      names.push_back(CauseName(c.parameters[i].cause));
      values[ParameterName(c.parameters[i])] = c.values[i];
    }
    candidates.push_back({{"causes", names},
                          {"parameters", values},
                          {"heldout_mse", PerJoint(c.heldout_mse)},
                          {"heldout_gain", c.gain},
                          {"bic", c.bic},
                          {"significant", c.significant}});
  }
  out["candidates"] = candidates;
  json groups = json::array();
  for (const ResidualGroup& g : d.residuals) {
    groups.push_back({{"joint", kJoints[g.channel]},
                      {"mode", g.mode},
                      {"direction", Direction(g.direction)},
                      {"samples", g.samples},
                      {"bias", g.mean},
                      {"trend_per_count", g.slope},
                      {"rms", g.rms},
                      {"excess", g.excess},
                      {"g_range", {g.input_min, g.input_max}}});
  }
  out["residuals"] = groups;
  json dir = json::object();
  for (int j = 0; j < 3; ++j) dir[kJoints[j]] = d.direction_difference[j];
  out["direction_dependence"] = dir;
  json changes = json::array();
  for (const ChangePoint& c : d.change_points) {
    changes.push_back({{"run", c.run},
                       {"sample", c.sample},
                       {"g", c.input},
                       {"from_mode", c.from_mode},
                       {"to_mode", c.to_mode},
                       {"joint", kJoints[c.channel]},
                       {"jump", c.jump}});
  }
  out["change_points"] = changes;
  out["seconds"] = seconds;
  return out;
}

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

std::string WhereText(const ResidualLocation& w) {
  return std::string(kJoints[w.channel]) + ", mode " + w.mode + ", " + Direction(w.direction) +
         ", g in [" + Fixed(w.input_min, 1) + ", " + Fixed(w.input_max, 1) + "], mean residual " +
         Fixed(w.mean_residual, 2) + " deg";
}

std::string ToText(const Diagnosis& d, const DiagnoseArgs& args, double seconds) {
  std::ostringstream out;
  out << "data: " << args.data << ": " << d.curves.size() << " runs, " << d.samples
      << " samples; outliers clamped (report's 5-degree rule): theta1 " << d.outliers.clamped[0]
      << ", theta2 " << d.outliers.clamped[1] << ", theta3 " << d.outliers.clamped[2] << "\n";
  out << "noise floor (" << d.noise.method << "): sd";
  for (int j = 0; j < 3; ++j) {
    out << " " << kJoints[j] << " " << Fixed(std::sqrt(d.noise.variance[j]), 2);
  }
  out << " deg\n";
  out << "cause:";
  for (const std::string& c : d.cause) out << " " << c;
  out << "\n";
  for (const auto& [p, v] : d.parameters) {
    out << "  " << ParameterName(p) << " = " << Fixed(v, 4) << " " << ParameterUnit(p) << "\n";
  }
  if (!d.parameters.empty()) {
    out << "explained: " << Fixed(100 * d.explained_fraction, 1)
        << "% of the baseline's excess over the noise floor\n";
  }
  if (d.remainder) out << "unexplained remainder: " << WhereText(*d.remainder) << "\n";
  if (d.where) out << "where: " << WhereText(*d.where) << "\n";
  out << "held-out MSE (deg^2)      theta1    theta2    theta3\n";
  auto row = [&](const char* name, const std::array<double, 3>& v) {
    out << "  " << name;
    for (double x : v)
      out << "  " << std::string(8 - std::min<size_t>(8, Fixed(x, 3).size()), ' ') << Fixed(x, 3);
    out << "\n";
  };
  row("baseline              ", d.baseline_mse);
  row("extended              ", d.extended_mse);
  row("noise floor (variance)", d.noise.variance);
  out << "candidates (held-out gain in chi-square units; * significant):\n";
  for (const CandidateFit& c : d.candidates) {
    std::string name;
    for (size_t i = 0; i < c.parameters.size(); ++i) {
      if (i > 0) name += " + ";
      name += ParameterName(c.parameters[i]) + "=" + Fixed(c.values[i], 3);
    }
    out << "  " << (c.significant ? "*" : " ") << " " << name << ": " << Fixed(c.gain, 1) << "\n";
  }
  for (const std::string& note : d.notes) out << "note: " << note << "\n";
  out << "time: " << Fixed(seconds, 2) << " s\n";
  return out.str();
}

}  // namespace

namespace {

void CheckDiagnoseOptions(const DiagnoseArgs& args) {
  CheckDiagnosisOptions(args.threads, args.significance);
}

// The diagnosis of args.data (its model, the options) and how long it took.
Diagnosis Diagnosed(const DiagnoseArgs& args, const FingerPredictor& predictor, double& seconds) {
  const auto start = std::chrono::steady_clock::now();
  MeasuredData data = ReadMeasuredDataFile(args.data);
  FingerDiagnosisOptions options;
  options.significance = args.significance;
  options.threads = args.threads;
  ProgressLine progress("diagnose", args.progress);
  if (progress.enabled()) {
    options.progress = [&progress](const std::string& stage, int done, int total) {
      progress.Report(
          stage + ": candidate " + std::to_string(done + 1) + " of " + std::to_string(total), true);
    };
  }
  Diagnosis d = Diagnose(predictor, std::move(data), options);
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return d;
}

}  // namespace

nlohmann::ordered_json DiagnoseReport(const DiagnoseArgs& args) {
  CheckDiagnoseOptions(args);
  const FingerPredictor predictor = LoadPredictor(args.model, FingerPredictor::FastOptions());
  double seconds = 0.0;
  const Diagnosis d = Diagnosed(args, predictor, seconds);
  return ToJson(d, args, seconds);
}

ExitCode RunDiagnose(const DiagnoseArgs& args) {
  CheckDiagnoseOptions(args);
  std::vector<NamedFile> inputs = {{"data", args.data}};
  for (NamedFile& f : ModelInputs("model", args.model)) inputs.push_back(std::move(f));
  const auto outputs = [&](const std::vector<std::pair<std::string, std::string>>& report) {
    std::vector<NamedFile> out = {{"out_model", args.out_model}};
    for (const auto& [path, text] : report) out.push_back({"report", path});
    return out;
  };
  // The report's files with fixed names; the run files are known after the diagnosis.
  std::vector<std::pair<std::string, std::string>> report_files;
  if (!args.report.empty()) {
    for (const char* name : {"diagnosis.json", "residuals.svg", "summary.svg"}) {
      report_files.emplace_back(args.report + "/" + name, "");
    }
  }
  CheckDistinctFiles(inputs, outputs(report_files));
  CheckOutputPlaces({{"out_model", args.out_model}}, {{"report", args.report}});
  const FingerPredictor predictor = LoadPredictor(args.model, FingerPredictor::FastOptions());
  double seconds = 0.0;
  const Diagnosis d = Diagnosed(args, predictor, seconds);
  const json report = ToJson(d, args, seconds);
  std::vector<std::pair<std::string, std::string>> files;
  if (!args.out_model.empty()) {
    std::ostringstream text;
    text << "# Extended finger model written by `hybrid diagnose " << args.data << "`.\n";
    text << "# Cause:";
    for (const std::string& c : d.cause) text << " " << c;
    text << "\n";
    for (const auto& [p, v] : d.parameters) {
      text << "#   " << ParameterName(p) << " = " << v << " " << ParameterUnit(p) << "\n";
    }
    text << "# g is the finger's drive position, g_motor the measured motor position; "
            "theta<j>_measured (if any) the measured angles. See docs/diagnosis.md.\n";
    text << PrintAutomaton(
        d.parameters.empty()
            ? predictor.finger()
            : ExtendFingerModel(predictor.finger(), d.effects, predictor.StartState(d.effects)));
    files.emplace_back(args.out_model, text.str());
  }
  if (!args.report.empty()) {
    report_files = DiagnosisReportFiles(d, args.report);
    report_files.insert(report_files.begin(),
                        {args.report + "/diagnosis.json", report.dump(2) + "\n"});
    CheckDistinctFiles(inputs, outputs(report_files));
    for (auto& f : report_files) files.push_back(std::move(f));
  }
  // The report directory is created (with its parents) only now, and removed again if a file
  // cannot be written.
  WriteOutputs(files, args.report.empty() ? std::vector<std::string>{}
                                          : std::vector<std::string>{args.report});
  WriteOutput("-", args.json ? report.dump(2) + "\n" : ToText(d, args, seconds));
  return ExitCode::kOk;
}

// Checks the sizes of `hybrid synthesize` before anything is allocated (the caps of
// include/hybrid/gripper/synthetic_data.h). Throws OptionError.
void CheckSyntheticSize(const SynthesizeArgs& args) {
  if (args.free_runs < 0 || args.free_runs > kMaxSyntheticFreeRuns) {
    throw OptionError("free_runs", Arg("free_runs") + " must lie in [0, " +
                                       std::to_string(kMaxSyntheticFreeRuns) + "] (got " +
                                       std::to_string(args.free_runs) + ")");
  }
  if (args.samples < kMinRunSamples || args.samples % 2 != 0 ||
      args.samples > kMaxSyntheticSamples) {
    throw OptionError("samples", Arg("samples") + " must be even and lie in [" +
                                     std::to_string(kMinRunSamples) + ", " +
                                     std::to_string(kMaxSyntheticSamples) + "] (got " +
                                     std::to_string(args.samples) + ")");
  }
  const SyntheticDesign design;
  const std::int64_t runs = static_cast<std::int64_t>(args.free_runs) +
                            static_cast<std::int64_t>(design.link1_gob.size()) +
                            static_cast<std::int64_t>(design.link2_gob.size());
  if (runs * args.samples > kMaxSyntheticSamples) {
    throw OptionError("samples", Arg("free_runs") + " " + std::to_string(args.free_runs) + " and " +
                                     Arg("samples") + " " + std::to_string(args.samples) +
                                     " make " + std::to_string(runs) + " runs of " +
                                     std::to_string(args.samples) + " samples, " +
                                     std::to_string(runs * args.samples) + " rows; at most " +
                                     std::to_string(kMaxSyntheticSamples) + " rows are made");
  }
}

ExitCode RunSynthesize(const SynthesizeArgs& args) {
  CheckSyntheticSize(args);
  CheckDistinctFiles(ModelInputs("model", args.model), {{"out", args.out}});
  CheckOutputPlaces({{"out", args.out}});
  HiddenEffects hidden;
  const FingerPredictor predictor = LoadPredictor(args.model, FingerPredictor::Options{});
  for (const std::string& e : args.effects) {
    const size_t eq = e.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw OptionError("effects", Arg("effects") + " '" + e + "': expected NAME=VALUE");
    }
    const std::string name = e.substr(0, eq);
    const double value = OptionNumber("effects", e.substr(eq + 1), e);
    if (name == "ripple_amplitude") {
      hidden.ripple_amplitude = value;
    } else if (name == "ripple_period") {
      hidden.ripple_period = value;
    } else if (name == "theta3_hysteresis") {
      hidden.theta3_hysteresis = value;
    } else {
      bool found = false;
      for (const EffectParameter& p : AllEffectParameters()) {
        if (ParameterName(p) == name) {
          SetEffect(hidden.finger, p, value);
          found = true;
        }
      }
      if (!found) {
        std::string names;
        for (const EffectParameter& p : AllEffectParameters()) names += " " + ParameterName(p);
        throw OptionError("effects", Arg("effects") + " " + e + ": unknown effect '" + name +
                                         "' (one of:" + names +
                                         " ripple_amplitude ripple_period theta3_hysteresis)");
      }
    }
  }
  SyntheticDesign design;
  design.seed = args.seed;
  design.free_runs = args.free_runs;
  design.samples_per_run = args.samples;
  const MeasuredData data = Synthesize(predictor, hidden, design);
  std::vector<std::string> comment = {
      "SYNTHETIC data (not measured): made by `hybrid synthesize` from the finger model",
      "  " + std::filesystem::path(args.model).filename().string(),
      "with seed " + std::to_string(args.seed) + ", " + std::to_string(args.free_runs) +
          " free runs, " + std::to_string(args.samples) + " samples per run, and hidden effects:"};
  if (args.effects.empty()) comment.push_back("  none");
  for (const std::string& e : args.effects) comment.push_back("  " + e);
  comment.push_back(
      "Noise: Gaussian, sd 0.7 / 0.7 / 1.2 deg (the report's section 5), theta3 "
      "outliers (2%), 0.5% missing samples.");
  std::ostringstream text;
  WriteMeasuredData(text, data, comment);
  WriteOutput(args.out, text.str());
  return ExitCode::kOk;
}

}  // namespace hybrid::cli

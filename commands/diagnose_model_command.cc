#include "commands/diagnose_model_command.h"

#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "commands/command_error.h"
#include "commands/diagnosis_plot.h"
#include "commands/model_file.h"
#include "commands/output.h"
#include "hybrid/automaton/printer.h"
#include "hybrid/model_diagnosis/automaton_diagnosis.h"
#include "hybrid/plotting/svg_plot.h"

namespace hybrid::cli {
namespace {

using json = nlohmann::ordered_json;

json Number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json PerChannel(const AutomatonDiagnosis& d, const std::vector<double>& v) {
  json out = json::object();
  for (size_t c = 0; c < d.channels.size(); ++c) out[d.channels[c]] = Number(v[c]);
  return out;
}

json Located(const AutomatonDiagnosis& d, const std::optional<SystematicResidual>& w) {
  if (!w) return nullptr;
  return {{"variable", d.channels[w->channel]},
          {"mode", w->mode},
          {"time_range", {w->input_min, w->input_max}},
          {"mean_residual", w->mean_residual},
          {"excess", w->excess}};
}

json Candidates(const AutomatonDiagnosis& d) {
  json candidates = json::array();
  for (const ParameterFit& c : d.result.candidates) {
    json names = json::array(), values = json::object();
    for (size_t i = 0; i < c.parameters.size(); ++i) {
      names.push_back(d.edits[c.parameters[i]].name);
      values[d.edits[c.parameters[i]].name] = c.values[i];
    }
    candidates.push_back({{"causes", names},
                          {"parameters", values},
                          {"heldout_mse", PerChannel(d, c.heldout_mse)},
                          {"heldout_gain", Number(c.gain)},
                          {"bic", Number(c.bic)},
                          {"significant", c.significant}});
  }
  return candidates;
}

json Residuals(const AutomatonDiagnosis& d) {
  json groups = json::array();
  for (const ChannelResiduals& g : d.result.residuals) {
    groups.push_back({{"variable", d.channels[g.channel]},
                      {"mode", g.mode},
                      {"samples", g.samples},
                      {"bias", g.mean},
                      {"trend_per_time", g.slope},
                      {"rms", g.rms},
                      {"excess", g.excess},
                      {"time_range", {g.input_min, g.input_max}}});
  }
  json changes = json::array();
  for (const ResidualJump& c : d.result.change_points) {
    changes.push_back({{"run", c.run},
                       {"sample", c.sample},
                       {"time", c.input},
                       {"from_mode", c.from_mode},
                       {"to_mode", c.to_mode},
                       {"variable", d.channels[c.channel]},
                       {"jump", c.jump}});
  }
  return {{"residuals", groups}, {"change_points", changes}};
}

json ToJson(const AutomatonDiagnosis& d, const DiagnoseModelArgs& args, double seconds) {
  json out;
  int samples = 0;
  for (const DiagnosisRun& r : d.runs) samples += static_cast<int>(r.input.size());
  out["model"] = args.model;
  out["data"] = {
      {"file", args.data}, {"runs", d.runs.size()}, {"samples", samples}, {"observed", d.channels}};
  out["cause"] = d.result.cause;
  json params = json::object();
  for (const auto& [name, value] : d.named) params[name] = value;
  out["parameters"] = params;
  out["explained_fraction"] = d.result.explained_fraction;
  out["baseline_mse"] = PerChannel(d, d.result.baseline_mse);
  out["extended_mse"] = PerChannel(d, d.result.extended_mse);
  json noise = PerChannel(d, d.noise.variance);
  noise["method"] = PerChannel(d, std::vector<double>(d.channels.size()));
  for (size_t c = 0; c < d.channels.size(); ++c) noise["method"][d.channels[c]] = d.noise_method[c];
  out["noise_floor"] = noise;
  out["where"] = Located(d, d.result.where);
  out["remainder"] = Located(d, d.result.remainder);
  out["candidates"] = Candidates(d);
  const json residuals = Residuals(d);
  out["residuals"] = residuals["residuals"];
  out["change_points"] = residuals["change_points"];
  out["notes"] = d.notes;
  out["seconds"] = seconds;
  return out;
}

std::string Fixed(double v, int digits) { return plotting::FormatFixed(v, digits); }

std::string Where(const AutomatonDiagnosis& d, const SystematicResidual& w) {
  return d.channels[w.channel] + ", mode " + w.mode + ", time in [" + Fixed(w.input_min, 3) + ", " +
         Fixed(w.input_max, 3) + "], mean residual " + Fixed(w.mean_residual, 4);
}

void MseTable(std::ostream& out, const AutomatonDiagnosis& d) {
  out << "held-out MSE        ";
  for (const std::string& c : d.channels) out << "  " << c;
  out << "\n";
  auto row = [&](const char* name, const std::vector<double>& v) {
    out << "  " << name;
    for (double x : v) out << "  " << Fixed(x, 5);
    out << "\n";
  };
  row("baseline          ", d.result.baseline_mse);
  row("extended          ", d.result.extended_mse);
  row("noise (variance)  ", d.noise.variance);
}

std::string ToText(const AutomatonDiagnosis& d, const DiagnoseModelArgs& args, double seconds) {
  std::ostringstream out;
  int samples = 0;
  for (const DiagnosisRun& r : d.runs) samples += static_cast<int>(r.input.size());
  out << "data: " << args.data << ": " << d.runs.size() << " runs, " << samples << " samples\n";
  out << "noise floor:";
  for (size_t c = 0; c < d.channels.size(); ++c) {
    out << " " << d.channels[c] << " sd " << Fixed(std::sqrt(d.noise.variance[c]), 4) << " ("
        << d.noise_method[c] << ")";
  }
  out << "\ncause:";
  for (const std::string& c : d.result.cause) out << " " << c;
  out << "\n";
  for (const auto& [name, value] : d.named) out << "  " << name << " = " << Fixed(value, 4) << "\n";
  if (!d.named.empty()) {
    out << "explained: " << Fixed(100 * d.result.explained_fraction, 1)
        << "% of the baseline's excess over the noise floor\n";
  }
  if (d.result.remainder) out << "unexplained remainder: " << Where(d, *d.result.remainder) << "\n";
  if (d.result.where) out << "where: " << Where(d, *d.result.where) << "\n";
  MseTable(out, d);
  out << "candidates (held-out gain in chi-square units; * significant):\n";
  for (const ParameterFit& c : d.result.candidates) {
    std::string name;
    for (size_t i = 0; i < c.parameters.size(); ++i) {
      name += (i > 0 ? " + " : "") + d.edits[c.parameters[i]].name + "=" + Fixed(c.values[i], 4);
    }
    out << "  " << (c.significant ? "*" : " ") << " " << name << ": " << Fixed(c.gain, 1) << "\n";
  }
  for (const std::string& note : d.notes) out << "note: " << note << "\n";
  out << "time: " << Fixed(seconds, 2) << " s\n";
  return out.str();
}

std::map<std::string, double> NoiseOption(const DiagnoseModelArgs& args) {
  std::map<std::string, double> noise;
  for (const std::string& item : args.noise) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw OptionError("noise", Arg("noise") + " '" + item + "': expected NAME=SD");
    }
    const double sd = OptionNumber("noise", item.substr(eq + 1), item);
    if (!(sd > 0))
      throw OptionError("noise", Arg("noise") + " '" + item + "': SD must be positive");
    noise[item.substr(0, eq)] = sd;
  }
  return noise;
}

// The diagnosis of args.data against args.model and how long it took.
AutomatonDiagnosis Diagnosed(const DiagnoseModelArgs& args, double& seconds) {
  const auto start = std::chrono::steady_clock::now();
  AutomatonDiagnosisOptions options;
  options.noise = NoiseOption(args);
  const System model = ReadModelArgument(args.model, args.config);
  const TraceData data = ReadTraceFile(args.data, model);
  options.engine.significance = args.significance;
  options.engine.threads = args.threads;
  ProgressLine progress("diagnose", args.progress);
  if (progress.enabled()) {
    options.engine.progress = [&progress](const std::string& stage, int done, int total) {
      progress.Report(
          stage + ": candidate " + std::to_string(done + 1) + " of " + std::to_string(total), true);
    };
  }
  AutomatonDiagnosis d;
  try {
    d = DiagnoseAutomaton(model, data, options);
  } catch (const std::invalid_argument& e) {
    if (options.noise.size() && std::string(e.what()).starts_with("noise")) {
      throw OptionError("noise", Arg("noise") + ": " + e.what());
    }
    throw InputError(args.model + ": " + e.what());
  }
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return d;
}

std::string ExtendedModelText(const AutomatonDiagnosis& d, const DiagnoseModelArgs& args) {
  std::ostringstream text;
  text << "# Extended model written by `hybrid diagnose " << args.model << " " << args.data
       << "`.\n# Cause:";
  for (const std::string& c : d.result.cause) text << " " << c;
  text << "\n";
  for (const auto& [name, value] : d.named) text << "#   " << name << " = " << value << "\n";
  text << "# x_measured (if any) is what the sensor of x reads. See docs/diagnosis.md.\n";
  text << PrintSystem(d.extended);
  return text.str();
}

json Values(const std::vector<double>& v) {
  json out = json::array();
  for (double x : v) out.push_back(Number(x));
  return out;
}

json Curves(const AutomatonDiagnosis& d) {
  json curves = json::array();
  for (size_t r = 0; r < d.runs.size(); ++r) {
    json measured = json::object(), baseline = json::object(), extended = json::object();
    for (size_t c = 0; c < d.channels.size(); ++c) {
      measured[d.channels[c]] = Values(d.runs[r].channels[c]);
      baseline[d.channels[c]] = Values(d.result.baseline[r].channels[c]);
      extended[d.channels[c]] = Values(d.result.extended[r].channels[c]);
    }
    curves.push_back({{"run", d.runs[r].label},
                      {"time", Values(d.runs[r].input)},
                      {"measured", measured},
                      {"baseline", baseline},
                      {"extended", extended}});
  }
  return curves;
}

}  // namespace

void CheckDiagnosisOptions(int threads, double significance) {
  if (threads < 1 || threads > 64) {
    throw OptionError("threads", Arg("threads") + " must lie in [1, 64]");
  }
  if (!(significance > 0) || !std::isfinite(significance)) {
    throw OptionError("significance", Arg("significance") + " must be positive");
  }
}

nlohmann::ordered_json DiagnoseModelReport(const DiagnoseModelArgs& args, bool curves) {
  CheckDiagnosisOptions(args.threads, args.significance);
  double seconds = 0.0;
  const AutomatonDiagnosis d = Diagnosed(args, seconds);
  json report = ToJson(d, args, seconds);
  if (curves) report["curves"] = Curves(d);
  return report;
}

ExitCode RunDiagnoseModel(const DiagnoseModelArgs& args) {
  CheckDiagnosisOptions(args.threads, args.significance);
  NoiseOption(args);
  std::vector<NamedFile> inputs = {{"data", args.data}};
  for (NamedFile& f :
       ModelInputs("model", args.model,
                   args.config.empty() ? std::nullopt : std::optional<std::string>(args.config))) {
    inputs.push_back(std::move(f));
  }
  std::vector<NamedFile> outputs = {{"out_model", args.out_model}};
  if (!args.report.empty()) outputs.push_back({"report", args.report + "/diagnosis.json"});
  CheckDistinctFiles(inputs, outputs);
  CheckOutputPlaces({{"out_model", args.out_model}}, {{"report", args.report}});
  double seconds = 0.0;
  const AutomatonDiagnosis d = Diagnosed(args, seconds);
  const json report = ToJson(d, args, seconds);
  std::vector<std::pair<std::string, std::string>> files;
  if (!args.out_model.empty()) files.emplace_back(args.out_model, ExtendedModelText(d, args));
  if (!args.report.empty()) {
    std::vector<std::pair<std::string, std::string>> report_files = {
        {args.report + "/diagnosis.json", report.dump(2) + "\n"}};
    for (size_t c = 0; c < d.channels.size(); ++c) {
      report_files.emplace_back(args.report + "/" + d.channels[c] + ".svg",
                                DiagnosisPlotSvg(d, static_cast<int>(c)));
    }
    std::vector<NamedFile> all = {{"out_model", args.out_model}};
    for (const auto& [path, text] : report_files) all.push_back({"report", path});
    CheckDistinctFiles(inputs, all);
    for (auto& f : report_files) files.push_back(std::move(f));
  }
  WriteOutputs(files, args.report.empty() ? std::vector<std::string>{}
                                          : std::vector<std::string>{args.report});
  WriteOutput("-", args.json ? report.dump(2) + "\n" : ToText(d, args, seconds));
  return ExitCode::kOk;
}

}  // namespace hybrid::cli

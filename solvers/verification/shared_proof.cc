#include "solvers/verification/shared_proof.h"

#include <exception>
#include <utility>

#include "automaton/internal_assert.h"
#include "hybrid/automaton/log.h"
#include "hybrid/checking/trace.h"

namespace hybrid {

namespace {

// "A, ctlA"
std::string InstanceList(const System& system, const std::vector<int>& which) {
  std::string out;
  for (const int c : which) {
    out += (out.empty() ? "" : ", ") + system.components()[c].instance;
  }
  return out;
}

}  // namespace

SharedProof SharedProof::ForInstance(const System& system, int same, int c) {
  const auto components = system.components();
  HYBRID_ASSERT(same >= 0 && same < c && c < static_cast<int>(components.size()),
                "a shared proof is an earlier component's");
  const std::string from = components[same].instance + ".", to = components[c].instance + ".";
  SharedProof how;
  how.rename_ = [from, to](const std::string& name) {
    return name.rfind(from, 0) == 0 ? to + name.substr(from.size()) : name;
  };
  how.component_ = {{same, c}};
  how.source_ = "instance " + components[same].instance;
  how.target_ = "instance " + components[c].instance;
  how.why_ = ", an instance of the same automaton";
  return how;
}

std::optional<SharedProof> SharedProof::ForProducts(const System& system, const std::vector<int>& a,
                                                    const std::vector<int>& b) {
  const auto components = system.components();
  if (a.size() != b.size() || a == b) return std::nullopt;
  std::map<std::string, std::string> prefixes;  // "A." -> "B."
  SharedProof how;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Component& ca = components[a[i]];
    const Component& cb = components[b[i]];
    if (ca.instance.empty() || cb.instance.empty() || !(ca.source == cb.source)) {
      return std::nullopt;
    }
    prefixes[ca.instance + "."] = cb.instance + ".";
    how.component_[a[i]] = b[i];
  }
  how.rename_ = [prefixes](const std::string& name) {
    for (const auto& [from, to] : prefixes) {
      if (name.rfind(from, 0) == 0) return to + name.substr(from.size());
    }
    return name;
  };
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto& binds_a = components[a[i]].binds;
    const auto& binds_b = components[b[i]].binds;
    if (binds_a.size() != binds_b.size()) return std::nullopt;
    for (const auto& [name, bound] : binds_a) {
      const auto it = binds_b.find(name);
      if (it == binds_b.end() || it->second != how.rename_(bound)) return std::nullopt;
    }
  }
  how.source_ = "instances " + InstanceList(system, a);
  how.target_ = "instances " + InstanceList(system, b);
  how.why_ = ", instances of the same automata bound alike";
  return how;
}

Trace SharedProof::Renamed(const System& system, const Trace& trace) const {
  Trace t = trace;
  for (auto& [name, v] : t.parameters) name = rename_(name);
  for (auto& [name, v] : t.initial_values) name = rename_(name);
  for (auto& [component, index] : t.initial_states) {
    if (auto it = component_.find(component); it != component_.end()) {
      component = it->second;
    }
  }
  for (InputSignal& in : t.inputs.inputs) {
    const auto slot = system.symbols().Find(rename_(system.symbols()[in.slot].name));
    if (slot) in.slot = *slot;
  }
  return t;
}

void SharedProof::CopyResults(const System& system, const ProofJob& from, const ProofJob& to,
                              std::chrono::steady_clock::time_point start,
                              std::vector<CheckResult>& results) const {
  HYBRID_ASSERT(from.goals.size() == to.goals.size(),
                "a shared proof answers the same questions, goal for goal");
  for (std::size_t g = 0; g < to.goals.size(); ++g) {
    const int src = from.goals[g].result;
    if (src < 0 || to.goals[g].result < 0) continue;
    std::vector<int> targets = to.goals[g].also;
    targets.insert(targets.begin(), to.goals[g].result);
    for (int dst : targets) {
      CheckResult r = results[src];
      r.property = results[dst].property;
      r.kind = results[dst].kind;
      if (r.trace) {
        Trace t = Renamed(system, *r.trace);
        bool ok = false;
        try {
          ok = ReplayTrace(system, to.goals[g].original, t);
        } catch (const std::exception& e) {
          Log(LogLevel::kDebug, "prove",
              "the trace found for " + source_ + " does not replay for " + target_ + ": " +
                  e.what());
        }
        if (ok) {
          r.trace = std::move(t);
        } else {
          r.trace.reset();
          r.verdict = Verdict::kUnknown;
          r.reason = "the trace found for " + source_ + " does not replay for " + target_;
        }
      }
      r.reason += " (the proof for " + source_ + why_ + ")";
      r.seconds = SecondsSince(start);
      results[dst] = std::move(r);
    }
  }
}

}  // namespace hybrid

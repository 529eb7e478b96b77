#include "hybrid/verification/property_prover.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <stdexcept>

#include "automaton/internal_assert.h"
#include "hybrid/automaton/log.h"
#include "solvers/verification/proof_plan.h"
#include "solvers/verification/proof_run.h"

namespace hybrid {

double PropertyProver::BudgetSeconds() const {
  return options_.search_seconds > 0 ? options_.search_seconds : options_.budget;
}

std::vector<CheckResult> PropertyProver::Check(const System& system,
                                               std::span<const Property> properties) const {
  SolverBudget budget(BudgetSeconds());
  return Check(system, properties, budget);
}

std::vector<CheckResult> PropertyProver::Check(const System& system,
                                               std::span<const Property> properties,
                                               SolverBudget& budget) const {
  const auto start = std::chrono::steady_clock::now();
  const std::string& dump = options_.query_dump_directory;
  if (!dump.empty() && !std::filesystem::is_directory(dump)) {
    throw std::invalid_argument("the directory for the SMT queries, '" + dump +
                                "', is not a directory");
  }
  std::vector<CheckResult> results(properties.size());
  const ProofPlan plan(system, properties, options_.max_product_modes, results);
  int dumped = 0;  // query files written (QueryDump)
  int runs = plan.runs();
  for (const ProofPlan::Step& step : plan.steps()) {
    if (step.from != nullptr) {
      step.how->CopyResults(system, *step.from, *step.job, start, results);
      continue;
    }
    // Each job gets an equal share of what is left of the budget; what one leaves goes on.
    const std::uint64_t share = budget.remaining() / std::max(runs--, 1);
    if (LogEnabled(LogLevel::kInfo)) {
      Log(LogLevel::kInfo, "prove",
          "checking automaton " + step.job->automaton->name() + " (" +
              std::to_string(step.job->goals.size()) + " goals) with " + std::to_string(share) +
              " resource units");
    }
    ProofRun(system, options_, budget, start, results, *step.job, share, {dump, &dumped}).Run();
  }
  // The gate of every verdict that rests on a trace: a fresh replay.
  for (std::size_t i = 0; i < properties.size(); ++i) {
    ConfirmTrace(system, properties[i], results[i]);
  }
  return results;
}

std::vector<PropertyProver::ModeReachability> PropertyProver::ReachableModes(const System& system,
                                                                             int component) const {
  SolverBudget budget(BudgetSeconds());
  return ReachableModes(system, component, budget);
}

std::vector<PropertyProver::ModeReachability> PropertyProver::ReachableModes(
    const System& system, int component, SolverBudget& budget) const {
  return ModeResults(system, component, Check(system, ModeQueries(system, component), budget));
}

std::vector<Property> PropertyProver::ModeQueries(const System& system, int component) {
  const Component& comp = system.components()[component];
  std::vector<Property> queries;
  for (int m = 0; m < comp.automaton.num_modes(); ++m) {
    const std::string name = system.QualifiedModeName(component, ModeId(m));
    queries.push_back({"reach " + name, Property::Kind::kReach, Predicate::InMode(name), {}});
  }
  return queries;
}

std::vector<PropertyProver::ModeReachability> PropertyProver::ModeResults(
    const System& system, int component, std::span<const CheckResult> results) {
  const Component& comp = system.components()[component];
  HYBRID_ASSERT(results.size() == static_cast<std::size_t>(comp.automaton.num_modes()),
                "one verdict per mode");
  std::vector<ModeReachability> out;
  for (int m = 0; m < comp.automaton.num_modes(); ++m) {
    const Mode& mode = comp.automaton.mode(ModeId(m));
    ModeReachability r;
    r.mode = system.QualifiedModeName(component, ModeId(m));
    for (const auto& [slot, value] : mode.discrete_values) {
      // The declared (unqualified) name: `source` has the same slots.
      r.discrete.emplace_back(comp.source.symbols()[slot].name, value);
    }
    r.verdict = results[m].verdict;
    r.reason = results[m].reason;
    r.trace = results[m].trace;
    if (results[m].within) {  // whether a run ever enters the mode: a bounded answer is none
      r.verdict = Verdict::kUnknown;
      r.reason = "unreachable within " + FormatNumber(*results[m].within) +
                 " only, not decided beyond: " + r.reason;
    }
    out.push_back(std::move(r));
  }
  return out;
}

// Every property the model declares, over System slots: the system's own, then (for composed
// systems) each component's, named INSTANCE.NAME.
std::vector<Property> DeclaredProperties(const System& system) {
  std::vector<Property> out(system.properties().begin(), system.properties().end());
  for (std::size_t c = 0; c < system.components().size(); ++c) {
    const Component& comp = system.components()[c];
    if (comp.instance.empty()) continue;
    for (const Property& p : comp.automaton.properties()) {
      Property q = p;
      q.name = comp.instance + "." + p.name;
      std::function<Predicate(const Predicate&)> remap = [&](const Predicate& x) -> Predicate {
        switch (x.kind()) {
          case Predicate::Kind::kComparison: {
            auto sub = [&](const Expression& e) {
              return e.Substitute(
                  [&](const std::string& name, int slot) -> std::optional<Expression> {
                    return Expression::Symbol(name, comp.global_slot[slot]);
                  });
            };
            const Comparison& k = x.comparison();
            return Predicate::Compare({sub(k.lhs), k.relation, sub(k.rhs)});
          }
          case Predicate::Kind::kInMode: {
            auto id = comp.automaton.FindMode(x.mode());
            return Predicate::InMode(id ? system.QualifiedModeName(static_cast<int>(c), *id)
                                        : x.mode());
          }
          case Predicate::Kind::kNot:
            return Predicate::Not(remap(x.operands()[0]));
          case Predicate::Kind::kAnd:
            return Predicate::And(remap(x.operands()[0]), remap(x.operands()[1]));
          case Predicate::Kind::kOr:
            return Predicate::Or(remap(x.operands()[0]), remap(x.operands()[1]));
          default:
            return x;
        }
      };
      q.predicate = remap(p.predicate);
      out.push_back(std::move(q));
    }
  }
  return out;
}

}  // namespace hybrid

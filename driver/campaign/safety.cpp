// Safety evidence of a campaign: diagnostic coverage, reaction against the safety time,
// traceability, from the FMEA and the verdicts.
#include "campaign/safety.hpp"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "campaign/driver.hpp"
#include "common/file.hpp"
#include "common/hash.hpp"

#ifndef PLCFI_VERSION
#error "PLCFI_VERSION must be defined by the build (driver/CMakeLists.txt)"
#endif

namespace plcfi::campaign {

namespace {

std::string fault_text(const TestCase& tc) {
  return fmt::format("{} ({}): {}", tc.target->name, tc.target_ref.text, tc.fault.text);
}

int64_t reaction_of(const Execution& e) { return e.reaction_ns >= 0 ? e.reaction_ns - e.inject_ns : -1; }

std::string file_hash(const std::string& path) {
  std::string text, err;
  if (!common::read_file(path, common::kMaxSourceBytes, &text, &err)) return "unreadable: " + err;
  return common::Fnv64().add(text).hex();
}

}  // namespace

std::vector<std::pair<std::string, std::string>> campaign_hashes(const CampaignBuild& cb) {
  const auto& c = cb.spec;
  std::vector<std::pair<std::string, std::string>> h;
  h.emplace_back("plcfi", PLCFI_VERSION);
  h.emplace_back("campaign " + c.path, file_hash(c.path));
  for (const auto& p : c.programs) h.emplace_back("program " + p, file_hash(p));
  if (std::filesystem::is_regular_file(c.plant)) h.emplace_back("plant " + c.plant, file_hash(c.plant));
  else h.emplace_back("plant", c.plant + " (built in)");
  if (!c.plant_config.empty()) h.emplace_back("plant_config " + c.plant_config, file_hash(c.plant_config));
  h.emplace_back("tsd " + c.tsd.path, file_hash(c.tsd.path));
  h.emplace_back("fmea " + c.fmea.path, file_hash(c.fmea.path));
  h.emplace_back("fault_classes " + c.classes.path, file_hash(c.classes.path));
  if (!c.requirements.empty()) h.emplace_back("requirements " + c.requirements, file_hash(c.requirements));
  h.emplace_back("seed", std::to_string(c.seed));
  h.emplace_back("journal fingerprint", campaign_fingerprint(cb));
  return h;
}

report::SafetyReport safety_evidence(const CampaignBuild& cb, const std::vector<Execution>& executions,
                                     const std::vector<size_t>& not_reached, const std::vector<size_t>& pending,
                                     bool vcd) {
  const auto& c = cb.spec;
  report::SafetyReport r;
  r.campaign = c.name;
  r.fingerprint = campaign_hashes(cb);
  const std::set<size_t> nr(not_reached.begin(), not_reached.end()), pend(pending.begin(), pending.end());

  // Executions by case, each with its journal line.
  std::vector<std::vector<size_t>> by_case(cb.cases.size());
  for (size_t k = 0; k < executions.size(); ++k) by_case[executions[k].case_index].push_back(k);
  for (auto& v : by_case)
    std::stable_sort(v.begin(), v.end(), [&](size_t a, size_t b) { return executions[a].path < executions[b].path; });
  auto cases_of = [&](const FmeaRow& row) {
    std::vector<size_t> v;
    for (size_t i = 0; i < cb.cases.size(); ++i)
      if (!cb.cases[i].explored && cb.cases[i].row == &row) v.push_back(i);
    return v;
  };
  // Why a row is not detected; "" when it is.
  auto undetected_why = [&](const FmeaRow& row) -> std::string {
    auto cs = cases_of(row);
    if (cs.empty()) return "no test case";
    for (size_t i : cs) {
      const auto& tc = cb.cases[i];
      if (nr.count(i)) return tc.id + " NOT REACHED: the precondition never held";
      if (pend.count(i)) return tc.id + " not tested: the campaign was interrupted";
      if (by_case[i].empty()) return tc.id + " never executed";
      for (size_t k : by_case[i]) {
        const auto& e = executions[k];
        if (e.outcome != Outcome::Pass)
          return fmt::format("{} path {} {}: {}", tc.id, e.path, outcome_name(e.outcome), e.reason);
      }
    }
    return "";
  };

  std::map<std::string, size_t> fn_index;
  for (const auto& row : c.fmea.rows) {
    if (row.safety_function.empty()) continue;
    auto [it, added] = fn_index.emplace(row.safety_function, r.functions.size());
    if (added) r.functions.push_back({});
    auto& f = r.functions[it->second];
    f.id = row.safety_function;
    f.rows.push_back(row.id);
    if (!row.dangerous) {
      f.has_safe = true;
      f.lambda_s += row.failure_rate;
      continue;
    }
    f.lambda_d += row.failure_rate;
    std::string why = undetected_why(row);
    if (why.empty()) f.lambda_dd += row.failure_rate;
    else f.undetected.emplace_back(row.id, why);
    for (size_t i : cases_of(row)) {
      const auto& tc = cb.cases[i];
      if (tc.cls->safety_time_ns >= 0 && (f.safety_time_ns < 0 || tc.cls->safety_time_ns < f.safety_time_ns))
        f.safety_time_ns = tc.cls->safety_time_ns;
      for (size_t k : by_case[i]) {
        const auto& e = executions[k];
        int64_t t = reaction_of(e);
        if (t < 0) {
          ++f.unreacted;
          continue;
        }
        ++f.reacted;
        if (t > f.worst_reaction_ns) {
          f.worst_reaction_ns = t;
          f.worst_execution = fmt::format("{} path {}", e.case_id, e.path);
        }
      }
    }
  }

  // Failures the exploration found: no row, so no rate; listed for the assessor.
  for (size_t i = 0; i < cb.cases.size(); ++i) {
    const auto& tc = cb.cases[i];
    if (!tc.explored) continue;
    for (size_t k : by_case[i]) {
      const auto& e = executions[k];
      if (e.outcome == Outcome::Pass) continue;
      r.unassessed.push_back({tc.id, tc.transition_ref(), fault_text(tc), outcome_name(e.outcome), e.reason, e.path});
    }
  }

  for (const auto& e : executions) {
    const auto& tc = cb.cases[e.case_index];
    r.executions.push_back({e.case_id, tc.explored ? "" : tc.row->id, outcome_name(e.outcome), e.path, reaction_of(e)});
  }

  // The traceability matrix: the FMEA's rows in order, each with its cases and paths, then
  // the explored cases.
  auto trace_case = [&](size_t i, const FmeaRow* row) {
    const auto& tc = cb.cases[i];
    report::TraceRow base;
    if (row) {
      base.fmea = row->id;
      base.safety_function = row->safety_function;
      base.failure_rate = row->failure_rate;
      base.dangerous = row->safety_function.empty() ? "" : row->dangerous ? "yes" : "no";
    }
    base.failure_mode = tc.row->failure_mode;
    base.case_id = tc.id;
    base.transition = tc.transition_ref();
    base.fault = fault_text(tc);
    base.safety_time_ns = tc.cls->safety_time_ns;
    base.sequence_diagram = "diagrams/" + tc.id + "_sequence.puml";
    base.timing_diagram = "diagrams/" + tc.id + "_timing.puml";
    if (by_case[i].empty()) {
      base.verdict = nr.count(i) ? "NOT REACHED" : "NOT TESTED";
      r.trace.push_back(base);
      return;
    }
    for (size_t k : by_case[i]) {
      const auto& e = executions[k];
      report::TraceRow t = base;
      t.path = e.path;
      t.verdict = outcome_name(e.outcome);
      t.inject_ns = e.inject_ns;
      t.reaction_ns = reaction_of(e);
      t.latency_ns = e.latency_ns;
      t.journal_line = k + 2;
      if (vcd) t.vcd = e.vcd;
      r.trace.push_back(t);
    }
  };
  for (const auto& row : c.fmea.rows)
    for (size_t i : cases_of(row)) trace_case(i, &row);
  for (size_t i = 0; i < cb.cases.size(); ++i)
    if (cb.cases[i].explored) trace_case(i, nullptr);
  return r;
}

}  // namespace plcfi::campaign

// A campaign rendered as text, JUnit and PlantUML facts (see campaign.hpp).
#include "report/campaign.hpp"

#include <algorithm>
#include <sstream>
#include <tuple>

#include <fmt/format.h>

#include "st/syntax/source.hpp"

namespace plcfi::report {

namespace {

using campaign::CampaignBuild;
using campaign::TestCase;

// A table column: cut with "~" when too long, padded with blanks when short.
std::string pad(std::string s, size_t n) {
  if (s.size() > n) return s.substr(0, n - 1) + "~";
  s.resize(n, ' ');
  return s;
}

std::string unrun_row(const TestCase& tc, const char* verdict, const std::string& why) {
  return fmt::format("{} {} {} {} {} {} {}\n", pad(tc.id, 5), pad("-", 5), pad(verdict, 12), pad("-", 9),
                     pad(std::to_string(tc.rpn), 4), pad(tc.transition_ref(), 30), why);
}

std::string branch_list(const CampaignBuild& cb, const campaign::CampaignResult& res, const campaign::Execution& e) {
  std::string list;
  for (const auto& d : campaign::distinguishing_branches(cb, res.executions, e)) list += (list.empty() ? "" : ", ") + d;
  return list;
}

// An execution as a JUnit test case: the verdict, what was tested and the case's facts.
JunitCase junit_execution(const CampaignBuild& cb, const campaign::CampaignResult& res, const campaign::Execution& e,
                          const std::string& suite) {
  const auto& tc = cb.cases[e.case_index];
  JunitCase jc;
  jc.classname = suite + "." + tc.transition_ref();
  jc.name = fmt::format("{} path {}: {}", e.case_id, e.path, tc.row->failure_mode);
  jc.seconds = static_cast<double>(e.end_ns - e.inject_ns) * 1e-9;
  jc.outcome = e.outcome == campaign::Outcome::Pass ? JunitCase::Outcome::Pass : JunitCase::Outcome::Fail;
  if (e.outcome != campaign::Outcome::Pass) jc.message = e.reason;
  jc.detail = fmt::format("precondition: {}\nfault: {}\nexpected: {}\nresult: {}", tc.precondition,
                          campaign_fault_text(tc), tc.expected, e.reason);
  jc.properties = {{"rpn", std::to_string(tc.rpn)},
                   {"fault_class", tc.cls->id},
                   {"fmea", tc.row->id},
                   {"path", std::to_string(e.path)},
                   {"path_branches", branch_list(cb, res, e)},
                   {"fault", campaign_fault_text(tc)},
                   {"latency_ms", e.latency_ns >= 0 ? fmt::format("{:.1f}", static_cast<double>(e.latency_ns) * 1e-6) : ""},
                   {"vcd", e.vcd}};
  return jc;
}

// A case without an execution as a skipped JUnit test case; `message` says why.
JunitCase junit_skipped(const TestCase& tc, const std::string& suite, std::string message) {
  JunitCase jc;
  jc.classname = suite + "." + tc.transition_ref();
  jc.name = fmt::format("{}: {}", tc.id, tc.row->failure_mode);
  jc.outcome = JunitCase::Outcome::Skipped;
  jc.message = std::move(message);
  return jc;
}

}  // namespace

std::string campaign_fault_text(const TestCase& tc) {
  return fmt::format("{} ({}): {}", tc.target->name, tc.target_ref.text, tc.fault.text);
}

std::string campaign_cases_text(const CampaignBuild& cb) {
  const auto& c = cb.spec;
  std::string o = fmt::format("campaign {}: {} test case(s) from {} and {}\n", c.name, cb.cases.size(), c.fmea.path, c.tsd.path);
  o += fmt::format("  program {}, plant {}, base tick {}, classes {}\n\n", c.programs.back(), c.plant,
                   campaign::human_duration(cb.schedule.tick_ns()), c.classes.path);
  o += fmt::format("{} {} {} {} {} {} {}\n", pad("case", 5), pad("RPN", 4), pad("FMEA", 5), pad("class", 6),
                   pad("transition", 30), pad("fault", 40), "deadline");
  for (const auto& tc : cb.cases)
    o += fmt::format("{} {} {} {} {} {} {}\n", pad(tc.id, 5), pad(std::to_string(tc.rpn), 4), pad(tc.explored ? "-" : tc.row->id, 5),
                     pad(tc.cls->id, 6), pad(tc.transition_ref(), 30), pad(campaign_fault_text(tc), 40),
                     campaign::human_duration(tc.deadline_ns));
  o += "\n";
  for (const auto& tc : cb.cases) {
    o += fmt::format("{}: {}\n", tc.id, tc.row->failure_mode);
    o += fmt::format("  precondition  {}\n", tc.precondition);
    o += fmt::format("  start         {}\n", tc.step->start.empty() ? "previous transition (the precondition)" : tc.start);
    o += fmt::format("  expected      {}\n", tc.expected);
    for (size_t k = tc.first_req + tc.reqs - tc.forbidden; k < tc.first_req + tc.reqs; ++k)
      o += fmt::format("  forbidden     {}\n", cb.monitors.requirements[k].text);
  }
  return o;
}

PumlCase campaign_puml_case(const CampaignBuild& cb, const TestCase& tc) {
  PumlCase p;
  p.id = tc.id;
  p.title = tc.transition_ref() + ": " + tc.row->failure_mode;
  p.precondition = tc.precondition;
  p.start = tc.step->start;
  p.target = tc.target->name + " (" + tc.target_ref.text + ")";
  p.fault = tc.fault.text;
  p.reaction = tc.expected;
  p.deadline_ns = tc.deadline_ns;
  p.max_duration_ns = tc.max_duration_ns;
  p.fault_class = tc.cls->id + (tc.cls->name.empty() ? "" : " " + tc.cls->name);
  p.restart = cb.spec.restart == campaign::RestartKind::Cold ? "cold" : "warm";
  p.rpn = tc.rpn;
  for (const auto& t : tc.step->transitions) {
    PumlTransition x;
    x.lifeline = t.lifeline;
    x.to = t.to;
    std::string up = st::canon(t.to);
    x.from = up == "TRUE" ? "FALSE" : up == "FALSE" ? "TRUE" : "before";
    for (const auto& ps : tc.step->pre)
      if (ps.lifeline == t.lifeline) x.from = ps.value;
    x.faulted = &t == tc.transition;
    x.min_ns = t.min_ns;
    x.max_ns = t.max_ns;
    const auto* l = cb.spec.tsd.find(t.lifeline);
    x.tolerance = t.tolerance >= 0 ? t.tolerance : (l ? l->tolerance : 0);
    p.transitions.push_back(x);
  }
  return p;
}

std::string campaign_verdict_table(const CampaignBuild& cb, const campaign::CampaignResult& res, size_t* fail) {
  std::string o = fmt::format("\n{} {} {} {} {} {} {}\n", pad("case", 5), pad("path", 5), pad("verdict", 12),
                              pad("latency", 9), pad("RPN", 4), pad("transition", 30), "fault / reason");
  *fail = 0;
  std::vector<campaign::Execution> table = res.executions;  // by case, then path
  std::stable_sort(table.begin(), table.end(), [](const auto& a, const auto& b) {
    return std::tie(a.case_index, a.path) < std::tie(b.case_index, b.path);
  });
  for (const auto& e : table) {
    const auto& tc = cb.cases[e.case_index];
    *fail += e.outcome != campaign::Outcome::Pass;
    std::string lat = e.latency_ns >= 0 ? fmt::format("{:.0f} ms", static_cast<double>(e.latency_ns) * 1e-6) : "-";
    o += fmt::format("{} {} {} {} {} {} {}\n", pad(e.case_id, 5), pad(std::to_string(e.path), 5),
                     pad(campaign::outcome_name(e.outcome), 12), pad(lat, 9), pad(std::to_string(tc.rpn), 4),
                     pad(tc.transition_ref(), 30), campaign_fault_text(tc));
    if (e.outcome != campaign::Outcome::Pass || tc.explored) o += fmt::format("{}{}\n", std::string(38, ' '), e.reason);
    std::string dist = branch_list(cb, res, e);
    if (!dist.empty()) o += fmt::format("{}path: {}\n", std::string(38, ' '), dist);
  }
  for (size_t i : res.not_reached)
    o += unrun_row(cb.cases[i], "NOT REACHED", "precondition never held: " + cb.cases[i].precondition);
  for (size_t i : res.pending) o += unrun_row(cb.cases[i], "NOT TESTED", "campaign interrupted before this case");
  return o;
}

std::string campaign_totals_text(const CampaignBuild& cb, const campaign::CampaignResult& res,
                                 const std::vector<std::string>& io_report, size_t fail, const std::string& out) {
  const auto& p = res.progress;
  std::string o = fmt::format("\n{} execution(s) of {} case(s): {} PASS, {} FAIL, {} NOT REACHED\n", res.executions.size(),
                              cb.cases.size(), res.executions.size() - fail, fail, res.not_reached.size());
  o += fmt::format("{} run(s), {} scans, {:.1f} s on the scan clock in {:.3f} s wall time; ended: {}\n", p.run, p.scans,
                   static_cast<double>(p.campaign_ns) * 1e-9, res.wall_s, res.end_reason);
  o += fmt::format("journal {}/results.jsonl, traces and diagrams in {}\n", out, out);
  if (!res.realtime_text.empty()) {
    std::istringstream lines(res.realtime_text);
    for (std::string l; std::getline(lines, l);) o += "  " + l + "\n";
  }
  for (const auto& l : io_report) o += "  " + l + "\n";
  return o;
}

std::string fmea_suggestions_text(const std::vector<campaign::FmeaSuggestion>& sug, const std::string& csv_path) {
  std::string o = fmt::format("\nFMEA suggestions: {} (the failures the FMEA misses, as rows in {})\n", sug.size(), csv_path);
  for (const auto& x : sug)
    o += fmt::format("  {} {}: {}; effect seen: {}; detecting alarm: {}\n", pad(x.case_id, 5), x.component, x.failure_mode,
                     x.effect, x.detection);
  return o;
}

std::string baseline_changes_text(const std::vector<BaselineChange>& changes, const std::string& old, size_t* regressions) {
  *regressions = 0;
  for (const auto& ch : changes) *regressions += ch.regression;
  if (changes.empty()) return fmt::format("no change since {} (baseline)\n", old);
  std::string o = fmt::format("{} change(s) since {} (baseline), {} regression(s)\n", changes.size(), old, *regressions);
  for (const auto& ch : changes) o += fmt::format("  {} {}\n", ch.regression ? "REGRESSION" : "changed   ", ch.what);
  return o;
}

JunitSuite campaign_junit(const CampaignBuild& cb, const campaign::CampaignResult& res,
                          const std::vector<std::string>& io_report, const std::optional<SafetyReport>& safety) {
  JunitSuite suite;
  suite.name = "campaign." + cb.spec.name;
  for (const auto& e : res.executions) suite.cases.push_back(junit_execution(cb, res, e, suite.name));
  suite.properties = res.realtime;
  suite.properties.emplace_back("plant", cb.spec.plant);
  for (size_t i = 0; i < io_report.size(); ++i) suite.properties.emplace_back(fmt::format("io_{}", i), io_report[i]);
  if (res.interrupted) suite.properties.emplace_back("incomplete", res.end_reason);
  if (safety)
    for (auto& prop : safety_junit_properties(*safety)) suite.properties.push_back(std::move(prop));
  for (size_t i : res.pending)
    suite.cases.push_back(junit_skipped(cb.cases[i], suite.name,
                                        "not tested: the campaign was interrupted (" + res.end_reason + "); finish it with --resume"));
  for (size_t i : res.not_reached) {
    const auto& tc = cb.cases[i];
    JunitCase jc = junit_skipped(tc, suite.name, "NOT REACHED: the precondition never held (coverage gap): " + tc.precondition);
    jc.properties = {{"rpn", std::to_string(tc.rpn)}, {"fault_class", tc.cls->id}, {"fmea", tc.row->id}};
    suite.cases.push_back(jc);
  }
  return suite;
}

}  // namespace plcfi::report

// The HTML report's model from a campaign's build, result and specs.
#include "report/campaign_html.hpp"

#include "campaign/explore.hpp"

#include <algorithm>
#include <filesystem>
#include <tuple>

#include <fmt/format.h>

namespace plcfi::report {

namespace {

report::HtmlVerdict verdict(campaign::Outcome o) {
  switch (o) {
    case campaign::Outcome::Pass: return report::HtmlVerdict::Pass;
    case campaign::Outcome::Fail: return report::HtmlVerdict::Fail;
    case campaign::Outcome::NotReached: return report::HtmlVerdict::NotReached;
  }
  return report::HtmlVerdict::Fail;
}

report::HtmlRow case_row(const campaign::TestCase& tc) {
  report::HtmlRow row;
  row.case_id = tc.id;
  row.rpn = tc.rpn;
  row.class_id = tc.cls->id;
  row.class_name = tc.cls->name;
  row.transition = tc.transition_ref();
  row.fmea_id = tc.row ? tc.row->id : "";
  row.failure_mode = tc.row ? tc.row->failure_mode : "";
  row.fault = fmt::format("{} ({}): {}", tc.target->name, tc.target_ref.text, tc.fault.text);
  row.expected = tc.expected;
  return row;
}

std::string seconds_text(int64_t ns) { return fmt::format("{:.1f} s", static_cast<double>(ns) * 1e-9); }

// The header: what ran, the totals, and the facts (sources, runs, journal, resumed,
// incomplete).
report::HtmlHeader header_of(const campaign::CampaignBuild& cb, const campaign::CampaignResult& res, const std::string& out_dir) {
  const auto& c = cb.spec;
  report::HtmlHeader h;
  h.name = c.name;
  h.text = c.text;
  h.programs = c.programs;
  h.plant = c.plant;
  h.seed = c.seed;
  h.end_reason = res.end_reason;
  h.cases = cb.cases.size();
  h.executions = res.executions.size();
  for (const auto& e : res.executions) (e.outcome == campaign::Outcome::Pass ? h.pass : h.fail)++;
  h.not_reached = res.not_reached.size();
  h.not_tested = res.pending.size();
  h.facts = {{"test cases from", c.fmea.path + ", " + c.tsd.path + ", " + c.classes.path},
             {"runs", fmt::format("{} run(s), {} scans, {} on the scan clock", res.progress.run, res.progress.scans,
                                  seconds_text(res.progress.campaign_ns))},
             {"journal", (std::filesystem::path(out_dir) / "results.jsonl").string()}};
  if (res.resumed) h.facts.emplace_back("resumed", fmt::format("{} verdict(s) read back from the journal", res.resumed));
  if (res.interrupted) h.facts.emplace_back("incomplete", "the campaign was interrupted; finish it with --resume");
  return h;
}

// An execution's waveform section: what was tested, its times, the VCD (when recorded).
report::HtmlExecution html_execution(const campaign::TestCase& tc, const campaign::Execution& e, const report::HtmlRow& row,
                                     const std::string& out_dir, bool vcd) {
  report::HtmlExecution x;
  x.title = fmt::format("{} path {}: {}", e.case_id, e.path, tc.transition_ref());
  x.verdict = row.verdict;
  x.summary = (tc.row ? tc.row->failure_mode + ". " : std::string()) + "Fault " + row.fault + "; expected " + tc.expected +
              (e.outcome == campaign::Outcome::Pass ? std::string() : ". " + e.reason);
  if (vcd && !e.vcd.empty()) x.vcd = (std::filesystem::path(out_dir) / e.vcd).string();
  x.inject_ns = e.inject_ns;
  x.start_ns = e.start_ns;
  x.deadline_ns = e.start_ns >= 0 ? e.start_ns + tc.deadline_ns : -1;
  x.reaction_ns = e.reaction_ns;
  x.end_ns = e.end_ns;
  x.faulted = tc.target->name;
  if (tc.row && !tc.row->alarm.empty()) x.alarms.push_back(tc.row->alarm);
  return x;
}

// The rows by case and path (as the text summary), each with its waveform section, then
// the cases NOT REACHED and NOT TESTED.
void add_rows(const campaign::CampaignBuild& cb, const campaign::CampaignResult& res, const std::string& out_dir, bool vcd,
              report::HtmlReport* r) {
  std::vector<campaign::Execution> table = res.executions;  // by case, then path
  std::stable_sort(table.begin(), table.end(), [](const auto& a, const auto& b) {
    return std::tie(a.case_index, a.path) < std::tie(b.case_index, b.path);
  });
  for (const auto& e : table) {
    const auto& tc = cb.cases[e.case_index];
    auto row = case_row(tc);
    row.path = e.path;
    row.verdict = verdict(e.outcome);
    row.latency_ns = e.latency_ns;
    row.reason = e.reason;
    row.branches = campaign::distinguishing_branches(cb, res.executions, e);
    row.execution = static_cast<int>(r->executions.size());
    r->rows.push_back(row);
    r->executions.push_back(html_execution(tc, e, row, out_dir, vcd));
  }
  for (size_t i : res.not_reached) {
    auto row = case_row(cb.cases[i]);
    row.verdict = report::HtmlVerdict::NotReached;
    row.reason = "precondition never held: " + cb.cases[i].precondition;
    r->rows.push_back(row);
  }
  for (size_t i : res.pending) {
    auto row = case_row(cb.cases[i]);
    row.verdict = report::HtmlVerdict::NotTested;
    row.reason = "campaign interrupted before this case";
    r->rows.push_back(row);
  }
}

// A TSD step as the report draws it: its preconditions and transitions, each transition
// with the cases that fault it.
report::HtmlStep html_step(const campaign::CampaignBuild& cb, const campaign::Step& s) {
  const auto& tsd = cb.spec.tsd;
  report::HtmlStep st{s.id, s.text, {}, s.condition, s.start, {}};
  for (const auto& p : s.pre) st.pre.emplace_back(p.lifeline, p.value);
  for (const auto& t : s.transitions) {
    report::HtmlTransition ht;
    ht.lifeline = t.lifeline;
    ht.to = t.to;
    for (const auto& p : s.pre)
      if (p.lifeline == t.lifeline) ht.from = p.value;
    ht.min_ns = t.min_ns;
    ht.max_ns = t.max_ns;
    const auto* l = tsd.find(t.lifeline);
    ht.tolerance = t.tolerance >= 0 ? t.tolerance : (l ? l->tolerance : 0);
    for (const auto& tc : cb.cases)
      if (tc.transition == &t) ht.cases.push_back(tc.id);
    st.transitions.push_back(std::move(ht));
  }
  return st;
}

// The TSD: its lifelines and scenarios.
void add_tsd(const campaign::CampaignBuild& cb, report::HtmlReport* r) {
  const auto& tsd = cb.spec.tsd;
  r->tsd_path = tsd.path;
  for (const auto& l : tsd.lifelines) r->lifelines.push_back({l.name, campaign::kind_name(l.kind)});
  for (const auto& sc : tsd.scenarios) {
    report::HtmlScenario hs{sc.id, sc.text, {}};
    for (const auto& s : sc.steps) hs.steps.push_back(html_step(cb, s));
    r->scenarios.push_back(std::move(hs));
  }
}

}  // namespace

HtmlReport campaign_html_model(const campaign::CampaignBuild& cb, const campaign::CampaignResult& res,
                               const std::string& out_dir, bool vcd) {
  report::HtmlReport r;
  r.header = header_of(cb, res, out_dir);
  add_rows(cb, res, out_dir, vcd, &r);
  for (const auto& s : campaign::fmea_suggestions(cb, res.executions))
    r.suggestions.push_back({s.component, s.failure_mode, s.effect, s.detection == "none" ? "" : s.detection, s.case_id,
                             s.transition});
  if (!vcd) r.waveform_note = "Waveforms omitted: the campaign ran with --no-vcd, so no traces were recorded.";
  add_tsd(cb, &r);
  return r;
}

}  // namespace plcfi::report

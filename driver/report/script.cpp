// A CPTest+ script's run rendered (see script.hpp).
#include "report/script.hpp"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

#include "common/csv.hpp"

namespace plcfi::report {

namespace {

using common::csv_field;

std::string secs(int64_t ns) { return fmt::format("{:.3f}", static_cast<double>(ns) * 1e-9); }

// "Undecidable", "Passed", "Failed": the words of the published history table.
std::string title(const std::string& verdict) {
  std::string t = verdict;
  if (!t.empty()) t[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(t[0])));
  return t;
}

}  // namespace

std::string script_run_text(const script::Script& s, const script::ScriptResult& r, const std::vector<std::string>& pous,
                            const script::RunOptions& ro, uint64_t failed_exchanges) {
  std::string pou_list;
  for (const auto& p : pous) pou_list += (pou_list.empty() ? "" : ", ") + p;
  std::string o = fmt::format("\n[{}] {}  ({} s on the scan clock, {} scans; POUs {}; p_lst {} of the latest {})\n", s.path,
                              title(script::verdict_name(r.verdict)), secs(r.end_ns), r.scans,
                              pou_list.empty() ? "none" : pou_list, ro.p_lst, ro.mci.psi);
  bool waited = false;
  for (const auto& a : r.asserts)
    if (a.waited) {
      waited = true;
      o += fmt::format("  {}: {}: waited {} cycle(s) through a communication error, {}; c = {}, m_ci = {:.3g}\n", a.where,
                       a.text, a.held ? a.cycles : a.cycles - 1, a.held ? "then it held" : "it never held", a.cycles, a.mci);
    }
  // The waited assertion's line says why the run ended, unless something cut its wait
  // short (a time-out, an interrupt).
  const bool said = waited && r.reason.rfind(r.asserts.back().where + ": ", 0) == 0;
  if (!r.reason.empty() && !said) o += "  " + r.reason + "\n";
  if (r.verdict == script::Verdict::Undecidable && !r.asserts.empty() && r.asserts.back().has_mci)
    o += fmt::format("  possible external problem, factor = {:.3g}\n", r.asserts.back().mci);
  if (failed_exchanges > 0) o += fmt::format("  communication: {} exchange(s) failed\n", failed_exchanges);
  return o;
}

std::string script_text_log(const script::ScriptResult& r) {
  std::string o =
      fmt::format("# {}: {}{}\n", r.test, script::verdict_name(r.verdict), r.reason.empty() ? "" : " (" + r.reason + ")");
  for (const auto& e : r.log) {
    std::string line = e.line ? fmt::format("line {:>3}", e.line) : std::string(8, ' ');
    const char* kind = e.kind == script::LogEntry::Kind::Command    ? "CMD "
                       : e.kind == script::LogEntry::Kind::Log      ? "LOG "
                       : e.kind == script::LogEntry::Kind::Snapshot ? "SNAP"
                                                                    : "END ";
    o += fmt::format("{:>10} s  scan {:>7}  {}  {}  {}\n", secs(e.t_ns), e.scan, line, kind, e.text);
    if (e.snapshot >= 0)
      for (size_t i = 0; i < r.snapshot_paths.size(); ++i)
        o += "      " + r.snapshot_paths[i] + " = " + r.snapshots[static_cast<size_t>(e.snapshot)][i] + "\n";
  }
  return o;
}

std::string script_csv_log(const script::ScriptResult& r) {
  std::string o = "time,scan,line,event";
  for (const auto& p : r.snapshot_paths) o += "," + csv_field(p);
  o += "\n";
  for (const auto& e : r.log) {
    if (e.snapshot < 0) continue;
    o += fmt::format("{},{},{},{}", secs(e.t_ns), e.scan, e.line, csv_field(e.text));
    for (const auto& v : r.snapshots[static_cast<size_t>(e.snapshot)]) o += "," + csv_field(v);
    o += "\n";
  }
  return o;
}

testing::TestSuite script_suite(const script::Script& s, const std::vector<std::pair<std::string, std::string>>& run_props) {
  testing::TestSuite suite;
  suite.name = s.path;
  suite.properties = run_props;
  suite.cases.emplace_back();
  suite.cases.back().name = s.name;
  return suite;
}

testing::TestCase script_case(const script::Script& s, const script::ScriptResult& r, const script::HistoryRow& row,
                              int64_t p_lst) {
  testing::TestCase c;
  c.name = s.name;
  c.seconds = static_cast<double>(r.end_ns) * 1e-9;
  c.verdict = r.verdict == script::Verdict::Failed        ? testing::Verdict::Fail
              : r.verdict == script::Verdict::Undecidable ? testing::Verdict::Undecidable
                                                          : testing::Verdict::Pass;
  if (c.verdict != testing::Verdict::Pass) c.findings.push_back({"", r.reason});
  if (c.verdict == testing::Verdict::Undecidable && row.mci) c.properties.emplace_back("m_ci", fmt::format("{:.3g}", *row.mci));
  c.properties.emplace_back("verdict", row.verdict);
  c.properties.emplace_back("p_lst", std::to_string(p_lst));
  return c;
}

std::string history_table(const std::vector<script::HistoryRow>& rows) {
  size_t w = 4;
  for (const auto& r : rows) w = std::max(w, r.test.size());
  std::string o = fmt::format("{:<{}}  {:<12} {:<20} {:>6} {:>5}  {}\n", "test", w, "verdict", "time (UTC)", "m_ci", "c", "note");
  for (const auto& r : rows) {
    std::string when = r.time;
    if (when.size() >= 19) when = when.substr(0, 10) + " " + when.substr(11, 8);
    std::string note =
        r.verdict == "undecidable" && r.mci ? fmt::format("possible external problem, factor = {:.3g}", *r.mci) : r.reason;
    o += fmt::format("{:<{}}  {:<12} {:<20} {:>6} {:>5}  {}\n", r.test, w, title(r.verdict), when,
                     r.mci ? fmt::format("{:.3g}", *r.mci) : "-", r.cycles ? std::to_string(*r.cycles) : "-", note);
  }
  return o;
}

}  // namespace plcfi::report

// The result models rendered by report/: a campaign (text table, totals, JUnit), EDTL
// verdicts and a scan-cycle run as JUnit.
#include <gtest/gtest.h>

#include <filesystem>

#include <fmt/format.h>

#include "campaign/spec.hpp"
#include "report/campaign.hpp"
#include "report/edtl.hpp"
#include "report/script.hpp"
#include "report/junit.hpp"

namespace fs = std::filesystem;
using namespace plcfi;

namespace {

campaign::CampaignBuild stamping_build() {
  campaign::Campaign c;
  std::string err;
  EXPECT_TRUE(campaign::load_campaign((fs::path(PLCFI_SOURCE_DIR) / "faults/campaigns/stamping/campaign.yaml").string(), &c, &err))
      << err;
  campaign::CampaignBuild cb;
  EXPECT_TRUE(campaign::prepare_campaign(std::move(c), &cb, &err)) << err;
  return cb;
}

campaign::Execution execution(const campaign::CampaignBuild& cb, size_t i, campaign::Outcome o, const std::string& reason) {
  campaign::Execution e;
  e.case_index = i;
  e.case_id = cb.cases[i].id;
  e.outcome = o;
  e.reason = reason;
  e.inject_ns = 1'000'000'000;
  e.end_ns = 1'250'000'000;
  e.latency_ns = o == campaign::Outcome::Pass ? 40'000'000 : -1;
  return e;
}

}  // namespace

// Four cases: one PASS, one FAIL, one NOT REACHED, one NOT TESTED (interrupted).
TEST(CampaignReport, TableTotalsAndJunitAgreeOnEveryVerdict) {
  auto cb = stamping_build();
  ASSERT_GE(cb.cases.size(), 4u);
  campaign::CampaignResult res;
  res.executions = {execution(cb, 1, campaign::Outcome::Fail, "no alarm within 500 ms"),
                    execution(cb, 0, campaign::Outcome::Pass, "alarm after 40 ms")};
  res.not_reached = {2};
  res.pending = {3};
  res.interrupted = true;
  res.end_reason = "SIGINT";

  size_t fail = 99;
  std::string table = report::campaign_verdict_table(cb, res, &fail);
  EXPECT_EQ(fail, 1u);
  // By case index, whatever the order they ran in.
  size_t first = table.find(cb.cases[0].id + " "), second = table.find(cb.cases[1].id + " ");
  ASSERT_NE(first, std::string::npos);
  EXPECT_LT(first, second);
  EXPECT_NE(table.find("40 ms"), std::string::npos);
  EXPECT_NE(table.find("no alarm within 500 ms"), std::string::npos);  // a FAIL's reason is shown
  EXPECT_EQ(table.find("alarm after 40 ms"), std::string::npos);      // a PASS's is not
  EXPECT_NE(table.find("NOT REACHED"), std::string::npos);
  EXPECT_NE(table.find("NOT TESTED"), std::string::npos);

  std::string totals = report::campaign_totals_text(cb, res, {"device d: 3 requests"}, fail, "OUT");
  EXPECT_NE(totals.find(fmt::format("2 execution(s) of {} case(s): 1 PASS, 1 FAIL, 1 NOT REACHED", cb.cases.size())),
            std::string::npos)
      << totals;
  EXPECT_NE(totals.find("  device d: 3 requests\n"), std::string::npos);

  auto suite = report::campaign_junit(cb, res, {"device d: 3 requests"}, std::nullopt);
  EXPECT_EQ(suite.name, "campaign." + cb.spec.name);
  ASSERT_EQ(suite.cases.size(), 4u);
  EXPECT_EQ(suite.cases[0].outcome, report::JunitCase::Outcome::Fail);
  EXPECT_EQ(suite.cases[0].message, "no alarm within 500 ms");
  EXPECT_DOUBLE_EQ(suite.cases[0].seconds, 0.25);
  EXPECT_EQ(suite.cases[1].outcome, report::JunitCase::Outcome::Pass);
  EXPECT_EQ(suite.cases[2].outcome, report::JunitCase::Outcome::Skipped);  // pending first
  EXPECT_NE(suite.cases[2].message.find("--resume"), std::string::npos);
  EXPECT_EQ(suite.cases[3].outcome, report::JunitCase::Outcome::Skipped);
  EXPECT_EQ(suite.cases[3].message.rfind("NOT REACHED", 0), 0u);
  auto has = [&](const std::string& k, const std::string& v) {
    for (const auto& [a, b] : suite.properties)
      if (a == k && b == v) return true;
    return false;
  };
  EXPECT_TRUE(has("io_0", "device d: 3 requests"));
  EXPECT_TRUE(has("incomplete", "SIGINT"));
  EXPECT_TRUE(has("plant", cb.spec.plant));
}

TEST(CampaignReport, CasesListingNamesEveryCase) {
  auto cb = stamping_build();
  std::string text = report::campaign_cases_text(cb);
  EXPECT_EQ(text.rfind(fmt::format("campaign {}: {} test case(s)", cb.spec.name, cb.cases.size()), 0), 0u);
  for (const auto& tc : cb.cases) EXPECT_NE(text.find(tc.id + ": " + tc.row->failure_mode), std::string::npos) << tc.id;
}

TEST(CampaignReport, BaselineChangesCountRegressions) {
  size_t reg = 9;
  EXPECT_EQ(report::baseline_changes_text({}, "old", &reg), "no change since old (baseline)\n");
  EXPECT_EQ(reg, 0u);
  std::string t = report::baseline_changes_text({{"TC1 PASS -> FAIL", true}, {"TC2 latency 40 -> 30 ms", false}}, "old", &reg);
  EXPECT_EQ(reg, 1u);
  EXPECT_EQ(t,
            "2 change(s) since old (baseline), 1 regression(s)\n"
            "  REGRESSION TC1 PASS -> FAIL\n"
            "  changed    TC2 latency 40 -> 30 ms\n");
}

TEST(EdtlReport, OneCasePerRequirementFailedAtItsFirstViolation) {
  monitor::Verdict ok;
  ok.id = "R1";
  ok.text = "alarm within 1 s";
  ok.triggers = 3;
  ok.holds = 3;
  monitor::Verdict bad;
  bad.id = "R2";
  bad.severity = "high";
  bad.triggers = 2;
  bad.violated_instances = 1;
  monitor::Violation v;
  v.state = 7;
  v.time_ns = 70'000'000;
  v.cause = monitor::Cause::Delay;
  bad.violations.push_back(v);
  auto s = report::edtl_junit("reqs.yaml", {ok, bad});
  ASSERT_EQ(s.cases.size(), 2u);
  EXPECT_EQ(s.cases[0].name, "R1: alarm within 1 s");
  EXPECT_EQ(s.cases[0].outcome, report::JunitCase::Outcome::Pass);
  EXPECT_EQ(s.cases[1].name, "R2");
  EXPECT_EQ(s.cases[1].outcome, report::JunitCase::Outcome::Fail);
  EXPECT_EQ(s.cases[1].message.rfind("violated at state 7 (t=0.070 s): ", 0), 0u) << s.cases[1].message;
  EXPECT_FALSE(s.cases[1].detail.empty());
  EXPECT_EQ(s.cases[1].properties.back(), (std::pair<std::string, std::string>{"severity", "high"}));
}

TEST(RunReport, AFailedScanCycleCarriesWhyAndTheDevicesFigures) {
  report::ScanRunFacts run;
  run.name = "scan cycle on io.yaml";
  run.seconds = 1.5;
  run.failed = true;
  run.ended = "device d lost";
  run.scans = 150;
  run.realtime = {{"overruns", "0"}};
  run.io_report = {"device d: 10 requests, 2 failed"};
  auto s = report::scan_run_junit(run);
  ASSERT_EQ(s.cases.size(), 1u);
  EXPECT_EQ(s.cases[0].outcome, report::JunitCase::Outcome::Fail);
  EXPECT_EQ(s.cases[0].message, "device d lost");
  EXPECT_EQ(s.cases[0].properties.front(), (std::pair<std::string, std::string>{"scans", "150"}));
  ASSERT_EQ(s.properties.size(), 2u);
  EXPECT_EQ(s.properties[1], (std::pair<std::string, std::string>{"io_0", "device d: 10 requests, 2 failed"}));
}

TEST(ScriptReport, LogsAndHistoryTableAsWritten) {
  script::ScriptResult r;
  r.test = "fill";
  r.verdict = script::Verdict::Failed;
  r.reason = "line 4: ASSERT level > 3 failed";
  r.snapshot_paths = {"Main.level", "Main.note"};
  r.snapshots = {{"2", "a,b"}};
  r.log.push_back({script::LogEntry::Kind::Command, 10'000'000, 1, 3, "WAIT 10ms", -1});
  r.log.push_back({script::LogEntry::Kind::Snapshot, 20'000'000, 2, 4, "SNAPSHOT", 0});
  EXPECT_EQ(report::script_text_log(r),
            "# fill: failed (line 4: ASSERT level > 3 failed)\n"
            "     0.010 s  scan       1  line   3  CMD   WAIT 10ms\n"
            "     0.020 s  scan       2  line   4  SNAP  SNAPSHOT\n"
            "      Main.level = 2\n"
            "      Main.note = a,b\n");
  EXPECT_EQ(report::script_csv_log(r), "time,scan,line,event,Main.level,Main.note\n0.020,2,4,SNAPSHOT,2,\"a,b\"\n");

  script::HistoryRow u;
  u.test = "fill";
  u.verdict = "undecidable";
  u.time = "2026-11-25T06:40:12Z";
  u.mci = 0.25;
  u.cycles = 3;
  script::HistoryRow p;
  p.test = "drain_all";
  p.verdict = "passed";
  p.time = "2026-11-25T06:41:00Z";
  EXPECT_EQ(report::history_table({u, p}),
            "test       verdict      time (UTC)             m_ci     c  note\n"
            "fill       Undecidable  2026-11-25 06:40:12    0.25     3  possible external problem, factor = 0.25\n"
            "drain_all  Passed       2026-11-25 06:41:00       -     -  \n");
}

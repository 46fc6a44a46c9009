// The run sequencer and the records of shared campaigns: the bookkeeping that makes
// --jobs and --shard write the single run's journal (the end-to-end comparison is
// tests/campaign/parallel.sh).
#include <gtest/gtest.h>

#include "campaign/parallel.hpp"

namespace plcfi::campaign {
namespace {

constexpr int64_t kTick = 10'000'000;  // 10 ms

RunSequencer::Limits limits(int64_t budget_ns, size_t cases = 2, int max_paths = 1) {
  RunSequencer::Limits l;
  l.budget_ns = budget_ns;
  l.tick_ns = kTick;
  l.search_window_ns = 60'000'000'000;
  l.max_paths = max_paths;
  l.cases = cases;
  return l;
}

RunRecord executed(uint64_t run, size_t c, int path, uint64_t inject_scan, uint64_t scans, const char* verdict = "PASS") {
  RunRecord r;
  r.kind = RunRecord::Kind::Executed;
  r.run = run;
  r.exec.case_index = c;
  r.exec.case_id = "TC" + std::to_string(c + 1);
  r.exec.path = path;
  r.exec.outcome = std::string(verdict) == "PASS" ? Outcome::Pass : Outcome::Fail;
  r.inject_scan = inject_scan;
  r.scans = scans;
  r.ns = static_cast<int64_t>(scans) * kTick;
  r.line = "{\"case\":\"" + r.exec.case_id + "\",\"verdict\":\"" + verdict + "\",\"campaign_ns\":0,\"scans\":0}";
  return r;
}

RunRecord ended(uint64_t run, uint64_t scans, std::string end) {
  RunRecord r;
  r.run = run;
  r.scans = scans;
  r.ns = static_cast<int64_t>(scans) * kTick;
  r.end = std::move(end);
  return r;
}

TEST(RunSequencer, AddsUpRunsAndFillsTheProgressIntoTheLine) {
  RunSequencer s(limits(3'600'000'000'000), JournalState{});
  RunSequencer::Fed fed;
  std::string err;
  ASSERT_TRUE(s.feed(executed(0, 1, 1, 12, 73), &fed, &err)) << err;
  EXPECT_TRUE(fed.executed);
  EXPECT_EQ(fed.line, "{\"case\":\"TC2\",\"verdict\":\"PASS\",\"campaign_ns\":730000000,\"scans\":73}");
  ASSERT_TRUE(s.feed(executed(1, 0, 1, 30, 80, "FAIL"), &fed, &err)) << err;
  EXPECT_EQ(fed.line, "{\"case\":\"TC1\",\"verdict\":\"FAIL\",\"campaign_ns\":1530000000,\"scans\":153}");
  EXPECT_TRUE(s.ended());
  EXPECT_EQ(s.end_reason(), "every case tested on 1 path(s)");
  EXPECT_EQ(s.progress().pass, 1u);
  EXPECT_EQ(s.progress().fail, 1u);
  EXPECT_EQ(s.progress().run, 2u);
}

TEST(RunSequencer, CutsARunWhereTheSingleRunSpendsTheBudget) {
  // Budget 1 s: run 0 uses 0.73 s; run 1 would inject at its 40th scan, but after its
  // 27th the budget is spent, so the single run never injects there.
  RunSequencer s(limits(1'000'000'000), JournalState{});
  RunSequencer::Fed fed;
  std::string err;
  ASSERT_TRUE(s.feed(executed(0, 1, 1, 12, 73), &fed, &err)) << err;
  ASSERT_TRUE(s.feed(executed(1, 0, 1, 40, 90), &fed, &err)) << err;
  EXPECT_FALSE(fed.executed);
  EXPECT_TRUE(s.ended());
  EXPECT_EQ(s.end_reason(), "time budget of 1 s spent");
  EXPECT_EQ(s.progress().scans, 73u + 27u);
  EXPECT_EQ(s.progress().campaign_ns, 1'000'000'000);
}

TEST(RunSequencer, InjectionInTheScanThatSpendsTheBudgetStillCounts) {
  // The budget is checked after the scans before the injection only: an injection in the
  // scan that reaches the budget is tested (the test may run past the budget).
  RunSequencer s(limits(1'000'000'000), JournalState{});
  RunSequencer::Fed fed;
  std::string err;
  ASSERT_TRUE(s.feed(executed(0, 1, 1, 12, 73), &fed, &err)) << err;
  ASSERT_TRUE(s.feed(executed(1, 0, 1, 27, 60), &fed, &err)) << err;
  EXPECT_TRUE(fed.executed);
  EXPECT_EQ(s.progress().scans, 133u);
}

TEST(RunSequencer, EndsOnTheSearchWindowAndOnAStop) {
  {
    RunSequencer s(limits(3'600'000'000'000), JournalState{});
    RunSequencer::Fed fed;
    std::string err;
    ASSERT_TRUE(s.feed(ended(0, 6000, "window"), &fed, &err)) << err;
    EXPECT_EQ(s.end_reason(), "no untested case or path within the search window of 60 s");
    EXPECT_EQ(s.progress().scans, 6000u);
  }
  {
    RunSequencer s(limits(3'600'000'000'000), JournalState{});
    RunSequencer::Fed fed;
    std::string err;
    ASSERT_TRUE(s.feed(ended(0, 250, "stopped: f.st:3:4: division by zero"), &fed, &err)) << err;
    EXPECT_EQ(s.end_reason(), "the program stopped outside a test: f.st:3:4: division by zero");
  }
}

TEST(RunSequencer, RefusesRecordsThatCannotBeTheNextRun) {
  RunSequencer s(limits(3'600'000'000'000), JournalState{});
  RunSequencer::Fed fed;
  std::string err;
  EXPECT_FALSE(s.feed(executed(1, 0, 1, 5, 9), &fed, &err));
  EXPECT_EQ(err, "expected the record of run 0, found run 1");
  RunRecord claimed = executed(0, 0, 1, 5, 5);
  claimed.kind = RunRecord::Kind::Claimed;
  EXPECT_FALSE(s.feed(claimed, &fed, &err));
  EXPECT_FALSE(s.feed(executed(0, 0, 2, 5, 9), &fed, &err));  // path 2 before path 1
  EXPECT_NE(err.find("does not follow"), std::string::npos) << err;
  RunRecord uneven = executed(0, 0, 1, 5, 9);
  uneven.ns += 1;  // real time: scans of uneven length
  EXPECT_FALSE(s.feed(uneven, &fed, &err));
  EXPECT_NE(err.find("virtual time"), std::string::npos) << err;
  // A share that stopped on the budget where the campaign did not.
  EXPECT_FALSE(s.feed(ended(0, 10, "budget"), &fed, &err));
  EXPECT_NE(err.find("another budget"), std::string::npos) << err;
}

TEST(RunSequencer, StartsFromAResumedJournal) {
  JournalState st;
  Execution e;
  e.case_index = 0;
  e.path = 1;
  e.outcome = Outcome::Fail;
  st.executions.push_back(e);
  st.next_run = 3;
  st.campaign_ns = 2'000'000'000;
  st.scans = 200;
  RunSequencer s(limits(3'600'000'000'000), st);
  EXPECT_EQ(s.next_run(), 3u);
  RunSequencer::Fed fed;
  std::string err;
  ASSERT_TRUE(s.feed(executed(3, 1, 1, 4, 10), &fed, &err)) << err;
  EXPECT_EQ(fed.line, "{\"case\":\"TC2\",\"verdict\":\"PASS\",\"campaign_ns\":2100000000,\"scans\":210}");
  EXPECT_TRUE(s.ended());
  EXPECT_EQ(s.progress().fail, 1u);
}

TEST(RunRecords, RoundTripThroughJson) {
  RunRecord r = executed(7, 1, 2, 12, 73, "FAIL");
  r.exec.vcd = "TC2_path2.vcd";
  RunRecord back;
  std::string why;
  ASSERT_TRUE(parse_record(record_json(r), &back, &why)) << why;
  EXPECT_EQ(back.run, 7u);
  EXPECT_EQ(back.exec.case_index, 1u);
  EXPECT_EQ(back.exec.path, 2);
  EXPECT_EQ(back.exec.outcome, Outcome::Fail);
  EXPECT_EQ(back.exec.vcd, "TC2_path2.vcd");
  EXPECT_EQ(back.line, r.line);
  EXPECT_EQ(back.inject_scan, 12u);
  ASSERT_TRUE(parse_record(record_json(ended(3, 100, "window")), &back, &why)) << why;
  EXPECT_EQ(back.end, "window");
  EXPECT_FALSE(parse_record("{\"run\":-1,\"kind\":\"ended\",\"scans\":1,\"ns\":1,\"inject_scan\":0}", &back, &why));
  EXPECT_FALSE(parse_record("{\"run\":1,\"kind\":\"other\",\"scans\":1,\"ns\":1,\"inject_scan\":0}", &back, &why));
  EXPECT_FALSE(parse_record("[1,2", &back, &why));
}

TEST(Shares, ParseKOverN) {
  int k = -1, n = -1;
  std::string why;
  EXPECT_TRUE(parse_share("0/4", &k, &n, &why));
  EXPECT_EQ(k, 0);
  EXPECT_EQ(n, 4);
  EXPECT_TRUE(parse_share("3/4", &k, &n, &why));
  EXPECT_FALSE(parse_share("4/4", &k, &n, &why));
  EXPECT_NE(why.find("K must be 0..3"), std::string::npos);
  for (const char* bad : {"", "1", "/4", "1/", "-1/4", "1/0", "1/2000", "a/b", "1/4/5", "99999999999/3"})
    EXPECT_FALSE(parse_share(bad, &k, &n, &why)) << bad;
}

}  // namespace
}  // namespace plcfi::campaign

// Running CPTest+ scripts: waits in time and in task cycles, ASSERT and ASSERT_COM
// through link faults with m_ci, program traps, the run history and the POU hash.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "engine.hpp"
#include "io/link_fault.hpp"
#include "io/sim/sim_backend.hpp"
#include "plant_model/plant.hpp"
#include "runtime/runtime.hpp"
#include "runtime/schedule.hpp"
#include "script/bind.hpp"
#include "script/cpt.hpp"
#include "script/history.hpp"
#include "script/runner.hpp"

namespace plcfi::script {
namespace {

// The bead dispenser on its plant, behind a link that scripts can break.
class BeadStand {
 public:
  explicit BeadStand(const std::string& program = "bead_dispenser.st") {
    st::CompileOptions opt;
    opt.warnings = false;
    b = st::build_files({std::string(PLCFI_SOURCE_DIR) + "/st_programs/bead_dispenser/" + program}, opt);
    EXPECT_TRUE(b->ok()) << b->diags.render_all();
    std::string err;
    EXPECT_TRUE(sched.from_configuration(*b->app, &err)) << err;
    sim = io::SimBackend::create(*b->app, plant::make_builtin_plant("bead_dispenser", "", &err), &err);
    EXPECT_TRUE(sim) << err;
    link = std::make_unique<io::LinkFaultBackend>(sim.get(), "plant");
    rt = std::make_unique<rt::Runtime>(*b->app, sched, link.get());
  }
  ScriptResult run(const std::string& text, RunOptions ro = {}) {
    std::string err;
    EXPECT_TRUE(parse_script("t.cpt", text, &script, &err)) << err;
    EXPECT_TRUE(bind_script(*b->app, script, {"plant"}, &bound, &err)) << err;
    rt->cold_restart(1);
    return run_script(*rt, bound, ro);
  }
  std::unique_ptr<st::Build> b;
  rt::Schedule sched;
  std::unique_ptr<io::SimBackend> sim;
  std::unique_ptr<io::LinkFaultBackend> link;
  std::unique_ptr<rt::Runtime> rt;
  Script script;
  BoundScript bound;
};

const char* kPublished = "01: SET PASS_ONE_BALL\n02: LOG ONE BALL MODE ON\n03: WAIT 500 MS\n04: RESET PASS_ONE_BALL\n"
                         "05: LOG ONE BALL MODE OFF\n06: ASSERT_COM ISTRUE IS_BEAD_SEEN\n";

TEST(ScriptRun, PublishedScriptPassesOnTheCorrectProgram) {
  BeadStand s;
  ScriptResult r = s.run(kPublished);
  EXPECT_EQ(r.verdict, Verdict::Passed) << r.reason;
  EXPECT_EQ(r.scans, 50u);  // 500 ms of 10 ms scans; the rest takes no time
  ASSERT_EQ(r.asserts.size(), 1u);
  EXPECT_TRUE(r.asserts[0].held);
  EXPECT_FALSE(r.asserts[0].waited);
  EXPECT_TRUE(r.snapshots.empty());
  EXPECT_EQ(s.sim->plant().stats()[0].second, 1);  // one bead released
}

TEST(ScriptRun, BuggyProgramFailsAtOnceWithAHealthyLink) {
  BeadStand s("bead_dispenser_buggy.st");
  ScriptResult r = s.run(kPublished);
  EXPECT_EQ(r.verdict, Verdict::Failed);
  EXPECT_EQ(r.reason, "line 6 (06): ASSERT_COM ISTRUE IS_BEAD_SEEN: IS_BEAD_SEEN is FALSE (no communication error)");
  ASSERT_EQ(r.asserts.size(), 1u);
  EXPECT_FALSE(r.asserts[0].waited);
  EXPECT_FALSE(r.asserts[0].has_mci);
  ASSERT_EQ(r.snapshots.size(), 1u);  // the snapshot of the failed condition
}

TEST(ScriptRun, BrokenLinkWithAPassingHistoryIsUndecidable) {
  BeadStand s;
  RunOptions ro;
  ro.p_lst = 10;
  ro.max_wait_ns = 200'000'000;
  ScriptResult r = s.run(std::string("FAULT LINK plant FOR 2 S\n") + kPublished, ro);
  EXPECT_EQ(r.verdict, Verdict::Undecidable) << r.reason;
  ASSERT_EQ(r.asserts.size(), 1u);
  const auto& a = r.asserts[0];
  EXPECT_TRUE(a.waited);
  EXPECT_TRUE(a.comm_error);
  EXPECT_FALSE(a.held);
  EXPECT_EQ(a.cycles, 21);  // 20 re-checks in 200 ms, never held: c = 21
  EXPECT_EQ(a.mci, 1.0);
  EXPECT_EQ(r.snapshots.size(), 21u);  // the first failure and each re-check
  EXPECT_GT(s.link->lost(), 0u);
}

TEST(ScriptRun, BrokenLinkWithoutHistoryFails) {
  BeadStand s;
  RunOptions ro;
  ro.p_lst = 0;
  ScriptResult r = s.run(std::string("FAULT LINK plant FOR 2 S\n") + kPublished, ro);
  EXPECT_EQ(r.verdict, Verdict::Failed);
  EXPECT_EQ(r.asserts.at(0).mci, 0.0);
}

TEST(ScriptRun, ConditionThatHoldsAfterTheLinkReturnsWeighsTheCycles) {
  // The bead is in the beam from 160 to 175 ms. The link breaks at 170 ms for 100 ms, so
  // the program's BeadSensor stays frozen TRUE until the first good read at 270 ms: the
  // check at 180 ms fails, then holds at the 10th re-check.
  const char* script = "SET PASS_ONE_BALL\nWAIT 170 MS\nFAULT LINK plant FOR 100 MS\nWAIT 10 MS\nASSERT_COM ISFALSE BeadSensor\n";
  BeadStand s;
  RunOptions ro;
  ro.p_lst = 5;  // middle band
  ScriptResult r = s.run(script, ro);
  ASSERT_EQ(r.asserts.size(), 1u);
  const auto& a = r.asserts[0];
  EXPECT_TRUE(a.waited);
  EXPECT_TRUE(a.held);
  EXPECT_EQ(a.cycles, 10);
  EXPECT_DOUBLE_EQ(a.mci, 0.1);  // c = gamma: alpha
  EXPECT_EQ(r.verdict, Verdict::Failed);
  // With gamma 50 the same wait is weighed on the line from beta to alpha.
  BeadStand s2;
  ro.mci.gamma = 50;
  ScriptResult r2 = s2.run(script, ro);
  EXPECT_NEAR(r2.asserts.at(0).mci, 0.9 - 0.8 * 9.0 / 49.0, 1e-12);
  EXPECT_EQ(r2.verdict, Verdict::Undecidable);
  // In the high band any wait is excused; in the low band none.
  BeadStand s3;
  ro.p_lst = 9;
  EXPECT_EQ(s3.run(script, ro).asserts.at(0).mci, 1.0);
  BeadStand s4;
  ro.p_lst = 1;
  EXPECT_EQ(s4.run(script, ro).verdict, Verdict::Failed);
}

TEST(ScriptRun, WaitCountsTaskCyclesAndRoundsTimeUp) {
  BeadStand s;
  ScriptResult r = s.run("WAIT 3 C\nWAIT 25 MS\nWAIT 1 S\n");
  EXPECT_EQ(r.verdict, Verdict::Passed);
  EXPECT_EQ(r.scans, 3u + 3u + 100u);
  EXPECT_EQ(r.end_ns, 1'060'000'000);
}

TEST(ScriptRun, TimeLimitEndsALongerRunFailed) {
  RunOptions ro;
  ro.time_limit_ns = 500'000'000;
  ro.time_limit_reason = "did not finish within the per-test time-out (500ms)";
  // 500 ms of waiting needs no scan beyond the limit: it passes.
  BeadStand s;
  ScriptResult r = s.run(kPublished, ro);
  EXPECT_EQ(r.verdict, Verdict::Passed) << r.reason;
  EXPECT_EQ(r.end_ns, 500'000'000);
  // 600 ms does: the run ends at the limit, Failed with the reason, the rest not run.
  BeadStand s2;
  r = s2.run("WAIT 600 MS\nLOG not reached\n", ro);
  EXPECT_EQ(r.verdict, Verdict::Failed);
  EXPECT_EQ(r.reason, "did not finish within the per-test time-out (500ms)");
  EXPECT_EQ(r.end_ns, 500'000'000);
  EXPECT_EQ(r.scans, 50u);
  for (const auto& e : r.log) EXPECT_NE(e.text, "not reached");
}

TEST(ScriptRun, TimeLimitCutsAnAssertComWaitFailed) {
  // Without the limit this run is undecidable (see above); the limit ends its wait first.
  BeadStand s;
  RunOptions ro;
  ro.p_lst = 10;
  ro.max_wait_ns = 200'000'000;
  ro.time_limit_ns = 600'000'000;
  ro.time_limit_reason = "out of time";
  ScriptResult r = s.run(std::string("FAULT LINK plant FOR 2 S\n") + kPublished, ro);
  EXPECT_EQ(r.verdict, Verdict::Failed);
  EXPECT_EQ(r.reason, "out of time");
  EXPECT_EQ(r.end_ns, 600'000'000);
  ASSERT_EQ(r.asserts.size(), 1u);
  EXPECT_TRUE(r.asserts[0].waited);
}

TEST(ScriptRun, PlainAssertFailsWithoutWaitingEvenOnABrokenLink) {
  BeadStand s;
  ScriptResult r = s.run("FAULT LINK plant FOR 1 S\nWAIT 50 MS\nASSERT ISTRUE IS_BEAD_SEEN\nLOG not reached\n");
  EXPECT_EQ(r.verdict, Verdict::Failed);
  EXPECT_EQ(r.scans, 5u);
  for (const auto& e : r.log) EXPECT_NE(e.text, "not reached");
}

TEST(ScriptRun, ATrapEndsTheRunFailed) {
  st::CompileOptions opt;
  opt.warnings = false;
  auto b = st::build_sources({{"p.st", "PROGRAM P VAR d : INT; x : INT; END_VAR IF d > 2 THEN x := 10 / (d - d); END_IF; END_PROGRAM\n"
                                       "CONFIGURATION C RESOURCE R ON PLC TASK T (INTERVAL := T#10ms, PRIORITY := 1); "
                                       "PROGRAM Main WITH T : P; END_RESOURCE END_CONFIGURATION\n"}},
                             opt);
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  rt::Schedule sched;
  std::string err;
  ASSERT_TRUE(sched.from_configuration(*b->app, &err));
  rt::Runtime rt(*b->app, sched, nullptr);
  Script s;
  ASSERT_TRUE(parse_script("t.cpt", "ASSIGN Main.d 5\nWAIT 1 S\nASSERT EQ Main.x 10\n", &s, &err));
  BoundScript bs;
  ASSERT_TRUE(bind_script(*b->app, s, {}, &bs, &err)) << err;
  rt.cold_restart(1);
  ScriptResult r = run_script(rt, bs, {});
  EXPECT_EQ(r.verdict, Verdict::Failed);
  EXPECT_EQ(r.reason.rfind("the program stopped: ", 0), 0u) << r.reason;
  EXPECT_EQ(r.scans, 1u);
}

// ---- history

class ScriptHistory : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (std::filesystem::temp_directory_path() / "plcfi_hist_XXXXXX").string();
    ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  HistoryRow row(const std::string& verdict, const std::string& hash) {
    HistoryRow r;
    r.test = "t";
    r.verdict = verdict;
    r.time = utc_now();
    r.program_hash = "p";
    r.pou_hash = hash;
    return r;
  }
  std::filesystem::path dir_;
};

TEST_F(ScriptHistory, PassesCountBackToTheLastChangeOfThePous) {
  std::string err;
  auto h = History::open((dir_ / "sub" / "h.sqlite").string(), &err);
  ASSERT_TRUE(h) << err;
  int64_t n = -1;
  ASSERT_TRUE(h->passes_since_change("t", "A", 10, &n, &err));
  EXPECT_EQ(n, 0);
  for (int i = 0; i < 12; ++i) ASSERT_TRUE(h->add(row("passed", "A"), &err)) << err;
  ASSERT_TRUE(h->passes_since_change("t", "A", 10, &n, &err));
  EXPECT_EQ(n, 10);  // only the latest psi runs
  ASSERT_TRUE(h->add(row("failed", "A"), &err));
  ASSERT_TRUE(h->passes_since_change("t", "A", 10, &n, &err));
  EXPECT_EQ(n, 9);
  ASSERT_TRUE(h->passes_since_change("t", "B", 10, &n, &err));
  EXPECT_EQ(n, 0);  // another version of the POUs: no history
  ASSERT_TRUE(h->add(row("passed", "B"), &err));
  ASSERT_TRUE(h->passes_since_change("t", "B", 10, &n, &err));
  EXPECT_EQ(n, 1);  // the runs of version A before it do not count
  ASSERT_TRUE(h->passes_since_change("other", "B", 10, &n, &err));
  EXPECT_EQ(n, 0);
  std::vector<HistoryRow> rows;
  ASSERT_TRUE(h->list("t", 3, &rows, &err));
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].pou_hash, "B");  // newest first
  EXPECT_EQ(rows[1].verdict, "failed");
  EXPECT_FALSE(rows[0].mci.has_value());
}

TEST_F(ScriptHistory, ConcurrentWritersLoseNothing) {
  const std::string path = (dir_ / "h.sqlite").string();
  std::string err;
  ASSERT_TRUE(History::open(path, &err)) << err;
  auto writer = [&](int k) {
    std::string e;
    auto h = History::open(path, &e);
    ASSERT_TRUE(h) << e;
    for (int i = 0; i < 50; ++i) {
      HistoryRow r = row(i % 2 ? "passed" : "failed", "A");
      r.test = "w" + std::to_string(k);
      r.mci = 0.5;
      ASSERT_TRUE(h->add(r, &e)) << e;
    }
  };
  std::thread a(writer, 1), b(writer, 2), c(writer, 3);
  a.join();
  b.join();
  c.join();
  auto h = History::open(path, &err);
  std::vector<HistoryRow> rows;
  ASSERT_TRUE(h->list("", 0, &rows, &err)) << err;
  EXPECT_EQ(rows.size(), 150u);
  ASSERT_TRUE(h->list("w2", 0, &rows, &err));
  EXPECT_EQ(rows.size(), 50u);
  EXPECT_EQ(rows[0].mci, 0.5);
}

TEST_F(ScriptHistory, NotAHistory) {
  const std::string path = (dir_ / "x.sqlite").string();
  std::ofstream(path) << "this is not a database, just text that is long enough to be looked at";
  std::string err;
  EXPECT_FALSE(History::open(path, &err));
  EXPECT_EQ(err.rfind(path + ": ", 0), 0u) << err;
  EXPECT_FALSE(History::open(dir_.string(), &err));
  EXPECT_EQ(err, dir_.string() + ": is a directory (the history is a file)");
}

TEST(ScriptPous, HashFollowsOnlyTheInvolvedPous) {
  auto hash = [](const std::string& text, const std::vector<std::string>& vars, std::vector<std::string>* names) {
    st::CompileOptions opt;
    opt.warnings = false;
    auto b = st::build_sources({{"p.st", text}}, opt);
    EXPECT_TRUE(b->ok()) << b->diags.render_all();
    return involved_pous_hash(*b, vars, names);
  };
  const std::string cfg =
      "CONFIGURATION C VAR_GLOBAL g : BOOL; h : BOOL; END_VAR RESOURCE R ON PLC TASK T (INTERVAL := T#10ms, PRIORITY := 1);\n"
      "PROGRAM Main WITH T : A; PROGRAM Other WITH T : B; END_RESOURCE END_CONFIGURATION\n";
  auto prog = [&](const std::string& helper_body, const std::string& b_body) {
    return "FUNCTION Helper : INT VAR_INPUT x : INT; END_VAR Helper := " + helper_body + "; END_FUNCTION\n"
           "PROGRAM A VAR n : INT; END_VAR n := Helper(n); g := n > 3; END_PROGRAM\n"
           "PROGRAM B VAR k : INT; END_VAR k := k + " + b_body + "; h := k > 5; END_PROGRAM\n" + cfg;
  };
  std::vector<std::string> names;
  std::string base = hash(prog("x + 1", "1"), {"g"}, &names);
  EXPECT_EQ(names, (std::vector<std::string>{"A", "HELPER"}));
  EXPECT_EQ(hash(prog("x + 1", "2"), {"g"}, &names), base);      // B is not involved
  EXPECT_NE(hash(prog("x + 2", "1"), {"g"}, &names), base);      // a FUNCTION that A calls
  EXPECT_NE(hash(prog("x + 1", "1"), {"Other.k"}, &names), base);
  EXPECT_EQ(names, (std::vector<std::string>{"B"}));
}

}  // namespace
}  // namespace plcfi::script

// The shared real-time scan loop: each way it ends (limit, stop signal, lost device, trap),
// pacing statistics, and the stop signals' install/restore contract.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <thread>

#include "engine.hpp"
#include "runtime/realtime.hpp"
#include "runtime/runtime.hpp"
#include "../../support/fake_backend.hpp"

namespace plcfi::rt {
namespace {

const char* kProgram = R"(
PROGRAM P
VAR
  in0 AT %IX0.0 : BOOL;
  out0 AT %QX0.0 : BOOL;
  n : DINT;
  d : DINT := 1;
  trapAt : DINT := -1;
END_VAR
n := n + 1;
out0 := in0;
IF n = trapAt THEN d := 0; END_IF;
n := n + 1 / d - 1;
END_PROGRAM
)";

class ScanLoopTest : public ::testing::Test {
 protected:
  void SetUp() override {
    b_ = st::build_sources({{"loop.st", kProgram}}, st::CompileOptions{});
    ASSERT_TRUE(b_->ok()) << b_->diags.render_all();
    std::string err;
    ASSERT_TRUE(sched_.single_program(*b_->app, "P", 1'000'000, &err)) << err;
    rt_ = std::make_unique<Runtime>(*b_->app, sched_, &io_);
    rt_->cold_restart(1);
  }
  int64_t var(const char* path) {
    std::string err;
    auto h = st::resolve(*b_->app, path, &err);
    EXPECT_TRUE(h) << err;
    return h ? st::read_int(rt_->machine(), *h) : -1;
  }

  std::unique_ptr<st::Build> b_;
  Schedule sched_;
  testing_support::FakeBackend io_{1, 1};
  std::unique_ptr<Runtime> rt_;
};

TEST_F(ScanLoopTest, EndsAfterTheCyclesAsked) {
  ScanLoop loop(*rt_, false, nullptr);
  EXPECT_EQ(loop.run(7, 0), LoopEnd::Done);
  EXPECT_EQ(loop.end_reason(), "done");
  EXPECT_EQ(loop.scans(), 7u);
  EXPECT_EQ(var("P.n"), 7);
  EXPECT_EQ(io_.writes, 7);
  EXPECT_TRUE(loop.figures().empty()) << "an unpaced loop has no real-time figures";
}

TEST_F(ScanLoopTest, ALostDeviceEndsItBeforeTheNextScan) {
  int asked = 0;
  ScanLoop loop(*rt_, false, nullptr, [&asked] { return ++asked > 3 ? std::string("plc1 (10.0.0.9:502): timeout") : std::string(); });
  EXPECT_EQ(loop.run(100, 0), LoopEnd::CommunicationLost);
  EXPECT_EQ(loop.end_reason(), "communication lost: plc1 (10.0.0.9:502): timeout");
  EXPECT_EQ(loop.scans(), 3u);
}

TEST_F(ScanLoopTest, ATrapEndsItWithTheLocation) {
  std::string err;
  ASSERT_TRUE(st::write_text(rt_->machine(), *st::resolve(*b_->app, "P.trapAt", &err), "4", &err)) << err;
  ScanLoop loop(*rt_, false, nullptr);
  EXPECT_EQ(loop.run(100, 0), LoopEnd::Trapped);
  EXPECT_EQ(loop.scans(), 4u);
  EXPECT_NE(loop.end_reason().find("trap: "), std::string::npos) << loop.end_reason();
  EXPECT_NE(loop.end_reason().find("loop.st:13"), std::string::npos) << loop.end_reason();
}

TEST_F(ScanLoopTest, AStopSignalEndsItAndNamesTheSignal) {
  StopSignals signals;
  ScanLoop loop(*rt_, false, &signals);
  EXPECT_EQ(loop.check_stop(), LoopEnd::None);
  ASSERT_EQ(std::raise(SIGTERM), 0);  // handled: the process goes on
  EXPECT_TRUE(signals.requested());
  EXPECT_EQ(signals.name(), "SIGTERM");
  EXPECT_EQ(loop.run(100, 0), LoopEnd::Signal);
  EXPECT_EQ(loop.end_reason(), "SIGTERM");
  EXPECT_EQ(loop.scans(), 0u);
}

void marker_handler(int) {}

TEST(StopSignals, PutsThePreviousHandlersBack) {
  struct sigaction mine{}, old{}, now{};
  mine.sa_handler = marker_handler;
  sigemptyset(&mine.sa_mask);
  ASSERT_EQ(sigaction(SIGINT, &mine, &old), 0);
  {
    StopSignals s;
    EXPECT_FALSE(s.requested()) << "a new instance starts without a request";
    sigaction(SIGINT, nullptr, &now);
    EXPECT_NE(now.sa_handler, marker_handler);
    sigaction(SIGPIPE, nullptr, &now);
    EXPECT_EQ(now.sa_handler, SIG_IGN);
  }
  sigaction(SIGINT, nullptr, &now);
  EXPECT_EQ(now.sa_handler, marker_handler);
  sigaction(SIGINT, &old, nullptr);
}

TEST_F(ScanLoopTest, APacedLoopReportsItsFigures) {
  ScanLoop loop(*rt_, true, nullptr);
  EXPECT_EQ(loop.run(5, 0), LoopEnd::Done);
  EXPECT_EQ(loop.pacer().wake_latency().count(), 5u);
  EXPECT_EQ(loop.pacer().exec_time().count(), 5u);
  auto f = loop.figures();
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(f[0].rfind("wake latency   min ", 0), 0u) << f[0];
  EXPECT_EQ(f[1].rfind("execution      min ", 0), 0u) << f[1];
  EXPECT_NE(f[2].find(" of 5 cycles of 1 ms"), std::string::npos) << f[2];
}

TEST_F(ScanLoopTest, AfterAnOverrunTheScanClockFollowsTheRealClock) {
  // Every exchange takes 3 ms at a 1 ms cycle: each scan overruns, the deadlines in
  // between are skipped, and the program's clock (its timers) moves on with real time
  // instead of lagging one tick per scan behind it.
  io_.on_read = [](uint8_t*, int64_t) { std::this_thread::sleep_for(std::chrono::milliseconds(3)); };
  ScanLoop loop(*rt_, true, nullptr);
  EXPECT_EQ(loop.run(6, 0), LoopEnd::Done);
  EXPECT_GE(loop.pacer().overruns(), 4u);
  EXPECT_GE(rt_->now(), 6 * 3'000'000) << "the clock lags the real time the scans took";
  EXPECT_GT(rt_->scan_count(), 6u) << "skipped ticks count as cycles that passed";
}

TEST_F(ScanLoopTest, ADurationOnTheRealClockEndsIt) {
  ScanLoop loop(*rt_, true, nullptr);
  EXPECT_EQ(loop.run(0, 20'000'000), LoopEnd::Done);  // 20 ms at a 1 ms cycle
  // Paced: no more scans than cycles fit (plus the one under way); a loaded machine may
  // make fewer.
  EXPECT_GE(loop.scans(), 1u);
  EXPECT_LE(loop.scans(), 21u);
}

}  // namespace
}  // namespace plcfi::rt

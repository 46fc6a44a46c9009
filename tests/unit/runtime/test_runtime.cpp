// Scan runtime: order of the scan, I/O layers and overlays, safe state after a trap,
// task scheduling with several intervals, cold and warm restarts, real-time statistics.
#include <gtest/gtest.h>

#include "engine.hpp"
#include "runtime/clock.hpp"
#include "runtime/runtime.hpp"
#include "../../support/fake_backend.hpp"

namespace plcfi::rt {
namespace {

// The shared fake, delivering a scripted byte at %IB0 and logging the scan order.
class FakeBackend {
 public:
  FakeBackend() : io(4, 4) {
    io.record_log = true;
    io.on_read = [this](uint8_t* in, int64_t) { in[0] = input_byte; };
  }
  uint8_t last_out() const { return io.outputs[0]; }

  testing_support::FakeBackend io;
  uint8_t input_byte = 0;
};

class OrderHooks final : public ScanHooks {
 public:
  explicit OrderHooks(FakeBackend* b) : b_(b) {}
  void before_scan(Runtime&) override { b_->io.log += "before "; }
  void after_scan(Runtime&) override { b_->io.log += "after "; }
  void end_of_scan(Runtime&) override { b_->io.log += "end "; }

 private:
  FakeBackend* b_;
};

std::unique_ptr<st::Build> build(const std::string& src) {
  auto b = st::build_sources({{"rt.st", src}}, st::CompileOptions{});
  EXPECT_TRUE(b->ok()) << b->diags.render_all();
  return b;
}

const char* kEcho = R"(
PROGRAM Echo
VAR
  in0 AT %IX0.0 : BOOL;
  in1 AT %IX0.1 : BOOL;
  out0 AT %QX0.0 : BOOL;
  out1 AT %QX0.1 : BOOL;
  count : DINT;
END_VAR
out0 := in0;
out1 := in1;
count := count + 1;
END_PROGRAM
)";

TEST(Runtime, ScanOrderIsReadOverlayHooksTasksWrite) {
  auto b = build(kEcho);
  Schedule s;
  std::string err;
  ASSERT_TRUE(s.single_program(*b->app, "Echo", 10'000'000, &err)) << err;
  FakeBackend fb;
  Runtime r(*b->app, s, &fb.io);
  OrderHooks hooks(&fb);
  r.add_hooks(&hooks);
  r.cold_restart(7);
  EXPECT_EQ(1, fb.io.resets);
  EXPECT_EQ(7u, fb.io.last_seed);
  fb.io.log.clear();
  r.scan();
  r.scan();
  EXPECT_EQ("read@0 before after write end read@10 before after write end ", fb.io.log);
  EXPECT_EQ(10'000'000, fb.io.last_dt);
  EXPECT_EQ(20'000'000, r.now());
}

TEST(Runtime, WithoutOverlayBothLayersAreEqual) {
  auto b = build(kEcho);
  Schedule s;
  std::string err;
  ASSERT_TRUE(s.single_program(*b->app, "", 10'000'000, &err));
  FakeBackend fb;
  Runtime r(*b->app, s, &fb.io);
  r.cold_restart(1);
  fb.input_byte = 0b11;
  r.scan();
  EXPECT_EQ(0b11, r.raw_inputs()[0]);
  EXPECT_EQ(0b11, r.machine().mem()[b->app->image_i.addr]);
  EXPECT_EQ(0b11, fb.last_out());
  EXPECT_EQ(0b11, r.delivered_outputs()[0]);
}

TEST(Runtime, InputOverlayChangesWhatTheProgramSeesNotTheRawLayer) {
  auto b = build(kEcho);
  Schedule s;
  std::string err;
  ASSERT_TRUE(s.single_program(*b->app, "", 10'000'000, &err));
  FakeBackend fb;
  Runtime r(*b->app, s, &fb.io);
  r.cold_restart(1);
  ImageRef ref;
  ASSERT_TRUE(parse_image_ref(*b->app, "%IX0.1", &ref, &err)) << err;
  r.input_overlay().add(std::make_unique<ForceRule>(ref, 0));  // sensor stuck at FALSE
  fb.input_byte = 0b11;
  r.scan();
  EXPECT_EQ(0b11, r.raw_inputs()[0]);                               // as delivered
  EXPECT_EQ(0b01, r.machine().mem()[b->app->image_i.addr]);         // as seen
  EXPECT_EQ(0b01, fb.last_out());                                     // the program echoed what it saw
  r.input_overlay().clear();
  r.scan();
  EXPECT_EQ(0b11, fb.last_out());
}

TEST(Runtime, OutputOverlayChangesWhatThePlantReceivesNotTheProgramVariable) {
  auto b = build(kEcho);
  Schedule s;
  std::string err;
  ASSERT_TRUE(s.single_program(*b->app, "", 10'000'000, &err));
  FakeBackend fb;
  Runtime r(*b->app, s, &fb.io);
  r.cold_restart(1);
  ImageRef ref;
  ASSERT_TRUE(parse_image_ref(*b->app, "%QX0.0", &ref, &err)) << err;
  r.output_overlay().add(std::make_unique<ForceRule>(ref, 0));  // the valve never gets the command
  fb.input_byte = 0b01;
  r.scan();
  auto out0 = st::resolve(*b->app, "Echo.out0", &err);
  ASSERT_TRUE(out0) << err;
  EXPECT_TRUE(st::read_bool(r.machine(), *out0));  // the program wrote TRUE
  EXPECT_EQ(0, fb.last_out() & 1);                    // the plant got FALSE
}

TEST(Runtime, ImageRefByAddressTakesTheDeclaredVariablesType) {
  auto b = build(R"(
PROGRAM P
VAR
  pressure AT %IW2 : INT;
  raw AT %IW4 : WORD;
  y AT %QW0 : INT;
END_VAR
y := pressure;
END_PROGRAM
)");
  ImageRef ref;
  std::string err;
  ASSERT_TRUE(parse_image_ref(*b->app, "%IW2", &ref, &err)) << err;
  EXPECT_EQ(ref.type->name, "INT");  // as the program declares it: signed, clamps at -32768..32767
  uint8_t area[8] = {};
  ref.set(area, -5);
  EXPECT_EQ(ref.get(area), -5);
  ASSERT_TRUE(parse_image_ref(*b->app, "%IW4", &ref, &err)) << err;
  EXPECT_EQ(ref.type->name, "WORD");
  ASSERT_TRUE(parse_image_ref(*b->app, "%IW6", &ref, &err)) << err;  // nothing declared there: what the address names
  EXPECT_EQ(ref.type->name, "WORD");
}

TEST(Runtime, ImageRefRejectsAddressesOutsideTheIoAreas) {
  auto b = build(kEcho);
  ImageRef ref;
  std::string err;
  EXPECT_FALSE(parse_image_ref(*b->app, "%MX0.0", &ref, &err));
  EXPECT_NE(std::string::npos, err.find("%MX0.0"));
  EXPECT_FALSE(parse_image_ref(*b->app, "%IX0.9", &ref, &err));
  EXPECT_TRUE(parse_image_ref(*b->app, "%QW2", &ref, &err));
  EXPECT_EQ('Q', ref.area);
  EXPECT_EQ(4u, ref.offset);
  EXPECT_EQ(2, ref.size);
}

TEST(Runtime, TrapStopsTheProgramAndWritesTheSafeState) {
  auto b = build(R"(
PROGRAM P
VAR
  valve AT %QX0.0 : BOOL;
  n : INT;
  d : INT;
END_VAR
valve := TRUE;
n := n + 1;
IF n = 3 THEN
  n := 10 / d;  (* division by zero in the third scan *)
END_IF;
END_PROGRAM
)");
  Schedule s;
  std::string err;
  ASSERT_TRUE(s.single_program(*b->app, "", 10'000'000, &err));
  FakeBackend fb;
  Runtime r(*b->app, s, &fb.io);
  r.cold_restart(1);
  EXPECT_EQ(ScanStatus::Ok, r.scan());
  EXPECT_EQ(1, fb.last_out() & 1);
  EXPECT_EQ(ScanStatus::Ok, r.scan());
  EXPECT_EQ(ScanStatus::Trapped, r.scan());
  EXPECT_TRUE(r.stopped());
  EXPECT_EQ(0, fb.last_out() & 1) << "outputs must be off after the trap";
  EXPECT_NE(std::string::npos, r.stop_reason().find("rt.st:11:")) << r.stop_reason();
  EXPECT_NE(std::string::npos, r.stop_reason().find("division by zero")) << r.stop_reason();
  EXPECT_EQ(ScanStatus::Stopped, r.scan());
  EXPECT_EQ(0, fb.last_out() & 1);
  // A restart brings the program back.
  r.cold_restart(1);
  EXPECT_EQ(ScanStatus::Ok, r.scan());
  EXPECT_EQ(1, fb.last_out() & 1);
}

TEST(Runtime, AnActuatorFaultDoesNotOverrideTheSafeStateAfterATrap) {
  auto b = build(R"(
PROGRAM P
VAR
  valve AT %QX0.0 : BOOL;
  n : INT;
  d : INT;
END_VAR
n := n + 1;
IF n = 2 THEN
  n := 10 / d;
END_IF;
END_PROGRAM
)");
  Schedule s;
  std::string err;
  ASSERT_TRUE(s.single_program(*b->app, "", 10'000'000, &err));
  FakeBackend fb;
  Runtime r(*b->app, s, &fb.io);
  r.cold_restart(1);
  ImageRef ref;
  ASSERT_TRUE(parse_image_ref(*b->app, "%QX0.0", &ref, &err)) << err;
  r.output_overlay().add(std::make_unique<ForceRule>(ref, 1));  // the valve stuck on
  EXPECT_EQ(ScanStatus::Ok, r.scan());
  EXPECT_EQ(1, fb.last_out() & 1);  // the fault acts while the program runs
  EXPECT_EQ(ScanStatus::Trapped, r.scan());
  EXPECT_EQ(0, fb.last_out() & 1) << "the safe state, not the injected fault, after a trap";
  EXPECT_EQ(ScanStatus::Stopped, r.scan());
  EXPECT_EQ(0, fb.last_out() & 1);
}

TEST(Runtime, TasksWithSeveralIntervalsRunAtTheirTicksInPriorityOrder) {
  auto b = build(R"(
VAR_GLOBAL
  trace : ARRAY[0..63] OF INT;
  n : INT;
END_VAR
PROGRAM Fast
VAR_EXTERNAL trace : ARRAY[0..63] OF INT; n : INT; END_VAR
IF n < 64 THEN trace[n] := 1; n := n + 1; END_IF;
END_PROGRAM
PROGRAM Slow
VAR_EXTERNAL trace : ARRAY[0..63] OF INT; n : INT; END_VAR
IF n < 64 THEN trace[n] := 2; n := n + 1; END_IF;
END_PROGRAM
CONFIGURATION Cell
  RESOURCE R ON PLC
    TASK TFast (INTERVAL := T#20ms, PRIORITY := 2);
    TASK TSlow (INTERVAL := T#30ms, PRIORITY := 1);
    PROGRAM F WITH TFast : Fast;
    PROGRAM S WITH TSlow : Slow;
  END_RESOURCE
END_CONFIGURATION
)");
  Schedule s;
  std::string err;
  ASSERT_TRUE(s.from_configuration(*b->app, &err)) << err;
  EXPECT_EQ(10'000'000, s.tick_ns()) << "base tick = gcd(20ms, 30ms)";
  Runtime r(*b->app, s, nullptr);
  r.cold_restart(0);
  for (int i = 0; i < 7; ++i) r.scan();  // ticks 0..6 = 0..60 ms
  auto n = st::resolve(*b->app, "n", &err);
  ASSERT_TRUE(n) << err;
  // t=0: Slow (prio 1) then Fast; t=20: Fast; t=30: Slow; t=40: Fast; t=60: Slow then Fast.
  std::vector<int> expected{2, 1, 1, 2, 1, 2, 1};
  ASSERT_EQ(static_cast<int64_t>(expected.size()), st::read_int(r.machine(), *n));
  for (size_t i = 0; i < expected.size(); ++i) {
    auto h = st::resolve(*b->app, "trace[" + std::to_string(i) + "]", &err);
    ASSERT_TRUE(h) << err;
    EXPECT_EQ(expected[i], st::read_int(r.machine(), *h)) << "entry " << i;
  }
}

TEST(Runtime, ColdRestartResetsEverythingWarmRestartKeepsRetain) {
  auto b = build(R"(
PROGRAM P
VAR RETAIN kept : DINT; END_VAR
VAR lost : DINT := 5; END_VAR
kept := kept + 1;
lost := lost + 1;
END_PROGRAM
)");
  Schedule s;
  std::string err;
  ASSERT_TRUE(s.single_program(*b->app, "", 10'000'000, &err));
  Runtime r(*b->app, s, nullptr);
  r.cold_restart(0);
  for (int i = 0; i < 3; ++i) r.scan();
  auto kept = st::resolve(*b->app, "P.kept", &err);
  auto lost = st::resolve(*b->app, "P.lost", &err);
  ASSERT_TRUE(kept && lost);
  EXPECT_EQ(3, st::read_int(r.machine(), *kept));
  EXPECT_EQ(8, st::read_int(r.machine(), *lost));
  r.warm_restart(0);
  EXPECT_EQ(3, st::read_int(r.machine(), *kept));
  EXPECT_EQ(5, st::read_int(r.machine(), *lost));
  EXPECT_EQ(0, r.now());
  r.cold_restart(0);
  EXPECT_EQ(0, st::read_int(r.machine(), *kept));
}

TEST(Runtime, DurationsParseLikeIecLiterals) {
  int64_t ns = 0;
  std::string err;
  ASSERT_TRUE(parse_duration("10ms", &ns, &err));
  EXPECT_EQ(10'000'000, ns);
  ASSERT_TRUE(parse_duration("1h30m", &ns, &err));
  EXPECT_EQ(5'400'000'000'000, ns);
  ASSERT_TRUE(parse_duration("T#1.5s", &ns, &err));
  EXPECT_EQ(1'500'000'000, ns);
  EXPECT_FALSE(parse_duration("10 parsecs", &ns, &err));
  EXPECT_FALSE(parse_duration("", &ns, &err));
  // Found by fuzzing the fault models (delayed(.s) threw std::invalid_argument from stod).
  EXPECT_FALSE(parse_duration(".s", &ns, &err));
  EXPECT_EQ(err, "'.s' is not a duration: unexpected '.' (expected a number)");
  EXPECT_FALSE(parse_duration("1.2.3s", &ns, &err));
  EXPECT_FALSE(parse_duration(std::string(400, '9') + "s", &ns, &err));
  EXPECT_FALSE(parse_duration("100000d100000d", &ns, &err));
  EXPECT_FALSE(parse_duration("5x", &ns, &err));
  EXPECT_EQ(err, "'5x' is not a duration: unknown duration unit 'x' (use d, h, m, s, ms, us or ns)");
  // Exact decimal arithmetic (no double): 8.2 ms is 8,200,000 ns, not 8,199,999.
  ASSERT_TRUE(parse_duration("8.2ms", &ns, &err));
  EXPECT_EQ(8'200'000, ns);
  EXPECT_FALSE(parse_duration("1.2.3ms", &ns, &err));
}

TEST(LatencyStats, PercentilesFromTheHistogram) {
  LatencyStats s;
  for (int i = 1; i <= 100; ++i) s.add(i * 1000);  // 1..100 us
  EXPECT_EQ(100u, s.count());
  EXPECT_EQ(1000, s.min());
  EXPECT_EQ(100'000, s.max());
  EXPECT_DOUBLE_EQ(50'500.0, s.avg());
  EXPECT_EQ(100'000, s.percentile(0.99));
  EXPECT_EQ(52'000, s.percentile(0.5));  // the 51st sample lies in the bucket [51us, 52us)
}

}  // namespace
}  // namespace plcfi::rt

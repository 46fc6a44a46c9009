// The stamping programs on the stamping plant model: production without alarms, each
// class-1 alarm when its sensor is broken by hand (an input overlay), the missing
// supervision of the reference stroke in stamping.st and its fix, and a VCD trace read back.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "engine.hpp"
#include "io/sim/sim_backend.hpp"
#include "monitor/edtl.hpp"
#include "monitor/trace_reader.hpp"
#include "plant_model/plant.hpp"
#include "report/trace.hpp"
#include "runtime/runtime.hpp"

namespace plcfi {
namespace {

std::string program_path(const std::string& name) {
  return (std::filesystem::path(PLCFI_NEGATIVE_DIR).parent_path().parent_path() / "st_programs" / "stamping" / name).string();
}

struct Cell {
  std::unique_ptr<st::Build> build;
  std::unique_ptr<io::SimBackend> backend;
  std::unique_ptr<rt::Runtime> runtime;

  explicit Cell(const std::string& program, uint64_t seed = 1, const st::GeneratedSources& late = {}) {
    build = st::build_files({program_path(program)}, st::CompileOptions{}, late);
    EXPECT_TRUE(build->ok()) << build->diags.render_all();
    std::string err;
    auto plant = plant::make_builtin_plant("stamping", "", &err);
    EXPECT_TRUE(plant) << err;
    backend = io::SimBackend::create(*build->app, std::move(plant), &err);
    EXPECT_TRUE(backend) << err;
    rt::Schedule s;
    EXPECT_TRUE(s.from_configuration(*build->app, &err)) << err;
    runtime = std::make_unique<rt::Runtime>(*build->app, s, backend.get());
    runtime->cold_restart(seed);
  }
  void run_for(double seconds) {
    int64_t end = runtime->now() + static_cast<int64_t>(seconds * 1e9);
    while (runtime->now() < end) runtime->scan();
  }
  // Runs until cond() or the time limit; returns the time (s) when cond became true, or -1.
  template <class F>
  double run_until(double limit_s, F cond) {
    int64_t end = runtime->now() + static_cast<int64_t>(limit_s * 1e9);
    while (runtime->now() < end) {
      runtime->scan();
      if (cond()) return static_cast<double>(runtime->now()) * 1e-9;
    }
    return -1;
  }
  bool flag(const std::string& path) {
    std::string err;
    auto h = st::resolve(*build->app, path, &err);
    EXPECT_TRUE(h) << err;
    return h && st::read_bool(runtime->machine(), *h);
  }
  int64_t value(const std::string& path) {
    std::string err;
    auto h = st::resolve(*build->app, path, &err);
    EXPECT_TRUE(h) << err;
    return h ? st::read_int(runtime->machine(), *h) : -1;
  }
  double stat(const std::string& name) {
    for (const auto& [k, v] : backend->plant().stats())
      if (k == name) return v;
    return -1;
  }
  void force(const std::string& address, int64_t value) {
    rt::ImageRef ref;
    std::string err;
    ASSERT_TRUE(rt::parse_image_ref(*build->app, address, &ref, &err)) << err;
    runtime->input_overlay().add(std::make_unique<rt::ForceRule>(ref, value));
  }
  bool any_alarm() {
    for (const char* a : {"gSliderError", "gStampCylError", "gStampStop", "gHandoverWarning", "gPressureWarning"})
      if (flag(a)) return true;
    return false;
  }
  bool outputs_off() {
    const uint8_t* q = runtime->delivered_outputs();
    return (q[0] & 0b11) == 0 && q[4] == 0 && q[5] == 0;  // valves off, pressure setpoint 0
  }
};

class BothPrograms : public ::testing::TestWithParam<const char*> {};

TEST_P(BothPrograms, TenMinutesOfProductionWithoutAlarm) {
  Cell c(GetParam());
  bool alarm = false;
  for (int i = 0; i < 60'000; ++i) {  // 10 min at 10 ms
    c.runtime->scan();
    alarm = alarm || c.any_alarm();
  }
  EXPECT_FALSE(alarm);
  EXPECT_FALSE(c.runtime->stopped()) << c.runtime->stop_reason();
  EXPECT_GE(c.stat("workpieces_stamped"), 100);
  EXPECT_EQ(0, c.stat("workpieces_defective"));
  EXPECT_EQ(0, c.stat("collisions"));
}

// Breaking a sensor in automatic mode raises its class-1 alarm, stops the module and
// switches the valves off.
struct SensorCase {
  const char* address;
  int64_t value;
  const char* alarm;
};

TEST_P(BothPrograms, EachBrokenSensorRaisesItsClassOneAlarm) {
  const SensorCase cases[] = {
      {"%IX0.1", 0, "gSliderError"},    // PosStamp never switches
      {"%IX0.4", 0, "gStampCylError"},  // StampLowered never switches
      {"%IW2", 0, "gStampCylError"},    // no pressure
      {"%IX0.3", 0, "gStampCylError"},  // StampUp lost
      {"%IX0.0", 0, "gSliderError"},    // PosCrane lost
  };
  for (const auto& sc : cases) {
    SCOPED_TRACE(sc.address);
    Cell c(GetParam());
    // Initialization is over and the first workpieces are being stamped.
    double ready = c.run_until(20, [&] { return c.stat("workpieces_stamped") >= 1; });
    ASSERT_GT(ready, 0) << "no workpiece stamped before the fault";
    c.force(sc.address, sc.value);
    double raised = c.run_until(20, [&] { return c.flag(sc.alarm); });
    ASSERT_GT(raised, 0) << sc.alarm << " not raised within 20 s";
    c.run_for(0.05);
    EXPECT_TRUE(c.flag("gStampStop"));
    EXPECT_TRUE(c.outputs_off());
  }
}

INSTANTIATE_TEST_SUITE_P(Stamping, BothPrograms, ::testing::Values("stamping.st", "stamping_fixed.st"));

// The reference stroke of the initialization run: StampLowered broken from the start.
TEST(StampingPlant, MissingSupervisionOfTheReferenceStrokeInStampingSt) {
  Cell c("stamping.st");
  c.force("%IX0.4", 0);
  double raised = c.run_until(30, [&] { return c.any_alarm(); });
  EXPECT_LT(raised, 0) << "stamping.st is expected to raise no alarm (the published defect)";
  std::string err;
  auto step = st::resolve(*c.build->app, "Main.step", &err);
  ASSERT_TRUE(step) << err;
  EXPECT_EQ("InitRefLower", st::format(c.runtime->machine(), *step)) << "the module hangs in the reference stroke";
}

TEST(StampingPlant, FixedProgramSupervisesTheReferenceStroke) {
  Cell c("stamping_fixed.st");
  c.force("%IX0.4", 0);
  double raised = c.run_until(30, [&] { return c.flag("gStampCylError"); });
  ASSERT_GT(raised, 0);
  EXPECT_TRUE(c.flag("gStampStop"));
  c.run_for(0.05);
  EXPECT_TRUE(c.outputs_off());
}

TEST(StampingPlant, VcdTraceReadsBack) {
  Cell c("stamping.st");
  std::string err;
  std::vector<st::VarHandle> vars;
  for (const char* p : {"Filled", "StampPressure", "Main.step"}) {
    auto h = st::resolve(*c.build->app, p, &err);
    ASSERT_TRUE(h) << err;
    vars.push_back(*h);
  }
  auto path = (std::filesystem::temp_directory_path() / ("plcfi_test_trace_" + std::to_string(::getpid()) + ".vcd")).string();
  auto vcd = report::open_vcd(path, vars, &err);
  ASSERT_TRUE(vcd) << err;
  int rises = 0;
  bool prev = false;
  int64_t max_pressure = 0;
  for (int i = 0; i < 3000; ++i) {  // 30 s
    c.runtime->scan();
    vcd->sample(c.runtime->now(), c.runtime->machine());
    bool f = st::read_bool(c.runtime->machine(), vars[0]);
    rises += f && !prev;
    prev = f;
    max_pressure = std::max(max_pressure, st::read_int(c.runtime->machine(), vars[1]));
  }
  ASSERT_TRUE(vcd->close(&err)) << err;
  auto reader = monitor::TraceReader::open(path, 0, &err);
  ASSERT_TRUE(reader) << err;
  ASSERT_EQ(3u, reader->columns().size());
  EXPECT_EQ("Filled", reader->columns()[0].name);
  EXPECT_EQ(monitor::TraceColumn::Kind::Bool, reader->columns()[0].kind);
  EXPECT_EQ("Main.step", reader->columns()[2].name);
  int vrises = 0;
  bool vprev = false;
  int64_t vmax = 0, t = 0, last_t = -1;
  std::vector<double> v;
  while (reader->next(&t, &v, &err)) {
    EXPECT_GT(t, last_t) << "time stamps increase";
    last_t = t;
    bool f = v[0] != 0;
    vrises += f && !vprev;
    vprev = f;
    vmax = std::max<int64_t>(vmax, static_cast<int64_t>(v[1]));
  }
  EXPECT_TRUE(err.empty()) << err;
  EXPECT_GT(rises, 0);
  EXPECT_EQ(rises, vrises);
  EXPECT_EQ(max_pressure, vmax);
  std::filesystem::remove(path);
}

// Online (a hook in the scan) and offline (on the CSV trace of the same run), one
// requirement gives one verdict.
class MonitorAndTrace final : public rt::ScanHooks {
 public:
  MonitorAndTrace(monitor::MonitorSet* set, report::TraceWriter* csv) : set_(set), csv_(csv) {}
  void end_of_scan(rt::Runtime& r) override {
    set_->step(r.machine(), r.scan_count(), r.now());
    csv_->sample(r.now(), r.machine());
  }

 private:
  monitor::MonitorSet* set_;
  report::TraceWriter* csv_;
};

TEST(StampingPlant, RequirementsGiveTheSameVerdictOnlineAndOffline) {
  auto dir = std::filesystem::temp_directory_path();
  auto reqs_path = (dir / ("plcfi_test_reqs_" + std::to_string(::getpid()) + ".yaml")).string();
  auto csv_path = (dir / ("plcfi_test_trace_" + std::to_string(::getpid()) + ".csv")).string();
  {
    std::ofstream f(reqs_path);
    f << "requirements:\n"
         "  - id: EXTEND\n    trigger: \"/Filled\"\n    delay: \"PASSED(T#500ms)\"\n    reaction: \"PosStamp\"\n"
         "  - id: PRESS\n    trigger: \"/StampDown AND PressureSetpoint = 6000\"\n    delay: \"PASSED(T#500ms)\"\n"
         "    reaction: \"StampLowered AND StampPressure >= 5700\"\n"
         "  - id: TOO_FAST\n    trigger: \"/StampDown AND PressureSetpoint = 6000\"\n    delay: \"PASSED(T#100ms)\"\n    reaction: \"StampPressure >= 5700\"\n"
         "  - id: RAISE\n    trigger: \"\\\\StampDown\"\n    invariant: \"NOT StampDown\"\n    delay: \"PASSED(T#300ms)\"\n"
         "    reaction: \"StampUp\"\n"
         "  - id: HOLD\n    trigger: \"/StampLowered\"\n    invariant: \"StampLowered\"\n    final: \"PASSED(T#1s)\"\n"
         "    delay: \"PASSED(T#2s)\"\n    reaction: \"NOT StampLowered\"\n";
  }
  monitor::RequirementsFile reqs;
  std::string err;
  ASSERT_TRUE(monitor::load_requirements(reqs_path, &reqs, &err)) << err;
  auto mon = monitor::generate_monitors(reqs);
  Cell c("stamping.st", 3, {{mon.name, mon.text}});
  ASSERT_TRUE(c.build->ok()) << c.build->diags.render_all();
  auto set = monitor::MonitorSet::create(*c.build->app, reqs, &err);
  ASSERT_TRUE(set) << err;
  std::vector<st::VarHandle> vars;
  for (const char* p : {"Filled", "PosStamp", "StampDown", "StampLowered", "StampUp", "StampPressure", "PressureSetpoint"}) {
    auto h = st::resolve(*c.build->app, p, &err);
    ASSERT_TRUE(h) << err;
    vars.push_back(*h);
  }
  auto csv = report::open_csv(csv_path, vars, &err);
  ASSERT_TRUE(csv) << err;
  MonitorAndTrace hook(set.get(), csv.get());
  c.runtime->add_hooks(&hook);
  c.run_for(60);
  ASSERT_TRUE(csv->close(&err)) << err;
  auto online = set->verdicts();
  monitor::TraceCheck offline;
  ASSERT_TRUE(monitor::check_trace(reqs, csv_path, 0, &offline, &err)) << err;
  EXPECT_EQ(6000u, offline.states);
  ASSERT_EQ(online.size(), offline.verdicts.size());
  for (size_t i = 0; i < online.size(); ++i) {
    const auto& a = online[i];
    const auto& b = offline.verdicts[i];
    SCOPED_TRACE(a.id);
    EXPECT_GT(a.triggers, 0u);
    EXPECT_EQ(a.violated(), b.violated());
    EXPECT_EQ(a.triggers, b.triggers);
    EXPECT_EQ(a.holds, b.holds);
    EXPECT_EQ(a.violated_instances, b.violated_instances);
    EXPECT_EQ(a.pending, b.pending);
    ASSERT_EQ(a.violations.size(), b.violations.size());
    for (size_t k = 0; k < a.violations.size(); ++k) {
      EXPECT_EQ(a.violations[k].state, b.violations[k].state);
      EXPECT_EQ(a.violations[k].trigger_state, b.violations[k].trigger_state);
      EXPECT_EQ(a.violations[k].cause, b.violations[k].cause);
    }
  }
  // The plant needs about 0.45 s to reach the pressure: TOO_FAST (0.1 s) fails every stroke.
  // (The reference stroke lowers the stamp without a setpoint: hence the setpoint in PRESS.)
  EXPECT_TRUE(online[2].violated());
  EXPECT_FALSE(online[0].violated());
  EXPECT_FALSE(online[1].violated());
  std::filesystem::remove(reqs_path);
  std::filesystem::remove(csv_path);
}

}  // namespace
}  // namespace plcfi

// GPIO backend. GpioConfig.*: the io section's GPIO entries and their errors (any host).
// GpioSim.*: the backend against the kernel's gpio-sim driver, run inside a qemu guest by
// tests/gpio/qemu/run-in-gpio-sim.sh, which creates the chip "plcfi-sim" with 8 lines
// (in0..in3, out0..out3) and names it in PLCFI_SIM_CHIP and its sysfs folder in
// PLCFI_SIM_SYSFS. Inputs are driven by writing pull-up/pull-down to sim_gpioN/pull,
// outputs read back from sim_gpioN/value.
#include <gtest/gtest.h>

#include "../support/temp_files.hpp"

#include <gpiod.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "engine.hpp"
#include "io/gpio/gpio_backend.hpp"
#include "io/io_config.hpp"
#include "runtime/runtime.hpp"

namespace plcfi::io {
namespace {

namespace fs = std::filesystem;

const char* kProgram = R"(
PROGRAM P
VAR
  i0 AT %IX0.0 : BOOL;
  i1 AT %IX0.1 : BOOL;
  i2 AT %IX0.2 : BOOL;
  i3 AT %IX0.3 : BOOL;
  q0 AT %QX0.0 : BOOL;
  q1 AT %QX0.1 : BOOL;
  q2 AT %QX0.2 : BOOL;
  q3 AT %QX0.3 : BOOL;
  w AT %QW2 : INT;
  mode : INT;  (* 0: outputs follow the inputs, 1: all on, 2: a pattern *)
END_VAR
CASE mode OF
  0: q0 := i0; q1 := i1; q2 := i2; q3 := i3;
  1: q0 := TRUE; q1 := TRUE; q2 := TRUE; q3 := TRUE;
  2: q0 := FALSE; q1 := TRUE; q2 := FALSE; q3 := TRUE;
END_CASE
END_PROGRAM
)";

using testing_support::remember_temp;

std::string temp(const std::string& text) {
  static int n = 0;
  fs::path p = fs::temp_directory_path() / ("plcfi_gpio_" + std::to_string(::getpid()) + "_" + std::to_string(n++) + ".yaml");
  std::ofstream(p) << text;
  return remember_temp(p.string());
}

class GpioTest : public ::testing::Test {
 public:
  void SetUp() override {
    b_ = st::build_sources({{"p.st", kProgram}}, st::CompileOptions{});
    ASSERT_TRUE(b_->ok()) << b_->diags.render_all();
    std::string err;
    ASSERT_TRUE(sched_.single_program(*b_->app, "P", 10'000'000, &err)) << err;
  }
  bool load(const std::string& text, IoConfig* cfg, std::string* err) {
    path_ = temp(text);
    return load_io_config(path_, *b_->app, cfg, err);
  }
  // The error of a config that must not load, without the path prefix: "LINE:COL: message".
  std::string error_of(const std::string& text) {
    IoConfig cfg;
    std::string err;
    EXPECT_FALSE(load(text, &cfg, &err));
    EXPECT_EQ(err.rfind(path_ + ":", 0), 0u) << err;
    return err.substr(std::min(err.size(), path_.size() + 1));
  }
  int64_t get(rt::Runtime& r, const char* path) {
    std::string err;
    auto h = st::resolve(*b_->app, path, &err);
    return st::read_int(r.machine(), *h);
  }
  void set(rt::Runtime& r, const char* path, int64_t v) {
    std::string err;
    auto h = st::resolve(*b_->app, path, &err);
    st::write_int(r.machine(), *h, v);
  }

  std::unique_ptr<st::Build> b_;
  rt::Schedule sched_;
  std::string path_;
};

using GpioConfig = GpioTest;

TEST_F(GpioConfig, ParsesChipsLinesAndFlags) {
  IoConfig cfg;
  std::string err;
  ASSERT_TRUE(load("io:\n"
                   "  devices:\n"
                   "    - {name: board, gpio: gpiochip0}\n"
                   "  map:\n"
                   "    - {image: \"%IX0.0\", device: board, lines: [0, 1], bias: pull-up, active_low: true}\n"
                   "    - {image: \"%IX0.2\", device: board, lines: [START, STOP]}\n"
                   "    - {image: \"%QX0.0\", device: board, lines: [4, out1], drive: open-drain}\n"
                   "  safe_state: {\"%QX0.1\": TRUE}\n",
                   &cfg, &err))
      << err;
  ASSERT_EQ(cfg.gpio_devices.size(), 1u);
  EXPECT_EQ(cfg.gpio_devices[0].chip, "gpiochip0");
  ASSERT_EQ(cfg.gpio_points.size(), 3u);
  EXPECT_EQ(cfg.gpio_points[0].lines[1].offset, 1);
  EXPECT_TRUE(cfg.gpio_points[0].active_low);
  EXPECT_EQ(cfg.gpio_points[0].bias, GpioBias::PullUp);
  EXPECT_EQ(cfg.gpio_points[1].lines[0].name, "START");
  EXPECT_EQ(cfg.gpio_points[1].lines[0].offset, -1);
  EXPECT_EQ(cfg.gpio_points[2].drive, GpioDrive::OpenDrain);
  EXPECT_EQ(cfg.gpio_points[2].image.area, 'Q');
  EXPECT_TRUE(cfg.devices.empty());
}

TEST_F(GpioConfig, ErrorsNameLineAndColumn) {
  const std::string head = "io:\n  devices:\n    - {name: board, gpio: gpiochip0}\n  map:\n";
  EXPECT_EQ(error_of(head + "    - {image: \"%IW2\", device: board, lines: [0]}\n"),
            "5:15: GPIO lines map to bits: %IXn.m (inputs) or %QXn.m (outputs)");
  EXPECT_EQ(error_of(head + "    - {image: \"%IX0.0\", device: board, lines: 3}\n"),
            "5:47: lines: expected a list, got '3'");
  EXPECT_EQ(error_of(head + "    - {image: \"%IX0.0\", device: board, lines: [0, 0]}\n"), "5:51: line 0 is listed twice");
  std::string twice = error_of(head + "    - {image: \"%IX0.0\", device: board, lines: [0]}\n    - {image: \"%IX0.1\", device: board, lines: [0]}\n");
  EXPECT_EQ(twice, "6:48: line 0 is already mapped at " + path_ + ":5:7");
  EXPECT_EQ(error_of(head + "    - {image: \"%IX0.0\", device: board, lines: [0], bias: up}\n"),
            "5:58: bias: expected as-is, disabled, pull-up or pull-down, got 'up'");
  EXPECT_EQ(error_of(head + "    - {image: \"%QX0.0\", device: board, lines: [0], bias: pull-up}\n"),
            "5:58: bias applies to inputs (%IX)");
  EXPECT_EQ(error_of(head + "    - {image: \"%IX0.0\", device: board, lines: [0], drive: open-drain}\n"),
            "5:59: drive applies to outputs (%QX)");
  EXPECT_EQ(error_of(head + "    - {image: \"%IX0.0\", device: board, lines: [0], active_low: maybe}\n"),
            "5:64: active_low: expected true or false, got 'maybe'");
  EXPECT_EQ(error_of(head + "    - {image: \"%IX0.0\", device: board, lines: [0], count: 2}\n"),
            "5:52: unknown key 'count' in a GPIO mapping (expected one of: image, device, lines, active_low, bias, drive)");
  std::string overlap = error_of(head + "    - {image: \"%IX0.0\", device: board, lines: [0, 1]}\n    - {image: \"%IX0.1\", device: board, lines: [2]}\n");
  EXPECT_EQ(overlap, "6:15: overlaps the mapping at " + path_ + ":5:7");
  EXPECT_EQ(error_of("io:\n  devices:\n    - {name: board, gpio: gpiochip0, unit: 1}\n  map: []\n"),
            "3:38: unknown key 'unit' in a GPIO device (expected one of: name, gpio)");
  EXPECT_EQ(error_of("io:\n  devices:\n    - {name: board, gpio: gpiochip0}\n    - {name: board, tcp: \"h:1\"}\n  map: []\n"),
            "4:14: device 'board' is defined twice");
}

TEST_F(GpioConfig, MissingChipIsAnErrorNamingDeviceAndChip) {
  IoConfig cfg;
  std::string err;
  ASSERT_TRUE(load("io:\n  devices:\n    - {name: board, gpio: no-such-chip}\n  map:\n"
                   "    - {image: \"%IX0.0\", device: board, lines: [0]}\n",
                   &cfg, &err))
      << err;
  EXPECT_EQ(GpioBackend::open(cfg, &err), nullptr);
  EXPECT_NE(err.find(path_ + ":3:7: device 'board': cannot open GPIO chip 'no-such-chip'"), std::string::npos) << err;
}

// ---- inside the gpio-sim guest ---------------------------------------------------------

class GpioSim : public GpioTest {
 public:
  void SetUp() override {
    const char* chip = std::getenv("PLCFI_SIM_CHIP");
    const char* sysfs = std::getenv("PLCFI_SIM_SYSFS");
    // A failure, not a skip: run by ctest only inside the guest, where this never passes silently.
    if (!chip || !sysfs) FAIL() << "PLCFI_SIM_CHIP/PLCFI_SIM_SYSFS unset: run me with tests/gpio/qemu/run-in-gpio-sim.sh";
    chip_ = chip;
    sysfs_ = sysfs;
    GpioTest::SetUp();
    for (int i = 0; i < 4; ++i) pull(i, false);
  }
  void pull(int line, bool up) {
    std::ofstream f(sysfs_ + "/sim_gpio" + std::to_string(line) + "/pull");
    f << (up ? "pull-up" : "pull-down");
    ASSERT_TRUE(f.good()) << "cannot drive " << sysfs_ << "/sim_gpio" << line << "/pull";
  }
  int value(int line) {
    std::ifstream f(sysfs_ + "/sim_gpio" + std::to_string(line) + "/value");
    int v = -1;
    f >> v;
    return v;
  }
  std::unique_ptr<GpioBackend> open(const std::string& map, std::string* err, const std::string& safe = "") {
    IoConfig cfg;
    EXPECT_TRUE(load("io:\n  devices:\n    - {name: board, gpio: " + chip_ + "}\n  map:\n" + map + safe, &cfg, err)) << *err;
    return GpioBackend::open(cfg, err);
  }
  const std::string kMap =
      "    - {image: \"%IX0.0\", device: board, lines: [in0, in1, in2, in3]}\n"
      "    - {image: \"%QX0.0\", device: board, lines: [out0, out1, out2, out3]}\n";
  std::string chip_, sysfs_;
};

TEST_F(GpioSim, InputsDrivenAndOutputsReadBackThroughTheScan) {
  std::string err;
  auto g = open(kMap, &err);
  ASSERT_TRUE(g) << err;
  rt::Runtime r(*b_->app, sched_, g.get());
  r.cold_restart(1);
  for (int pattern = 0; pattern < 16; ++pattern) {
    for (int i = 0; i < 4; ++i) pull(i, (pattern >> i) & 1);
    r.scan();
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(get(r, ("P.i" + std::to_string(i)).c_str()), (pattern >> i) & 1) << "pattern " << pattern << " in" << i;
      EXPECT_EQ(value(4 + i), (pattern >> i) & 1) << "pattern " << pattern << " out" << i;
    }
  }
}

TEST_F(GpioSim, OneBulkRequestPerDirectionAndEveryLineOfItSet) {
  std::string err;
  auto g = open(kMap, &err);
  ASSERT_TRUE(g) << err;
  auto d = g->describe();
  ASSERT_EQ(d.size(), 2u);
  EXPECT_NE(d[0].find("input lines 0,1,2,3 (one bulk request)"), std::string::npos) << d[0];
  EXPECT_NE(d[1].find("output lines 4,5,6,7 (one bulk request)"), std::string::npos) << d[1];
  // Every line of the request is ours (consumer plcfi), seen from another handle.
  gpiod_chip* other = gpiod_chip_open_lookup(chip_.c_str());
  ASSERT_NE(other, nullptr);
  for (unsigned i = 0; i < 8; ++i) {
    gpiod_line* l = gpiod_chip_get_line(other, i);
    ASSERT_NE(l, nullptr);
    EXPECT_TRUE(gpiod_line_is_used(l)) << i;
    EXPECT_STREQ(gpiod_line_consumer(l), "plcfi") << i;
    EXPECT_EQ(gpiod_line_direction(l), i < 4 ? GPIOD_LINE_DIRECTION_INPUT : GPIOD_LINE_DIRECTION_OUTPUT) << i;
  }
  gpiod_chip_close(other);
  // A pattern whose first line is 0: a single-line set on the bulk would only touch out0.
  rt::Runtime r(*b_->app, sched_, g.get());
  r.cold_restart(1);
  set(r, "P.mode", 2);
  r.scan();
  EXPECT_EQ(value(4), 0);
  EXPECT_EQ(value(5), 1);
  EXPECT_EQ(value(6), 0);
  EXPECT_EQ(value(7), 1);
  set(r, "P.mode", 1);
  r.scan();
  for (int i = 4; i < 8; ++i) EXPECT_EQ(value(i), 1) << i;
}

TEST_F(GpioSim, BiasAndActiveLow) {
  std::string err;
  // Requested with a pull-up, the simulated line reads high without being driven; the
  // pull-down one low; the active-low one inverts what the line carries.
  auto g = open("    - {image: \"%IX0.0\", device: board, lines: [0], bias: pull-up}\n"
                "    - {image: \"%IX0.1\", device: board, lines: [1], bias: pull-down}\n"
                "    - {image: \"%IX0.2\", device: board, lines: [2, 3], active_low: true}\n"
                "    - {image: \"%QX0.0\", device: board, lines: [4], active_low: true}\n",
                &err);
  ASSERT_TRUE(g) << err;
  auto d = g->describe();
  ASSERT_EQ(d.size(), 4u);  // three biases among the inputs: three requests; one output
  EXPECT_NE(d[2].find("input lines 2,3 (one bulk request, active-low 2,3)"), std::string::npos) << d[2];
  rt::Runtime r(*b_->app, sched_, g.get());
  r.cold_restart(1);
  r.scan();
  EXPECT_EQ(value(0), 1);
  EXPECT_EQ(value(1), 0);
  EXPECT_EQ(get(r, "P.i0"), 1);
  EXPECT_EQ(get(r, "P.i1"), 0);
  pull(2, true);
  pull(3, false);
  r.scan();
  EXPECT_EQ(get(r, "P.i2"), 0);
  EXPECT_EQ(get(r, "P.i3"), 1);
  set(r, "P.mode", 1);  // q0 TRUE: the active-low line goes low
  r.scan();
  EXPECT_EQ(value(4), 0);
  set(r, "P.mode", 2);  // q0 FALSE: high
  r.scan();
  EXPECT_EQ(value(4), 1);
}

TEST_F(GpioSim, ActiveLowLinesShareTheBulkRequest) {
  std::string err;
  auto g = open("    - {image: \"%IX0.0\", device: board, lines: [in0, in1]}\n"
                "    - {image: \"%IX0.2\", device: board, lines: [in2, in3], active_low: true}\n"
                "    - {image: \"%QX0.0\", device: board, lines: [out0, out1]}\n"
                "    - {image: \"%QX0.2\", device: board, lines: [out2, out3], active_low: true}\n",
                &err);
  ASSERT_TRUE(g) << err;
  auto d = g->describe();
  ASSERT_EQ(d.size(), 2u);
  EXPECT_NE(d[0].find("input lines 0,1,2,3 (one bulk request, active-low 2,3)"), std::string::npos) << d[0];
  EXPECT_NE(d[1].find("output lines 4,5,6,7 (one bulk request, active-low 6,7)"), std::string::npos) << d[1];
  // Requested in the safe state: all off, so the active-low lines are high.
  EXPECT_EQ(value(4), 0);
  EXPECT_EQ(value(6), 1);
  rt::Runtime r(*b_->app, sched_, g.get());
  r.cold_restart(1);
  for (int i = 0; i < 4; ++i) pull(i, i % 2 == 0);  // in0 1, in1 0, in2 1, in3 0
  r.scan();  // mode 0: q := i
  EXPECT_EQ(get(r, "P.i0"), 1);
  EXPECT_EQ(get(r, "P.i1"), 0);
  EXPECT_EQ(get(r, "P.i2"), 0);  // active-low: a high line is FALSE
  EXPECT_EQ(get(r, "P.i3"), 1);
  EXPECT_EQ(value(4), 1);
  EXPECT_EQ(value(5), 0);
  EXPECT_EQ(value(6), 1);  // q2 FALSE on an active-low line: high
  EXPECT_EQ(value(7), 0);  // q3 TRUE: low
}

TEST_F(GpioSim, OutputsStartAndEndInTheSafeState) {
  std::string err;
  auto g = open(kMap, &err, "  safe_state: {\"%QX0.1\": TRUE}\n");
  ASSERT_TRUE(g) << err;
  // Requested: safe state before the first scan.
  EXPECT_EQ(value(4), 0);
  EXPECT_EQ(value(5), 1);
  IoConfig cfg;
  ASSERT_TRUE(load("io:\n  devices:\n    - {name: board, gpio: " + chip_ + "}\n  map:\n" + kMap +
                   "  safe_state: {\"%QX0.1\": TRUE}\n", &cfg, &err));
  rt::Runtime r(*b_->app, sched_, g.get());
  r.set_safe_state(cfg.safe_state);
  r.cold_restart(1);
  set(r, "P.mode", 2);  // out0 0, out1 1, out2 0, out3 1
  r.scan();
  set(r, "P.mode", 1);
  r.scan();
  for (int i = 4; i < 8; ++i) EXPECT_EQ(value(i), 1) << i;
  r.write_safe_outputs();  // what every way out of a run does
  EXPECT_EQ(value(4), 0);
  EXPECT_EQ(value(5), 1);
  EXPECT_EQ(value(6), 0);
  EXPECT_EQ(value(7), 0);
  g->close();
  // Released: the lines are free again.
  gpiod_chip* other = gpiod_chip_open_lookup(chip_.c_str());
  ASSERT_NE(other, nullptr);
  EXPECT_FALSE(gpiod_line_is_used(gpiod_chip_get_line(other, 4)));
  gpiod_chip_close(other);
}

TEST_F(GpioSim, LineErrorsNameChipAndLine) {
  std::string err;
  EXPECT_EQ(open("    - {image: \"%IX0.0\", device: board, lines: [8]}\n", &err), nullptr);
  EXPECT_NE(err.find(":5:7: board (" + chip_ + " 'plcfi-sim'): line 8 does not exist (the chip has 8 lines, 0..7)"),
            std::string::npos) << err;
  EXPECT_EQ(open("    - {image: \"%IX0.0\", device: board, lines: [in9]}\n", &err), nullptr);
  EXPECT_NE(err.find("no line named 'in9'"), std::string::npos) << err;
  EXPECT_EQ(open("    - {image: \"%IX0.0\", device: board, lines: [in0, 0]}\n", &err), nullptr);
  EXPECT_NE(err.find("line 0 is already mapped"), std::string::npos) << err;
  // A line held by another program: busy, with its consumer named.
  gpiod_chip* other = gpiod_chip_open_lookup(chip_.c_str());
  ASSERT_NE(other, nullptr);
  gpiod_line* l = gpiod_chip_get_line(other, 2);
  ASSERT_EQ(gpiod_line_request_input(l, "other-tool"), 0);
  EXPECT_EQ(open(kMap, &err), nullptr);
  EXPECT_NE(err.find("cannot request input lines 0,1,2,3: Device or resource busy (line 2 is used by 'other-tool')"),
            std::string::npos) << err;
  gpiod_line_release(l);
  gpiod_chip_close(other);
  auto g = open(kMap, &err);
  EXPECT_TRUE(g) << err;
}

}  // namespace
}  // namespace plcfi::io

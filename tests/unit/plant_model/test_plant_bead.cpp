// The bead dispenser's plant model: release timing of the gates, the beam, the hoppers,
// the counters and the parameter file.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "plant_model/bead_dispenser/bead_dispenser.hpp"
#include "plant_model/plant.hpp"

namespace plcfi::plant {
namespace {

// Steps the plant with gate 1 open for `open_ms` from t = 0, then closed until `total_ms`;
// returns the beam sensor after each step.
std::vector<bool> pulse(BeadDispenserPlant& p, int open_ms, int total_ms, int step_ms, int gate = 0) {
  std::vector<bool> beam;
  double act[3] = {0, 0, 0}, sens[3] = {0, 0, 0};
  for (int t = 0; t < total_ms; t += step_ms) {
    act[gate] = t < open_ms ? 1.0 : 0.0;
    p.step(step_ms * 1e-3, act, sens);
    beam.push_back(sens[BeadDispenserPlant::kBeadSensor] > 0.5);
  }
  return beam;
}

// The sample times (end of step, ms) at which the beam was interrupted.
std::vector<int> seen_at(const std::vector<bool>& beam, int step_ms) {
  std::vector<int> out;
  for (size_t i = 0; i < beam.size(); ++i)
    if (beam[i]) out.push_back(static_cast<int>(i + 1) * step_ms);
  return out;
}

TEST(PlantBead, SignalsFollowTheIoMap) {
  BeadDispenserPlant p;
  const auto& s = p.signals();
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[BeadDispenserPlant::kGate1].address, "%QX0.0");
  EXPECT_EQ(s[BeadDispenserPlant::kGate2].address, "%QX0.1");
  EXPECT_EQ(s[BeadDispenserPlant::kBeadSensor].address, "%IX0.0");
  EXPECT_EQ(s[BeadDispenserPlant::kBeadSensor].dir, Direction::FromPlant);
  EXPECT_EQ(s[BeadDispenserPlant::kGate1].dir, Direction::ToPlant);
}

TEST(PlantBead, GateOpenSixtyMsReleasesOneBeadSeenFifteenMs) {
  BeadDispenserPlant p;
  // Released at 40 ms, in the beam from 160 ms to 175 ms: samples at 1 ms steps see it
  // for exactly 15 of them.
  auto beam = pulse(p, 60, 400, 1);
  auto at = seen_at(beam, 1);
  ASSERT_EQ(at.size(), 15u);
  EXPECT_EQ(at.front(), 160);
  EXPECT_EQ(at.back(), 174);
  EXPECT_EQ(p.released(0), 1);
  EXPECT_EQ(p.left_in_hopper(0), 49);
  EXPECT_EQ(p.passed_beam(), 1);
  EXPECT_EQ(p.double_releases(), 0);
}

TEST(PlantBead, TooShortAnOpeningReleasesNothing) {
  BeadDispenserPlant p;
  auto beam = pulse(p, 30, 400, 10);
  EXPECT_TRUE(seen_at(beam, 10).empty());
  EXPECT_EQ(p.released(0), 0);
}

TEST(PlantBead, OneHundredTenMsReleaseASecondBead) {
  BeadDispenserPlant p;
  pulse(p, 100, 500, 10);
  EXPECT_EQ(p.released(0), 1);  // 40..110 ms: one
  BeadDispenserPlant q;
  pulse(q, 110, 500, 10);
  EXPECT_EQ(q.released(0), 2);  // 110 ms: the second
  EXPECT_EQ(q.double_releases(), 1);
  BeadDispenserPlant r;
  pulse(r, 250, 700, 10);
  EXPECT_EQ(r.released(0), 4);  // 40, 110, 180, 250
  EXPECT_EQ(r.passed_beam(), 4);
}

TEST(PlantBead, ReleaseTimeIsExactWithinAStep) {
  // With 20 ms steps a release at 45 ms puts the bead in the beam from 165 to 180 ms:
  // between the samples at 160 and 180, so the scan never sees it, though it passed.
  BeadParams prm;
  prm.release_after = 0.045;
  BeadDispenserPlant p(prm);
  auto beam = pulse(p, 60, 400, 20);
  EXPECT_TRUE(seen_at(beam, 20).empty());
  EXPECT_EQ(p.released(0), 1);
  EXPECT_EQ(p.passed_beam(), 1);
  // The same release sampled every millisecond is seen.
  BeadDispenserPlant q(prm);
  EXPECT_EQ(seen_at(pulse(q, 60, 400, 1), 1).front(), 165);
}

TEST(PlantBead, EmptyHopperReleasesNothingAndGatesAreIndependent) {
  BeadParams prm;
  prm.hopper_beads[0] = 1;
  BeadDispenserPlant p(prm);
  pulse(p, 250, 700, 10);
  EXPECT_EQ(p.released(0), 1);
  EXPECT_EQ(p.left_in_hopper(0), 0);
  pulse(p, 250, 700, 10, 1);
  EXPECT_EQ(p.released(1), 4);
  EXPECT_EQ(p.left_in_hopper(1), 46);
  p.reset(1);
  EXPECT_EQ(p.left_in_hopper(0), 1);
  EXPECT_EQ(p.released(1), 0);
}

TEST(PlantBead, StatsNameTheCounters) {
  BeadDispenserPlant p;
  pulse(p, 110, 500, 10);
  auto s = p.stats();
  ASSERT_EQ(s.size(), 4u);
  EXPECT_EQ(s[0].first, "beads_released_black");
  EXPECT_EQ(s[0].second, 2);
  EXPECT_EQ(s[2].first, "beads_through_beam");
  EXPECT_EQ(s[2].second, 2);
  EXPECT_EQ(s[3].first, "double_releases");
  EXPECT_EQ(s[3].second, 1);
}

class PlantBeadYaml : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (std::filesystem::temp_directory_path() / "plcfi_bead_XXXXXX").string();
    ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& text) {
    const std::string path = (dir_ / ("p" + std::to_string(n_++) + ".yaml")).string();
    std::ofstream(path) << text;
    return path;
  }
  std::filesystem::path dir_;
  int n_ = 0;
};

TEST_F(PlantBeadYaml, ByNameWithAndWithoutFile) {
  std::string err;
  auto plant = make_builtin_plant("bead_dispenser", "", &err);
  ASSERT_TRUE(plant) << err;
  EXPECT_EQ(plant->name(), "bead_dispenser");
  auto f = write("gate:\n  release_after: 0.02\nhoppers:\n  white: 3\n");
  plant = make_builtin_plant("bead_dispenser", f, &err);
  ASSERT_TRUE(plant) << err;
  const auto& prm = static_cast<BeadDispenserPlant&>(*plant).params();
  EXPECT_EQ(prm.release_after, 0.02);
  EXPECT_EQ(prm.release_period, 0.07);
  EXPECT_EQ(prm.hopper_beads[0], 50);
  EXPECT_EQ(prm.hopper_beads[1], 3);
  bool listed = false;
  for (const auto& n : builtin_plant_names()) listed = listed || n == "bead_dispenser";
  EXPECT_TRUE(listed);
}

TEST_F(PlantBeadYaml, TheShippedFileHoldsTheDefaults) {
  BeadParams p;
  std::string err;
  ASSERT_TRUE(load_bead_params(std::string(PLCFI_SOURCE_DIR) + "/plant_model/bead_dispenser/bead_dispenser.yaml", &p, &err))
      << err;
  BeadParams d;
  EXPECT_EQ(p.release_after, d.release_after);
  EXPECT_EQ(p.release_period, d.release_period);
  EXPECT_EQ(p.fall_time, d.fall_time);
  EXPECT_EQ(p.beam_time, d.beam_time);
  EXPECT_EQ(p.hopper_beads[0], d.hopper_beads[0]);
  EXPECT_EQ(p.hopper_beads[1], d.hopper_beads[1]);
}

TEST_F(PlantBeadYaml, ErrorsCarryFileLineColumn) {
  std::string err;
  BeadParams p;
  auto f = write("gate:\n  release_afte: 0.02\n");
  EXPECT_FALSE(load_bead_params(f, &p, &err));
  EXPECT_EQ(err, f + ":2:3: unknown key 'release_afte' in gate (expected one of: release_after, release_period)");
  f = write("fall_time: -1\n");
  EXPECT_FALSE(load_bead_params(f, &p, &err));
  EXPECT_EQ(err, f + ":1:12: fall_time: -1 is outside 0..3600 (seconds)");
  f = write("hoppers:\n  black: lots\n");
  EXPECT_FALSE(load_bead_params(f, &p, &err));
  EXPECT_NE(err.find(f + ":2:10: hoppers.black: expected an integer"), std::string::npos) << err;
  EXPECT_EQ(p.release_after, BeadParams{}.release_after);  // untouched on error
}

}  // namespace
}  // namespace plcfi::plant

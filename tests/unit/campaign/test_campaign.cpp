// Campaign layer: spec validation with file:line:col errors, test-case generation, the
// published result of the stamping campaign, resume from a torn journal, determinism.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include "campaign/driver.hpp"
#include "campaign/generate.hpp"
#include "campaign/journal.hpp"
#include "campaign/spec.hpp"

namespace fs = std::filesystem;
using namespace plcfi;
using namespace plcfi::campaign;

namespace {

const fs::path kRoot = fs::path(PLCFI_SOURCE_DIR);
const fs::path kSpecDir = kRoot / "faults/campaigns/stamping";

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write(const fs::path& p, const std::string& text) {
  std::ofstream out(p);
  out << text;
}

// A private copy of the stamping campaign whose files a test may edit.
class SpecCopy {
 public:
  explicit SpecCopy(const std::string& tag) {
    dir_ = fs::temp_directory_path() / ("plcfi_campaign_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    for (const char* f : {"campaign.yaml", "tsd.yaml", "fmea.csv", "fault_classes.yaml"}) {
      std::string text = read(kSpecDir / f);
      if (std::string(f) == "campaign.yaml")
        text = std::regex_replace(text, std::regex("\\.\\./\\.\\./\\.\\./st_programs"), (kRoot / "st_programs").string());
      write(dir_ / f, text);
    }
  }
  ~SpecCopy() { fs::remove_all(dir_); }
  fs::path path(const std::string& f) const { return dir_ / f; }
  // Replaces the first occurrence of `from` in file f (the test fails if it is absent).
  void edit(const std::string& f, const std::string& from, const std::string& to) {
    std::string text = read(dir_ / f);
    size_t p = text.find(from);
    ASSERT_NE(p, std::string::npos) << from;
    text.replace(p, from.size(), to);
    write(dir_ / f, text);
  }
  std::string load_error() {
    Campaign c;
    std::string err;
    if (!load_campaign(path("campaign.yaml").string(), &c, &err)) return err;
    CampaignBuild cb;
    if (!prepare_campaign(std::move(c), &cb, &err)) return err;
    return "";
  }

 private:
  fs::path dir_;
};

CampaignBuild prepare(const fs::path& campaign, const std::string& program = "") {
  Campaign c;
  std::string err;
  EXPECT_TRUE(load_campaign(campaign.string(), &c, &err)) << err;
  if (!program.empty()) c.programs = {program};
  CampaignBuild cb;
  EXPECT_TRUE(prepare_campaign(std::move(c), &cb, &err)) << err;
  return cb;
}

const TestCase* find_case(const CampaignBuild& cb, const std::string& fmea_id) {
  for (const auto& c : cb.cases)
    if (c.row->id == fmea_id) return &c;
  return nullptr;
}

}  // namespace

// ------------------------------------------------------------------ validation

TEST(CampaignSpec, StampingFilesLoad) {
  Campaign c;
  std::string err;
  ASSERT_TRUE(load_campaign((kSpecDir / "campaign.yaml").string(), &c, &err)) << err;
  EXPECT_EQ(c.name, "stamping");
  EXPECT_EQ(c.tsd.scenarios.size(), 2u);
  EXPECT_EQ(c.fmea.rows.size(), 8u);
  EXPECT_EQ(c.classes.classes.size(), 2u);
  EXPECT_EQ(c.max_paths, 3);
  EXPECT_EQ(c.search_window_ns, 60'000'000'000);
  // The published FMEA row: S 5, O 3, D 3, RPN 45, class 1, gStampCylError.
  const FmeaRow& f1 = c.fmea.rows[0];
  EXPECT_EQ(f1.transition, "normal.stamp.StampLowered");
  EXPECT_EQ(f1.failure_mode, "cylinder cannot extend, wrong stamping duration");
  EXPECT_EQ(f1.s * f1.o * f1.d, 45);
  EXPECT_EQ(f1.alarm, "gStampCylError");
}

struct BadSpec {
  const char* name;
  const char* file;
  const char* from;
  const char* to;
  const char* expected;  // regex on the error
};

class CampaignSpecErrors : public ::testing::TestWithParam<BadSpec> {};

TEST_P(CampaignSpecErrors, NamesFileLineAndColumn) {
  const BadSpec& b = GetParam();
  SpecCopy copy(b.name);
  copy.edit(b.file, b.from, b.to);
  std::string err = copy.load_error();
  EXPECT_TRUE(std::regex_search(err, std::regex(b.expected))) << err;
}

INSTANTIATE_TEST_SUITE_P(
    All, CampaignSpecErrors,
    ::testing::Values(
        BadSpec{"unknown_lifeline_pre", "tsd.yaml", "{PosStamp: TRUE, Filled: TRUE, StampUp: TRUE, StampPressure: 0",
                "{PosStamp: TRUE, Filed: TRUE, StampUp: TRUE, StampPressure: 0",
                "tsd\\.yaml:63:40: unknown lifeline 'Filed'"},
        BadSpec{"unknown_lifeline_tr", "tsd.yaml", "{lifeline: PosStamp, to: TRUE", "{lifeline: PosStamps, to: TRUE",
                "tsd\\.yaml:\\d+:\\d+: unknown lifeline 'PosStamps'"},
        BadSpec{"unknown_variable", "tsd.yaml", "bind: Main.step", "bind: Main.stepp",
                "tsd\\.yaml:18:28: lifeline Sequence: .*stepp"},
        BadSpec{"bad_address", "tsd.yaml", "bind: \"%QW2\"", "bind: \"%QW200000\"", "tsd\\.yaml:22:"},
        BadSpec{"severity_range", "fmea.csv", "wrong stamping duration\",5,", "wrong stamping duration\",11,",
                "fmea\\.csv:2:\\d+: S: 11 is outside 1\\.\\.10"},
        BadSpec{"occurrence_range", "fmea.csv", "end sensor broken\",3,check", "end sensor broken\",0,check",
                "fmea\\.csv:2:\\d+: O: 0 is outside 1\\.\\.10"},
        BadSpec{"rpn_product", "fmea.csv", ",3,45,1,gStampCylError,\nF2", ",3,44,1,gStampCylError,\nF2",
                "fmea\\.csv:2:\\d+: RPN 44 is not S x O x D = 5 x 3 x 3 = 45"},
        BadSpec{"rpn_not_number", "fmea.csv", ",3,45,1,gStampCylError,\nF2", ",3,4x5,1,gStampCylError,\nF2",
                "fmea\\.csv:2:\\d+: RPN: expected a whole number, got '4x5'"},
        BadSpec{"no_transition", "fmea.csv", "F1,normal.stamp.StampLowered", "F1,normal.stamp.PosCrane",
                "fmea\\.csv:2:4: step 'normal\\.stamp' expects no transition of 'PosCrane'"},
        BadSpec{"no_step", "fmea.csv", "F1,normal.stamp.StampLowered", "F1,normal.stomp.StampLowered",
                "fmea\\.csv:2:4: scenario 'normal' has no step 'stomp'"},
        BadSpec{"bad_ref", "fmea.csv", "F1,normal.stamp.StampLowered", "F1,StampLowered",
                "fmea\\.csv:2:4: 'StampLowered' is not a TSD transition"},
        BadSpec{"undefined_class", "fmea.csv", ",3,45,1,gStampCylError,\nF2", ",3,45,7,gStampCylError,\nF2",
                "fmea\\.csv:2:\\d+: fault class '7' is not defined in .*fault_classes\\.yaml"},
        BadSpec{"alarm_unknown", "fmea.csv", ",3,45,1,gStampCylError,\nF2", ",3,45,1,gStampCylErr,\nF2",
                "fmea\\.csv:2:\\d+: alarm: .*gStampCylErr"},
        BadSpec{"alarm_not_bool", "fmea.csv", ",3,45,1,gStampCylError,\nF2", ",3,45,1,Main.pieceCount,\nF2",
                "fmea\\.csv:2:\\d+: alarm 'Main.pieceCount' is not a BOOL"},
        BadSpec{"bad_fault_model", "fmea.csv", "StampDown: no_effect", "StampDown: no_efect",
                "fmea\\.csv:5:\\d+: .*no_efect"},
        BadSpec{"fault_misfit", "fmea.csv", "StampDown: no_effect", "StampDown: offset(100)", "fmea\\.csv:5:\\d+: .*offset"},
        BadSpec{"fault_not_io", "fmea.csv", "StampDown: no_effect", "Sequence: stuck",
                "fmea\\.csv:5:\\d+: lifeline Sequence \\(Main\\.step\\) is not an I/O address"},
        BadSpec{"missing_column", "fmea.csv", "id,tsd_transition,failure_mode,S,", "id,tsd_transition,failure_mode,",
                "fmea\\.csv:1:1: the header lacks the column 's'|fmea\\.csv:\\d+:1: \\d+ fields"},
        BadSpec{"class_formula", "fault_classes.yaml", "reaction: \"{alarm} AND gStampStop\"",
                "reaction: \"{alarm} AND gStampStopp\"", "^[^\\n]*fault_classes\\.yaml:23:20: error\\[ST200\\]: unknown identifier 'gStampStopp'\\n[^\\n]*\\n[^\\n]*\\^\\n$"},
        BadSpec{"recovery_ack_output", "fault_classes.yaml", "{acknowledge: AckButton, hold: 1s, press: 200ms, within: 1s, cleared",
                "{acknowledge: StampDown, hold: 1s, press: 200ms, within: 1s, cleared",
                "fault_classes\\.yaml:26:15: class 1: recovery: acknowledge: 'StampDown' is not a BOOL input \\(%IX\\)"},
        BadSpec{"recovery_cleared", "fault_classes.yaml", "cleared: [gStampStop]", "cleared: [gStampStp]",
                "fault_classes\\.yaml:26:15: class 1: recovery: cleared: .*gStampStp"},
        BadSpec{"recovery_key", "fault_classes.yaml", "press: 200ms, within: 1s, cleared", "presss: 200ms, within: 1s, cleared",
                "fault_classes\\.yaml:26:\\d+: unknown key 'presss' in a class's recovery"},
        BadSpec{"recovery_press", "fault_classes.yaml", "press: 200ms, within: 1s, cleared", "press: 0ms, within: 1s, cleared",
                "fault_classes\\.yaml:26:\\d+: press"},
        BadSpec{"class_key", "fault_classes.yaml", "reaction_time: 100ms", "reaction_tme: 100ms",
                "fault_classes\\.yaml:18:5: unknown key 'reaction_tme'"},
        BadSpec{"bad_duration", "tsd.yaml", "max: 500ms}", "max: 500 parsecs}", "tsd\\.yaml:\\d+:\\d+: max: .*"},
        BadSpec{"condition_error", "tsd.yaml", "start: \"StampDown\"", "condition: \"Main.nothing\"\n        start: \"StampDown\"",
                "tsd\\.yaml:\\d+:\\d+: error\\[ST\\d+\\].*nothing.*precondition of init\\.ref_lower"},
        BadSpec{"campaign_key", "campaign.yaml", "max_paths: 3", "max_path: 3", "campaign\\.yaml:\\d+:1: unknown key 'max_path'"},
        BadSpec{"yaml_syntax", "tsd.yaml", "lifelines:", "lifelines: [", "tsd\\.yaml:\\d+:\\d+: "}),
    [](const ::testing::TestParamInfo<BadSpec>& i) { return std::string(i.param.name); });

TEST(CampaignSpec, MissingFileIsNamed) {
  Campaign c;
  std::string err;
  EXPECT_FALSE(load_campaign("/nonexistent/campaign.yaml", &c, &err));
  EXPECT_NE(err.find("/nonexistent/campaign.yaml: cannot open"), std::string::npos) << err;
}

TEST(CampaignSpec, FmeaQuotedFieldsAndSemicolons) {
  fs::path p = fs::temp_directory_path() / ("plcfi_fmea_semi_" + std::to_string(::getpid()) + ".csv");
  write(p,
        "id;tsd_transition;failure_mode;S;effect;cause;O;detection;D;RPN;fault_class;alarm\n"
        "X1;a.b.c;\"two\nlines; quoted \"\"x\"\"\";2;e;c;3;d;4;24;1;gA\n");
  Fmea f;
  std::string err;
  ASSERT_TRUE(load_fmea(p.string(), &f, &err)) << err;
  ASSERT_EQ(f.rows.size(), 1u);
  EXPECT_EQ(f.rows[0].failure_mode, "two\nlines; quoted \"x\"");
  EXPECT_EQ(f.rows[0].rpn, 24);
  EXPECT_EQ(f.rows[0].alarm, "gA");
  fs::remove(p);
}

// The safety columns: a decimal comma under ';', dangerous no, a row outside every safety
// function, and an FMEA without the columns (has_rates false, the rows' defaults).
TEST(CampaignSpec, FmeaSafetyColumns) {
  fs::path p = fs::temp_directory_path() / ("plcfi_fmea_safety_" + std::to_string(::getpid()) + ".csv");
  write(p,
        "id;tsd_transition;S;O;D;RPN;fault_class;alarm;failure_rate;safety_function;dangerous\n"
        "A;a.b.c;2;3;4;24;1;gA;12,5;SF_a;no\n"
        "B;a.b.c;2;3;4;24;1;gA;7;SF_a;\n"
        "C;a.b.c;2;3;4;24;1;gA;;;\n");
  Fmea f;
  std::string err;
  ASSERT_TRUE(load_fmea(p.string(), &f, &err)) << err;
  EXPECT_TRUE(f.has_rates);
  ASSERT_EQ(f.rows.size(), 3u);
  EXPECT_DOUBLE_EQ(f.rows[0].failure_rate, 12.5);
  EXPECT_EQ(f.rows[0].safety_function, "SF_a");
  EXPECT_FALSE(f.rows[0].dangerous);
  EXPECT_DOUBLE_EQ(f.rows[1].failure_rate, 7);
  EXPECT_TRUE(f.rows[1].dangerous);
  EXPECT_EQ(f.rows[2].safety_function, "");
  EXPECT_LT(f.rows[2].failure_rate, 0);
  fs::remove(p);

  Fmea plain;
  ASSERT_TRUE(load_fmea((kSpecDir / "fmea.csv").string(), &plain, &err)) << err;
  EXPECT_FALSE(plain.has_rates);
  for (const auto& r : plain.rows) EXPECT_LT(r.failure_rate, 0);

  FaultClasses fc;
  ASSERT_TRUE(load_fault_classes((kSpecDir / "fault_classes_safety.yaml").string(), &fc, &err)) << err;
  ASSERT_NE(fc.find("1"), nullptr);
  EXPECT_EQ(fc.find("1")->safety_time_ns, 2'000'000'000);
  EXPECT_EQ(fc.find("2")->safety_time_ns, 15'000'000'000);
}

// ------------------------------------------------------------------ generation

TEST(CampaignGenerate, OneCasePerFmeaRowInRpnOrder) {
  CampaignBuild cb = prepare(kSpecDir / "campaign.yaml");
  ASSERT_EQ(cb.cases.size(), 8u);
  for (size_t i = 1; i < cb.cases.size(); ++i) EXPECT_GE(cb.cases[i - 1].rpn, cb.cases[i].rpn);
  EXPECT_EQ(cb.cases[0].id, "TC1");
  EXPECT_EQ(cb.cases[0].row->id, "F1");  // ties keep the FMEA order
  const TestCase* f1 = find_case(cb, "F1");
  ASSERT_TRUE(f1);
  EXPECT_EQ(f1->precondition, "(PosStamp) AND (Filled) AND (StampUp) AND (StampPressure >= -50 AND StampPressure <= 50) AND (ModeAuto)");
  EXPECT_EQ(f1->start, "StampDown AND PressureSetpoint = 6000");
  EXPECT_EQ(f1->target_ref.text, "%IX0.4");
  EXPECT_EQ(f1->deadline_ns, 600'000'000);  // 500 ms transition + 100 ms class-1 reaction time
  EXPECT_EQ(f1->reqs, 2u);                   // the alarm requirement and one forbidden reaction
  EXPECT_EQ(f1->forbidden, 1u);
  EXPECT_EQ(cb.monitors.requirements[f1->first_req].reaction.text, "gStampCylError AND gStampStop");
  EXPECT_EQ(cb.monitors.requirements[f1->first_req].delay.text, "PASSED(T#600ms)");
  // Default fault: BOOL sensor stuck, analog frozen; "Lifeline: model" targets another one.
  EXPECT_NE(f1->fault.text.find("stuck"), std::string::npos) << f1->fault.text;
  EXPECT_NE(find_case(cb, "F2")->fault.text.find("frozen"), std::string::npos);
  EXPECT_EQ(find_case(cb, "F4")->target_ref.text, "%QX0.1");
  EXPECT_EQ(find_case(cb, "F5")->start, "TRUE");  // start: previous
  EXPECT_EQ(find_case(cb, "F8")->deadline_ns, 10'100'000'000);
  EXPECT_NE(cb.preconditions_source.find("pre[0] := " + cb.cases[0].precondition + ";"), std::string::npos);
}

// ------------------------------------------------------------------ the published result

namespace {

std::map<std::string, std::vector<Outcome>> verdicts_by_fmea(const CampaignBuild& cb, const CampaignResult& r) {
  std::map<std::string, std::vector<Outcome>> m;
  for (const auto& e : r.executions) m[cb.cases[e.case_index].row->id].push_back(e.outcome);
  for (size_t i : r.not_reached) m[cb.cases[i].row->id].push_back(Outcome::NotReached);
  return m;
}

fs::path out_dir(const std::string& tag) {
  fs::path p = fs::temp_directory_path() / ("plcfi_campaign_out_" + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

}  // namespace

TEST(CampaignStamping, PublishedResultOnStampingSt) {
  CampaignBuild cb = prepare(kSpecDir / "campaign.yaml");
  CampaignResult r;
  DriverOptions opt;
  std::string err;
  ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  auto v = verdicts_by_fmea(cb, r);
  // Every precondition is found.
  EXPECT_TRUE(r.not_reached.empty());
  // The initialization-run StampLowered case fails: no supervision of the reference stroke.
  ASSERT_EQ(v["F3"].size(), 1u);
  EXPECT_EQ(v["F3"][0], Outcome::Fail);
  // The automatic-mode StampLowered case runs on two control-flow paths (first WP after a
  // start through CheckPressure, later WPs straight to Stamp), and passes on both.
  EXPECT_EQ(v["F1"], (std::vector<Outcome>{Outcome::Pass, Outcome::Pass}));
  // The pressure case passes (on both paths too).
  ASSERT_FALSE(v["F2"].empty());
  for (auto o : v["F2"]) EXPECT_EQ(o, Outcome::Pass);
  for (const auto& [id, outs] : v) {
    if (id == "F3") continue;
    for (auto o : outs) EXPECT_EQ(o, Outcome::Pass) << id;
  }
  // The two F1 paths differ in the branch of `IF firstPiece` in ExtendSlider.
  std::vector<const Execution*> f1;
  for (const auto& e : r.executions)
    if (cb.cases[e.case_index].row->id == "F1") f1.push_back(&e);
  ASSERT_EQ(f1.size(), 2u);
  EXPECT_NE(f1[0]->path_hash, f1[1]->path_hash);
  auto d = distinguishing_branches(cb, r.executions, *f1[0]);
  std::string all;
  for (const auto& s : d) all += s + " ";
  EXPECT_NE(all.find("stamping.st:"), std::string::npos) << all;
  // The failing case names the missed deadline; passing ones report a latency.
  for (const auto& e : r.executions) {
    if (e.outcome == Outcome::Fail) {
      EXPECT_NE(e.reason.find("deadline missed"), std::string::npos) << e.reason;
    } else {
      EXPECT_GE(e.latency_ns, 0);
      EXPECT_LE(e.latency_ns, cb.cases[e.case_index].deadline_ns);
    }
  }
}

TEST(CampaignStamping, AllPassOnFixedProgram) {
  CampaignBuild cb = prepare(kSpecDir / "campaign.yaml", (kRoot / "st_programs/stamping/stamping_fixed.st").string());
  CampaignResult r;
  DriverOptions opt;
  std::string err;
  ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  EXPECT_TRUE(r.not_reached.empty());
  EXPECT_GE(r.executions.size(), cb.cases.size());
  for (const auto& e : r.executions) EXPECT_EQ(e.outcome, Outcome::Pass) << e.case_id << ": " << e.reason;
}

TEST(CampaignStamping, UnreachablePreconditionIsNotReached) {
  SpecCopy copy("unreached");
  // Manual mode never happens in the simulated shift: the hand-over case cannot start.
  copy.edit("tsd.yaml", "WorkpieceReady: TRUE, NextReady: TRUE, ModeAuto: TRUE", "WorkpieceReady: TRUE, NextReady: TRUE, ModeAuto: FALSE");
  copy.edit("campaign.yaml", "search_window: 60s", "search_window: 20s");
  CampaignBuild cb = prepare(copy.path("campaign.yaml"));
  CampaignResult r;
  DriverOptions opt;
  std::string err;
  ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  ASSERT_EQ(r.not_reached.size(), 1u);
  EXPECT_EQ(cb.cases[r.not_reached[0]].row->id, "F8");
}

TEST(CampaignStamping, ForbiddenReactionFails) {
  SpecCopy copy("forbidden");
  // Class 2 forbids the warning lamp here: the warning itself lights it, in the very scan
  // the reaction comes, so the case fails on the forbidden reaction.
  copy.edit("fault_classes.yaml", "{formula: \"gStampStop\", text: \"a warning must not stop the module\"}",
            "{formula: \"WarningLamp\", text: \"no warning lamp\"}");
  CampaignBuild cb = prepare(copy.path("campaign.yaml"));
  CampaignResult r;
  DriverOptions opt;
  std::string err;
  ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  auto v = verdicts_by_fmea(cb, r);
  ASSERT_EQ(v["F8"].size(), 1u);
  EXPECT_EQ(v["F8"][0], Outcome::Fail);
  for (const auto& e : r.executions)
    if (cb.cases[e.case_index].row->id == "F8") {
      EXPECT_NE(e.reason.find("forbidden reaction at +"), std::string::npos) << e.reason;
      EXPECT_NE(e.reason.find("no warning lamp"), std::string::npos) << e.reason;
    }
}

TEST(CampaignStamping, MaximumTestDurationFails) {
  SpecCopy copy("maxdur");
  // The hand-over warning comes after 10 s; a class that gives up after 5 s fails it.
  copy.edit("fault_classes.yaml", "  - id: 2\n    name: warning\n    text: \"Warning message, the module goes on\"\n    reaction_time: 100ms\n    max_duration: 30s",
            "  - id: 2\n    name: warning\n    text: \"Warning message, the module goes on\"\n    reaction_time: 100ms\n    max_duration: 5s");
  CampaignBuild cb = prepare(copy.path("campaign.yaml"));
  CampaignResult r;
  DriverOptions opt;
  std::string err;
  ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  bool seen = false;
  for (const auto& e : r.executions)
    if (cb.cases[e.case_index].row->id == "F8") {
      seen = true;
      EXPECT_EQ(e.outcome, Outcome::Fail);
      EXPECT_NE(e.reason.find("maximum test duration 5 s reached"), std::string::npos) << e.reason;
      EXPECT_EQ(e.end_ns - e.inject_ns, 5'000'000'000);
    }
  EXPECT_TRUE(seen);
}

TEST(CampaignStamping, BudgetEndsTheCampaign) {
  SpecCopy copy("budget");
  copy.edit("campaign.yaml", "budget: 1h", "budget: 3s");
  CampaignBuild cb = prepare(copy.path("campaign.yaml"));
  CampaignResult r;
  DriverOptions opt;
  std::string err;
  ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  EXPECT_NE(r.end_reason.find("time budget of 3 s spent"), std::string::npos) << r.end_reason;
  EXPECT_FALSE(r.not_reached.empty());  // what did not get its turn is reported, not passed
  EXPECT_LT(r.executions.size(), cb.cases.size());
}

TEST(CampaignStamping, SameSeedSameJournal) {
  fs::path a = out_dir("det_a"), b = out_dir("det_b");
  for (const auto& dir : {a, b}) {
    CampaignBuild cb = prepare(kSpecDir / "campaign.yaml");
    CampaignResult r;
    DriverOptions opt;
    opt.out_dir = dir.string();
    std::string err;
    ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  }
  std::string ja = read(a / "results.jsonl"), jb = read(b / "results.jsonl");
  EXPECT_FALSE(ja.empty());
  EXPECT_EQ(ja, jb);
  // One VCD per execution.
  size_t lines = static_cast<size_t>(std::count(ja.begin(), ja.end(), '\n'));
  size_t vcds = 0;
  for (const auto& e : fs::directory_iterator(a)) vcds += e.path().extension() == ".vcd";
  EXPECT_EQ(vcds, lines - 1);
  fs::remove_all(a);
  fs::remove_all(b);
}

TEST(CampaignStamping, ResumeFromTornJournalGivesSameVerdicts) {
  fs::path full = out_dir("resume_full"), part = out_dir("resume_part");
  {
    CampaignBuild cb = prepare(kSpecDir / "campaign.yaml");
    CampaignResult r;
    DriverOptions opt;
    opt.out_dir = full.string();
    std::string err;
    ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  }
  std::string journal = read(full / "results.jsonl");
  // Keep the header and three verdicts, then half of the fourth (a kill in mid-write).
  std::vector<std::string> lines;
  std::stringstream ss(journal);
  for (std::string l; std::getline(ss, l);) lines.push_back(l);
  ASSERT_GE(lines.size(), 6u);
  fs::create_directories(part);
  write(part / "results.jsonl", lines[0] + "\n" + lines[1] + "\n" + lines[2] + "\n" + lines[3] + "\n" + lines[4].substr(0, 40));
  CampaignBuild cb = prepare(kSpecDir / "campaign.yaml");
  CampaignResult r;
  DriverOptions opt;
  opt.out_dir = part.string();
  opt.resume = true;
  std::string err;
  ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  EXPECT_EQ(r.resumed, 3u);
  EXPECT_EQ(read(part / "results.jsonl"), journal);  // nothing re-run, nothing duplicated
  fs::remove_all(full);
  fs::remove_all(part);
}

TEST(CampaignStamping, ResumeRefusesAnotherCampaignsJournal) {
  fs::path dir = out_dir("resume_other");
  {
    CampaignBuild cb = prepare(kSpecDir / "campaign.yaml");
    CampaignResult r;
    DriverOptions opt;
    opt.out_dir = dir.string();
    std::string err;
    ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  }
  CampaignBuild cb = prepare(kSpecDir / "campaign.yaml", (kRoot / "st_programs/stamping/stamping_fixed.st").string());
  CampaignResult r;
  DriverOptions opt;
  opt.out_dir = dir.string();
  opt.resume = true;
  std::string err;
  EXPECT_FALSE(run_campaign(cb, opt, &r, &err));
  EXPECT_NE(err.find("belongs to another campaign"), std::string::npos) << err;
  fs::remove_all(dir);
}

TEST(CampaignStamping, ResumeReportsACorruptJournal) {
  fs::path dir = out_dir("resume_corrupt");
  {
    CampaignBuild cb = prepare(kSpecDir / "campaign.yaml");
    CampaignResult r;
    DriverOptions opt;
    opt.out_dir = dir.string();
    std::string err;
    ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  }
  std::string journal = read(dir / "results.jsonl");
  std::string header = journal.substr(0, journal.find('\n') + 1);
  for (const std::string& bad : {std::string("{\"case\":\"TC1\",\"verdict\":\"PASS\",\"path_hash\":\"zz\"}\n"),
                                std::string("{\"case\":\"TC99\",\"verdict\":\"PASS\",\"path_hash\":\"00\"}\n"),
                                std::string("not json at all\n")}) {
    write(dir / "results.jsonl", header + bad);
    CampaignBuild cb = prepare(kSpecDir / "campaign.yaml");
    CampaignResult r;
    DriverOptions opt;
    opt.out_dir = dir.string();
    opt.resume = true;
    std::string err;
    EXPECT_FALSE(run_campaign(cb, opt, &r, &err)) << bad;
    // The line, and the column where the JSON stops making sense ("not json": 2).
    EXPECT_TRUE(std::regex_search(err, std::regex(bad[0] == '{' ? "results\\.jsonl:2:1: " : "results\\.jsonl:2:2: not a journal line \\(")))
        << err;
  }
  fs::remove_all(dir);
}

// Fault-space exploration (campaign/explore.hpp): which signals and fault models a step
// gets, deduplication against the FMEA, ordering and ids, classes and their errors, the
// journal mark, and FMEA suggestions that load as FMEA rows once rated.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <unistd.h>

#include "campaign/driver.hpp"
#include "campaign/explore.hpp"
#include "campaign/generate.hpp"
#include "campaign/journal.hpp"
#include "campaign/spec.hpp"

namespace fs = std::filesystem;
using namespace plcfi;
using namespace plcfi::campaign;

namespace {

const fs::path kRoot = fs::path(PLCFI_SOURCE_DIR);
const fs::path kSpecDir = kRoot / "faults/campaigns/stamping";
const std::string kFixed = (kRoot / "st_programs/stamping/stamping_fixed.st").string();

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A private copy of the stamping campaign whose files a test may edit.
class Copy {
 public:
  explicit Copy(const std::string& tag) {
    dir_ = fs::temp_directory_path() / ("plcfi_explore_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    for (const char* f : {"campaign.yaml", "tsd.yaml", "fmea.csv", "fault_classes.yaml"}) {
      std::string text = read(kSpecDir / f);
      if (std::string(f) == "campaign.yaml")
        text = std::regex_replace(text, std::regex("\\.\\./\\.\\./\\.\\./st_programs"), (kRoot / "st_programs").string());
      std::ofstream(dir_ / f) << text;
    }
  }
  ~Copy() { fs::remove_all(dir_); }
  fs::path path(const std::string& f) const { return dir_ / f; }
  void edit(const std::string& f, const std::string& from, const std::string& to) {
    std::string text = read(dir_ / f);
    size_t p = text.find(from);
    ASSERT_NE(p, std::string::npos) << from;
    text.replace(p, from.size(), to);
    std::ofstream(dir_ / f) << text;
  }
  void append(const std::string& f, const std::string& text) { std::ofstream(dir_ / f, std::ios::app) << text; }

 private:
  fs::path dir_;
};

// Loads and prepares with exploring on; *err gets the first error.
bool prepare_explore(const fs::path& campaign, CampaignBuild* cb, std::string* err, const std::string& program = kFixed) {
  Campaign c;
  if (!load_campaign(campaign.string(), &c, err)) return false;
  c.programs = {program};
  c.explore.enabled = true;
  return prepare_campaign(std::move(c), cb, err);
}

const TestCase* find(const CampaignBuild& cb, const std::string& ref, const std::string& fault) {
  for (const auto& tc : cb.cases)
    if (tc.explored && tc.transition_ref() == ref && tc.fault.text == fault) return &tc;
  return nullptr;
}

}  // namespace

TEST(CampaignExplore, OffByDefaultAndOnlyAfterTheFmeaCases) {
  CampaignBuild plain;
  std::string err;
  Campaign c;
  ASSERT_TRUE(load_campaign((kSpecDir / "campaign.yaml").string(), &c, &err)) << err;
  EXPECT_FALSE(c.explore.enabled);  // the section is there, exploring is not on
  EXPECT_EQ(c.explore.default_class, "1");
  ASSERT_TRUE(prepare_campaign(std::move(c), &plain, &err)) << err;
  EXPECT_EQ(plain.cases.size(), 8u);
  EXPECT_TRUE(plain.explore.source.empty());

  CampaignBuild cb;
  ASSERT_TRUE(prepare_explore(kSpecDir / "campaign.yaml", &cb, &err)) << err;
  ASSERT_GT(cb.cases.size(), 8u);
  // The FMEA's cases first, unchanged (ids, order, preconditions); explored ones after.
  for (size_t i = 0; i < 8; ++i) {
    EXPECT_FALSE(cb.cases[i].explored);
    EXPECT_EQ(cb.cases[i].id, plain.cases[i].id);
    EXPECT_EQ(cb.cases[i].row->id, plain.cases[i].row->id);
    EXPECT_EQ(cb.cases[i].precondition, plain.cases[i].precondition);
  }
  size_t prev_step = 0;
  for (size_t i = 8; i < cb.cases.size(); ++i) {
    const TestCase& tc = cb.cases[i];
    EXPECT_TRUE(tc.explored);
    EXPECT_EQ(tc.id, "X" + std::to_string(i - 7));
    EXPECT_EQ(tc.row->id, "");
    EXPECT_GE(tc.explore_step, prev_step) << tc.id;  // TSD step order
    prev_step = tc.explore_step;
  }
  // No two explored cases alike.
  std::set<std::string> keys;
  for (size_t i = 8; i < cb.cases.size(); ++i)
    EXPECT_TRUE(keys.insert(cb.cases[i].transition_ref() + "|" + cb.cases[i].fault.text).second) << cb.cases[i].id;
}

TEST(CampaignExplore, SignalsOfAStepAndTheirFaultModels) {
  CampaignBuild cb;
  std::string err;
  ASSERT_TRUE(prepare_explore(kSpecDir / "campaign.yaml", &cb, &err)) << err;
  // deliver names PosCrane, Filled, StampUp (precondition) and PosStamp (transition); the
  // program reads all four. Outputs the program writes come in every step.
  std::set<std::string> deliver;
  for (const auto& tc : cb.cases)
    if (tc.explored && tc.step->id == "deliver") deliver.insert(tc.target->name);
  EXPECT_EQ(deliver, (std::set<std::string>{"PosCrane", "PosStamp", "Filled", "StampUp", "SliderExtend", "StampDown",
                                            "PressureSetpoint"}));
  // Not faulted there: a sensor the step does not name, mode and interface lifelines.
  EXPECT_FALSE(find(cb, "normal.deliver.StampLowered", "stuck_at(1)"));
  EXPECT_FALSE(find(cb, "normal.deliver.ModeAuto", "stuck_at(0)"));
  EXPECT_FALSE(find(cb, "normal.deliver.StationEmpty", "stuck_on"));
  // Fault models per kind.
  EXPECT_TRUE(find(cb, "normal.deliver.PosCrane", "stuck_at(0)"));
  EXPECT_TRUE(find(cb, "normal.deliver.PosCrane", "stuck_at(1)"));
  EXPECT_TRUE(find(cb, "normal.hold.StampPressure", "frozen"));
  EXPECT_TRUE(find(cb, "normal.hold.StampPressure", "offset(500)"));  // 10 x tolerance 50
  EXPECT_TRUE(find(cb, "normal.hold.StampPressure", "stuck_at(0)"));
  EXPECT_TRUE(find(cb, "normal.hold.StampDown", "no_effect"));
  EXPECT_TRUE(find(cb, "normal.hold.StampDown", "stuck_on"));
  EXPECT_TRUE(find(cb, "normal.hold.StampDown", "stuck_off"));
  EXPECT_TRUE(find(cb, "normal.hold.PressureSetpoint", "no_effect"));
  EXPECT_TRUE(find(cb, "normal.hold.PressureSetpoint", "stuck_off"));
  EXPECT_FALSE(find(cb, "normal.hold.PressureSetpoint", "stuck_on"));
  // The explore program holds one line per step, transition and explored case.
  EXPECT_NE(cb.explore.source.find("PROGRAM __FI_EXPLORE"), std::string::npos);
  EXPECT_EQ(cb.explore.steps.size(), 8u);  // 3 init + 5 normal steps
}

TEST(CampaignExplore, ASignalTheProgramDoesNotReadIsNotFaulted) {
  // A program that never reads PosCrane: no explored case on it.
  fs::path prog = fs::temp_directory_path() / ("plcfi_explore_noread_" + std::to_string(::getpid()) + ".st");
  std::string text = read(kFixed);
  text = std::regex_replace(text, std::regex("IF PosCrane AND StampUp THEN"), "IF StampUp THEN");
  text = std::regex_replace(text, std::regex("IF PosCrane THEN"), "IF NOT PosStamp THEN");
  text = std::regex_replace(text, std::regex("AtRetracted := PosCrane"), "AtRetracted := NOT PosStamp");
  std::ofstream(prog) << text;
  CampaignBuild cb;
  std::string err;
  ASSERT_TRUE(prepare_explore(kSpecDir / "campaign.yaml", &cb, &err, prog.string())) << err;
  for (const auto& tc : cb.cases) EXPECT_NE(tc.target->name, "PosCrane") << tc.id;
  fs::remove(prog);
}

TEST(CampaignExplore, DeduplicatedAgainstTheFmea) {
  CampaignBuild cb;
  std::string err;
  ASSERT_TRUE(prepare_explore(kSpecDir / "campaign.yaml", &cb, &err)) << err;
  // F1: stamp.StampLowered "stuck", FALSE before its transition to TRUE = stuck_at(0).
  EXPECT_FALSE(find(cb, "normal.stamp.StampLowered", "stuck_at(0)"));
  EXPECT_TRUE(find(cb, "normal.stamp.StampLowered", "stuck_at(1)"));
  // F2: StampPressure frozen; F4: StampDown no_effect in the same step.
  EXPECT_FALSE(find(cb, "normal.stamp.StampPressure", "frozen"));
  EXPECT_TRUE(find(cb, "normal.stamp.StampPressure", "offset(500)"));
  EXPECT_FALSE(find(cb, "normal.stamp.StampDown", "no_effect"));
  EXPECT_TRUE(find(cb, "normal.stamp.StampDown", "stuck_on"));
  // F8: handover.Filled stuck, TRUE in the precondition = stuck_at(1).
  EXPECT_FALSE(find(cb, "normal.handover.Filled", "stuck_at(1)"));
  EXPECT_TRUE(find(cb, "normal.handover.Filled", "stuck_at(0)"));
  // The equivalence rule itself.
  const Step* stamp = nullptr;
  for (const auto& s : cb.spec.tsd.scenarios[1].steps)
    if (s.id == "stamp") stamp = &s;
  ASSERT_TRUE(stamp);
  faults::FaultSpec stuck;
  std::string e;
  uint32_t col = 0;
  ASSERT_TRUE(faults::parse_fault("stuck", &stuck, &e, &col));
  rt::ImageRef bit;
  bit.is_bit = true;
  EXPECT_EQ(equivalent_fault(*stamp, *cb.spec.tsd.find("StampUp"), bit, stuck), "stuck_at(1)");       // precondition TRUE
  EXPECT_EQ(equivalent_fault(*stamp, *cb.spec.tsd.find("StampLowered"), bit, stuck), "stuck_at(0)");  // goes to TRUE
  rt::ImageRef word;
  word.size = 2;
  EXPECT_EQ(equivalent_fault(*stamp, *cb.spec.tsd.find("StampPressure"), word, stuck), "frozen");
}

TEST(CampaignExplore, ClassOfTheFmeaRowElseTheDefault) {
  CampaignBuild cb;
  std::string err;
  ASSERT_TRUE(prepare_explore(kSpecDir / "campaign.yaml", &cb, &err)) << err;
  // Filled has an FMEA row (F8, class 2, gHandoverWarning): its class and alarm.
  const TestCase* filled = find(cb, "normal.deliver.Filled", "stuck_at(0)");
  ASSERT_TRUE(filled);
  EXPECT_EQ(filled->cls->id, "2");
  EXPECT_EQ(filled->row->alarm, "gHandoverWarning");
  // StampDown is faulted by F4 ("StampDown: no_effect"): class 1, gStampCylError.
  EXPECT_EQ(find(cb, "normal.hold.StampDown", "stuck_on")->row->alarm, "gStampCylError");
  // PosCrane has no row: the default class 1, detected by any alarm of the FMEA.
  const TestCase* pc = find(cb, "normal.deliver.PosCrane", "stuck_at(1)");
  ASSERT_TRUE(pc);
  EXPECT_EQ(pc->cls->id, "1");
  EXPECT_EQ(pc->row->alarm, "(gStampCylError OR gSliderError OR gHandoverWarning)");
  // Explored cases keep the class's forbidden reactions as monitors, not its requirements.
  EXPECT_EQ(pc->reqs, pc->forbidden);
  EXPECT_EQ(pc->forbidden, 1u);
}

TEST(CampaignExplore, ErrorsNameTheCampaignFileLine) {
  {
    Copy c("noclass");
    c.edit("campaign.yaml", "explore: {enabled: false, default_class: 1}", "explore: {enabled: true}");
    CampaignBuild cb;
    std::string err;
    EXPECT_FALSE(prepare_explore(c.path("campaign.yaml"), &cb, &err));
    EXPECT_NE(err.find(c.path("campaign.yaml").string() + ":"), std::string::npos) << err;
    EXPECT_NE(err.find("explore: no FMEA row gives a fault class to lifeline PosCrane (faulted in init.home)"),
              std::string::npos)
        << err;
  }
  {
    Copy c("badclass");
    c.edit("campaign.yaml", "default_class: 1}", "default_class: 9}");
    Campaign spec;
    std::string err;
    EXPECT_FALSE(load_campaign(c.path("campaign.yaml").string(), &spec, &err));
    EXPECT_NE(err.find("explore: default_class '9' is not defined"), std::string::npos) << err;
  }
  {
    Copy c("badkey");
    c.edit("campaign.yaml", "explore: {enabled: false,", "explore: {enable: false,");
    Campaign spec;
    std::string err;
    EXPECT_FALSE(load_campaign(c.path("campaign.yaml").string(), &spec, &err));
    EXPECT_NE(err.find("unknown key 'enable' in the explore section"), std::string::npos) << err;
  }
  {
    Copy c("badbool");
    c.edit("campaign.yaml", "enabled: false", "enabled: maybe");
    Campaign spec;
    std::string err;
    EXPECT_FALSE(load_campaign(c.path("campaign.yaml").string(), &spec, &err));
    EXPECT_NE(err.find("explore: enabled"), std::string::npos) << err;
  }
}

TEST(CampaignExplore, SuggestionsOfAFailedCaseAndTheJournalMark) {
  // The fixed program with the slider unsupervised on its way back.
  fs::path prog = fs::temp_directory_path() / ("plcfi_explore_return_" + std::to_string(::getpid()) + ".st");
  std::string text = read(kFixed);
  const std::string line = "superviseStamp := superviseSlider;\n";
  size_t p = text.find(line);
  ASSERT_NE(p, std::string::npos);
  text.insert(p + line.size(), "superviseSlider := superviseSlider AND step <> E_Step#RetractSlider;\n");
  std::ofstream(prog) << text;
  CampaignBuild cb;
  std::string err;
  ASSERT_TRUE(prepare_explore(kSpecDir / "campaign.yaml", &cb, &err, prog.string())) << err;
  const TestCase* x = find(cb, "normal.retract.PosCrane", "stuck_at(0)");
  ASSERT_TRUE(x);
  CampaignResult r;
  DriverOptions opt;
  ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  const Execution* e = nullptr;
  for (const auto& ex : r.executions)
    if (ex.case_id == x->id) e = &ex;
  ASSERT_TRUE(e);
  EXPECT_EQ(e->outcome, Outcome::Fail);
  EXPECT_EQ(e->reason, "transition normal.retract.PosCrane not within 500 ms (to TRUE); no alarm");
  // FMEA cases keep passing: the FMEA has nothing on the way back.
  for (const auto& ex : r.executions)
    if (!cb.cases[ex.case_index].explored) {
      EXPECT_EQ(ex.outcome, Outcome::Pass) << ex.case_id << ": " << ex.reason;
    }

  auto sug = fmea_suggestions(cb, r.executions);
  const FmeaSuggestion* s = nullptr;
  for (const auto& y : sug)
    if (y.case_id == x->id) s = &y;
  ASSERT_TRUE(s);
  EXPECT_EQ(s->component, "PosCrane");
  EXPECT_EQ(s->transition, "normal.retract.PosCrane");
  EXPECT_EQ(s->failure_mode, "PosCrane stuck_at(0)");
  EXPECT_EQ(s->effect, "transition normal.retract.PosCrane not within 500 ms (to TRUE)");
  EXPECT_EQ(s->detection, "none");
  EXPECT_EQ(s->fault_model, "PosCrane: stuck_at(0)");
  std::string csv = fmea_suggestions_csv(sug);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), read(kSpecDir / "fmea.csv").substr(0, csv.find('\n')));  // the FMEA's columns

  // The journal line says the case is explored; an FMEA case's line does not.
  Progress pr;
  EXPECT_NE(journal_line(*e, *x, pr).find("\"fmea\":\"\",\"explore\":true,"), std::string::npos);
  const Execution* fmea_case = nullptr;
  for (const auto& ex : r.executions)
    if (!fmea_case && !cb.cases[ex.case_index].explored) fmea_case = &ex;
  ASSERT_TRUE(fmea_case);
  EXPECT_EQ(journal_line(*fmea_case, cb.cases[fmea_case->case_index], pr).find("explore"), std::string::npos);
  fs::remove(prog);
}

TEST(CampaignExplore, ARatedSuggestionLoadsAsAnFmeaRowAndReplacesTheExploredCase) {
  CampaignBuild cb;
  std::string err;
  ASSERT_TRUE(prepare_explore(kSpecDir / "campaign.yaml", &cb, &err)) << err;
  const TestCase* x = find(cb, "normal.hold.StampUp", "stuck_at(1)");
  ASSERT_TRUE(x);
  FmeaSuggestion s;
  s.case_id = "F9";
  s.transition = x->row->transition;
  s.failure_mode = x->row->failure_mode;
  s.effect = "transition normal.hold.StampUp too early: after 0 ms of its min 1 s (at +0 ms)";
  s.detection = "none";
  s.fault_class = x->cls->id;
  s.alarm = x->row->alarm;
  s.fault_model = x->row->fault_model;
  std::string row = fmea_suggestions_csv({s});
  row = row.substr(row.find('\n') + 1);
  // Rated by the user: S, O, D and RPN filled in (columns 4, 7, 9, 10).
  ASSERT_EQ(row.find('"'), std::string::npos) << row;  // no quoted field in this one
  std::vector<std::string> f;
  std::stringstream ss(row.substr(0, row.find('\n')));
  for (std::string field; std::getline(ss, field, ',');) f.push_back(field);
  ASSERT_EQ(f.size(), 13u) << row;
  f[3] = "2";
  f[6] = "2";
  f[8] = "2";
  f[9] = "8";
  row.clear();
  for (size_t k = 0; k < f.size(); ++k) row += (k ? "," : "") + f[k];
  row += "\n";
  Copy c("paste");
  c.append("fmea.csv", row);
  CampaignBuild after;
  ASSERT_TRUE(prepare_explore(c.path("campaign.yaml"), &after, &err)) << err << "\nrow: " << row;
  bool fmea_case = false;
  for (const auto& tc : after.cases)
    if (!tc.explored && tc.row->id == "F9") {
      fmea_case = true;
      EXPECT_EQ(tc.transition_ref(), "normal.hold.StampUp");
      EXPECT_EQ(tc.fault.text, "stuck_at(1)");
    }
  EXPECT_TRUE(fmea_case);
  EXPECT_FALSE(find(after, "normal.hold.StampUp", "stuck_at(1)"));  // now the FMEA's
  EXPECT_EQ(after.cases.size(), cb.cases.size());                  // one FMEA case more, one explored less
}

TEST(CampaignExplore, CampaignRequirementsTurnATolerableRunIntoAFail) {
  Copy c("reqs");
  c.append("campaign.yaml", "requirements: reqs.yaml\n");
  std::ofstream(c.path("reqs.yaml")) << "requirements:\n"
                                        "  - id: P1\n"
                                        "    text: \"the pressure the program reads stays below 6300\"\n"
                                        "    trigger: \"TRUE\"\n"
                                        "    invariant: \"StampPressure < 6300\"\n"
                                        "    final: \"FALSE\"\n";
  CampaignBuild cb;
  std::string err;
  ASSERT_TRUE(prepare_explore(c.path("campaign.yaml"), &cb, &err)) << err;
  const TestCase* offset = find(cb, "normal.stamp.StampPressure", "offset(500)");
  const TestCase* setpoint = find(cb, "init.ref_lower.PressureSetpoint", "no_effect");
  ASSERT_TRUE(offset && setpoint);
  EXPECT_EQ(offset->reqs, offset->forbidden + 1);  // the class's forbidden reaction, then P1
  for (size_t i = 0; i < 8; ++i) EXPECT_EQ(cb.cases[i].reqs, 2u) << cb.cases[i].id;  // FMEA cases: as before
  CampaignResult r;
  DriverOptions opt;
  ASSERT_TRUE(run_campaign(cb, opt, &r, &err)) << err;
  bool seen_offset = false, seen_setpoint = false;
  for (const auto& e : r.executions) {
    if (e.case_id == offset->id) {
      seen_offset = true;
      EXPECT_EQ(e.outcome, Outcome::Fail);
      EXPECT_EQ(e.reason.rfind("the TSD's transitions in time, but requirement P1 violated at +", 0), 0u) << e.reason;
    }
    if (e.case_id == setpoint->id) {  // tolerated, and P1 holds
      seen_setpoint = true;
      EXPECT_EQ(e.outcome, Outcome::Pass) << e.reason;
      EXPECT_EQ(e.reason.rfind("tolerated: ", 0), 0u) << e.reason;
    }
  }
  EXPECT_TRUE(seen_offset && seen_setpoint);

  // A bad formula is reported in the requirements file.
  std::ofstream(c.path("reqs.yaml")) << "requirements:\n"
                                        "  - id: P1\n"
                                        "    text: \"bad\"\n"
                                        "    trigger: \"TRUE\"\n"
                                        "    invariant: \"NoSuchVariable < 6300\"\n";
  CampaignBuild bad;
  EXPECT_FALSE(prepare_explore(c.path("campaign.yaml"), &bad, &err));
  EXPECT_NE(err.find("reqs.yaml:5:"), std::string::npos) << err;
}

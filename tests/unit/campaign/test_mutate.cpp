// Mutation analysis: each operator's patch on a small ST program changes what the
// program does the way its name says (run on the VM), dead code is proven equivalent,
// and the stamping campaign's mutation journal is the same with workers and with merged
// shards as with one process.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "campaign/mutate.hpp"
#include "campaign/spec.hpp"
#include "engine.hpp"
#include "vm/vm.hpp"

namespace fs = std::filesystem;
using namespace plcfi;
using namespace plcfi::campaign;

namespace {

const fs::path kRoot = fs::path(PLCFI_SOURCE_DIR);

// gAlarm latches when the supervision FB's timer runs out (TMax from T_SUP), ack resets
// it, gStop follows it; FB_Unused is never called.
const char* kProgram = R"(
FUNCTION_BLOCK FB_Sup
VAR_INPUT In : BOOL; TMax : TIME; END_VAR
VAR_OUTPUT Error : BOOL; END_VAR
VAR t : TON; END_VAR
t(IN := In, PT := TMax);
IF t.Q THEN
  Error := TRUE;
END_IF;
END_FUNCTION_BLOCK

FUNCTION_BLOCK FB_Unused
VAR_OUTPUT x : BOOL; END_VAR
gAlarm := TRUE;
END_FUNCTION_BLOCK

PROGRAM P
VAR_EXTERNAL gAlarm : BOOL; gStop : BOOL; sensor : BOOL; ack : BOOL; END_VAR
VAR CONSTANT T_SUP : TIME := T#100ms; END_VAR
VAR sup : FB_Sup; END_VAR
sup(In := sensor, TMax := T_SUP);
IF sup.Error THEN
  gAlarm := TRUE;
END_IF;
IF ack THEN
  gAlarm := FALSE;
END_IF;
gStop := gAlarm;
END_PROGRAM

CONFIGURATION C
  VAR_GLOBAL gAlarm : BOOL; gStop : BOOL; sensor : BOOL; ack : BOOL; END_VAR
  RESOURCE R ON PLC
    TASK T (INTERVAL := T#10ms, PRIORITY := 1);
    PROGRAM Main WITH T : P;
  END_RESOURCE
END_CONFIGURATION
)";

struct Small {
  CampaignBuild cb;
  std::vector<Mutant> mutants;

  Small() {
    st::CompileOptions whole;
    whole.condition_jumps = false;  // as `plcfi mutate` compiles (Campaign::for_mutation)
    whole.loop_tails = false;
    cb.build = st::build_sources({{"small.st", kProgram}}, whole);
    EXPECT_TRUE(cb.build->ok()) << cb.build->diags.render_all();
    FmeaRow row;
    row.alarm = "gAlarm";
    cb.spec.fmea.rows.push_back(row);
    for (uint32_t f = 0; f < cb.build->app->file_paths.size(); ++f)
      if (cb.build->app->file_paths[f] == "small.st") cb.program_files.push_back(f);
    mutants = generate_mutants(cb);
  }

  const Mutant* find(MutationOp op, uint32_t line) const {
    for (const auto& m : mutants)
      if (m.op == op && m.line == line) return &m;
    return nullptr;
  }

  // Runs `scans` 10 ms scans with the given inputs (mutant applied when m != null) and
  // returns the scan index at which gAlarm first read TRUE (-1: never).
  int first_alarm(const Mutant* m, bool sensor, int scans, bool ack = false) {
    std::vector<CodePatch> uc;
    std::vector<ImagePatch> ui;
    if (m) apply_mutant(cb, *m, &uc, &ui);
    const st::Application& app = *cb.build->app;
    st::Machine vm(app);
    EXPECT_TRUE(vm.cold_restart());
    std::string err;
    auto alarm = st::resolve(app, "gAlarm", &err);
    auto s = st::resolve(app, "sensor", &err);
    auto a = st::resolve(app, "ack", &err);
    int at = -1;
    for (int k = 0; k < scans && at < 0; ++k) {
      st::write_bool(vm, *s, sensor);
      st::write_bool(vm, *a, ack);
      vm.set_now(int64_t{k} * 10'000'000);
      EXPECT_TRUE(vm.call(app.programs[0].pou->entry, app.programs[0].addr));
      if (st::read_bool(vm, *alarm)) at = k;
    }
    if (m) undo_mutant(cb, uc, ui);
    return at;
  }
};

TEST(Mutate, OperatorsOnASmallProgram) {
  Small s;
  // Original: the alarm comes at 100 ms of a TRUE sensor, never without it.
  EXPECT_EQ(s.first_alarm(nullptr, true, 50), 10);
  EXPECT_EQ(s.first_alarm(nullptr, false, 50), -1);

  const Mutant* remove = s.find(MutationOp::RemoveAssign, 23);
  ASSERT_NE(remove, nullptr);
  EXPECT_EQ(remove->change, "`gAlarm := TRUE;` removed");
  EXPECT_EQ(remove->variable, "gAlarm");
  EXPECT_EQ(remove->col, 3u);
  EXPECT_EQ(s.first_alarm(remove, true, 50), -1);

  const Mutant* negate = s.find(MutationOp::NegateCond, 22);
  ASSERT_NE(negate, nullptr);
  EXPECT_EQ(negate->change, "condition of `IF sup.Error THEN` negated");
  EXPECT_EQ(s.first_alarm(negate, false, 5), 0);  // Error FALSE: the alarm at once

  const Mutant* drop = s.find(MutationOp::DropCond, 22);
  ASSERT_NE(drop, nullptr);
  EXPECT_EQ(s.first_alarm(drop, false, 5), 0);

  const Mutant* off = s.find(MutationOp::ForceFalse, 22);
  ASSERT_NE(off, nullptr);
  EXPECT_EQ(s.first_alarm(off, true, 50), -1);

  const Mutant* latch = s.find(MutationOp::ClearLatch, 23);
  ASSERT_NE(latch, nullptr);
  EXPECT_EQ(s.first_alarm(latch, true, 50), -1);

  // The supervising FB's latch is a feeder: its Error output is read by the alarm's IF.
  const Mutant* fb_set = s.find(MutationOp::RemoveAssign, 8);
  ASSERT_NE(fb_set, nullptr);
  EXPECT_EQ(fb_set->variable, "FB_Sup.Error");
  EXPECT_EQ(s.first_alarm(fb_set, true, 50), -1);

  // The reset's guard dropped: the alarm is cleared in every scan after it was set.
  const Mutant* reset_drop = s.find(MutationOp::DropCond, 25);
  ASSERT_NE(reset_drop, nullptr);
  EXPECT_EQ(s.first_alarm(reset_drop, true, 50), -1);

  // The preset T_SUP (100 ms) scaled: x2 alarms at 200 ms, x0.5 at 50 ms.
  std::vector<const Mutant*> scaled;
  for (const auto& m : s.mutants)
    if (m.op == MutationOp::ScaleTimer) scaled.push_back(&m);
  ASSERT_EQ(scaled.size(), 2u);
  EXPECT_NE(scaled[0]->change.find("x2 to T#200ms"), std::string::npos) << scaled[0]->change;
  EXPECT_EQ(s.first_alarm(scaled[0], true, 50), 20);
  EXPECT_EQ(s.first_alarm(scaled[1], true, 50), 5);

  // Undo restored everything: the original behaves as before.
  EXPECT_EQ(s.first_alarm(nullptr, true, 50), 10);
}

TEST(Mutate, DeadCodeIsProvenEquivalent) {
  Small s;
  const Mutant* dead = s.find(MutationOp::RemoveAssign, 14);
  ASSERT_NE(dead, nullptr);
  EXPECT_TRUE(dead->equivalent);
  EXPECT_EQ(dead->proof, "FB_Unused is never called from a task's program: its code is unreachable");
  // Exactly the mutants of FB_Unused are equivalent.
  for (const auto& m : s.mutants) EXPECT_EQ(m.equivalent, m.pou->name == "FB_Unused") << m.change;
  // Patches never repeat, and the list is the same on a second generation.
  auto again = generate_mutants(s.cb);
  ASSERT_EQ(again.size(), s.mutants.size());
  for (size_t i = 0; i < again.size(); ++i) EXPECT_EQ(again[i].change, s.mutants[i].change);
}

TEST(Mutate, PatchProofs) {
  Small s;
  const st::Application& app = *s.cb.build->app;
  const Mutant* remove = s.find(MutationOp::RemoveAssign, 23);
  ASSERT_NE(remove, nullptr);
  std::vector<Mutant> ms(3, *remove);
  for (size_t i = 0; i < ms.size(); ++i) ms[i].index = i;
  // #0 rewrites the instruction with its own words; #2 repeats #1's patch.
  ms[0].code[0].words.assign(app.code.begin() + ms[0].pc, app.code.begin() + ms[0].pc + ms[0].code[0].words.size());
  mark_patch_equivalents(app, &ms);
  EXPECT_TRUE(ms[0].equivalent);
  EXPECT_EQ(ms[0].proof, "the patched program is byte-identical to the original");
  EXPECT_FALSE(ms[1].equivalent);
  EXPECT_TRUE(ms[2].equivalent);
  EXPECT_EQ(ms[2].proof, "the same patch as mutant #1 (reported there)");
  // The generated list has no duplicate patch.
  for (const auto& m : s.mutants) {
    if (m.equivalent) {
      EXPECT_EQ(m.proof.find("the same patch"), std::string::npos) << m.change;
    }
  }
}

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

CampaignBuild stamping_fixed(bool for_mutation = true) {
  Campaign c;
  std::string err;
  EXPECT_TRUE(load_campaign((kRoot / "faults/campaigns/stamping/campaign.yaml").string(), &c, &err)) << err;
  c.programs = {(kRoot / "st_programs/stamping/stamping_fixed.st").string()};
  c.for_mutation = for_mutation;  // true: as `plcfi mutate` prepares it
  CampaignBuild cb;
  EXPECT_TRUE(prepare_campaign(std::move(c), &cb, &err)) << err;
  return cb;
}

TEST(Mutate, ConditionsCompiledAsChainsOfJumpsAreRefused) {
  // `IF (gSliderError OR gStampCylError) AND NOT gStampStop THEN` is a chain of three
  // jumps when compiled for a campaign; negating the last of them is no mutant of the IF.
  CampaignBuild chained = stamping_fixed(false);
  ASSERT_TRUE(chained.build && chained.build->app);
  EXPECT_TRUE(chained.build->app->condition_chains);
  MutationRun r;
  std::string err;
  EXPECT_FALSE(run_mutation(chained, MutateOptions{}, &r, &err));
  EXPECT_NE(err.find("chains of jumps, statements copied into arms, IFs as selects, ELSIFs reading"), std::string::npos) << err;
  EXPECT_FALSE(stamping_fixed().build->app->condition_chains);
}

TEST(Mutate, StampingJournalSameWithWorkersAndMergedShards) {
  fs::path dir = fs::temp_directory_path() / ("plcfi_mutate_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  CampaignBuild cb = stamping_fixed();
  auto run = [&](unsigned jobs, unsigned shard, unsigned shards, const std::string& name) {
    MutateOptions opt;
    opt.jobs = jobs;
    opt.shard = shard;
    opt.shards = shards;
    opt.out_dir = (dir / name).string();
    MutationRun r;
    std::string err;
    EXPECT_TRUE(run_mutation(cb, opt, &r, &err)) << err;
    return r;
  };
  MutationRun one = run(1, 0, 0, "one");
  // The killed and surviving mutants this test relies on.
  ASSERT_FALSE(one.mutants.empty());
  bool saw_kill = false, saw_survivor = false;
  for (size_t i = 0; i < one.mutants.size(); ++i) {
    const Mutant& m = one.mutants[i];
    if (m.change == "`gStampCylError := TRUE;` removed") {
      EXPECT_EQ(one.results[i].status, MutantStatus::Killed);
      EXPECT_EQ(one.results[i].kill, "fail");
      EXPECT_EQ(one.results[i].executions, 1u);  // stopped at the first kill
      saw_kill = true;
    }
    if (m.change == "`gStampStop := FALSE;` removed") {  // the class's recovery acknowledges: the stop stays
      EXPECT_EQ(one.results[i].status, MutantStatus::Killed);
      EXPECT_NE(one.results[i].detail.find("not recovered: gStampStop still TRUE"), std::string::npos)
          << one.results[i].detail;
    }
    if (m.change == "`PressureSetpoint := 0;` removed" && m.line == 272) {  // the step actions' default, also the safe state's
      EXPECT_EQ(one.results[i].status, MutantStatus::Survived);
      EXPECT_TRUE(one.results[i].reached);
      EXPECT_NE(one.results[i].detail.find("PressureSetpoint also written"), std::string::npos);
      saw_survivor = true;
    }
  }
  EXPECT_TRUE(saw_kill);
  EXPECT_TRUE(saw_survivor);
  double score = mutation_score(one);
  EXPECT_GT(score, 0.5);
  EXPECT_LT(score, 1.0);

  run(2, 0, 0, "two");
  run(1, 0, 2, "s0");
  run(2, 1, 2, "s1");
  std::string single = read(dir / "one/mutants.jsonl");
  EXPECT_EQ(read(dir / "two/mutants.jsonl"), single);
  std::string err;
  std::string s0 = (dir / "s0/mutants.jsonl").string(), s1 = (dir / "s1/mutants.jsonl").string();
  ASSERT_TRUE(merge_mutant_journals({s1, s0}, (dir / "merged.jsonl").string(), &err)) << err;
  EXPECT_EQ(read(dir / "merged.jsonl"), single);

  // A shard missing, twice, or from another run: refused with the reason.
  EXPECT_FALSE(merge_mutant_journals({s0}, (dir / "bad.jsonl").string(), &err));
  EXPECT_EQ(err, "shard 1/2 is missing");
  EXPECT_FALSE(merge_mutant_journals({s0, s0}, (dir / "bad.jsonl").string(), &err));
  EXPECT_NE(err.find("shard 0/2 also in"), std::string::npos) << err;
  std::string other = read(s1);
  other.replace(other.find("\"seed\":1"), 8, "\"seed\":2");
  { std::ofstream((dir / "other.jsonl")) << other; }
  EXPECT_FALSE(merge_mutant_journals({s0, (dir / "other.jsonl").string()}, (dir / "bad.jsonl").string(), &err));
  EXPECT_NE(err.find("another mutation run"), std::string::npos) << err;
  EXPECT_FALSE(merge_mutant_journals({(dir / "one/mutants.jsonl").string()}, (dir / "bad.jsonl").string(), &err));
  EXPECT_NE(err.find("not a shard journal"), std::string::npos) << err;
  fs::remove_all(dir);
}

}  // namespace

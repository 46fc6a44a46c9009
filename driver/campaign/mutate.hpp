// Mutation analysis of a program's error handling: mutants are patches of the compiled
// program (bytecode words, or the cold-start image of a constant), made against the one
// CampaignBuild, and each is judged by running the campaign on it (prepare once, then
// run_campaign per mutant, early stop at the first kill).
//
// Which variables the operators act on ("alarm/stop variables"), in order:
//   1. the FMEA alarm column's variables;
//   2. every program variable named in the fault classes' requirement and forbidden
//      formulas (gStampStop, SliderExtend, PressureSetpoint, ...);
//   3. feeders: BOOL variables of the same POU (VAR, VAR_OUTPUT) and BOOL outputs of user
//      FB instances read by the condition of an IF/ELSIF that writes a variable of 1-3
//      (pressureFault, FB_Cylinder.Error), to a fixpoint. Inputs are never feeders.
// Only code of the program's own files is mutated (not the standard library, not the
// generated preconditions and monitors).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "driver.hpp"
#include "generate.hpp"

namespace plcfi::campaign {

enum class MutationOp : uint8_t {
  RemoveAssign,  // remove-assign: the store to the variable becomes NOPs
  NegateCond,    // negate-cond: the IF/ELSIF's conditional jump inverted
  DropCond,      // drop-cond: the conditional jump removed (the branch always taken)
  ForceFalse,    // force-false: the jump made unconditional (the branch never taken)
  ScaleTimer,    // scale-timer: a TIME constant feeding a timer's PT x2 or x0.5
  ClearLatch,    // clear-latch: `x := TRUE` of a latched variable stores FALSE instead
};
const char* mutation_op_name(MutationOp op);
constexpr int kMutationOps = 6;

struct CodePatch {
  uint32_t pc = 0;
  std::vector<uint32_t> words;  // code[pc .. pc + words.size()) := words
};
struct ImagePatch {
  uint32_t addr = 0;
  std::vector<uint8_t> bytes;  // init_image[addr ..) := bytes (a constant's slot)
};

struct Mutant {
  size_t index = 0;
  MutationOp op = MutationOp::RemoveAssign;
  std::string file;  // as the program was named to the compiler
  uint32_t line = 0, col = 0;
  std::string variable;  // the alarm/stop variable (or constant) the operator is about
  std::string change;    // "`gStampCylError := TRUE;` removed"
  uint32_t pc = 0;       // the mutated instruction (ScaleTimer: the first instruction reading the constant)
  int32_t branch = -1;   // branch id whose body holds pc (-1: runs whenever its POU runs, or unknown)
  bool branch_known = false;  // branch = -1 is proven "runs with its POU"
  std::vector<CodePatch> code;
  std::vector<ImagePatch> image;
  bool equivalent = false;
  std::string proof;  // why it is equivalent
  std::string writers;  // other statements writing the variable ("stamping_fixed.st:255, 326"), for the reasons
  const st::PouInfo* pou = nullptr;  // the POU whose code or constant is patched
};

// The mutants of the campaign's program (compiled with CompileOptions::condition_jumps
// and loop_tails off: Campaign::for_mutation), in a deterministic order (POU code order, then
// operator). Equivalence proofs are filled in: byte-identical patch, duplicate of an
// earlier mutant, or code unreachable from every task entry.
std::vector<Mutant> generate_mutants(const CampaignBuild& cb);
// The proofs from the patches alone (part of generate_mutants): a patch that leaves code
// and image byte-identical, and a patch equal to an earlier mutant's (reported there).
void mark_patch_equivalents(const st::Application& app, std::vector<Mutant>* mutants);

// Applies / undoes a mutant's patches on cb's application (in place; the sizes never change).
void apply_mutant(CampaignBuild& cb, const Mutant& m, std::vector<CodePatch>* undo_code, std::vector<ImagePatch>* undo_image);
void undo_mutant(CampaignBuild& cb, const std::vector<CodePatch>& undo_code, const std::vector<ImagePatch>& undo_image);

enum class MutantStatus : uint8_t { Killed, Survived, Equivalent };
const char* mutant_status_name(MutantStatus s);

struct MutantResult {
  MutantStatus status = MutantStatus::Survived;
  std::string kill;       // killed: "fail", "trap" or "not-reached"
  std::string killed_by;  // "TC3 path 1"
  std::string detail;     // killed: the verdict's reason; survived: why it survived; equivalent: the proof
  size_t executions = 0;  // executions the campaign ran on the mutant
  bool reached = false;   // the mutated code ran in a test window (as far as branch coverage tells)
};

// The original program's campaign: what a mutant is compared with.
struct Baseline {
  std::vector<bool> passed;  // per case: some execution PASSed
  std::vector<bool> tested;  // per case: executed at all
  size_t executions = 0, pass = 0, fail = 0;
  std::string end_reason;
};

struct MutateOptions {
  unsigned jobs = 1;              // worker processes (forked after the campaign is prepared)
  unsigned shard = 0, shards = 0;  // shards > 0: evaluate only the mutants with index % shards == shard (0-based)
  std::string out_dir;            // mutants.jsonl ("": none)
};

struct MutationRun {
  std::string fingerprint;  // campaign fingerprint and the mutant list
  Baseline baseline;
  std::vector<Mutant> mutants;
  std::vector<MutantResult> results;  // index = mutant index
  std::vector<bool> evaluated;        // in this run's shard
  double wall_s = 0;
};

// Runs the baseline and every mutant of this shard. false + *err: the campaign cannot run
// (plant, output folder) or a worker died.
bool run_mutation(CampaignBuild& cb, const MutateOptions& opt, MutationRun* out, std::string* err);

// Judges one mutant (in the calling process).
MutantResult evaluate_mutant(CampaignBuild& cb, const Baseline& base, const Mutant& m, std::string* err);
bool run_baseline(CampaignBuild& cb, Baseline* out, std::string* err);

// The journal: a header line, then one line per evaluated mutant in index order. Nothing
// time-dependent, so runs with any --jobs and merged shards write the same bytes.
std::string mutation_header_line(const CampaignBuild& cb, const MutationRun& run, const MutateOptions& opt);
std::string mutant_line(const Mutant& m, const MutantResult& r);
bool write_mutation_journal(const CampaignBuild& cb, const MutationRun& run, const MutateOptions& opt, std::string* err);

// Combines the shard journals of one mutation run (same fingerprint, every shard once,
// disjoint and complete) into the journal a single run writes, byte for byte.
bool merge_mutant_journals(const std::vector<std::string>& inputs, const std::string& out_path, std::string* err);

// The text report: score, per-operator counts, survivors with file:line:col, change, reason.
std::string mutation_report(const CampaignBuild& cb, const MutationRun& run);
// killed / (generated - equivalent) over the evaluated mutants; -1 when none counts.
double mutation_score(const MutationRun& run);

}  // namespace plcfi::campaign

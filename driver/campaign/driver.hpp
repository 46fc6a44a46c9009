// The passive fault-injection driver. Before each scan it checks the preconditions of all
// pending test cases (one generated program, one VM call); when a case's precondition
// becomes true on a control-flow path not tested yet, it injects the case's fault into
// the image overlay; after each scan the case's fault-class monitors decide PASS or
// FAIL; then the fault is withdrawn, program and plant restart, and the search goes on
// until every case is tested on up to max_paths paths, no new case/path turns up within
// the search window, or the time budget is spent.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "execution.hpp"
#include "generate.hpp"
#include "journal.hpp"
#include "native/native.hpp"
#include "runtime/backend.hpp"
#include "runtime/realtime.hpp"

namespace plcfi::campaign {

struct DriverOptions {
  std::string out_dir;  // results.jsonl and the VCDs; empty: no files
  bool resume = false;  // continue the journal in out_dir
  bool vcd = true;
  std::function<void(const Execution&, const Progress&)> on_verdict;
  std::function<void(const Progress&)> on_progress;  // about every simulated second
  // Real I/O: scans paced on real-time deadlines; the run ends (faults withdrawn, safe
  // outputs written) on a stop signal or when io_lost() names a lost device.
  bool realtime = false;
  const rt::StopSignals* signals = nullptr;
  std::function<std::string()> io_lost;
  std::vector<std::pair<rt::ImageRef, int64_t>> safe_state;
  const st::NativeCode* native = nullptr;  // run program, preconditions and monitors natively
  // A share of the runs (parallel.hpp): runs r with r % share_n == share_k are tested, the
  // others end at their injection. on_run gets every run's record in run order (false:
  // stop); with on_run set, no journal is written here (VCDs are, for the own runs).
  int share_k = 0, share_n = 1;
  std::function<bool(const RunRecord&)> on_run;
  const JournalState* resumed = nullptr;  // with on_run: start from this journal state
  // Mutation analysis (mutate.hpp). stop_after: called after each verdict; true ends the
  // campaign there (end_reason "stopped after ..."). window_branches: when set, the branch
  // ids the program took in the scans of every test window are OR-ed into it
  // (Machine::taken() layout).
  std::function<bool(const Execution&)> stop_after;
  std::vector<uint64_t>* window_branches = nullptr;
  // Coverage exports: when set, receives per branch id the scans of this invocation (every
  // run: search and test windows) that took the branch (st::Machine::hits()).
  std::vector<uint64_t>* branch_hits = nullptr;
};

struct CampaignResult {
  std::vector<Execution> executions;  // in the order they ran (resumed ones first)
  std::vector<size_t> not_reached;    // case indexes never injected
  Progress progress;
  size_t resumed = 0;                 // executions read back from the journal
  std::string end_reason;             // "all cases tested", "search window ...", "budget ..."
  bool interrupted = false;           // stopped by a signal or lost communication (incomplete)
  std::vector<size_t> pending;        // cases not tested because the campaign was interrupted
  // Real-time runs: wake latency, execution time and overruns (text and JUnit properties).
  std::string realtime_text;
  std::vector<std::pair<std::string, std::string>> realtime;
  double wall_s = 0;
};

// Runs the campaign on the offline plant model. Fails (false, *err) only on errors that
// stop the campaign: an unusable plant, an unwritable output folder, a journal of another
// campaign.
bool run_campaign(CampaignBuild& cb, const DriverOptions& opt, CampaignResult* out, std::string* err);

// The same driver on any backend (tests use synthetic plants).
bool run_campaign_on(CampaignBuild& cb, rt::IoBackend* backend, const DriverOptions& opt, CampaignResult* out,
                     std::string* err);

// The branch points (file:line) that set an execution's path apart from the other paths of
// its case; empty when the case ran on one path.
std::vector<std::string> distinguishing_branches(const CampaignBuild& cb, const std::vector<Execution>& all,
                                                 const Execution& e);

// A fingerprint of the generated test set; a journal written for another one is refused.
std::string campaign_fingerprint(const CampaignBuild& cb);

}  // namespace plcfi::campaign

// Campaigns on several processes and machines, with the journal one process writes.
//
// Which case a run injects depends on what earlier runs injected (a case and path once
// tested is not tested again), never on how their tests ended: the search of a run is the
// fault-free program on the plant from a restart with the run's seed, up to the first
// precondition of an untested case and path. So every process searches in every run and
// keeps the same record of tested cases, but tests only its share of the runs (run r
// belongs to share r mod N); a run of another share ends at its injection. Searching is
// cheap next to testing when a campaign has many cases (exploration) or long tests.
//
// The records of the runs' owners, taken in run order, give back what one process does:
// RunSequencer adds up the scans and scan-clock time, applies the time budget (a share
// cannot know it: the test times of other shares are missing, so each share stops no
// earlier than the campaign would) and ends where the single run ends. `--jobs N` runs the
// shares in N forked worker processes and writes the journal as records arrive;
// `--shard K/N` runs one share and writes a shard file; merge_shards() combines the N
// shard files into the journal. Both need cold restarts (a warm restart carries a run's
// state into the next, so runs cannot be split) and the offline plant (virtual time).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "driver.hpp"
#include "execution.hpp"
#include "journal.hpp"

namespace plcfi::campaign {

class RunSequencer {
 public:
  struct Limits {
    int64_t budget_ns = 0;
    int64_t tick_ns = 0;
    int64_t search_window_ns = 0;
    int max_paths = 1;
    size_t cases = 0;
  };
  // start: the journal state of a resumed campaign (empty for a new one).
  RunSequencer(const Limits& lim, const JournalState& start);

  bool ended() const { return ended_; }
  uint64_t next_run() const { return pr_.run; }
  const std::string& end_reason() const { return end_reason_; }
  const Progress& progress() const { return pr_; }

  struct Fed {
    bool executed = false;  // the run ends with an execution: its journal line follows
    std::string line;       // with campaign_ns and scans of the campaign so far
    common::Json object;    // the same line, parsed
  };
  // Takes the record of run next_run(), as its owner saw it (Executed or Ended). false and
  // *err when the record cannot be that run's (another run, an inconsistent budget end).
  bool feed(const RunRecord& rec, Fed* out, std::string* err);

 private:
  void check_end();
  Limits lim_;
  Progress pr_;
  std::vector<int> paths_;
  bool ended_ = false;
  std::string end_reason_;
};

// A record as one JSON line and back (the worker pipes and the shard files).
std::string record_json(const RunRecord& r);
bool parse_record(const std::string& line, RunRecord* r, std::string* why);

// Shares "K/N": 0 <= K < N <= 1024. false and *why otherwise.
bool parse_share(const std::string& text, int* k, int* n, std::string* why);

// Runs the campaign on `jobs` worker processes (forked; each opens its own plant), writes
// the journal in opt.out_dir as the single run writes it, calls opt.on_verdict in run
// order. Errors as run_campaign; also a worker that dies.
bool run_campaign_jobs(CampaignBuild& cb, int jobs, const DriverOptions& opt, CampaignResult* out, std::string* err);

struct ShardSummary {
  uint64_t runs = 0;        // runs searched
  size_t executions = 0;    // runs of this share tested
  size_t pass = 0, fail = 0;
  std::string end_reason;   // where this share stopped
};
// Runs share k of n and writes the shard file `shard_path` (VCDs of the share's tests go to
// opt.out_dir).
bool run_campaign_shard(CampaignBuild& cb, int k, int n, const DriverOptions& opt, const std::string& shard_path,
                        ShardSummary* out, std::string* err);

struct MergedExecution {
  std::string case_id, transition, verdict, reason;
  int path = 0;
  uint64_t run = 0;
};
struct MergeResult {
  std::string campaign;
  std::vector<MergedExecution> executions;  // in run order
  std::vector<std::string> not_reached;     // case ids never executed
  size_t cases = 0;
  Progress progress;
  std::string end_reason;
  size_t traces_copied = 0;                 // VCDs copied from beside the shard files
  std::vector<std::string> traces_missing;  // VCDs the journal names that were not there
};
// True when `path` holds a campaign shard file (its first line says so).
bool is_campaign_shard(const std::string& path);
// Checks that the files are the N shards of one campaign, each complete, writes the
// journal the single run writes to `journal_path`, and copies the traces of its
// executions from beside the shard files to beside the journal.
bool merge_shards(const std::vector<std::string>& files, const std::string& journal_path, MergeResult* out,
                  std::string* err);

}  // namespace plcfi::campaign

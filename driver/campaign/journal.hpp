// The results journal (results.jsonl): a header line naming the campaign, then one JSON
// object per verdict, appended and flushed to disk (fsync) as each test ends, so a killed
// campaign resumes where it stopped without re-running or duplicating a finished case.
// No wall-clock values: the same campaign and seed give an identical journal. The lines are
// JSON (nlohmann-json, common/json.hpp) with the fields in a fixed order.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "common/json.hpp"
#include "execution.hpp"
#include "generate.hpp"

namespace plcfi::campaign {

struct JournalState {
  std::vector<Execution> executions;
  uint64_t next_run = 0;
  int64_t campaign_ns = 0;
  uint64_t scans = 0;
};

class Journal {
 public:
  Journal() = default;
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;
  ~Journal();

  // Opens `path`. With resume, reads the verdicts already there into *state (a torn last
  // line, from a kill in mid-write, is dropped) and refuses a journal of another
  // campaign; without it, starts a new journal.
  bool open(const std::string& path, bool resume, const std::string& campaign, const std::string& fingerprint,
            const std::vector<TestCase>& cases, JournalState* state, std::string* err);
  bool is_open() const { return f_ != nullptr; }
  // The plant the campaign runs on (a built-in name or a plant file), written into the
  // header line by open().
  void set_plant(std::string plant) { plant_ = std::move(plant); }
  // Appends one verdict and forces it to disk.
  bool append(const Execution& e, const Progress& p, std::string* err);
  // Appends a verdict line rendered elsewhere (parallel runs), and forces it to disk.
  bool append_line(const std::string& line, std::string* err);

 private:
  bool write_line(const std::string& line, std::string* err);
  std::FILE* f_ = nullptr;
  std::string path_, plant_;
  const std::vector<TestCase>* cases_ = nullptr;
};

// One verdict as a journal line (without the newline); exposed for tests.
std::string journal_line(const Execution& e, const TestCase& tc, const Progress& p);
// The header line; `plant` empty: none named.
std::string journal_header(const std::string& campaign, const std::string& plant, const std::string& fingerprint,
                           size_t cases);
// An execution from a journal line's object (case looked up in `cases`); false and *why
// when a field the journal needs is missing or malformed.
bool parse_execution(const common::Json& o, const std::vector<TestCase>& cases, Execution* out, std::string* why);

}  // namespace plcfi::campaign

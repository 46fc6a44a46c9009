// The run history of test scripts, one row per run, in an SQLite database: the verdict,
// when, m_ci and the cycles waited, and hashes of the program and of the POUs the test
// involves. p_lst (the passes among the latest runs) counts only runs since those POUs
// last changed. Several processes may write one history file at once (SQLite's locking,
// WAL journal, a busy timeout).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "engine.hpp"

struct sqlite3;

namespace plcfi::script {

struct HistoryRow {
  int64_t id = 0;
  std::string test;
  std::string verdict;  // passed, failed, undecidable
  std::string time;     // UTC, ISO 8601: 2026-11-25T06:40:12Z
  std::optional<double> mci;
  std::optional<int64_t> cycles;
  std::string program_hash;
  std::string pou_hash;
  std::string reason;
};

class History {
 public:
  // Opens or creates the database (and its folder). False with "PATH: message" in err.
  static std::unique_ptr<History> open(const std::string& path, std::string* err);
  ~History();
  History(const History&) = delete;
  History& operator=(const History&) = delete;

  // Passes among the latest `psi` runs of `test` that share pou_hash, counted back to the
  // first run with another hash (a change of the test's POUs starts the count anew).
  bool passes_since_change(const std::string& test, const std::string& pou_hash, int64_t psi, int64_t* out,
                           std::string* err);
  bool add(const HistoryRow& row, std::string* err);
  // Newest first; `test` empty: every test. `limit` 0: all.
  bool list(const std::string& test, size_t limit, std::vector<HistoryRow>* out, std::string* err);
  const std::string& path() const { return path_; }

 private:
  History() = default;
  std::string error_text() const;
  sqlite3* db_ = nullptr;
  std::string path_;
};

// $PLCFI_HISTORY, else $XDG_STATE_HOME/plcfi/history.sqlite, else
// ~/.local/state/plcfi/history.sqlite, else ./plcfi-history.sqlite.
std::string default_history_path();

// The current time as HistoryRow::time.
std::string utc_now();

// The POUs a script's variables reach: the PROGRAM instances they name, the POUs whose
// text uses the globals they name, and everything those POUs use by name, transitively
// (FB types, FUNCTIONs, methods). `names` gets them sorted; the result is a hash of their
// source text, so a change elsewhere in the files leaves the history of the test alone.
std::string involved_pous_hash(const st::Build& b, const std::vector<std::string>& var_paths, std::vector<std::string>* names);
// A hash of all the program's source files.
std::string program_hash(const st::Build& b);

}  // namespace plcfi::script

// Branch coverage of an ST program in the formats other tools read: an lcov tracefile
// (genhtml renders it) and Cobertura XML (CI servers show it).
//
// What the counts mean. The engine records, per scan (per test execution or cycle of
// `plcfi test`), which arms were taken (Machine::set_count_hits); a count is the number
// of scans that took the arm at least once, not the number of times.
// - A decision is one IF statement (arms IF, ELSIF..., ELSE), one CASE statement (one arm
//   per label list, ELSE) or one FOR/WHILE loop (one arm: the body ran). BRDA records sit
//   on the statement's line, one block per decision, one branch per arm. The engine has
//   no id for "no arm taken" of an IF or CASE without ELSE, nor for "loop body skipped":
//   those outcomes are not listed. A REPEAT body always runs: no branch, only lines.
// - Taken "-": the statement is known not to have run (the arm holding it was never
//   taken, or it has an ELSE and no arm was ever taken); else the count, 0 included.
// - DA lines: the first statement of each arm (exact: it ran in the scans that took the
//   arm), ELSE and CASE label lines (exact), and the lines of IF/ELSIF/CASE/loop
//   statements, counted as the scans known to have run them: at least the most taken arm
//   from there on. An IF without ELSE whose condition was never TRUE thus shows 0.
//   Other statement lines carry no count (they are neither hit nor missed).
// - No FN records: the engine does not count POU entries.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "engine.hpp"
#include "vm/program.hpp"

namespace plcfi::report {

struct CoverageDecision {
  uint32_t line = 0;
  uint32_t block = 0;                        // decisions on one line: 0, 1, ...
  std::vector<std::optional<uint64_t>> arms;  // scans that took the arm; nullopt: never reached
};

struct FileCoverage {
  std::string path;                    // absolute
  std::map<uint32_t, uint64_t> lines;  // line -> scans (DA)
  std::vector<CoverageDecision> decisions;  // by line, then block
  size_t branches() const;
  size_t branches_taken() const;
  size_t lines_hit() const;
};

// The coverage of the files `files` (indices into app.file_paths: the program under test,
// neither the standard library nor generated units) from per-branch-id scan counts
// (Machine::hits(); shorter vectors count as zeros). Files without branch points are left
// out. Sorted by path.
std::vector<FileCoverage> coverage_by_file(const st::Application& app, const std::vector<uint64_t>& hits,
                                           const std::vector<uint32_t>& files);

// The program's own ST files of a build (for coverage_by_file): neither the libraries nor
// generated or imported text (monitors, preconditions, --until, PLCopen XML/TwinCAT units,
// whose lines are not the file's), nor test files.
std::vector<uint32_t> coverage_files(const st::Build& b);

// lcov tracefile text; `test_name` becomes TN: (characters other than letters, digits and
// '_' become '_').
std::string lcov_tracefile(const std::vector<FileCoverage>& files, const std::string& test_name);

// Cobertura XML (coverage-04 DTD): one package per source folder, one class per file;
// `timestamp_ms` is written as is (pass a fixed value for reproducible files).
std::string cobertura_xml(const std::vector<FileCoverage>& files, int64_t timestamp_ms);

// The timestamp a CLI run writes: SOURCE_DATE_EPOCH (seconds) when set, else now, in ms.
int64_t coverage_timestamp_ms();

// Writes text to path (through a temporary file); false with "PATH: cannot write (REASON)".
bool write_coverage_file(const std::string& path, const std::string& text, std::string* err);

}  // namespace plcfi::report

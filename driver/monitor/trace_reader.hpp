// Recorded traces for offline requirement checks: CSV (a header `time,var,...` or just
// `var,...`; one row per state) and VCD (as plcfi sim writes it). Read as a stream of
// states so memory does not grow with the trace length.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "engine.hpp"

namespace plcfi::monitor {

struct TraceColumn {
  std::string name;  // path as in the header: PosCrane, Main.step, %IX0.1
  // Time, Date, Tod, Dt: a CSV column holding IEC literals (T#1s500ms, D#2024-03-01,
  // TOD#12:00:00, DT#2024-03-01-12:00:00), its values in nanoseconds as plcfi holds them.
  enum class Kind { Bool, Int, Real, Time, Date, Tod, Dt } kind = Kind::Bool;
  bool is_time() const { return kind >= Kind::Time; }
};

enum class TraceFormat { Csv, Vcd };

// Limits of what a trace may hold. Far above anything plcfi writes; they make a binary,
// endless or hostile input an error at its line and column within a moment instead of
// a hang, an exhausted memory or an exhausted stack.
struct TraceLimits {
  static constexpr size_t kMaxLineBytes = 16u << 20;     // one CSV line (a million columns)
  static constexpr size_t kMaxWordBytes = 1u << 20;      // one VCD word
  static constexpr size_t kMaxSectionBytes = 16u << 20;  // one VCD $...$end section
  static constexpr size_t kMaxColumns = 1'000'000;
  static constexpr size_t kMaxNameDepth = 64;            // scopes and dotted parts of a name
};

class TraceReader {
 public:
  virtual ~TraceReader() = default;
  // Opens a trace (by extension: .vcd, else CSV). Without a time column time(i) is
  // i * cycle_ns; a VCD with cycle_ns > 0 is sampled every cycle, else one state per
  // time stamp. Errors read "FILE:LINE:COL: message" (or "FILE: message" when the file
  // cannot be read at all). A CSV trace is read twice (the first pass finds each
  // column's type and checks every row), so it must be a regular file. A CSV cell is a
  // number, TRUE/FALSE, or a TIME, LTIME, DATE, TOD or DT literal as plcfi's CSV traces
  // write them (T#1s500ms; a malformed one is an error at its line and column); a plain
  // number in a time column is its value in nanoseconds, as older traces wrote it.
  static std::unique_ptr<TraceReader> open(const std::string& path, int64_t cycle_ns, std::string* err);
  // The same from memory (tests, fuzzing); `name` stands for the file in messages.
  static std::unique_ptr<TraceReader> from_text(const std::string& name, std::string text, TraceFormat format,
                                                int64_t cycle_ns, std::string* err);

  const std::vector<TraceColumn>& columns() const { return columns_; }
  bool has_time() const { return has_time_; }
  // Next state; false at the end or on an error (err non-empty then). Times never
  // decrease: a trace whose time goes back is an error at that line.
  virtual bool next(int64_t* t_ns, std::vector<double>* values, std::string* err) = 0;
  // The values of the state next() gave last, of the columns that are is_time(), in
  // nanoseconds exactly (a double holds a DT of today to 256 ns only); index = column.
  // Empty when the trace has no such column.
  const std::vector<int64_t>& time_values() const { return time_values_; }

 protected:
  std::vector<TraceColumn> columns_;
  std::vector<int64_t> time_values_;
  bool has_time_ = false;
};

// ST declarations of a trace's variables, so monitors compile against them: plain names
// become globals, dotted names programs (Main.step -> PROGRAM Main with step), %-addresses
// need none. Fails for names that are not ST identifiers or nest deeper than
// TraceLimits::kMaxNameDepth. Linear in the total length of the names.
bool trace_program(const std::vector<TraceColumn>& cols, std::string* source, std::string* err);

// The handles of a trace's columns in a build of trace_program()'s source, resolved in
// one pass: globals, program instances and each struct's members are indexed once
// (st::resolve searches them for every column, quadratic in a wide trace's columns).
// %-addresses and anything the index does not hold go through st::resolve. Errors name
// the column.
bool resolve_trace_columns(const st::Application& app, const std::vector<TraceColumn>& cols,
                           std::vector<st::VarHandle>* handles, std::string* err);

}  // namespace plcfi::monitor

// Recorded traces for offline requirement checks: CSV (a header `time,var,...` or just
// `var,...`; one row per state) and VCD (as plcfi sim writes it). Read as a stream of
// states so memory does not grow with the trace length.
#pragma once

#include <cstdint>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

namespace plcfi::monitor {

struct TraceColumn {
  std::string name;  // path as in the header: PosCrane, Main.step, %IX0.1
  enum class Kind { Bool, Int, Real } kind = Kind::Bool;
};

class TraceReader {
 public:
  virtual ~TraceReader() = default;
  // Opens a trace (by extension: .vcd, else CSV). Without a time column time(i) is
  // i * cycle_ns; a VCD with cycle_ns > 0 is sampled every cycle, else one state per
  // time stamp. Errors name the file and line.
  static std::unique_ptr<TraceReader> open(const std::string& path, int64_t cycle_ns, std::string* err);

  const std::vector<TraceColumn>& columns() const { return columns_; }
  bool has_time() const { return has_time_; }
  // Next state; false at the end or on an error (err non-empty then).
  virtual bool next(int64_t* t_ns, std::vector<double>* values, std::string* err) = 0;

 protected:
  std::vector<TraceColumn> columns_;
  bool has_time_ = false;
};

// ST declarations of a trace's variables, so monitors compile against them: plain names
// become globals, dotted names programs (Main.step -> PROGRAM Main with step), %-addresses
// need none. Fails for names that are not ST identifiers.
bool trace_program(const std::vector<TraceColumn>& cols, std::string* source, std::string* err);

}  // namespace plcfi::monitor

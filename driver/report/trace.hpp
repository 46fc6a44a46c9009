// Signal traces of a run: VCD (IEEE 1364 value change dump, change-only, readable by
// GTKWave) and CSV (one row per sample). Values are read through variable handles.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "engine.hpp"

namespace plcfi::report {

class TraceWriter {
 public:
  virtual ~TraceWriter() = default;
  // Records the values of the watched variables at time t (ns).
  virtual void sample(int64_t t_ns, const st::Machine& m) = 0;
  // Flushes and closes; returns false (err) on an I/O error.
  virtual bool close(std::string* err) = 0;
};

// Opens `path` for a VCD trace of `vars`. Fails for unwritable files and for variables
// VCD cannot represent (strings, arrays, structures: name their elements instead).
// `comment`, when not empty, goes into the header as a $comment (what ran on which plant).
std::unique_ptr<TraceWriter> open_vcd(const std::string& path, const std::vector<st::VarHandle>& vars, std::string* err,
                                      const std::string& comment = "");
// CSV with a header `time,<path>,...`; time in seconds; BOOL as 0/1; TIME, LTIME, DATE,
// TOD and DT as the IEC literals --print shows (T#1s500ms, D#2024-03-01, TOD#12:00:00,
// DT#2024-03-01-12:00:00), which the trace reader takes back; other numbers as numbers.
std::unique_ptr<TraceWriter> open_csv(const std::string& path, const std::vector<st::VarHandle>& vars, std::string* err);

}  // namespace plcfi::report

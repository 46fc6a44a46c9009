// Size-limited reading of a user's input file (ST sources, specs, journals) into memory.
#pragma once

#include <cstddef>
#include <string>

namespace plcfi::common {

// Limits per kind of input: far above any real file, low enough that /dev/zero or a
// runaway generator stops within a second instead of exhausting memory.
inline constexpr size_t kMiB = size_t{1} << 20;
inline constexpr size_t kMaxSourceBytes = 32 * kMiB;   // one ST source file
inline constexpr size_t kMaxSpecBytes = 16 * kMiB;     // a YAML or CSV specification
inline constexpr size_t kMaxJournalBytes = 256 * kMiB; // a campaign's results journal

// How long a non-regular input (FIFO, character device) may stall before reading gives
// up: a pipe whose writer never writes must not hang the driver.
inline constexpr int kStallTimeoutMs = 10'000;

// Reads the whole of `path` into *text. Fails (false, *err) with one of:
//   "PATH: cannot open (REASON)", "PATH: is a directory",
//   "PATH: is larger than N MiB" (stops reading at the limit, so endless inputs end),
//   "PATH: read error (REASON)", "PATH: no data for 10 s (a pipe nobody writes to?)".
// Never throws for the file's sake (std::bad_alloc aside). stall_timeout_ms applies to
// FIFOs and devices only (tests shorten it).
bool read_file(const std::string& path, size_t max_bytes, std::string* text, std::string* err,
               int stall_timeout_ms = kStallTimeoutMs);

// Writes all of `data` to the file descriptor, resuming after EINTR and short writes
// (pipes between worker processes). false when the descriptor fails or is closed.
bool write_all(int fd, const std::string& data);

// "16 MiB" for whole mebibytes, else "N bytes": the limit as a message names it.
std::string size_text(size_t bytes);

}  // namespace plcfi::common

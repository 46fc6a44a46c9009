// The native tier: an application's bytecode translated to C++ (one function per code
// entry, instruction by instruction, with the interpreter's semantics from vm/ops.hpp),
// compiled by the system's C++ compiler into a shared object, cached by content and
// loaded. A Machine given a NativeCode runs the entries it has natively and everything
// else in the interpreter; results, traps (kind, location, message), coverage, the
// watchdog budget and the clock are the same in both.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "native_abi.hpp"
#include "vm/program.hpp"

namespace plcfi::st {

struct NativeOptions {
  std::string cache_dir;   // "": $PLCFI_NATIVE_CACHE, $XDG_CACHE_HOME/plcfi/native, ~/.cache/plcfi/native
  std::string compiler;    // "": $PLCFI_CXX or c++
  std::string optimize = "-O2";  // the compiler's optimization flag (tests that compile many programs: -O0)
  // A program whose generated C++ is larger than split_bytes is compiled as several
  // units, in parallel, each cached on its own, at optimize_split (a large program's
  // compile time grows with every optimization pass; its scan time far less). 0: one unit.
  size_t split_bytes = 1024 * 1024;
  std::string optimize_split = "-Og";
  // A function longer than this many instructions is compiled as pieces of that length
  // (the C++ compiler's time and memory grow faster than a function's length).
  size_t chunk_instructions = 2000;
  unsigned jobs = 0;       // compilers at once: 0: $PLCFI_JOBS, else the machine's cores
  bool progress = false;   // show the units compiled on stderr once a compile takes 2 s
};

// The translation in compilation units. One unit ("all") for most programs. A split
// program has units of functions grouped by the POU they belong to, with names and
// relative positions that do not depend on where the code lies, so an edit to one POU's
// body changes one unit's text; plus "index", the small unit that holds where each
// function's code is and the table plcfi loads.
struct NativeUnit {
  std::string name;
  std::string text;
};
struct NativeProgram {
  std::vector<NativeUnit> units;
  std::vector<uint32_t> entries;  // translated
  std::vector<uint32_t> skipped;  // left to the interpreter (an instruction the translator does not handle)
  bool split = false;
};
NativeProgram native_program(const Application& app, size_t split_bytes, size_t chunk_instructions);

// The C++ translation of every code entry reachable from the application's programs,
// tests and observers, in one unit. `entries` receives the entries translated, `skipped`
// those left to the interpreter.
std::string native_source(const Application& app, std::vector<uint32_t>* entries, std::vector<uint32_t>* skipped);

// The memory the native tier does not keep exact: the compiler temporaries of every POU
// instance and frame (each frame's last part; a FUNCTION's frame lies in its caller's
// temporaries) and the method stack. A temporary is scratch within one statement: no
// variable, probe, report or later scan reads what a finished one left there, and the
// native tier leaves out the stores nobody reads back. Everything else in memory is the
// same in both tiers after every call. Absolute (start, end) pairs, sorted.
std::vector<std::pair<uint64_t, uint64_t>> scratch_ranges(const Application& app);
// The first address below n where a and b differ outside scratch (n: none).
uint64_t first_difference(const std::vector<std::pair<uint64_t, uint64_t>>& scratch, const uint8_t* a, const uint8_t* b, uint64_t n);

class NativeCode {
 public:
  // Generates, compiles (or finds in the cache) and loads the application's native code.
  // Errors (no compiler, a compiler error, dlopen) come back in *err.
  static std::unique_ptr<NativeCode> build(const Application& app, const NativeOptions& o, std::string* err);
  ~NativeCode();
  NativeCode(const NativeCode&) = delete;
  NativeCode& operator=(const NativeCode&) = delete;

  native_abi::Fn find(uint32_t entry) const { return entry < by_entry_.size() ? by_entry_[entry] : nullptr; }
  size_t functions() const { return functions_; }
  size_t interpreted() const { return skipped_; }
  bool from_cache() const { return from_cache_; }
  size_t units() const { return units_; }                  // compilation units (1 unless split)
  size_t units_compiled() const { return units_compiled_; }  // of those, compiled by this build
  double compile_seconds() const { return compile_s_; }
  const std::string& library() const { return library_; }

 private:
  NativeCode() = default;
  void* handle_ = nullptr;
  std::vector<native_abi::Fn> by_entry_;
  size_t functions_ = 0, skipped_ = 0;
  bool from_cache_ = false;
  size_t units_ = 1, units_compiled_ = 0;
  double compile_s_ = 0;
  std::string library_;
};

}  // namespace plcfi::st

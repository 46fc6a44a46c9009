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
#include <vector>

#include "native_abi.hpp"
#include "vm/program.hpp"

namespace plcfi::st {

struct NativeOptions {
  std::string cache_dir;   // "": $PLCFI_NATIVE_CACHE, $XDG_CACHE_HOME/plcfi/native, ~/.cache/plcfi/native
  std::string compiler;    // "": $PLCFI_CXX or c++
  std::string optimize = "-O2";  // the compiler's optimization flag (tests that compile many programs: -O0)
};

// The C++ translation of every code entry reachable from the application's programs,
// tests and observers. `entries` receives the entries translated, `skipped` those left
// to the interpreter (an instruction the translator does not handle).
std::string native_source(const Application& app, std::vector<uint32_t>* entries, std::vector<uint32_t>* skipped);

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
  double compile_seconds() const { return compile_s_; }
  const std::string& library() const { return library_; }

 private:
  NativeCode() = default;
  void* handle_ = nullptr;
  std::vector<native_abi::Fn> by_entry_;
  size_t functions_ = 0, skipped_ = 0;
  bool from_cache_ = false;
  double compile_s_ = 0;
  std::string library_;
};

}  // namespace plcfi::st

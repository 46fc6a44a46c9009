// Diagnostics: the compiler collects them, never throws; they render as
// `file:line:col: error[ST123]: message`, the source line and a caret.
#pragma once

#include <string>
#include <unordered_set>
#include <vector>

#include "source.hpp"

namespace plcfi::st {

enum class Severity { Note, Warning, Error };

struct Diagnostic {
  Severity severity = Severity::Error;
  std::string code;     // "ST101"; the catalogue is driver/st/DIAGNOSTICS.md
  std::string message;
  SourceLoc loc;
  // Secondary locations ("declared here").
  std::vector<std::pair<SourceLoc, std::string>> notes;
};

class DiagEngine {
 public:
  explicit DiagEngine(const SourceManager& sm) : sm_(&sm) {}

  // A location in generated text is reported where that text came from (the source
  // manager's origins), with the origin's context added to the message. A diagnostic
  // identical to one already reported (generated code instantiating one user formula
  // several times) is not reported again: the earlier one is returned.
  Diagnostic& error(std::string code, SourceLoc loc, std::string message);
  Diagnostic& warning(std::string code, SourceLoc loc, std::string message);
  // Off: warnings are neither stored nor counted (commands that show errors only).
  void set_warnings(bool on) { warnings_on_ = on; }

  const std::vector<Diagnostic>& all() const { return diags_; }
  size_t error_count() const { return errors_; }
  size_t warning_count() const { return warnings_; }
  bool has_errors() const { return errors_ != 0; }
  // Caps runaway output on garbage input; further errors are counted but not stored.
  static constexpr size_t kMaxStored = 10000;
  // How many render_all shows unless told otherwise: a screenful a user reads.
  static constexpr size_t kShown = 50;

  // Renders one diagnostic with its source line and caret.
  std::string render(const Diagnostic& d) const;
  // Every stored diagnostic in source order, at most `limit` of them (0: all): errors
  // first, warnings fill what is left; a last line counts those not shown.
  std::string render_all(size_t limit = kShown) const;

 private:
  Diagnostic& report(Severity sev, std::string code, SourceLoc loc, std::string message);

  const SourceManager* sm_;
  std::vector<Diagnostic> diags_;
  std::unordered_set<std::string> seen_;  // code, location and message of each stored one
  Diagnostic overflow_;
  size_t errors_ = 0;
  size_t warnings_ = 0;
  bool warnings_on_ = true;
};

}  // namespace plcfi::st

// Collection and rendering of compiler diagnostics.
#include "diag.hpp"

#include <algorithm>
#include <tuple>

namespace plcfi::st {

Diagnostic& DiagEngine::report(Severity sev, std::string code, SourceLoc loc, std::string message) {
  std::string context;
  loc = sm_->origin(loc, &context);
  // A library's warnings are not the program's to fix (as for the built-in libraries,
  // whose code is compiled without them).
  if (sev == Severity::Warning && loc.file < sm_->size() && sm_->file(loc.file).library) return overflow_ = Diagnostic{};
  if (!context.empty()) message += " (" + context + ")";
  std::string key = code + '\x1f' + std::to_string(loc.file) + ':' + std::to_string(loc.line) + ':' + std::to_string(loc.col) +
                    '\x1f' + message;
  if (!seen_.insert(key).second) {
    for (auto& d : diags_)
      if (d.code == code && d.loc.file == loc.file && d.loc.line == loc.line && d.loc.col == loc.col && d.message == message)
        return d;
    overflow_ = Diagnostic{};  // the first one came after the cap: counted then, not again
    return overflow_;
  }
  ++(sev == Severity::Error ? errors_ : warnings_);
  if (diags_.size() >= kMaxStored) {
    overflow_ = Diagnostic{};
    return overflow_;
  }
  diags_.push_back(Diagnostic{sev, std::move(code), std::move(message), loc, {}});
  return diags_.back();
}

Diagnostic& DiagEngine::error(std::string code, SourceLoc loc, std::string message) {
  return report(Severity::Error, std::move(code), loc, std::move(message));
}

Diagnostic& DiagEngine::warning(std::string code, SourceLoc loc, std::string message) {
  if (!warnings_on_) return overflow_ = Diagnostic{};
  return report(Severity::Warning, std::move(code), loc, std::move(message));
}

static void render_loc(std::string& out, const SourceManager& sm, SourceLoc loc) {
  if (loc.file < sm.size()) out += sm.file(loc.file).path;
  else out += "<input>";
  if (loc.valid()) {
    out += ':' + std::to_string(loc.line) + ':' + std::to_string(loc.col);
  }
}

static void render_snippet(std::string& out, const SourceManager& sm, SourceLoc loc) {
  if (!loc.valid() || loc.file >= sm.size()) return;
  std::string_view line = sm.file(loc.file).line_text(loc.line);
  out += "  ";
  out.append(line.data(), line.size());
  out += "\n  ";
  for (uint32_t i = 1; i < loc.col && i <= line.size(); ++i) out += line[i - 1] == '\t' ? '\t' : ' ';
  out += "^\n";
}

std::string DiagEngine::render(const Diagnostic& d) const {
  std::string out;
  render_loc(out, *sm_, d.loc);
  out += d.severity == Severity::Error ? ": error[" : d.severity == Severity::Warning ? ": warning[" : ": note[";
  out += d.code + "]: " + d.message + "\n";
  render_snippet(out, *sm_, d.loc);
  for (const auto& [loc, text] : d.notes) {
    render_loc(out, *sm_, loc);
    out += ": note: " + text + "\n";
  }
  return out;
}

std::string DiagEngine::render_all(size_t limit) const {
  // Errors are what a user must fix: they are shown before warnings fill the screen.
  std::vector<const Diagnostic*> order;
  for (const auto& d : diags_)
    if (d.severity == Severity::Error && (limit == 0 || order.size() < limit)) order.push_back(&d);
  for (const auto& d : diags_)
    if (d.severity != Severity::Error && (limit == 0 || order.size() < limit)) order.push_back(&d);
  // Source order, whichever stage found a problem first (declarations are checked
  // after bodies start compiling, so collection order is not reading order).
  std::stable_sort(order.begin(), order.end(), [](const Diagnostic* a, const Diagnostic* b) {
    return std::tie(a->loc.file, a->loc.line, a->loc.col) < std::tie(b->loc.file, b->loc.line, b->loc.col);
  });
  std::string out;
  size_t errors_shown = 0, warnings_shown = 0;
  for (const Diagnostic* d : order) {
    out += render(*d);
    ++(d->severity == Severity::Error ? errors_shown : warnings_shown);
  }
  size_t more_errors = errors_ - std::min(errors_, errors_shown);
  size_t more_warnings = warnings_ - std::min(warnings_, warnings_shown);
  if (more_errors || more_warnings) {
    std::string what;
    if (more_errors) what = std::to_string(more_errors) + (more_errors == 1 ? " more error" : " more errors");
    if (more_warnings)
      what += (what.empty() ? "" : " and ") + std::to_string(more_warnings) + (more_warnings == 1 ? " more warning" : " more warnings");
    out += "(" + what + " not shown" + (limit && diags_.size() > order.size() ? "; `plcfi check --max-shown 0` shows them all" : "") + ")\n";
  }
  return out;
}

}  // namespace plcfi::st

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

std::string DiagEngine::render_all() const {
  // Source order, whichever stage found a problem first (declarations are checked
  // after bodies start compiling, so collection order is not reading order).
  std::vector<const Diagnostic*> order;
  for (const auto& d : diags_) order.push_back(&d);
  std::stable_sort(order.begin(), order.end(), [](const Diagnostic* a, const Diagnostic* b) {
    return std::tie(a->loc.file, a->loc.line, a->loc.col) < std::tie(b->loc.file, b->loc.line, b->loc.col);
  });
  std::string out;
  for (const Diagnostic* d : order) out += render(*d);
  if (errors_ + warnings_ > diags_.size())
    out += "(" + std::to_string(errors_ + warnings_ - diags_.size()) + " further diagnostics not shown)\n";
  return out;
}

}  // namespace plcfi::st

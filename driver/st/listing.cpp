// The bytecode listing, coverage per file and trap texts (listing.hpp).
#include "listing.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "vm/cpp_functions.hpp"

namespace plcfi::st {

std::string disassemble(const Application& app, const Build* build) {
  // Entry points by pc, for headers.
  std::map<uint32_t, std::string> heads;
  for (const auto& p : app.pous) {
    if (p->is_stdlib || app.is_library_file(p->loc.file) || !p->compiled) continue;
    if (p->kind != PouKind::Interface && !p->is_test) heads[p->entry] = p->name;
    if (p->has_init) heads[p->init_entry] = p->name + " (FB_init of its instances)";
    if (p->has_exit) heads[p->exit_entry] = p->name + " (FB_exit of its instances)";
    for (const auto& m : p->methods)
      if (m->compiled && m->has_body) heads[m->entry] = p->name + "." + m->name;
  }
  if (app.has_init) heads[app.init_entry] = "FB_init of the application's instances";
  if (app.has_exit) heads[app.exit_entry] = "FB_exit of the application's instances";
  for (const auto& t : app.tests) {
    heads[t.setup_entry] = "TEST '" + t.name + "' (setup)";
    heads[t.body_entry] = "TEST '" + t.name + "'";
    heads[t.teardown_entry] = "TEST '" + t.name + "' (teardown)";
  }
  std::set<uint32_t> stdlib_ranges;
  std::string out;
  bool show = false;
  uint32_t last_line = 0, last_file = UINT32_MAX;
  for (uint32_t pc = 0; pc < app.code.size();) {
    auto h = heads.find(pc);
    if (h != heads.end()) {
      show = true;
      out += "\n" + h->second + ":\n";
      last_line = 0;
    } else {
      // Library bodies are not listed unless reached from a header.
      for (const auto& p : app.pous) {
        if (!p->compiled || !(p->is_stdlib || app.is_library_file(p->loc.file))) continue;
        if (p->entry == pc) show = false;
        for (const auto& m : p->methods)
          if (m->compiled && m->has_body && m->entry == pc) show = false;
      }
    }
    uint32_t len = op_length(&app.code[pc]);
    if (pc + len > app.code.size()) break;
    if (show) {
      SourceLoc loc = app.loc_of(pc);
      if (loc.valid() && (loc.line != last_line || loc.file != last_file)) {
        std::string src;
        if (build && loc.file < build->sm.size()) src = std::string(build->sm.file(loc.file).line_text(loc.line));
        size_t start = src.find_first_not_of(" \t");
        out += fmt::format("  ; {}:{}  {}\n", app.file_paths[loc.file], loc.line, start == std::string::npos ? "" : src.substr(start));
        last_line = loc.line;
        last_file = loc.file;
      }
      const OpInfo& info = op_info(static_cast<Op>(app.code[pc]));
      std::string line = fmt::format("  {:6}  {:<10}", pc, info.name);
      for (uint32_t k = 1; k < len; ++k) line += fmt::format(" {}", app.code[pc + k]);
      if (static_cast<Op>(app.code[pc]) == Op::NATIVE) line += fmt::format("   ({})", native_name(app.code[pc + 1] & 0xffffu));
      // A displaced index (v + K): its lower-bound operand is the dimension's minus K.
      if (int32_t k = app.index_shift(pc); k != 0) line += fmt::format("   (index {} {})", k < 0 ? "-" : "+", k < 0 ? -int64_t{k} : int64_t{k});
      out += line + "\n";
    }
    pc += len;
  }
  return out;
}

std::string coverage_report(const Application& app, const std::vector<uint64_t>& covered) {
  struct FileCov {
    size_t total = 0, taken = 0;
    std::vector<std::string> missed;
  };
  std::map<std::string, FileCov> files;
  for (size_t i = 0; i < app.branches.size(); ++i) {
    const auto& b = app.branches[i];
    if (b.loc.file >= app.file_paths.size() || app.is_library_file(b.loc.file)) continue;
    auto& fc = files[app.file_paths[b.loc.file]];
    ++fc.total;
    bool hit = i / 64 < covered.size() && ((covered[i / 64] >> (i % 64)) & 1u);
    if (hit) ++fc.taken;
    else fc.missed.push_back(fmt::format("{}:{}:{} {} in {}", app.file_paths[b.loc.file], b.loc.line, b.loc.col, b.kind, b.pou));
  }
  std::string out = "branch coverage:\n";
  for (const auto& [f, c] : files) {
    out += fmt::format("  {}: {}/{} branches ({:.0f}%)\n", f, c.taken, c.total, c.total ? 100.0 * c.taken / c.total : 100.0);
    for (const auto& m : c.missed) out += "    not taken: " + m + "\n";
  }
  if (files.empty()) out += "  (no branches)\n";
  return out;
}

const char* trap_code(TrapKind k) {
  switch (k) {
    case TrapKind::DivisionByZero: return "ST501";
    case TrapKind::IndexOutOfRange: return "ST502";
    case TrapKind::RangeError: return "ST503";
    case TrapKind::NullReference: return "ST504";
    case TrapKind::Watchdog: return "ST505";
    case TrapKind::CallDepth: return "ST506";
    case TrapKind::AssertFailed: return "ST507";
    case TrapKind::NotImplemented: return "ST508";
    case TrapKind::BadAddress: return "ST509";
    default: return "ST500";
  }
}

std::string describe_trap_kind(const Trap& t) {
  return fmt::format("runtime error[{}]: {}{}", trap_code(t.kind), trap_name(t.kind),
                     t.message.empty() || t.message == trap_name(t.kind) ? "" : ": " + t.message);
}

std::string describe_trap(const Application& app, const Trap& t) {
  return app.where(t.loc) + ": " + describe_trap_kind(t);
}

}  // namespace plcfi::st

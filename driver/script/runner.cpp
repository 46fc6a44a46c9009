// The CPTest+ script runner.
#include "script/runner.hpp"

#include <fmt/format.h>

#include "sema/types.hpp"

namespace plcfi::script {

namespace {

// "line 8", or "line 8 (06)" when the script numbers its lines.
std::string where(const Command& c) {
  return c.number.empty() ? fmt::format("line {}", c.at.line) : fmt::format("line {} ({})", c.at.line, c.number);
}

void collect(const st::Application& app, const std::string& path, const st::Type* t, int depth, size_t limit,
             std::vector<st::VarHandle>& out) {
  if (out.size() >= limit || !t) return;
  if (t->is_elementary() || t->is_string()) {
    std::string err;
    if (auto h = st::resolve(app, path, &err)) out.push_back(*h);
    return;
  }
  if ((t->kind == st::TypeKind::Struct || t->kind == st::TypeKind::Pou) && depth < 6)
    for (const auto& f : t->fields) {
      if (f.name.rfind("__", 0) == 0) continue;  // the compiler's hidden state
      collect(app, path + "." + f.name, f.type, depth + 1, limit, out);
    }
}

class Run {
 public:
  Run(rt::Runtime& rt, const BoundScript& s, const RunOptions& opt) : rt_(rt), s_(s), opt_(opt) {
    res_.test = s.script->name;
    vars_ = snapshot_variables(rt.app());
    for (const auto& v : vars_) res_.snapshot_paths.push_back(v.path);
    // WAIT n C and ASSERT_COM count cycles of the program's task (the first program's).
    const auto& app = rt.app();
    int64_t interval = rt.schedule().tick_ns();
    if (!app.programs.empty())
      for (const auto& t : rt.schedule().tasks())
        if (!t.programs.empty() && t.programs.front() == 0) interval = t.interval_ns;
    ticks_per_cycle_ = std::max<int64_t>(1, interval / rt.schedule().tick_ns());
    start_scans_ = rt.scan_count();
    start_ns_ = rt.now();
    errors_mark_ = errors();
  }

  ScriptResult run() {
    for (const BoundCommand& bc : s_.cmds) {
      const Command& c = *bc.cmd;
      if (c.kind != CmdKind::Log) note(LogEntry::Kind::Command, c.at.line, c.text);
      if (!step(bc)) break;
    }
    res_.end_ns = rt_.now();
    res_.scans = rt_.scan_count() - start_scans_;
    note(LogEntry::Kind::Verdict, 0, fmt::format("{}{}", verdict_name(res_.verdict), res_.reason.empty() ? "" : ": " + res_.reason));
    return std::move(res_);
  }

 private:
  uint64_t errors() const { return rt_.backend() ? rt_.backend()->failed_exchanges() : 0; }

  void note(LogEntry::Kind k, uint32_t line, std::string text, int snap = -1) {
    LogEntry e;
    e.kind = k;
    e.t_ns = rt_.now();
    e.scan = rt_.scan_count() - start_scans_;
    e.line = line;
    e.text = std::move(text);
    e.snapshot = snap;
    res_.log.push_back(std::move(e));
  }

  void snapshot(uint32_t line, const std::string& why) {
    std::vector<std::string> values;
    values.reserve(vars_.size());
    for (const auto& v : vars_) values.push_back(st::format(rt_.machine(), v));
    res_.snapshots.push_back(std::move(values));
    note(LogEntry::Kind::Snapshot, line, why, static_cast<int>(res_.snapshots.size() - 1));
  }

  // One scan; false when the run must end (trap, interrupt, a lost device, the time limit).
  bool scan() {
    if (opt_.signals && opt_.signals->requested()) return end(Verdict::Undecidable, "interrupted (" + opt_.signals->name() + ")");
    if (opt_.time_limit_ns > 0 && rt_.now() - start_ns_ >= opt_.time_limit_ns) return end(Verdict::Failed, opt_.time_limit_reason);
    std::string why;
    if (opt_.scan) {
      if (!opt_.scan(rt_, &why)) return end(Verdict::Undecidable, why);
    } else {
      rt_.scan();
    }
    if (rt_.stopped()) return end(Verdict::Failed, "the program stopped: " + rt_.stop_reason());
    return true;
  }

  bool scans(int64_t n) {
    for (int64_t i = 0; i < n; ++i)
      if (!scan()) return false;
    return true;
  }

  bool end(Verdict v, std::string reason) {
    res_.verdict = v;
    res_.reason = std::move(reason);
    return false;
  }

  bool step(const BoundCommand& bc) {
    const Command& c = *bc.cmd;
    st::Machine& m = rt_.machine();
    switch (c.kind) {
      case CmdKind::Set: st::write_bool(m, bc.var, true); return true;
      case CmdKind::Reset: st::write_bool(m, bc.var, false); return true;
      case CmdKind::Assign: {
        std::string err;
        // Checked when the script was bound; cannot fail here.
        st::write_text(m, bc.var, c.value, &err);
        return true;
      }
      case CmdKind::Log: note(LogEntry::Kind::Log, c.at.line, c.message); return true;
      case CmdKind::Wait: {
        errors_mark_ = errors();
        if (c.unit == WaitUnit::Cycles) return scans(c.amount * ticks_per_cycle_);
        const int64_t tick = rt_.schedule().tick_ns();
        const int64_t ns = duration_ns(c.amount, c.unit);
        return scans((ns + tick - 1) / tick);
      }
      case CmdKind::FaultLink:
        // The device was checked against the backend's when the script was bound.
        if (rt_.backend()) rt_.backend()->break_link(c.device, rt_.now(), duration_ns(c.amount, c.unit));
        return true;
      case CmdKind::Assert:
      case CmdKind::AssertCom: return check(bc);
    }
    return true;
  }

  bool holds(const BoundCommand& bc) const { return compare(read_operand(rt_.machine(), bc.var), bc.cmd->op, bc.value); }

  bool check(const BoundCommand& bc) {
    const Command& c = *bc.cmd;
    AssertOutcome o;
    o.line = c.at.line;
    o.where = where(c);
    o.text = c.text;
    o.com = c.kind == CmdKind::AssertCom;
    o.held = holds(bc);
    if (!o.held && o.com) {
      snapshot(c.at.line, "ASSERT_COM failed: " + c.var + " = " + st::format(rt_.machine(), bc.var));
      o.comm_error = errors() > errors_mark_;
      if (o.comm_error) {
        // Re-check once per task cycle until it holds or the longest wait has passed.
        o.waited = true;
        const int64_t deadline = rt_.now() + opt_.max_wait_ns;
        int64_t cycles = 0;
        bool alive = true;
        while (!o.held && rt_.now() < deadline) {
          if (!(alive = scans(ticks_per_cycle_))) break;
          ++cycles;
          o.held = holds(bc);
          snapshot(c.at.line, fmt::format("ASSERT_COM re-check {}: {} = {}", cycles, c.var, st::format(rt_.machine(), bc.var)));
        }
        o.cycles = o.held ? cycles : cycles + 1;
        o.has_mci = true;
        o.mci = m_ci(opt_.mci, opt_.p_lst, o.cycles);
        o.actual = st::format(rt_.machine(), bc.var);
        o.verdict = verdict_of(false, o.mci);
        res_.asserts.push_back(o);
        if (!alive) return false;
        return end(o.verdict, fmt::format("{}: {} waited {} cycle(s) through a communication error{}; m_ci = {:.3g}",
                                          where(c), c.text, cycles, o.held ? " until it held" : ", never held", o.mci));
      }
    }
    o.actual = st::format(rt_.machine(), bc.var);
    o.verdict = o.held ? Verdict::Passed : Verdict::Failed;
    res_.asserts.push_back(o);
    if (o.held) return true;
    if (!o.com) snapshot(c.at.line, "ASSERT failed: " + c.var + " = " + o.actual);
    return end(Verdict::Failed, fmt::format("{}: {}: {} is {}{}", where(c), c.text, c.var, o.actual,
                                            o.com ? " (no communication error)" : ""));
  }

  rt::Runtime& rt_;
  const BoundScript& s_;
  const RunOptions& opt_;
  ScriptResult res_;
  std::vector<st::VarHandle> vars_;
  int64_t ticks_per_cycle_ = 1;
  uint64_t start_scans_ = 0;
  int64_t start_ns_ = 0;
  uint64_t errors_mark_ = 0;
};

}  // namespace

std::vector<st::VarHandle> snapshot_variables(const st::Application& app, size_t limit) {
  std::vector<st::VarHandle> out;
  for (const auto& g : app.globals) collect(app, g.sym->name, g.sym->type, 0, limit, out);
  for (const auto& p : app.programs) collect(app, p.name, p.pou->type, 0, limit, out);
  return out;
}

ScriptResult run_script(rt::Runtime& rt, const BoundScript& s, const RunOptions& opt) { return Run(rt, s, opt).run(); }

}  // namespace plcfi::script

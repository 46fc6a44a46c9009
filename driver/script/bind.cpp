// Binding a CPTest+ script to a compiled program (names, types, values, devices).
#include "script/bind.hpp"

#include <fmt/format.h>

#include "sema/types.hpp"
#include "vm/vm.hpp"

namespace plcfi::script {

namespace {

bool is_bool(const st::Type* t) { return t && t->kind == st::TypeKind::Bool; }

bool is_ordered(const st::Type* t) {
  return t->is_numeric() || t->is_bitstring() || t->is_time_like() || t->kind == st::TypeKind::Enum;
}

Operand::K kind_of(const st::Type* t) {
  if (t->is_real()) return Operand::K::Real;
  if (t->is_string()) return Operand::K::Str;
  return Operand::K::Int;
}

std::string where(const Script& s, Pos p) { return fmt::format("{}:{}:{}", s.path, p.line, p.col); }

}  // namespace

Operand read_operand(const st::Machine& m, const st::VarHandle& h) {
  Operand o;
  o.k = kind_of(h.type);
  switch (o.k) {
    case Operand::K::Int: o.i = st::read_int(m, h); break;
    case Operand::K::Real: o.r = st::read_real(m, h); break;
    case Operand::K::Str: o.s = st::format(m, h); break;
  }
  return o;
}

std::string operand_text(const st::Machine& m, const st::VarHandle& h) { return st::format(m, h); }

bool compare(const Operand& v, CmpOp op, const Operand& e) {
  if (op == CmpOp::IsTrue) return v.i != 0;
  if (op == CmpOp::IsFalse) return v.i == 0;
  int c = 0;
  switch (v.k) {
    case Operand::K::Int: c = v.i < e.i ? -1 : v.i > e.i ? 1 : 0; break;
    case Operand::K::Real: c = v.r < e.r ? -1 : v.r > e.r ? 1 : 0; break;
    case Operand::K::Str: c = v.s < e.s ? -1 : v.s > e.s ? 1 : 0; break;
  }
  switch (op) {
    case CmpOp::Eq: return c == 0;
    case CmpOp::Neq: return c != 0;
    case CmpOp::Lt: return c < 0;
    case CmpOp::Lte: return c <= 0;
    case CmpOp::Gt: return c > 0;
    case CmpOp::Gte: return c >= 0;
    default: return false;
  }
}

bool bind_script(const st::Application& app, const Script& s, const std::vector<std::string>& devices, BoundScript* out,
                 std::string* err) {
  BoundScript b;
  b.script = &s;
  st::Machine scratch(app);  // values are parsed into it, never into the running program
  for (const Command& c : s.commands) {
    BoundCommand bc;
    bc.cmd = &c;
    const bool has_var = c.kind == CmdKind::Set || c.kind == CmdKind::Reset || c.kind == CmdKind::Assign ||
                         c.kind == CmdKind::Assert || c.kind == CmdKind::AssertCom;
    if (has_var) {
      std::string e;
      auto h = st::resolve(app, c.var, &e);
      if (!h) {
        *err = where(s, c.var_at) + ": " + e;
        return false;
      }
      bc.var = *h;
      const st::Type* t = h->type;
      bool known = false;
      for (const auto& p : b.var_paths) known = known || p == c.var;
      if (!known) b.var_paths.push_back(c.var);
      const char* word = c.kind == CmdKind::Set ? "SET" : c.kind == CmdKind::Reset ? "RESET" : c.kind == CmdKind::Assign ? "ASSIGN"
                         : c.kind == CmdKind::Assert ? "ASSERT" : "ASSERT_COM";
      if ((c.kind == CmdKind::Set || c.kind == CmdKind::Reset) && !is_bool(t)) {
        *err = fmt::format("{}: {} needs a BOOL variable; {} is {} (use ASSIGN)", where(s, c.var_at), word, c.var, t->name);
        return false;
      }
      if (!t->is_elementary() && !t->is_string()) {
        *err = fmt::format("{}: {} is {}, not a single value", where(s, c.var_at), c.var, t->name);
        return false;
      }
      if ((c.kind == CmdKind::Assert || c.kind == CmdKind::AssertCom)) {
        if ((c.op == CmpOp::IsTrue || c.op == CmpOp::IsFalse) && !is_bool(t)) {
          *err = fmt::format("{}: {} {} needs a BOOL variable; {} is {} (compare it with EQ)", where(s, c.var_at), word,
                             op_name(c.op), c.var, t->name);
          return false;
        }
        if (c.op != CmpOp::Eq && c.op != CmpOp::Neq && op_takes_value(c.op) && !is_ordered(t)) {
          *err = fmt::format("{}: {} {}: {} ({}) has no order; use EQ or NEQ", where(s, c.at), word, op_name(c.op), c.var,
                             t->name);
          return false;
        }
      }
      if (c.has_value) {
        if (!st::write_text(scratch, *h, c.value, &e)) {
          *err = where(s, c.value_at) + ": " + e;
          return false;
        }
        bc.value = read_operand(scratch, *h);
      }
    }
    if (c.kind == CmdKind::FaultLink) {
      bool found = false;
      std::string known;
      for (const auto& d : devices) {
        found = found || d == c.device;
        known += (known.empty() ? "" : ", ") + d;
      }
      if (!found) {
        *err = fmt::format("{}: unknown device '{}' (known: {})", where(s, c.device_at), c.device, known.empty() ? "none" : known);
        return false;
      }
    }
    b.cmds.push_back(std::move(bc));
  }
  *out = std::move(b);
  return true;
}

}  // namespace plcfi::script

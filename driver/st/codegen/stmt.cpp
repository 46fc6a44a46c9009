// Statements: assignment, calls, IF, CASE, FOR, WHILE, REPEAT, EXIT, CONTINUE, RETURN,
// and the test-file statements; every branch arm gets a coverage id.
#include <algorithm>
#include <bit>
#include <map>
#include <optional>
#include <set>

#include <cstring>

#include "compiler_impl.hpp"
#include "sema/stdfuncs.hpp"

namespace plcfi::st::detail {

uint32_t Compiler::branch(SourceLoc loc, const char* kind, SourceLoc stmt, uint32_t* decision, const StmtList& body) {
  uint32_t id = static_cast<uint32_t>(app_->branches.size());
  if (*decision == kNoBranch) *decision = id;
  BranchPoint bp;
  bp.loc = loc;
  bp.kind = kind;
  bp.pou = b_ && b_->pou ? b_->pou->name : "";
  bp.decision = *decision;
  bp.stmt = stmt;
  if (!body.empty()) bp.body = body.front()->loc;
  bp.parent = b_ ? b_->arm : kNoBranch;
  app_->branches.push_back(std::move(bp));
  if (opt_.coverage) emit(Op::COV, {id});
  return id;
}

namespace {
// The arm whose body is being compiled, for the nesting of coverage ids (BranchPoint::parent).
struct ArmScope {
  Body* b;
  uint32_t saved;
  ArmScope(Body* body, uint32_t id) : b(body), saved(body->arm) { b->arm = id; }
  ~ArmScope() { b->arm = saved; }
  ArmScope(const ArmScope&) = delete;
  ArmScope& operator=(const ArmScope&) = delete;
};
}  // namespace

// Drops the code from `at` on (an instruction a peephole replaces) and returns the
// operands it had at words at + 2 and at + 3, each with its slot kind.
std::pair<Arg, Arg> Compiler::unemit(uint32_t at) {
  auto& code = b_->code;
  Arg x(code[at + 2]), y(at + 3 < code.size() ? Arg(code[at + 3]) : Arg(0u));
  for (auto it = b_->slot_fix.begin(); it != b_->slot_fix.end();) {
    if (it->first == at + 2) x = Arg(Slot{code[at + 2], it->second});
    if (it->first == at + 3) y = Arg(Slot{code[at + 3], it->second});
    if (it->first >= at) it = b_->slot_fix.erase(it);
    else ++it;
  }
  code.resize(at);
  return {x, y};
}

SK Compiler::kind_at(uint32_t word) const {
  for (const auto& [w, k] : b_->slot_fix)
    if (w == word) return k;
  return SK::Var;
}

std::optional<uint64_t> Compiler::const_at(uint32_t word, uint32_t width) const {
  const auto& code = b_->code;
  if (word >= code.size() || kind_at(word) != SK::Const || width > 8 || uint64_t{code[word]} + width > b_->consts.size())
    return std::nullopt;
  uint64_t v = 0;
  std::memcpy(&v, b_->consts.data() + code[word], width);  // little-endian, as the VM reads it
  return v;
}

// A test of bits: "AND t, x, m; EQ/NE c, t, 0" compiled into a jump is one JTZ or JTNZ
// on x and m, when the AND is the instruction right before the comparison, in the same
// statement line and block, and defines a temporary only the comparison reads. `if_zero`:
// the jump is to be taken when the AND gives zero. False: nothing changed.
std::optional<uint32_t> Compiler::zero_tested_temp(uint32_t cmp_at, uint32_t type_idx) const {
  const auto& code = b_->code;
  const uint32_t op_at = b_->prev_instr;
  if (op_at == UINT32_MAX || op_at >= cmp_at || op_at < b_->last_label_pos || type_idx >= 8) return std::nullopt;
  if (!b_->lines.empty() && b_->lines.back().first > op_at) return std::nullopt;
  static constexpr uint32_t kWidth[] = {1, 2, 4, 8, 1, 2, 4, 8};
  auto zero = [&](uint32_t word) { return const_at(word, kWidth[type_idx]) == uint64_t{0}; };
  // The comparison reads op_at's temporary and a constant zero, in either order.
  const uint32_t t = code[op_at + 1];
  if (kind_at(op_at + 1) != SK::Temp) return std::nullopt;
  auto is_t = [&](uint32_t word) { return code[word] == t && kind_at(word) == SK::Temp; };
  if (!(is_t(cmp_at + 2) && zero(cmp_at + 3)) && !(is_t(cmp_at + 3) && zero(cmp_at + 2))) return std::nullopt;
  return op_at;
}

bool Compiler::test_bits(uint32_t cmp_at, uint32_t type_idx, Label target, bool if_zero) {
  const std::optional<uint32_t> and_at = zero_tested_temp(cmp_at, type_idx);
  constexpr uint32_t stride = static_cast<uint32_t>(Op::MOD_I16) - static_cast<uint32_t>(Op::MOD_I8);
  if (!and_at || b_->code[*and_at] != static_cast<uint32_t>(Op::AND_I8) + type_idx * stride || *and_at + 4 != cmp_at)
    return false;
  auto [x, y] = unemit(*and_at);
  emit(int_op(if_zero ? Op::JTZ_I8 : Op::JTNZ_I8, static_cast<Storage>(type_idx)), {Arg::target(target.id), x, y});
  b_->last_def_pos = UINT32_MAX;
  return true;
}

void Compiler::branch_on(const Val& c, SourceLoc loc, Label target, bool when_true) {
  Slot cs = to_slot(c, elem(TypeKind::Bool), loc);
  // Peephole: "CMP t, a, b; JMPF target, t" -> "J<inverse> target, a, b".
  auto& code = b_->code;
  uint32_t at = b_->last_instr;
  if (at >= code.size()) {
    emit(when_true ? Op::JMPT : Op::JMPF, {Arg::target(target.id), cs});
    return;
  }
  // A jump on a BOOL variable that the instruction just before set to a constant, with no
  // jump target between (`moving := FALSE;` at the end of a loop body's arm, followed by
  // the loop's own test, rule 17): when the constant says it is not taken, it is left out.
  // (Taken, it stays: a jump back counts against the watchdog.)
  if (!c.is_const && code[at] == static_cast<uint32_t>(Op::MOV1) && at + 3 == code.size() && b_->last_label_pos <= at &&
      cs.kind == SK::Var && kind_at(at + 1) == SK::Var && code[at + 1] == cs.off) {
    if (const auto k = const_at(at + 2, 1); k && (*k != 0) != when_true) return;
  }
  if (!c.is_const && b_->last_def_pos == at && b_->last_label_pos <= at && code[at] == static_cast<uint32_t>(Op::BNOT) &&
      b_->last_def.kind == cs.kind && b_->last_def.off == cs.off && cs.kind == SK::Temp) {
    // "BNOT t, x; JMPF target, t" -> "JMPT target, x".
    Arg x = unemit(at).first;
    emit(when_true ? Op::JMPF : Op::JMPT, {Arg::target(target.id), x});
    b_->last_def_pos = UINT32_MAX;
    return;
  }
  if (!c.is_const && b_->last_def_pos == at && b_->last_label_pos <= at && b_->last_def_operand == 1 &&
      b_->last_def.kind == cs.kind && b_->last_def.off == cs.off && cs.kind == SK::Temp) {
    uint32_t op = code[at];
    constexpr uint32_t stride = static_cast<uint32_t>(Op::ADD_I16) - static_cast<uint32_t>(Op::ADD_I8);
    uint32_t base_i8 = static_cast<uint32_t>(Op::ADD_I8);
    if (op >= base_i8 && op < base_i8 + 10 * stride) {
      uint32_t type_idx = (op - base_i8) / stride;
      auto in_block = static_cast<Op>(op - type_idx * stride);
      // The jump we need: taken when the comparison's outcome equals when_true.
      struct Map {
        Op cmp;
        Op jtrue;  // jump if the comparison holds
        bool jtrue_swap;
        Op jfalse;  // jump if it does not
        bool jfalse_swap;
      };
      static const Map kMap[] = {
          {Op::LT_I8, Op::JLT_I8, false, Op::JGE_I8, false}, {Op::GE_I8, Op::JGE_I8, false, Op::JLT_I8, false},
          {Op::GT_I8, Op::JLT_I8, true, Op::JGE_I8, true},   {Op::LE_I8, Op::JGE_I8, true, Op::JLT_I8, true},
          {Op::EQ_I8, Op::JEQ_I8, false, Op::JNE_I8, false}, {Op::NE_I8, Op::JNE_I8, false, Op::JEQ_I8, false},
      };
      for (const auto& m : kMap) {
        if (in_block != m.cmp) continue;
        // Floating-point compares are not inverted (NaN makes a < b and a >= b both false):
        // the jump on a failed comparison is its own instruction (JNLT, JNGE); = and <>
        // invert exactly (NaN = x is FALSE, NaN <> x is TRUE).
        bool is_float = type_idx >= 8;
        Op j = when_true ? m.jtrue : m.jfalse;
        bool swap = when_true ? m.jtrue_swap : m.jfalse_swap;
        Op fj = Op::NOP;
        if (is_float && !when_true && m.cmp != Op::EQ_I8 && m.cmp != Op::NE_I8) {
          bool f64 = type_idx == 9;
          bool lt = m.cmp == Op::LT_I8 || m.cmp == Op::GT_I8;  // a < b, or b < a
          fj = lt ? (f64 ? Op::JNLT_F64 : Op::JNLT_F32) : (f64 ? Op::JNGE_F64 : Op::JNGE_F32);
          swap = m.cmp == Op::GT_I8 || m.cmp == Op::LE_I8;
        }
        if (!is_float && (m.cmp == Op::EQ_I8 || m.cmp == Op::NE_I8) && test_bits(at, type_idx, target, m.cmp == Op::EQ_I8 ? when_true : !when_true))
          return;
        auto [a, b2] = unemit(at);
        Op op_j = fj != Op::NOP ? fj : static_cast<Op>(static_cast<uint32_t>(j) + type_idx * stride);
        emit(op_j, {Arg::target(target.id), swap ? b2 : a, swap ? a : b2});
        b_->last_def_pos = UINT32_MAX;
        return;
      }
    }
  }
  emit(when_true ? Op::JMPT : Op::JMPF, {Arg::target(target.id), cs});
}

namespace {
bool is_and_or(const Expr& e) {
  if (e.kind != ExprKind::Binary) return false;
  const BinaryOp op = static_cast<const BinaryExpr&>(e).op;
  return op == BinaryOp::And || op == BinaryOp::Or;
}

// Whether b is no division or MOD, or one by a number written out that is not zero (a
// variable divisor may be zero).
bool divisor_cannot_fail(const BinaryExpr& b) {
  if (b.op != BinaryOp::Div && b.op != BinaryOp::Mod) return true;
  if (b.rhs->kind != ExprKind::Literal) return false;
  const auto& d = static_cast<const LiteralExpr&>(*b.rhs);
  return (d.lit == LiteralKind::Int && d.int_value != 0) || (d.lit == LiteralKind::Real && d.real_value != 0);
}

// Whether two expressions that plain_read_type accepts are written alike (names compared
// as IEC compares them, without case).
bool same_expr(const Expr& a, const Expr& b, int depth) {
  if (a.kind != b.kind || depth > 64) return false;
  switch (a.kind) {
    case ExprKind::Literal: {
      const auto& x = static_cast<const LiteralExpr&>(a);
      const auto& y = static_cast<const LiteralExpr&>(b);
      return x.lit == LiteralKind::Int && y.lit == LiteralKind::Int && x.int_value == y.int_value &&
             iequals(x.type_prefix, y.type_prefix);
    }
    case ExprKind::Name:
      return iequals(static_cast<const NameExpr&>(a).name.text, static_cast<const NameExpr&>(b).name.text);
    case ExprKind::Member: {
      const auto& x = static_cast<const MemberExpr&>(a);
      const auto& y = static_cast<const MemberExpr&>(b);
      return iequals(x.member.text, y.member.text) && same_expr(*x.base, *y.base, depth + 1);
    }
    case ExprKind::BitAccess: {
      const auto& x = static_cast<const BitAccessExpr&>(a);
      const auto& y = static_cast<const BitAccessExpr&>(b);
      return x.bit == y.bit && same_expr(*x.base, *y.base, depth + 1);
    }
    case ExprKind::Index: {
      const auto& x = static_cast<const IndexExpr&>(a);
      const auto& y = static_cast<const IndexExpr&>(b);
      if (x.indices.size() != y.indices.size() || !same_expr(*x.base, *y.base, depth + 1)) return false;
      for (size_t i = 0; i < x.indices.size(); ++i)
        if (!same_expr(*x.indices[i], *y.indices[i], depth + 1)) return false;
      return true;
    }
    case ExprKind::Unary: {
      const auto& x = static_cast<const UnaryExpr&>(a);
      const auto& y = static_cast<const UnaryExpr&>(b);
      return x.op == y.op && same_expr(*x.operand, *y.operand, depth + 1);
    }
    case ExprKind::Binary: {
      const auto& x = static_cast<const BinaryExpr&>(a);
      const auto& y = static_cast<const BinaryExpr&>(b);
      return x.op == y.op && same_expr(*x.lhs, *y.lhs, depth + 1) && same_expr(*x.rhs, *y.rhs, depth + 1);
    }
    default: return false;
  }
}

// The array accesses in an expression that plain_read_type accepts: each of them is
// evaluated, with its index checked, whenever the expression is.
void collect_indexes(const Expr& e, std::vector<const IndexExpr*>* out, int depth) {
  if (depth > 64) return;
  switch (e.kind) {
    case ExprKind::Member: collect_indexes(*static_cast<const MemberExpr&>(e).base, out, depth + 1); break;
    case ExprKind::BitAccess: collect_indexes(*static_cast<const BitAccessExpr&>(e).base, out, depth + 1); break;
    case ExprKind::Index: {
      const auto& x = static_cast<const IndexExpr&>(e);
      out->push_back(&x);
      collect_indexes(*x.base, out, depth + 1);
      for (const auto& i : x.indices) collect_indexes(*i, out, depth + 1);
      break;
    }
    case ExprKind::Unary: collect_indexes(*static_cast<const UnaryExpr&>(e).operand, out, depth + 1); break;
    case ExprKind::Binary:
      collect_indexes(*static_cast<const BinaryExpr&>(e).lhs, out, depth + 1);
      collect_indexes(*static_cast<const BinaryExpr&>(e).rhs, out, depth + 1);
      break;
    default: break;
  }
}
}  // namespace

const Type* Compiler::plain_read_type(const Expr& e, const std::vector<const IndexExpr*>* checked, int depth) {
  if (depth > 64) return nullptr;
  switch (e.kind) {
    case ExprKind::Literal: {
      const auto& l = static_cast<const LiteralExpr&>(e);
      if (l.lit == LiteralKind::Bool) return elem(TypeKind::Bool);
      // A number takes its type from the context; only "some integer" matters here.
      if (l.lit == LiteralKind::Int || l.lit == LiteralKind::Real) return elem(TypeKind::LInt);
      return nullptr;
    }
    case ExprKind::Name: {
      const Symbol* s = lookup(canon(static_cast<const NameExpr&>(e).name.text));
      // Not a variable: a property read by its bare name, a POU, a qualified enum value.
      if (!s || s->kind != SymKind::Var || !s->type || s->where == Where::InOut) return nullptr;
      if (s->type->kind == TypeKind::Ref || s->type->kind == TypeKind::Interface) return nullptr;
      return s->type;
    }
    case ExprKind::Member: {
      const auto& m = static_cast<const MemberExpr&>(e);
      const Type* bt = plain_read_type(*m.base, checked, depth + 1);
      if (!bt || (bt->kind != TypeKind::Struct && bt->kind != TypeKind::Pou)) return nullptr;
      const Field* f = bt->field(m.member.text);  // none: a property (its getter is a call)
      if (!f || !f->type || f->type->kind == TypeKind::Ref || f->type->kind == TypeKind::Interface) return nullptr;
      return f->type;
    }
    case ExprKind::BitAccess: {
      const Type* bt = plain_read_type(*static_cast<const BitAccessExpr&>(e).base, checked, depth + 1);
      return bt && (bt->is_bitstring() || bt->is_integer()) ? elem(TypeKind::Bool) : nullptr;
    }
    case ExprKind::Index: {
      const auto& x = static_cast<const IndexExpr&>(e);
      const Type* at = plain_read_type(*x.base, checked, depth + 1);
      if (!at || at->kind != TypeKind::Array || at->open || x.indices.size() != at->dims.size()) return nullptr;
      bool constant = true;
      for (const auto& i : x.indices) {
        const Type* it = plain_read_type(*i, checked, depth + 1);
        if (!it || !it->is_integer()) return nullptr;
        if (i->kind != ExprKind::Literal) constant = false;  // a literal index is checked by the compiler
      }
      // A variable index could fail its bounds check; not when the same access was
      // evaluated (and checked) before, with nothing written since.
      if (!constant && checked &&
          std::none_of(checked->begin(), checked->end(), [&](const IndexExpr* c) { return same_expr(*c, x, 0); }))
        return nullptr;
      return at->elem;
    }
    case ExprKind::Unary: return plain_read_type(*static_cast<const UnaryExpr&>(e).operand, checked, depth + 1);
    case ExprKind::Binary: {
      const auto& b = static_cast<const BinaryExpr&>(e);
      if (b.op == BinaryOp::Pow || b.op == BinaryOp::AndThen || b.op == BinaryOp::OrElse) return nullptr;
      if (!divisor_cannot_fail(b)) return nullptr;
      const Type* l = plain_read_type(*b.lhs, checked, depth + 1);
      const Type* r = l ? plain_read_type(*b.rhs, checked, depth + 1) : nullptr;
      if (!l || !r) return nullptr;
      switch (b.op) {
        case BinaryOp::Lt: case BinaryOp::Gt: case BinaryOp::Le: case BinaryOp::Ge: case BinaryOp::Eq: case BinaryOp::Ne:
          return elem(TypeKind::Bool);
        case BinaryOp::And: case BinaryOp::Or: case BinaryOp::Xor:
          return l->kind == TypeKind::Bool && r->kind == TypeKind::Bool ? l : (l->kind == TypeKind::Bool ? r : l);
        default: return l;
      }
    }
    default: return nullptr;
  }
}

// An AND or OR chain of conditions as jumps, the way C compiles && and ||: for AND, each
// term FALSE jumps out; for OR, each term TRUE jumps in. IEC evaluates every operand of
// AND and OR, so the terms after the first are chained only when leaving them out cannot
// be seen: they read variables and nothing else, and cannot fail (plain_read_type; an
// element access whose index the first term already checked counts). `IF tags[i].zone =
// z AND tags[i].alarm THEN` is then two fused element jumps, not two loads, a comparison,
// an AND and a jump; the same for `IF pi1.sat OR pi2.sat OR pi3.sat THEN`.
bool Compiler::chain_terms(const Expr& e, std::vector<const Expr*>* terms) {
  if (!opt_.condition_jumps || !is_and_or(e)) return false;
  const BinaryOp op = static_cast<const BinaryExpr&>(e).op;
  // a AND b AND c is ((a AND b) AND c): the left spine of the one operator, in order.
  terms->clear();
  const Expr* n = &e;
  while (n->kind == ExprKind::Binary && static_cast<const BinaryExpr*>(n)->op == op) {
    terms->push_back(static_cast<const BinaryExpr*>(n)->rhs.get());
    n = static_cast<const BinaryExpr*>(n)->lhs.get();
  }
  terms->push_back(n);
  std::reverse(terms->begin(), terms->end());
  std::vector<const IndexExpr*> checked;
  for (size_t k = 0; k < terms->size(); ++k) {
    const Expr& t = *(*terms)[k];
    // A constant term keeps the whole condition a value (folded, warned about).
    if (t.kind == ExprKind::Literal || t.kind == ExprKind::EnumLiteral) return false;
    // The first term is evaluated whatever it holds; it may fail its own index checks.
    const Type* tt = plain_read_type(t, k > 0 ? &checked : nullptr, 0);
    if (k > 0 && (!tt || tt->kind != TypeKind::Bool)) return false;
    // A term compiled as a value evaluates all its accesses: they prove the same
    // accesses in the terms after it (a chain of jumps inside a term does not).
    if (tt && !is_and_or(t) && !(t.kind == ExprKind::Unary && static_cast<const UnaryExpr&>(t).op == UnaryOp::Not))
      collect_indexes(t, &checked, 0);
  }
  return true;
}

Val Compiler::cond_branch(const Expr& e, Label target, bool when_true) {
  // NOT (a OR b): the chain of a OR b, jumping on the other outcome.
  const Expr* x = &e;
  bool jump_when = when_true;
  while (x->kind == ExprKind::Unary && static_cast<const UnaryExpr*>(x)->op == UnaryOp::Not &&
         is_and_or(*static_cast<const UnaryExpr*>(x)->operand)) {
    x = static_cast<const UnaryExpr*>(x)->operand.get();
    jump_when = !jump_when;
  }
  std::vector<const Expr*> terms;
  if (chain_terms(*x, &terms)) {
    app_->condition_chains = true;
    const bool decides = static_cast<const BinaryExpr*>(x)->op == BinaryOp::Or;  // the value of a term that decides the whole
    const uint32_t saved = b_->temp_top;
    Val v;
    if (jump_when == decides) {
      for (size_t k = 0; k < terms.size() && v.ok; ++k) {
        v = cond_branch(*terms[k], target, decides);
        b_->temp_top = saved;
      }
    } else {
      Label skip = new_label();
      for (size_t k = 0; k < terms.size() && v.ok; ++k) {
        const bool last = k + 1 == terms.size();
        v = cond_branch(*terms[k], last ? target : skip, last ? !decides : decides);
        b_->temp_top = saved;
      }
      bind_forward(skip);
    }
    if (!v.ok) return bad();
    Val out;
    out.type = elem(TypeKind::Bool);
    return out;
  }
  Val v = cond(e);
  if (v.ok) branch_on(v, e.loc, target, when_true);
  return v;
}

namespace {
struct DepthScope {
  int& depth;
  explicit DepthScope(int& d) : depth(d) { ++depth; }
  ~DepthScope() { --depth; }
  DepthScope(const DepthScope&) = delete;
  DepthScope& operator=(const DepthScope&) = delete;
};

// The nodes of an expression, up to `limit` (more: limit + 1); a call counts as one node
// and its arguments.
size_t plain_size(const Expr& e, size_t limit) {
  size_t n = 0;
  std::vector<const Expr*> work{&e};
  while (!work.empty() && n <= limit) {
    const Expr* x = work.back();
    work.pop_back();
    ++n;
    switch (x->kind) {
      case ExprKind::Member: work.push_back(static_cast<const MemberExpr*>(x)->base.get()); break;
      case ExprKind::BitAccess: work.push_back(static_cast<const BitAccessExpr*>(x)->base.get()); break;
      case ExprKind::Index:
        work.push_back(static_cast<const IndexExpr*>(x)->base.get());
        for (const auto& i : static_cast<const IndexExpr*>(x)->indices) work.push_back(i.get());
        break;
      case ExprKind::Deref: work.push_back(static_cast<const DerefExpr*>(x)->base.get()); break;
      case ExprKind::Unary: work.push_back(static_cast<const UnaryExpr*>(x)->operand.get()); break;
      case ExprKind::Binary:
        work.push_back(static_cast<const BinaryExpr*>(x)->lhs.get());
        work.push_back(static_cast<const BinaryExpr*>(x)->rhs.get());
        break;
      case ExprKind::Call:
        for (const auto& a : static_cast<const CallExpr*>(x)->args) {
          if (a.is_output) return limit + 1;  // f(x, OUT => y) writes y
          if (a.value) work.push_back(a.value.get());
        }
        break;
      case ExprKind::ArrayInit: case ExprKind::StructInit: return limit + 1;
      default: break;
    }
  }
  return n;
}

// Whether the statements of `list` from `from` on are a few small assignments (no REF=,
// S=/R=, chained or declaring assignment, no output argument): a copy of them is short.
bool short_rest(const StmtList& list, size_t from) {
  constexpr size_t kMaxStatements = 2, kMaxNodes = 32;
  if (from >= list.size() || list.size() - from > kMaxStatements) return false;
  size_t nodes = 0;
  for (size_t j = from; j < list.size(); ++j) {
    if (list[j]->kind != StmtKind::Assign) return false;
    const auto& a = static_cast<const AssignStmt&>(*list[j]);
    if (a.is_ref_assign || a.set_reset || a.chained || a.declares_temp) return false;
    nodes += plain_size(*a.lhs, kMaxNodes) + plain_size(*a.rhs, kMaxNodes);
    if (nodes > kMaxNodes) return false;
  }
  return true;
}
}  // namespace

void Compiler::stmts(const StmtList& list) {
  DepthScope depth(b_->stmt_depth);
  if (b_->stmt_depth == 1) declare_labels(list);
  bool dead = false;
  // Only the last statement of the list ends where the list does (see loop_tail_); an IF
  // or CASE that only a few short assignments follow (`steps := steps + 1;` after an
  // IF in a WHILE body) ends its arms with a copy of them and of the loop's bottom: the
  // arms that jumped to the IF's end now go on as the code after it does, without the
  // jump (the tail duplication of C compilers).
  const std::function<void()>* const tail = loop_tail_;
  std::function<void()> longer;
  for (size_t k = 0; k < list.size(); ++k) {
    const auto& s = list[k];
    loop_tail_ = k + 1 == list.size() ? tail : nullptr;
    if (tail && k + 1 < list.size() && (s->kind == StmtKind::If || s->kind == StmtKind::Case) && short_rest(list, k + 1)) {
      longer = [this, &list, k, tail] {
        app_->copied_statements = true;
        const std::function<void()>* const inside = loop_tail_;
        loop_tail_ = nullptr;
        for (size_t j = k + 1; j < list.size(); ++j) stmt(*list[j]);
        (*tail)();
        loop_tail_ = inside;
      };
      loop_tail_ = &longer;
    }
    if (s->kind == StmtKind::Label) dead = false;  // a jump may reach it
    if (dead && opt_.warnings && s->kind != StmtKind::Empty && !(b_->pou && b_->pou->is_stdlib)) {
      diags_.warning("ST402", s->loc, "unreachable statement");
      dead = false;  // once per list
    }
    stmt(*s);
    if (s->kind == StmtKind::Return || s->kind == StmtKind::Exit || s->kind == StmtKind::Continue ||
        s->kind == StmtKind::Jump)
      dead = true;
  }
  loop_tail_ = tail;
}

// The end of an IF or CASE arm that other code follows: a jump to the statement's end,
// or, when the statement ends a loop body, the loop's bottom (loop_tail_).
void Compiler::arm_end(Label end) {
  if (!loop_tail_) {
    emit(Op::JMP, {Arg::target(end.id)});
    return;
  }
  b_->cvt_cache.clear();  // conversions the condition made: their temporaries are free again
  (*loop_tail_)();
}

// The labels of an outermost statement list, known before its first JMP (a jump forward).
void Compiler::declare_labels(const StmtList& list) {
  b_->goto_labels.clear();
  for (const auto& s : list) {
    if (s->kind != StmtKind::Label) continue;
    const auto& l = static_cast<const LabelStmt&>(*s);
    auto [it, fresh] = b_->goto_labels.try_emplace(canon(l.name.text), std::pair{new_label(), l.name.loc});
    if (!fresh) {
      const SourceLoc first = it->second.second;
      diags_.error("ST244", l.name.loc, "label '" + l.shown() + "' is declared twice (first at line " +
                                            std::to_string(first.line) + ")");
    }
  }
}

void Compiler::label_stmt(const LabelStmt& s) {
  if (!s.from_il && opt_.dialect == Dialect::Iec) {
    diags_.error("ST241", s.loc, "a label (" + s.shown() + ":) is CODESYS ST, not IEC 61131-3: use IF, CASE or a loop, or --dialect codesys");
    return;
  }
  auto it = b_->goto_labels.find(canon(s.name.text));
  if (b_->stmt_depth != 1 || it == b_->goto_labels.end()) {
    diags_.error("ST244", s.name.loc, "label '" + s.shown() +
                                          "' must stand at the outer level of the body, not inside IF, CASE or a loop (a jump may leave a block, not enter one)");
    return;
  }
  // A label declared twice binds where it was first declared (the second is reported).
  if (it->second.second.line == s.name.loc.line && it->second.second.col == s.name.loc.col) bind(it->second.first);
  for (auto& w : b_->flag_watches) w.dirty = w.ever = true;  // a JMP from anywhere may lead here (rule 28)
}

void Compiler::jump_stmt(const JumpStmt& s) {
  if (!s.from_il && opt_.dialect == Dialect::Iec) {
    diags_.error("ST241", s.loc, "JMP is CODESYS ST, not IEC 61131-3: use IF, CASE or a loop, or --dialect codesys");
    return;
  }
  auto it = b_->goto_labels.find(canon(s.label.text));
  if (it == b_->goto_labels.end()) {
    diags_.error("ST244", s.label.loc, "JMP to '" + s.shown() + "', a label the body does not have");
    return;
  }
  const Label target = it->second.first;
  // A jump back to a label already placed is a loop: it counts against the watchdog.
  emit(b_->label_pos[target.id] == UINT32_MAX ? Op::JMP : Op::JMPB, {Arg::target(target.id)});
}

// `__IL_CRn := e` from Instruction List: a variable of this body, typed by e, in the
// hidden area of the frame (never reused, so it survives the statements and jumps that
// follow; names with two underscores cannot clash with the program's own).
void Compiler::declare_temp(const AssignStmt& s) {
  const auto& name = static_cast<const NameExpr&>(*s.lhs).name;
  if (s.rhs->kind == ExprKind::Call) {
    const PouInfo* f = callee_pou(*static_cast<const CallExpr&>(*s.rhs).callee);
    if (f && f->kind == PouKind::Function && f->result && f->result->kind == TypeKind::Void) {
      call(static_cast<const CallExpr&>(*s.rhs), true);  // a function without a result: a call
      return;
    }
  }
  Val v = expr(*s.rhs);
  if (!v.ok) return;
  const Type* t = v.type ? v.type : default_type(v.c);
  const Slot at = hidden(t->size ? t->size : 1, t->align < 8 ? t->align : 8);
  auto sym = std::make_unique<Symbol>();
  sym->name = name.text;
  sym->type = t;
  sym->where = Where::Frame;
  sym->offset = align_up(b_->vars_end, 8) + at.off;
  sym->section = VarSection::Temp;
  sym->loc = name.loc;
  b_->locals[canon(name.text)] = sym.get();
  const Symbol* declared = sym.get();
  b_->owned.push_back(std::move(sym));
  Place dst;
  dst.k = Place::K::Frame;
  dst.type = t;
  dst.off = declared->offset;
  dst.sym = declared;
  assign(dst, v, s.loc);
}

void Compiler::stmt(const Stmt& s) {
  uint32_t saved_top = b_->temp_top;
  b_->cvt_cache.clear();
  mark(s.loc);
  switch (s.kind) {
    case StmtKind::Assign: assign_stmt(static_cast<const AssignStmt&>(s)); break;
    case StmtKind::Call:
      if (!enabled_call(*static_cast<const CallStmt&>(s).call, nullptr)) call(*static_cast<const CallStmt&>(s).call, true);
      break;
    case StmtKind::If: if_stmt(static_cast<const IfStmt&>(s)); break;
    case StmtKind::Case: case_stmt(static_cast<const CaseStmt&>(s)); break;
    case StmtKind::For: case StmtKind::While: case StmtKind::Repeat: {
      // Rule 28: the paths through a loop come back to its start; what its body may
      // write anywhere, it may have written where the loop is left.
      std::vector<bool> ever;
      for (auto& w : b_->flag_watches) {
        ever.push_back(w.ever);
        w.ever = false;
      }
      if (s.kind == StmtKind::For) for_stmt(static_cast<const ForStmt&>(s));
      else if (s.kind == StmtKind::While) while_stmt(static_cast<const WhileStmt&>(s));
      else repeat_stmt(static_cast<const RepeatStmt&>(s));
      for (size_t k = 0; k < ever.size() && k < b_->flag_watches.size(); ++k) {
        auto& w = b_->flag_watches[k];
        w.dirty = w.dirty || w.ever;
        w.ever = w.ever || ever[k];
      }
      break;
    }
    case StmtKind::Exit:
    case StmtKind::Continue:
      if (b_->loops.empty()) {
        diags_.error("ST219", s.loc, std::string(s.kind == StmtKind::Exit ? "EXIT" : "CONTINUE") + " outside a loop");
        break;
      }
      emit(Op::JMP, {Arg::target(s.kind == StmtKind::Exit ? b_->loops.back().exit.id : b_->loops.back().cont.id)});
      break;
    case StmtKind::Return: emit(Op::RET, {}); break;
    case StmtKind::Empty: break;
    case StmtKind::Label: label_stmt(static_cast<const LabelStmt&>(s)); break;
    case StmtKind::Jump: jump_stmt(static_cast<const JumpStmt&>(s)); break;
    case StmtKind::Mock: {
      const auto& m = static_cast<const MockStmt&>(s);
      if (!b_->in_test) {
        diags_.error("ST234", s.loc, "MOCK is only allowed in TEST, SETUP and TEARDOWN blocks of test files");
        break;
      }
      Place p = place(*m.target, false);
      if (!p.ok) break;
      if (p.type->kind != TypeKind::Pou) {
        diags_.error("ST234", m.target->loc, "MOCK needs a function block instance, not " + p.type->name);
        break;
      }
      emit(Op::SETMOCK, {addr_of(p, s.loc)});
      break;
    }
    case StmtKind::MockFunction: {
      b_->cvt_cache.clear();
      const auto& m = static_cast<const MockFunctionStmt&>(s);
      if (!b_->in_test) {
        diags_.error("ST234", s.loc, "MOCK_FUNCTION is only allowed in TEST, SETUP and TEARDOWN blocks of test files");
        break;
      }
      auto it = pous_.find(canon(m.function.text));
      if (it == pous_.end() || it->second->kind != PouKind::Function || it->second->is_stdlib) {
        diags_.error("ST234", m.function.loc, "'" + m.function.text + "' is not a user FUNCTION");
        break;
      }
      PouInfo* f = it->second;
      ensure_compiled(f, s.loc);
      if (!f->compiled || !f->mock_addr) break;
      Val v = m.value ? expr(*m.value, f->result) : bad();
      if (!v.ok) break;
      if (f->result->kind == TypeKind::Void) {
        diags_.error("ST234", s.loc, "'" + f->name + "' returns nothing");
        break;
      }
      Val c = coerce(v, f->result, m.value->loc, "MOCK_FUNCTION");
      if (!c.ok) break;
      Slot val = to_slot(c, f->result, m.value->loc);
      Place flag;
      flag.k = Place::K::Abs;
      flag.type = elem(TypeKind::Bool);
      flag.off = f->mock_addr;
      store(flag, konst(elem(TypeKind::Bool), ConstV{ConstV::K::Bool, 1, 0, {}}, s.loc));
      Place value = flag;
      value.type = f->result;
      value.off = f->mock_addr + 8;
      store(value, val);
      break;
    }
  }
  b_->temp_top = saved_top;
  b_->cvt_cache.clear();
}

void Compiler::assign_stmt(const AssignStmt& s) {
  if (s.chained && opt_.dialect == Dialect::Iec) {
    diags_.error("ST241", s.loc, "a chained assignment (a := b := c) is CODESYS, not IEC 61131-3: write one assignment per statement, or use --dialect codesys");
    return;
  }
  if (s.set_reset) {
    // x S= c  ->  IF c THEN x := TRUE; END_IF   (R=: FALSE)
    const char* op = s.set_reset == 'S' ? "S=" : "R=";
    if (opt_.dialect == Dialect::Iec)
      diags_.error("ST241", s.loc, std::string(op) + " is CODESYS, not IEC 61131-3: write IF c THEN x := " +
                                       (s.set_reset == 'S' ? "TRUE" : "FALSE") + "; END_IF, or use --dialect codesys");
    Place dst = place(*s.lhs, true);
    uint32_t saved = b_->temp_top;
    Val c = cond(*s.rhs);
    if (!dst.ok || !c.ok) return;
    if (dst.type->kind != TypeKind::Bool) {
      diags_.error("ST203", s.lhs->loc, std::string(op) + " sets a BOOL, not " + dst.type->name);
      return;
    }
    Label skip = new_label();
    branch_on(c, s.rhs->loc, skip, false);
    b_->temp_top = saved;
    Val v;
    v.type = elem(TypeKind::Bool);
    v.is_const = true;
    v.c.k = ConstV::K::Bool;
    v.c.i = s.set_reset == 'S' ? 1 : 0;
    assign(dst, v, s.loc);
    bind(skip);
    return;
  }
  if (s.declares_temp) return declare_temp(s);  // with EN: the value, or the type's initial value
  if (s.rhs->kind == ExprKind::Call && enabled_call(static_cast<const CallExpr&>(*s.rhs), &s)) return;
  // Warn about x := x, a typing accident more often than intent.
  if (opt_.warnings && s.lhs->kind == ExprKind::Name && s.rhs->kind == ExprKind::Name &&
      iequals(static_cast<const NameExpr&>(*s.lhs).name.text, static_cast<const NameExpr&>(*s.rhs).name.text))
    diags_.warning("ST401", s.loc, "assignment of '" + static_cast<const NameExpr&>(*s.lhs).name.text + "' to itself");

  // Property setters: obj.Prop := v, or Prop := v inside the FB.
  if (s.lhs->kind == ExprKind::Member) {
    const auto& m = static_cast<const MemberExpr&>(*s.lhs);
    bool is_global = false;
    if (m.base->kind == ExprKind::Name && !lookup(canon(static_cast<const NameExpr&>(*m.base).name.text))) is_global = true;
    if (!is_global) {
      // Evaluate the base place only when the member is not a plain field.
      const Expr* base_e = m.base.get();
      std::string setter = "__SET_" + canon(m.member.text);
      const Symbol* bs = base_e->kind == ExprKind::Name ? lookup(canon(static_cast<const NameExpr&>(*base_e).name.text)) : nullptr;
      if (bs && bs->type && bs->type->kind == TypeKind::Interface) {
        if (PouInfo* st = bs->type->pou->find_method(setter)) {
          Val itf = expr(*base_e);
          Val v = expr_for(*s.rhs, st->inputs.empty() ? nullptr : st->inputs[0]->type);
          property_set(st, itf.slot, v, s.loc);
          return;
        }
      }
      if (!bs || (bs->type && bs->type->kind == TypeKind::Pou && !bs->type->field(m.member.text)) || !bs) {
        defer_index_cvt_ = !may_call(*s.rhs) && !may_call(*base_e);  // arr[i].f := e: see index_place
        Place base = place(*base_e, true);
        defer_index_cvt_ = false;
        if (!base.ok) return;
        if (base.type->kind == TypeKind::Pou && base.type->pou && !base.type->field(m.member.text)) {
          if (PouInfo* st = base.type->pou->find_method(setter)) {
            Val v = expr_for(*s.rhs, st->inputs.empty() ? nullptr : st->inputs[0]->type);
            property_set(st, addr_of(base, s.loc), v, s.loc);
            return;
          }
        }
        if (base.type->kind == TypeKind::Interface && base.type->pou) {
          if (PouInfo* st = base.type->pou->find_method(setter)) {
            Val itf = load(base);
            Val v = expr_for(*s.rhs, st->inputs.empty() ? nullptr : st->inputs[0]->type);
            property_set(st, itf.slot, v, s.loc);
            return;
          }
        }
        Place dst = implicit_deref(member_place(base, m.member, s.lhs->loc), s.lhs->loc);
        if (!dst.ok) return;
        Val v = expr_for(*s.rhs, dst.type);
        if (s.is_ref_assign) {
          diags_.error("ST232", s.loc, "REF= needs a reference on the left");
          return;
        }
        assign(dst, v, s.loc);
        return;
      }
    }
  }
  if (s.lhs->kind == ExprKind::Name && b_->this_type && b_->this_type->pou) {
    std::string key = canon(static_cast<const NameExpr&>(*s.lhs).name.text);
    const PouInfo* cur = b_->pou;
    bool is_result = cur && ((!cur->property.empty() && iequals(cur->property, key)) || iequals(cur->name, key));
    if (!lookup(key) && !is_result) {
      if (PouInfo* st = b_->this_type->pou->find_method("__SET_" + key)) {
        Place self = this_place(s.loc);
        Val v = expr_for(*s.rhs, st->inputs.empty() ? nullptr : st->inputs[0]->type);
        property_set(st, addr_of(self, s.loc), v, s.loc);
        return;
      }
    }
  }
  defer_index_cvt_ = !s.is_ref_assign && !may_call(*s.rhs) && !may_call(*s.lhs);  // arr[i] := e: see index_place
  Place dst = s.is_ref_assign ? place_ref(*s.lhs, true) : place(*s.lhs, true);
  defer_index_cvt_ = false;
  if (!dst.ok) {
    expr(*s.rhs);  // still check the right-hand side
    return;
  }
  if (s.is_ref_assign) {
    // r REF= x: r takes the address of x.
    if (dst.type->kind != TypeKind::Ref) {
      diags_.error("ST232", s.loc, "REF= needs a reference on the left, not " + dst.type->name);
      return;
    }
    bind_reference(dst, *s.rhs, s.loc);
    return;
  }
  Val v = expr_for(*s.rhs, dst.type);
  if (v.ok && v.type && v.type->kind == TypeKind::Pou && dst.type->kind == TypeKind::Pou && v.type != dst.type) {
    diags_.error("ST203", s.loc, "cannot assign an instance of " + v.type->name + " to " + dst.type->name);
    return;
  }
  assign(dst, v, s.loc);
}

bool Compiler::select_safe(const Expr& e, const std::vector<const IndexExpr*>* checked, int depth) {
  if (depth > 64) return false;
  switch (e.kind) {
    case ExprKind::EnumLiteral: return true;
    case ExprKind::Literal: {
      const LiteralKind k = static_cast<const LiteralExpr&>(e).lit;
      return k != LiteralKind::String && k != LiteralKind::WString;  // numbers, BOOL, times, dates
    }
    case ExprKind::Unary: return select_safe(*static_cast<const UnaryExpr&>(e).operand, checked, depth + 1);
    case ExprKind::Binary: {
      const auto& b = static_cast<const BinaryExpr&>(e);
      if (b.op == BinaryOp::Pow || b.op == BinaryOp::AndThen || b.op == BinaryOp::OrElse) return false;
      if (!divisor_cannot_fail(b)) return false;
      return select_safe(*b.lhs, checked, depth + 1) && select_safe(*b.rhs, checked, depth + 1);
    }
    case ExprKind::Call: {
      const auto& c = static_cast<const CallExpr&>(e);
      if (c.callee->kind != ExprKind::Name) return false;
      const std::string key = canon(static_cast<const NameExpr&>(*c.callee).name.text);
      if (lookup(key) || pous_.count(key)) return false;  // the program's own, whatever its name
      static const std::set<std::string, std::less<>> kValueFunctions = {"SHL", "SHR", "ROL", "ROR", "MIN",
                                                                         "MAX", "LIMIT", "MOVE"};
      if (!kValueFunctions.count(key)) {
        // A conversion between numbers, bit strings and BOOL (no BCD, no STRING, no units).
        const std::optional<ConversionName> cn = parse_conversion(*tt_, key);
        auto plain = [](const Type* t) { return t->is_numeric() || t->is_anybit(); };
        if (!cn || !cn->to || cn->bcd != ConversionName::Bcd::None || cn->unit_ns != 0 || !plain(cn->to) ||
            (cn->from && !plain(cn->from)))
          return false;
      }
      for (const CallArg& a : c.args)
        if (a.is_output || a.name || !a.value || !select_safe(*a.value, checked, depth + 1)) return false;
      return !c.args.empty();
    }
    default: return plain_read_type(e, checked, depth) != nullptr;
  }
}

namespace {
// The one assignment `v := e` an arm consists of, when it is a plain one to a variable
// named by itself (no element, member, REF=, S=/R=, chained or declaring form).
const AssignStmt* single_assignment(const StmtList& body) {
  if (body.size() != 1 || body[0]->kind != StmtKind::Assign) return nullptr;
  const auto* a = static_cast<const AssignStmt*>(body[0].get());
  if (a->is_ref_assign || a->set_reset || a->chained || a->declares_temp || a->lhs->kind != ExprKind::Name) return nullptr;
  return a;
}

bool int_literal(const Expr& e, uint64_t* value) {
  if (e.kind != ExprKind::Literal) return false;
  const auto& l = static_cast<const LiteralExpr&>(e);
  if (l.lit != LiteralKind::Int) return false;
  *value = l.int_value;
  return true;
}
}  // namespace

// A comparison of one bit with 0 that was just emitted as a value, "AND t, x, m; EQ/NE
// c, t, 0" with a single-bit constant m (either operand order) or "MODK t, x, .., 2;
// EQ/NE c, t, 0", in the same line and block, t read by the comparison only: replaced by
// one GETBIT of x, the bit (set: the "<> 0"; *inverted for "= 0"). Nullopt: nothing changed.
std::optional<Slot> Compiler::single_bit(bool* inverted) {
  auto& code = b_->code;
  const uint32_t cmp_at = b_->last_instr;
  if (cmp_at >= code.size() || cmp_at + 4 != code.size()) return std::nullopt;
  constexpr uint32_t num_stride = static_cast<uint32_t>(Op::ADD_I16) - static_cast<uint32_t>(Op::ADD_I8);
  constexpr uint32_t int_stride = static_cast<uint32_t>(Op::MOD_I16) - static_cast<uint32_t>(Op::MOD_I8);
  static constexpr uint32_t kWidth[] = {1, 2, 4, 8, 1, 2, 4, 8};
  uint32_t ti = 8;
  bool eq = false;
  for (uint32_t k = 0; k < 8; ++k) {
    if (code[cmp_at] == static_cast<uint32_t>(Op::EQ_I8) + k * num_stride) ti = k, eq = true;
    if (code[cmp_at] == static_cast<uint32_t>(Op::NE_I8) + k * num_stride) ti = k;
  }
  const std::optional<uint32_t> at = ti < 8 ? zero_tested_temp(cmp_at, ti) : std::nullopt;
  if (!at) return std::nullopt;
  const uint32_t op_at = *at, op = code[op_at], t = code[op_at + 1];
  uint32_t bit = 0;
  bool x_second = false;  // AND's x is its second operand (the mask the first)
  if (op == static_cast<uint32_t>(Op::AND_I8) + ti * int_stride && op_at + 4 == cmp_at) {
    auto single = [&](uint32_t word) -> std::optional<uint32_t> {
      std::optional<uint64_t> m = const_at(word, kWidth[ti]);
      if (!m || *m == 0 || (*m & (*m - 1)) != 0) return std::nullopt;
      return static_cast<uint32_t>(std::countr_zero(*m));
    };
    if (std::optional<uint32_t> b = single(op_at + 3)) bit = *b;
    else if (std::optional<uint32_t> b2 = single(op_at + 2)) bit = *b2, x_second = true;
    else return std::nullopt;
  } else if ((op == static_cast<uint32_t>(Op::MODK_I32) && ti == 2) || (op == static_cast<uint32_t>(Op::MODK_I16) && ti == 1)) {
    if (op_at + 6 != cmp_at || code[op_at + 5] != 2) return std::nullopt;
    bit = 0;  // x MOD 2 <> 0: bit 0 set, whatever the sign
  } else {
    return std::nullopt;
  }
  auto [a, b] = unemit(op_at);
  const Arg x = x_second ? b : a;
  // The bit goes where the AND's (or MODK's) result went, and the comparison's
  // temporary, allocated after it, is free again: the temporaries after it are placed as
  // after a GETBIT of the word written out.
  const Slot d{t, SK::Temp};
  b_->temp_top = t + 1;
  const uint32_t n = kWidth[ti];
  emit(n == 1 ? Op::GETBIT1 : n == 2 ? Op::GETBIT2 : n == 4 ? Op::GETBIT4 : Op::GETBIT8, {d, x, bit});
  def(d);
  *inverted = eq;
  return d;
}

// Rule 26 (chosen on the tuning half): an IF whose condition tests bits of data and whose
// arms each assign the same variable, `IF (crc AND 16#8000) <> 0 THEN crc := SHL(crc, 1)
// XOR 16#1021; ELSE crc := SHL(crc, 1); END_IF` or `IF flags[i] THEN w := w OR SHL(WORD#1,
// k); END_IF`, evaluates both values and selects one (SEL1..SEL8): such bits are
// data, a CRC's or a parity's or a flag array's, and a jump on them goes either way at
// random (a mispredicted jump costs more than the few instructions of the other arm).
// Comparisons of magnitudes (limits, state machine events, counters) and BOOL status
// variables (an edge's Q, a limit switch) mostly go one way and keep their jump: selects
// made the tuning kernels that have them slower. Applies when the arms only read
// variables and cannot fail (select_safe), so evaluating the arm not taken cannot be
// seen; the variable is a plain one of a type of 1, 2, 4 or 8 bytes without a subrange;
// the condition is an element of a BOOL array or a bit of a word (w.3), NOT of one, or
// (x AND K) or x MOD 2^k compared (= or <>) with 0; there is no ELSIF; and no coverage
// is collected. The condition is evaluated once, as before.
bool Compiler::select_if(const IfStmt& s) {
  if (!opt_.if_selects || opt_.coverage || s.arms.size() != 1 || !s.arms[0].label.empty()) return false;
  const auto& arm = s.arms[0];
  const AssignStmt* yes = single_assignment(arm.body);
  const AssignStmt* no = s.else_body ? single_assignment(*s.else_body) : nullptr;
  if (!yes || (s.else_body && (!no || !same_expr(*yes->lhs, *no->lhs, 0)))) return false;
  const Type* t = plain_read_type(*yes->lhs, nullptr, 0);
  if (!t || !t->is_elementary() || t->is_string() || t->ranged || t->kind == TypeKind::Ref ||
      (t->size != 1 && t->size != 2 && t->size != 4 && t->size != 8))
    return false;
  // x := x in an arm: ST401's warning is the assignment statement's.
  auto self = [&](const AssignStmt* a) {
    return a && a->rhs->kind == ExprKind::Name &&
           iequals(static_cast<const NameExpr&>(*a->rhs).name.text, static_cast<const NameExpr&>(*a->lhs).name.text);
  };
  if (self(yes) || self(no)) return false;

  // The condition, NOTs taken off: which form of bit test, if any.
  const Expr* c = arm.cond.get();
  bool when = true;  // the select takes `yes` when the test gives this
  while (c->kind == ExprKind::Unary && static_cast<const UnaryExpr*>(c)->op == UnaryOp::Not) {
    c = static_cast<const UnaryExpr*>(c)->operand.get();
    when = !when;
  }
  if (c->kind == ExprKind::Index || c->kind == ExprKind::BitAccess) {
    const Type* ct = plain_read_type(*c, nullptr, 0);
    if (!ct || ct->kind != TypeKind::Bool) return false;
  } else if (c->kind == ExprKind::Binary) {
    const auto& cmp = static_cast<const BinaryExpr&>(*c);
    if (cmp.op != BinaryOp::Eq && cmp.op != BinaryOp::Ne) return false;
    uint64_t zero = 1;
    const Expr* tested = int_literal(*cmp.rhs, &zero) ? cmp.lhs.get() : int_literal(*cmp.lhs, &zero) ? cmp.rhs.get() : nullptr;
    if (!tested || zero != 0 || tested->kind != ExprKind::Binary) return false;
    const auto& m = static_cast<const BinaryExpr&>(*tested);
    uint64_t k = 0;
    if (m.op == BinaryOp::And) {
      if (!int_literal(*m.rhs, &k) && !int_literal(*m.lhs, &k)) return false;
    } else if (m.op == BinaryOp::Mod) {
      // x MOD 2^k is 0 exactly when the k low bits of x are (either sign, truncated MOD).
      if (!int_literal(*m.rhs, &k) || k < 2 || (k & (k - 1)) != 0) return false;
    } else {
      return false;
    }
  } else {
    return false;
  }
  // The arms are evaluated whether taken or not: each only reads and cannot fail (an
  // element the condition reads is checked by then).
  std::vector<const IndexExpr*> checked;
  collect_indexes(*c, &checked, 0);
  if (!select_safe(*yes->rhs, &checked, 0) || (no && !select_safe(*no->rhs, &checked, 0))) return false;

  const uint32_t saved = b_->temp_top;
  mark(arm.loc);
  const size_t code_before = b_->code.size();
  // The condition as a value, compiled (and type-checked) as any BOOL expression; a
  // constant one (nothing emitted) is left to the jumps, which fold it and warn (ST404).
  Val cond_value = expr(*c, elem(TypeKind::Bool));
  if (cond_value.ok && cond_value.is_const && b_->code.size() == code_before) return b_->temp_top = saved, false;
  if (!cond_value.ok) return b_->temp_top = saved, true;
  if (!cond_value.type || cond_value.type->kind != TypeKind::Bool) {
    diags_.error("ST205", c->loc, "a condition must be BOOL, not " + tname(cond_value.type));
    return b_->temp_top = saved, true;
  }
  Slot test = to_slot(cond_value, elem(TypeKind::Bool), c->loc);
  // One bit tested: GETBIT instead of the AND (or MOD 2) and the comparison.
  bool inverted = false;
  if (std::optional<Slot> bit = single_bit(&inverted)) {
    test = *bit;
    if (inverted) when = !when;
  }
  // The arms' coverage ids as the jumps would have them (no COV: no coverage here).
  uint32_t decision = kNoBranch;
  branch(arm.loc, "IF", s.loc, &decision, arm.body);
  if (s.else_body) branch(s.else_loc.valid() ? s.else_loc : s.loc, "ELSE", s.loc, &decision, *s.else_body);
  auto value = [&](const Expr& e, SourceLoc loc) -> std::optional<Slot> {
    Val v = expr_for(e, t);
    if (!v.ok) return std::nullopt;
    Val cv = coerce(v, t, loc, "assignment");
    if (!cv.ok) return std::nullopt;
    return to_slot(cv, t, loc);
  };
  mark(yes->loc);
  std::optional<Slot> a = value(*yes->rhs, yes->loc);
  if (no) mark(no->loc);
  std::optional<Slot> b = no ? value(*no->rhs, no->loc) : value(*yes->lhs, yes->loc);
  if (!a || !b) return b_->temp_top = saved, true;
  Slot d = temp_for(t);
  emit(sel_op(t->size), {d, test, when ? *a : *b, when ? *b : *a});
  def(d, 1);
  Place dst = place(*yes->lhs, true);
  assign(dst, slot_val(t, d), yes->loc);
  b_->temp_top = saved;
  b_->cvt_cache.clear();
  app_->if_selects = true;
  return true;
}

namespace {
// The nodes of e (an expression plain_read_type accepts) written as `x` is.
void find_same(const Expr& e, const Expr& x, std::vector<const Expr*>* out, int depth) {
  if (depth > 64) return;
  if (same_expr(e, x, 0)) {
    out->push_back(&e);
    return;
  }
  switch (e.kind) {
    case ExprKind::Member: find_same(*static_cast<const MemberExpr&>(e).base, x, out, depth + 1); break;
    case ExprKind::BitAccess: find_same(*static_cast<const BitAccessExpr&>(e).base, x, out, depth + 1); break;
    case ExprKind::Index:
      for (const auto& i : static_cast<const IndexExpr&>(e).indices) find_same(*i, x, out, depth + 1);
      break;
    case ExprKind::Unary: find_same(*static_cast<const UnaryExpr&>(e).operand, x, out, depth + 1); break;
    case ExprKind::Binary:
      find_same(*static_cast<const BinaryExpr&>(e).lhs, x, out, depth + 1);
      find_same(*static_cast<const BinaryExpr&>(e).rhs, x, out, depth + 1);
      break;
    default: break;
  }
}
}  // namespace

// Rule 27, for `IF tags[half].tag = want THEN ... ELSIF tags[half].tag < want THEN` and
// `IF x[i] > top THEN top := x[i];`: a condition that compares two operands that only
// read (plain_read_type), each a variable, a literal or an array element, ends with one
// jump to `next` reading the temporaries the elements were loaded into, in the block the
// loads are in (a load converted before the comparison is not the element as its type has
// it: not held). Where the jump goes and where it falls through, nothing has run since
// the loads: the temporaries hold the elements, with array and index unchanged. An ELSIF
// that compared an element `carried` held for it (no load of its own) hands it on.
Compiler::Held Compiler::compared_elements(const Expr& cond, Label next, const Held& carried) {
  if (!opt_.elsif_reuse || cond.kind != ExprKind::Binary) return {};
  const auto& b = static_cast<const BinaryExpr&>(cond);
  if (!is_cmp(b.op) || !plain_read_type(cond, nullptr, 0)) return {};
  const auto& code = b_->code;
  const uint32_t j = b_->last_instr;
  if (j >= code.size() || j < b_->last_label_pos || j + op_length(&code[j]) != code.size()) return {};
  if (!is_conditional_jump(static_cast<Op>(code[j])) || b_->label_refs[next.id] != 1) return {};
  if (std::none_of(b_->target_fix.begin(), b_->target_fix.end(),
                   [&](const auto& f) { return f.first == j + 1 && f.second == next.id; }))
    return {};
  auto jump_reads = [&](Slot t) {
    for (uint32_t w = j + 2; w < j + op_length(&code[j]); ++w)
      if (code[w] == t.off && kind_at(w) == SK::Temp) return true;
    return false;
  };
  Held out;
  for (const Expr* side : {b.lhs.get(), b.rhs.get()}) {
    if (side->kind != ExprKind::Index && side->kind != ExprKind::Member) continue;
    const Type* t = plain_read_type(*side, nullptr, 0);
    std::vector<const IndexExpr*> indexes;
    collect_indexes(*side, &indexes, 0);
    if (!t || !t->is_elementary() || t->is_string() || indexes.empty()) continue;
    const auto from = std::find_if(carried.begin(), carried.end(), [&](const HeldElement& h) { return same_expr(*side, *h.e, 0); });
    if (from != carried.end()) {
      if (jump_reads(from->slot)) out.push_back({side, from->slot, t});
      continue;
    }
    for (const auto& [e, at] : b_->elem_loads) {
      if (e != side || at < b_->last_label_pos || at >= j || kind_at(at + 1) != SK::Temp) continue;
      const std::string_view name = op_info(static_cast<Op>(code[at])).name;
      if (!(name.starts_with("LDX") || name.starts_with("LDI")) || name == "LDXB") continue;
      const Slot held{code[at + 1], SK::Temp};
      if (jump_reads(held)) out.push_back({side, held, t});
    }
  }
  return out;
}

namespace {
// The variables named in an expression, through its operators; false when it holds
// anything but names, literals and operators (an index, a member, a call), whose own
// names are not collected.
bool names_read(const Expr& e, std::vector<std::string>* out) {
  bool plain = true;
  std::vector<const Expr*> work{&e};
  while (!work.empty()) {
    const Expr* x = work.back();
    work.pop_back();
    switch (x->kind) {
      case ExprKind::Name: out->push_back(static_cast<const NameExpr*>(x)->name.text); break;
      case ExprKind::Literal: case ExprKind::EnumLiteral: break;
      case ExprKind::Unary: work.push_back(static_cast<const UnaryExpr*>(x)->operand.get()); break;
      case ExprKind::Binary:
        work.push_back(static_cast<const BinaryExpr*>(x)->lhs.get());
        work.push_back(static_cast<const BinaryExpr*>(x)->rhs.get());
        break;
      default: plain = false; break;
    }
  }
  return plain;
}

bool has_name(const std::vector<std::string>& names, const std::string& n) {
  return std::any_of(names.begin(), names.end(), [&](const std::string& x) { return iequals(x, n); });
}
}  // namespace

// Rule 29: whether an arm of the IF that ends a loop body leaves the loop: a statement of
// its own list (not nested) is EXIT or RETURN, or assigns to a variable that the innermost
// WHILE's condition or REPEAT's UNTIL reads a value made of literals and the condition's
// other variables (`found := TRUE`, `i := 64` in `WHILE i < 64`, `lo := hi + 1` in
// `WHILE lo <= hi`; not `lo := half + 1`, not `i := i + 1`). Such an arm runs once per
// entry of the loop; the others run on every pass.
bool Compiler::leaves_loop(const StmtList& body) const {
  std::vector<std::string> reads;  // the condition's plain names (not inside an index or a call)
  if (!b_->loops.empty() && b_->loops.back().cond) names_read(*b_->loops.back().cond, &reads);
  for (const auto& st : body) {
    if (st->kind == StmtKind::Exit || st->kind == StmtKind::Return) return true;
    if (st->kind != StmtKind::Assign) continue;
    const auto& a = static_cast<const AssignStmt&>(*st);
    if (a.is_ref_assign || a.set_reset || a.chained || a.declares_temp || a.lhs->kind != ExprKind::Name) continue;
    const std::string& name = static_cast<const NameExpr&>(*a.lhs).name.text;
    std::vector<std::string> value;
    if (!has_name(reads, name) || !names_read(*a.rhs, &value) || has_name(value, name)) continue;
    if (std::all_of(value.begin(), value.end(), [&](const std::string& v) { return has_name(reads, v); })) return true;
  }
  return false;
}

void Compiler::if_stmt(const IfStmt& s) {
  if (select_if(s)) return;
  Label end = new_label();
  uint32_t decision = kNoBranch;
  // Rule 27: what the condition before held (for an ELSIF's condition or the ELSE's first
  // statement) and what an arm's own condition holds (for the arm's first statement).
  Held held;
  std::vector<const Expr*> reuse;
  // Presets the reads of h's element in e (only reads, no call: nothing between writes
  // the array, the index or the temporary), the temporaries of e's code after h's.
  auto hold = [&](const Expr* e, const Held& hs) {
    reuse.clear();
    if (hs.empty() || !e || !plain_read_type(*e, nullptr, 0)) return;
    for (const HeldElement& h : hs) {
      const size_t before = reuse.size();
      find_same(*e, *h.e, &reuse, 0);
      for (size_t k = before; k < reuse.size(); ++k) preset_[reuse[k]] = slot_val(h.type, h.slot);
      if (reuse.size() > before) b_->temp_top = std::max(b_->temp_top, h.slot.off + h.type->size);
    }
    if (!reuse.empty()) app_->elsif_reuse = true;
  };
  auto release = [&] {
    for (const Expr* x : reuse) preset_.erase(x);
  };
  // The value an arm's first statement assigns, when it is a plain assignment (its
  // target's indexes only read): a read of the held element there comes before any store.
  auto first_value = [&](const StmtList& body) -> const Expr* {
    if (body.empty() || body[0]->kind != StmtKind::Assign) return nullptr;
    const auto& a = static_cast<const AssignStmt&>(*body[0]);
    if (a.is_ref_assign || a.set_reset || a.chained || a.declares_temp || !plain_read_type(*a.lhs, nullptr, 0)) return nullptr;
    return a.rhs.get();
  };
  // Rule 28: each arm starts from what the conditions before it left; the IF's end is
  // reached from the arms that end with a jump to it (not those that end a loop body
  // with a copy of its bottom) and from the last condition without ELSE.
  const bool tails = loop_tail_ != nullptr;
  std::vector<bool> conds = watch_state(), after = conds;
  // Rule 29: the arms that leave the loop, placed after the others (each condition in
  // its place, jumping to its arm when it holds). Not with coverage: the arms' ids would
  // be numbered in another order than the source's.
  struct Cold {
    size_t arm;
    Label at;
    std::vector<bool> watch;
    std::vector<const Expr*> rest;  // an AND's terms after the first, tested at `at`
    Held held;                      // what the condition loaded (rule 27)
  };
  std::vector<Cold> cold;
  // Placed after the last conditional arm when that one stays in the loop (before the
  // ELSE, which its condition jumps to, as the arms that leave do not), else after the
  // ELSE; an ELSE that leaves the loop too then keeps the source's order (it would jump).
  const bool last_leaves = tails && leaves_loop(s.arms.back().body);
  const bool place_cold = tails && opt_.cold_arms && !opt_.coverage && !(last_leaves && s.else_body && leaves_loop(*s.else_body));
  // The arms that leave, each after its own condition's jump; the last one may fall
  // through to the statement's end when nothing follows it.
  auto emit_cold = [&](bool last_falls) {
    for (size_t k = 0; k < cold.size(); ++k) {
      const auto& arm = s.arms[cold[k].arm];
      bind(cold[k].at);
      mark(arm.loc);
      set_watch_state(cold[k].watch);
      const uint32_t saved = b_->temp_top;
      Label fails = new_label();
      for (const Expr* t : cold[k].rest) {
        cond_branch(*t, fails, false);  // read only, cannot fail (chain_terms)
        b_->temp_top = saved;
      }
      {
        ArmScope in(b_, branch(arm.loc, !arm.label.empty() ? arm.label.c_str() : cold[k].arm == 0 ? "IF" : "ELSIF",
                               s.loc, &decision, arm.body));
        hold(first_value(arm.body), cold[k].held);  // reached straight from its condition
        stmts(arm.body);
        release();
      }
      b_->temp_top = saved;
      if (k + 1 < cold.size() || !cold[k].rest.empty() || !last_falls) arm_end(end);
      merge_watch_state(&after, watch_state());
      if (!cold[k].rest.empty()) {
        // The AND failed after its first term: the ELSE again (it ends the statement).
        bind(fails);
        set_watch_state(cold[k].watch);
        if (s.else_body) {
          app_->copied_statements = true;
          stmts(*s.else_body);
          b_->temp_top = saved;
        }
        merge_watch_state(&after, watch_state());
      }
    }
    cold.clear();
  };
  for (size_t i = 0; i < s.arms.size(); ++i) {
    const auto& arm = s.arms[i];
    uint32_t saved = b_->temp_top;
    mark(arm.loc);
    if (place_cold && leaves_loop(arm.body)) {
      set_watch_state(conds);
      Label at = new_label();
      // `a AND b`, the last condition, an ELSE of a few short assignments or none: a
      // jump to `at` when a holds, b tested there; where it fails, a copy of the ELSE
      // (and the loop's bottom) follows, so that the passes on which a fails, the most
      // of a search, go straight on.
      std::vector<const Expr*> terms;
      const bool split = cold.empty() && i + 1 == s.arms.size() && (!s.else_body || short_rest(*s.else_body, 0)) &&
                         arm.cond->kind == ExprKind::Binary &&
                         static_cast<const BinaryExpr&>(*arm.cond).op == BinaryOp::And && chain_terms(*arm.cond, &terms);
      if (split) app_->condition_chains = true;
      hold(arm.cond.get(), held);
      const bool carried = !reuse.empty();
      Val c = cond_branch(split ? *terms[0] : *arm.cond, at, true);
      release();
      if (split) terms.erase(terms.begin());
      else terms.clear();
      if (opt_.warnings && c.ok && c.is_const && !(b_->pou && b_->pou->is_stdlib))
        diags_.warning("ST404", arm.cond->loc, std::string("condition is always ") + (c.c.i ? "TRUE" : "FALSE"));
      // Rule 27: what the comparison loaded is there both where it jumps (the arm, placed
      // later) and where it falls through (the next condition).
      held = !split && c.ok && !c.is_const ? compared_elements(*arm.cond, at, carried ? held : Held{}) : Held{};
      conds = watch_state();
      cold.push_back({i, at, conds, std::move(terms), held});
      b_->temp_top = saved;
      app_->cold_arms = true;
      continue;
    }
    Label next = new_label();
    set_watch_state(conds);
    hold(arm.cond.get(), held);
    const bool carried = !reuse.empty();
    Val c = cond_branch(*arm.cond, next, false);
    release();
    if (opt_.warnings && c.ok && c.is_const && !(b_->pou && b_->pou->is_stdlib))
      diags_.warning("ST404", arm.cond->loc, std::string("condition is always ") + (c.c.i ? "TRUE" : "FALSE"));
    held = c.ok && !c.is_const ? compared_elements(*arm.cond, next, carried ? held : Held{}) : Held{};
    conds = watch_state();
    b_->temp_top = saved;
    {
      const char* kind = !arm.label.empty() ? arm.label.c_str() : i == 0 ? "IF" : "ELSIF";
      ArmScope in(b_, branch(arm.loc, kind, s.loc, &decision, arm.body));
      hold(first_value(arm.body), held);
      stmts(arm.body);
      release();
      b_->temp_top = saved;
    }
    const bool cold_here = !cold.empty() && i + 1 == s.arms.size();  // this arm stays, the last
    if (i + 1 < s.arms.size() || s.else_body || cold_here) arm_end(end);
    if (!tails || (i + 1 == s.arms.size() && !s.else_body)) merge_watch_state(&after, watch_state());
    if (cold_here) emit_cold(false);
    bind(next);
  }
  set_watch_state(conds);
  if (s.else_body) {
    ArmScope in(b_, branch(s.else_loc.valid() ? s.else_loc : s.loc, "ELSE", s.loc, &decision, *s.else_body));
    const uint32_t saved = b_->temp_top;
    hold(first_value(*s.else_body), held);
    stmts(*s.else_body);
    release();
    b_->temp_top = saved;
  }
  merge_watch_state(&after, watch_state());
  if (!cold.empty()) {
    // The passes that stay in the loop end here; the arms that leave it follow.
    arm_end(end);
    emit_cold(true);
  }
  set_watch_state(after);
  bind_forward(end);
}

void Compiler::case_stmt(const CaseStmt& s) {
  Val sel = expr(*s.selector);
  if (!sel.ok) return;
  const Type* st = sel.type ? sel.type : default_type(sel.c);
  if (!st->is_integer() && st->kind != TypeKind::Enum && !st->is_bitstring()) {
    diags_.error("ST221", s.selector->loc, "CASE needs an integer or enumeration selector, not " + st->name);
    return;
  }
  Slot sslot = to_slot(sel, st, s.selector->loc);
  // Labels: constants checked for type and duplicates.
  struct Range {
    int64_t lo, hi;
    size_t arm;
  };
  std::vector<Range> ranges;
  auto label_value = [&](const Expr& e) -> std::optional<int64_t> {
    Val v = expr(e, st);
    if (!v.ok) return std::nullopt;
    if (!v.is_const || v.c.k != ConstV::K::Int) {
      diags_.error("ST221", e.loc, "a CASE label must be a constant");
      return std::nullopt;
    }
    if (v.type && st->kind == TypeKind::Enum && v.type != st) {
      diags_.error("ST221", e.loc, "label of type " + v.type->name + " in a CASE over " + st->name);
      return std::nullopt;
    }
    if (!v.type && st->kind == TypeKind::Enum) {
      diags_.error("ST221", e.loc, "use " + st->name + " values as labels, not integers");
      return std::nullopt;
    }
    return v.c.i;
  };
  for (size_t a = 0; a < s.arms.size(); ++a) {
    for (const auto& l : s.arms[a].labels) {
      if (!l.lo) continue;
      std::optional<int64_t> lo_opt = label_value(*l.lo);
      std::optional<int64_t> hi_opt = l.hi ? label_value(*l.hi) : lo_opt;
      if (!lo_opt || !hi_opt) continue;
      int64_t lo = *lo_opt, hi = *hi_opt;
      if (hi < lo) {
        diags_.error("ST221", l.lo->loc, "empty label range");
        continue;
      }
      for (const auto& r : ranges)
        if (!(hi < r.lo || lo > r.hi)) {
          diags_.error("ST221", l.lo->loc, "CASE label " + std::to_string(std::max(lo, r.lo)) + " appears twice");
          break;
        }
      ranges.push_back({lo, hi, a});
    }
  }
  std::vector<Label> arm_labels;
  for (size_t a = 0; a < s.arms.size(); ++a) arm_labels.push_back(new_label());
  Label else_label = new_label();
  Label end = new_label();

  int64_t mn = INT64_MAX, mx = INT64_MIN;
  uint64_t covered = 0;
  for (const auto& r : ranges) {
    mn = std::min(mn, r.lo);
    mx = std::max(mx, r.hi);
    covered += static_cast<uint64_t>(r.hi - r.lo + 1);
  }
  bool fits32 = st->size <= 4 && !(st->storage() == Storage::U32);
  if (!ranges.empty() && fits32 && mx - mn < 1024 && covered * 3 >= static_cast<uint64_t>(mx - mn + 1)) {
    // Dense labels: one jump table.
    Slot idx = convert(sslot, st->kind == TypeKind::Enum ? st->base : st, elem(TypeKind::DInt));
    std::vector<Arg> args{idx, static_cast<uint32_t>(static_cast<int32_t>(mn)), static_cast<uint32_t>(mx - mn + 1),
                          Arg::target(else_label.id)};
    for (int64_t v = mn; v <= mx; ++v) {
      Label target = else_label;
      for (const auto& r : ranges)
        if (v >= r.lo && v <= r.hi) target = arm_labels[r.arm];
      args.push_back(Arg::target(target.id));
    }
    emit_list(Op::JTAB, args);
  } else {
    const Type* ct = st->kind == TypeKind::Enum ? st->base : st;
    for (const auto& r : ranges) {
      Slot lo = konst(ct, ConstV{ConstV::K::Int, r.lo, 0, {}}, s.loc);
      if (r.lo == r.hi) {
        emit(num_op(Op::JEQ_I8, ct->storage()), {Arg::target(arm_labels[r.arm].id), sslot, lo});
      } else {
        Slot hi = konst(ct, ConstV{ConstV::K::Int, r.hi, 0, {}}, s.loc);
        Label skip = new_label();
        emit(num_op(Op::JLT_I8, ct->storage()), {Arg::target(skip.id), sslot, lo});
        emit(num_op(Op::JGE_I8, ct->storage()), {Arg::target(arm_labels[r.arm].id), hi, sslot});
        bind(skip);
      }
    }
    emit(Op::JMP, {Arg::target(else_label.id)});
  }
  uint32_t decision = kNoBranch;
  const std::vector<bool> start = watch_state();  // rule 28, as in if_stmt
  const bool tails = loop_tail_ != nullptr;
  std::vector<bool> after = start;
  for (size_t a = 0; a < s.arms.size(); ++a) {
    bind(arm_labels[a]);
    set_watch_state(start);
    {
      ArmScope in(b_, branch(s.arms[a].loc, "CASE", s.loc, &decision, s.arms[a].body));
      stmts(s.arms[a].body);
    }
    arm_end(end);
    if (!tails) merge_watch_state(&after, watch_state());
  }
  bind(else_label);
  set_watch_state(start);
  if (s.else_body) {
    ArmScope in(b_, branch(s.else_loc.valid() ? s.else_loc : s.loc, "ELSE", s.loc, &decision, *s.else_body));
    stmts(*s.else_body);
  }
  merge_watch_state(&after, watch_state());
  set_watch_state(after);
  bind(end);
}

const Compiler::CounterRange* Compiler::proven_range(Slot s) const {
  for (auto it = counters_.rbegin(); it != counters_.rend(); ++it)
    if (it->slot.off == s.off && it->slot.kind == s.kind) return &*it;
  return nullptr;
}

// True when nothing in `body` can change the local variable `counter` (canonical name):
// no call other than a standard function that only computes (a method or action of this
// POU could write it; a VAR_IN_OUT or output could reach it), and no assignment whose
// target is the counter, or goes through a pointer or reference (which could point at it).
bool Compiler::keeps_counter(const StmtList& body, const std::string& counter) const {
  // A variable, element or field other than the counter, reached through no pointer or
  // reference (an assignment to a REFERENCE writes what it refers to).
  auto target_ok = [&](const Expr& lhs) {
    for (const Expr* e = &lhs;;) {
      if (e->kind == ExprKind::BitAccess) {
        e = static_cast<const BitAccessExpr&>(*e).base.get();
        continue;
      }
      const Type* t = field_path_type(*e);
      if (!t || t->kind == TypeKind::Ref || t->kind == TypeKind::Interface) return false;
      if (e->kind == ExprKind::Member) e = static_cast<const MemberExpr&>(*e).base.get();
      else if (e->kind == ExprKind::Index) e = static_cast<const IndexExpr&>(*e).base.get();
      else if (e->kind == ExprKind::Name) return canon(static_cast<const NameExpr&>(*e).name.text) != counter && !may_call(lhs);
      else return false;
    }
  };
  for (const StmtPtr& sp : body) {
    const Stmt& st = *sp;
    switch (st.kind) {
      case StmtKind::Assign: {
        const auto& a = static_cast<const AssignStmt&>(st);
        if (!target_ok(*a.lhs) || may_call(*a.rhs)) return false;
        break;
      }
      case StmtKind::If: {
        const auto& i = static_cast<const IfStmt&>(st);
        for (const auto& arm : i.arms)
          if (may_call(*arm.cond) || !keeps_counter(arm.body, counter)) return false;
        if (i.else_body && !keeps_counter(*i.else_body, counter)) return false;
        break;
      }
      case StmtKind::Case: {
        const auto& c = static_cast<const CaseStmt&>(st);
        if (may_call(*c.selector)) return false;
        for (const auto& arm : c.arms)
          if (!keeps_counter(arm.body, counter)) return false;
        if (c.else_body && !keeps_counter(*c.else_body, counter)) return false;
        break;
      }
      case StmtKind::For: {
        const auto& f = static_cast<const ForStmt&>(st);
        if (!target_ok(*f.var) || may_call(*f.from) || may_call(*f.to) || (f.by && may_call(*f.by)) ||
            !keeps_counter(f.body, counter))
          return false;
        break;
      }
      case StmtKind::While: {
        const auto& w = static_cast<const WhileStmt&>(st);
        if (may_call(*w.cond) || !keeps_counter(w.body, counter)) return false;
        break;
      }
      case StmtKind::Repeat: {
        const auto& r = static_cast<const RepeatStmt&>(st);
        if (may_call(*r.until) || !keeps_counter(r.body, counter)) return false;
        break;
      }
      case StmtKind::Exit:
      case StmtKind::Continue:
      case StmtKind::Return:
      case StmtKind::Empty:
      case StmtKind::Jump:  // leaves the loop; a label is never inside one
        break;
      default: return false;  // calls, labels, test-file statements
    }
  }
  return true;
}

namespace {
// An index a row offset can be kept for: a variable, or a variable plus or minus an integer literal.
const NameExpr* index_variable(const Expr& e) {
  if (e.kind == ExprKind::Name) return &static_cast<const NameExpr&>(e);
  if (e.kind != ExprKind::Binary) return nullptr;
  const auto& b = static_cast<const BinaryExpr&>(e);
  if (b.op != BinaryOp::Add && b.op != BinaryOp::Sub) return nullptr;
  if (b.lhs->kind == ExprKind::Name && b.rhs->kind == ExprKind::Literal) return &static_cast<const NameExpr&>(*b.lhs);
  if (b.op == BinaryOp::Add && b.rhs->kind == ExprKind::Name && b.lhs->kind == ExprKind::Literal)
    return &static_cast<const NameExpr&>(*b.rhs);
  return nullptr;
}

size_t count_indexed(const Expr* e, const Compiler::RowScan& scan) {
  auto among = [](const std::vector<std::string>& names, const std::string& n) {
    return std::find(names.begin(), names.end(), n) != names.end();
  };
  size_t n = 0;
  while (e) {
    switch (e->kind) {
      case ExprKind::Index: {
        const auto& x = static_cast<const IndexExpr&>(*e);
        bool by_counter = false, by_outer = false, simple = true;
        size_t vars = 0;
        for (const auto& i : x.indices) {
          if (const NameExpr* v = index_variable(*i)) {
            const std::string name = canon(v->name.text);
            ++vars;
            by_counter = by_counter || name == scan.counter;
            by_outer = by_outer || among(scan.outer, name);
            simple = simple && !among(scan.inner, name);
          } else if (i->kind != ExprKind::Literal) {
            simple = false;
          }
          n += count_indexed(i.get(), scan);
        }
        if (by_counter && by_outer && simple && vars == 2) ++n;
        // One index linear in the counter and an outer counter: v * C + w, C * v + w or
        // w + v * C (a rank-2 table kept in a rank-1 array).
        if (x.indices.size() == 1 && x.indices[0]->kind == ExprKind::Binary) {
          const auto& sum = static_cast<const BinaryExpr&>(*x.indices[0]);
          auto scaled = [](const Expr& f) -> const NameExpr* {
            if (f.kind != ExprKind::Binary) return nullptr;
            const auto& m = static_cast<const BinaryExpr&>(f);
            if (m.op != BinaryOp::Mul) return nullptr;
            if (m.lhs->kind == ExprKind::Name && m.rhs->kind == ExprKind::Literal) return &static_cast<const NameExpr&>(*m.lhs);
            if (m.rhs->kind == ExprKind::Name && m.lhs->kind == ExprKind::Literal) return &static_cast<const NameExpr&>(*m.rhs);
            return nullptr;
          };
          const NameExpr* v = sum.op == BinaryOp::Add ? scaled(*sum.lhs) : nullptr;
          const Expr* w = sum.rhs.get();
          if (!v && sum.op == BinaryOp::Add) {
            v = scaled(*sum.rhs);
            w = sum.lhs.get();
          }
          if (v && w->kind == ExprKind::Name) {
            const std::string a = canon(v->name.text), b = canon(static_cast<const NameExpr&>(*w).name.text);
            if ((a == scan.counter && among(scan.outer, b)) || (b == scan.counter && among(scan.outer, a))) ++n;
          }
        }
        e = x.base.get();
        break;
      }
      case ExprKind::Member: e = static_cast<const MemberExpr&>(*e).base.get(); break;
      case ExprKind::BitAccess: e = static_cast<const BitAccessExpr&>(*e).base.get(); break;
      case ExprKind::Deref: e = static_cast<const DerefExpr&>(*e).base.get(); break;
      case ExprKind::Unary: e = static_cast<const UnaryExpr&>(*e).operand.get(); break;
      case ExprKind::Binary: {
        // A long chain is a deep left spine: walked in this loop, the right operands recursively.
        const auto& b = static_cast<const BinaryExpr&>(*e);
        n += count_indexed(b.rhs.get(), scan);
        e = b.lhs.get();
        break;
      }
      case ExprKind::Call: {
        for (const auto& a : static_cast<const CallExpr&>(*e).args) n += count_indexed(a.value.get(), scan);
        e = nullptr;
        break;
      }
      default: e = nullptr; break;
    }
  }
  return n;
}
}  // namespace

// How many row offsets a FOR loop may keep: the accesses in its body with two variable
// indices (each plus or minus a literal, the others literals), its counter and a counter
// of a proven loop around it, or with one index linear in the two. An upper bound: the
// compiler decides access by access (row_for).
size_t Compiler::row_candidates(const StmtList& body, RowScan& scan) {
  size_t n = 0;
  for (const StmtPtr& sp : body) {
    const Stmt& st = *sp;
    switch (st.kind) {
      case StmtKind::Assign: {
        const auto& a = static_cast<const AssignStmt&>(st);
        n += count_indexed(a.lhs.get(), scan) + count_indexed(a.rhs.get(), scan);
        break;
      }
      case StmtKind::If: {
        const auto& i = static_cast<const IfStmt&>(st);
        for (const auto& arm : i.arms) n += count_indexed(arm.cond.get(), scan) + row_candidates(arm.body, scan);
        if (i.else_body) n += row_candidates(*i.else_body, scan);
        break;
      }
      case StmtKind::Case: {
        const auto& c = static_cast<const CaseStmt&>(st);
        n += count_indexed(c.selector.get(), scan);
        for (const auto& arm : c.arms) n += row_candidates(arm.body, scan);
        if (c.else_body) n += row_candidates(*c.else_body, scan);
        break;
      }
      case StmtKind::For: {
        const auto& f = static_cast<const ForStmt&>(st);
        n += count_indexed(f.from.get(), scan) + count_indexed(f.to.get(), scan) + count_indexed(f.by.get(), scan);
        scan.inner.push_back(f.var->kind == ExprKind::Name ? canon(static_cast<const NameExpr&>(*f.var).name.text) : std::string());
        n += row_candidates(f.body, scan);
        scan.inner.pop_back();
        break;
      }
      case StmtKind::While: {
        const auto& w = static_cast<const WhileStmt&>(st);
        n += count_indexed(w.cond.get(), scan) + row_candidates(w.body, scan);
        break;
      }
      case StmtKind::Repeat: {
        const auto& r = static_cast<const RepeatStmt&>(st);
        n += row_candidates(r.body, scan) + count_indexed(r.until.get(), scan);
        break;
      }
      default: break;
    }
  }
  return n;
}

// A DINT constant's value (a slot in the constant pool).
static std::optional<int64_t> const_dint(const std::vector<uint8_t>& consts, Slot s) {
  if (s.kind != SK::Const || uint64_t{s.off} + 4 > consts.size()) return std::nullopt;
  int32_t v = 0;
  std::memcpy(&v, consts.data() + s.off, 4);
  return v;
}

// Whether x * m + y (a linear index, Place::has_lin) stays inside lo..hi: one of x and m
// a constant, the other and y counters of proven FOR loops, so every value they take is
// known (and the sum cannot wrap).
bool Compiler::linear_in_range(const Place& p, int64_t lo, int64_t hi) const {
  const std::optional<int64_t> cx = const_dint(b_->consts, p.lin_x), cm = const_dint(b_->consts, p.lin_m);
  const CounterRange* v = cm ? proven_range(p.lin_x) : cx ? proven_range(p.lin_m) : nullptr;
  const CounterRange* w = proven_range(p.lin_y);
  if (!v || !w) return false;
  const int64_t c = cm ? *cm : *cx;
  const int64_t a = v->lo * c, b = v->hi * c;
  return std::min(a, b) + w->lo >= lo && std::max(a, b) + w->hi <= hi;
}

std::optional<Compiler::RowAccess> Compiler::row_for(const Place& p) {
  if (p.k != Place::K::FrameIdx || p.sk != SK::Var || row_loops_.empty()) return std::nullopt;
  const bool linear = p.has_lin && p.lin_proven;
  if (!linear && !(p.proven && p.two)) return std::nullopt;
  const uint32_t size = p.type->size;
  if (!p.type->is_elementary() || (size != 1 && size != 2 && size != 4 && size != 8)) return std::nullopt;
  // Two variables and their strides in bytes: the indices of a rank-2 access, or the
  // scaled variable and the added one of a linear index (x * m + y), whose element `lo`
  // the offset k names.
  Slot v0 = p.idx, v1 = p.idx2;
  int64_t m0 = p.stride, m1 = p.stride2;
  int64_t k = int64_t{p.off} + p.unchecked_disp();
  if (linear) {
    const std::optional<int64_t> cm = const_dint(b_->consts, p.lin_m), cx = const_dint(b_->consts, p.lin_x);
    v0 = cm ? p.lin_x : p.lin_m;
    m0 = (cm ? *cm : cx.value_or(0)) * size;
    v1 = p.lin_y;
    m1 = size;
    k = int64_t{p.off} - int64_t{p.lo} * size;
  }
  // The innermost loop keeping rows whose counter is one of the variables; the other
  // must be a counter of a loop around it (constant while it runs).
  for (size_t li = row_loops_.size(); li-- > 0;) {
    RowLoop& loop = row_loops_[li];
    const bool first = v0 == loop.counter, second = v1 == loop.counter;
    if (!first && !second) continue;
    if (first && second) return std::nullopt;
    const Slot inner = first ? v0 : v1, outer = first ? v1 : v0;
    const int64_t m_inner = first ? m0 : m1, m_outer = first ? m1 : m0;
    if (inner.kind != SK::Var || outer.kind != SK::Var) return std::nullopt;
    bool around = false;
    for (size_t d = 0; d < loop.depth && d < counters_.size(); ++d) around = around || counters_[d].slot == outer;
    if (!around) return std::nullopt;
    auto fits = [](int64_t x) { return x >= INT32_MIN && x <= INT32_MAX; };
    if (!fits(k) || !fits(m_inner) || !fits(m_outer)) return std::nullopt;
    RowAccess a{Slot{}, inner, m_inner};
    for (size_t c = 0; c < loop.used.size(); ++c) {
      const RowOffset& u = loop.used[c];
      if (u.k == k && u.v == outer && u.m == m_outer) {
        a.row = loop.slots[c];
        return a;
      }
    }
    if (loop.used.size() == loop.slots.size()) return std::nullopt;
    loop.used.push_back({k, outer, m_outer});
    a.row = loop.slots[loop.used.size() - 1];
    return a;
  }
  return std::nullopt;
}

void Compiler::for_stmt(const ForStmt& s) {
  Place var = place(*s.var, true);
  if (!var.ok) return;
  if (!var.type->is_integer() || var.readonly) {
    diags_.error("ST220", s.var->loc, "the FOR control variable must be a writable variable of an integer type");
    return;
  }
  // A local is counted in place. Any other variable (a global, a VAR_IN_OUT, a member, an
  // element: TwinCAT takes them) is counted in a temporary that is stored to it before each
  // pass of the body and read back after it, so the body sees and may change the variable,
  // and after the loop it holds the value that ended it.
  const bool direct = var.k == Place::K::Frame;
  const Type* t = var.type->ranged ? elem(var.type->kind) : var.type;
  Val from = expr(*s.from, t);
  Val to = expr(*s.to, t);
  Val by = s.by ? expr(*s.by, t) : Val{nullptr, true, true, ConstV{ConstV::K::Int, 1, 0, {}}, {}};
  if (!from.ok || !to.ok || !by.ok) return;
  from = coerce(from, t, s.from->loc, "FOR");
  to = coerce(to, t, s.to->loc, "FOR");
  by = coerce(by, t, s.by ? s.by->loc : s.loc, "FOR");
  if (!from.ok || !to.ok || !by.ok) return;
  if (by.is_const && by.c.i == 0) {
    diags_.error("ST220", s.by ? s.by->loc : s.loc, "FOR step must not be zero");
    return;
  }
  // TO and BY are evaluated once, before the first iteration (IEC 61131-3).
  Slot limit = to.is_const ? konst(t, to.c, s.loc) : temp_for(t);
  if (!to.is_const) emit(mov_op(t->size), {limit, to.slot});
  Slot step = by.is_const ? konst(t, by.c, s.loc) : temp_for(t);
  if (!by.is_const) emit(mov_op(t->size), {step, by.slot});
  assign(var, from, s.loc);
  Slot iv = direct ? Slot{var.off, var.sk} : temp_for(t);
  auto read_back = [&] {
    if (!direct) emit(mov_op(t->size), {iv, load(var).slot});
  };
  auto write_out = [&] {
    if (!direct) store(var, iv);
  };
  read_back();
  Label body = new_label(), cont = new_label(), exit = new_label();
  bool down = by.is_const && by.c.i < 0;
  Storage st = t->storage();
  if (by.is_const) {
    // Skip the loop when the range is empty.
    if (down) emit(num_op(Op::JLT_I8, st), {Arg::target(exit.id), iv, limit});
    else emit(num_op(Op::JLT_I8, st), {Arg::target(exit.id), limit, iv});
    // Coverage records that the body ran, once per entry into the loop, not per iteration.
    uint32_t decision = kNoBranch;
    ArmScope in(b_, branch(s.loc, "FOR", s.loc, &decision, s.body));
    b_->loops.push_back({exit, cont});
    // A DINT local counted in place, with bounds that are constants or counters proven
    // the same way, by a constant step, in a body that cannot change it: inside the body
    // it lies between the bounds, and an index by it needs no check there.
    const size_t outer = counters_.size();
    if (direct && st == Storage::I32 && s.var->kind == ExprKind::Name) {
      auto bounds = [&](const Val& v, int64_t* lo, int64_t* hi) {
        if (v.is_const) {
          *lo = *hi = v.c.i;
          return v.c.k == ConstV::K::Int;
        }
        const CounterRange* r = proven_range(v.slot);
        if (!r) return false;
        *lo = r->lo;
        *hi = r->hi;
        return true;
      };
      // The first pass starts at FROM even when the range is empty, should the test on
      // entry be gone (mutation analysis removes and negates conditional jumps): hence
      // FROM's whole range, not only TO's side of it.
      int64_t flo, fhi, tlo, thi;
      const std::string name = canon(static_cast<const NameExpr&>(*s.var).name.text);
      if (bounds(from, &flo, &fhi) && bounds(to, &tlo, &thi) && keeps_counter(s.body, name)) {
        counters_.push_back({iv, down ? std::min(tlo, flo) : flo, down ? fhi : std::max(thi, fhi), name});
        // Row offsets for the rank-2 accesses the body makes by the counter: their slots
        // and the ROWS that sets them are laid down now, what each holds is known after
        // the body.
        RowScan scan{name, {}, {}};
        for (size_t d = 0; d + 1 < counters_.size(); ++d) scan.outer.push_back(counters_[d].name);
        const size_t want = std::min<size_t>(row_candidates(s.body, scan), 8);
        if (want > 0 && iv.kind == SK::Var && opt_.row_offsets) {
          RowLoop loop;
          loop.counter = iv;
          loop.depth = counters_.size() - 1;
          std::vector<Arg> args{Arg(static_cast<uint32_t>(2 + 4 * want)), Arg(0u)};
          for (size_t c = 0; c < want; ++c) {
            loop.slots.push_back(temp(4, 4));
            args.insert(args.end(), {Arg(loop.slots.back()), Arg(0u), Arg(0u), Arg(0u)});
          }
          loop.at = static_cast<uint32_t>(b_->code.size());
          emit_list(Op::ROWS, args);
          row_loops_.push_back(std::move(loop));
        }
      }
    }
    // Jumps back to the body skip the ROWS just emitted (only a counter in place has
    // rows; write_out stores any other before each pass).
    bind(body);
    write_out();
    const Op step_op = int_op(down ? Op::LOOPDN_I8 : Op::LOOPUP_I8, st);
    const std::function<void()> tail = [&] {
      emit(step_op, {iv, step, limit, Arg::target(body.id)});
      emit(Op::JMP, {Arg::target(exit.id)});
    };
    loop_tail_ = direct && opt_.loop_tails ? &tail : nullptr;
    stmts(s.body);
    loop_tail_ = nullptr;
    counters_.resize(outer);
    if (!row_loops_.empty() && row_loops_.back().depth == outer) {
      const RowLoop& rows = row_loops_.back();
      auto& code = b_->code;
      code[rows.at + 2] = static_cast<uint32_t>(rows.used.size());
      for (size_t c = 0; c < rows.used.size(); ++c) {
        uint32_t* e = &code[rows.at + 3 + 4 * c];
        e[1] = static_cast<uint32_t>(static_cast<int32_t>(rows.used[c].k));
        e[2] = rows.used[c].v.off;
        e[3] = static_cast<uint32_t>(static_cast<int32_t>(rows.used[c].m));
      }
      row_loops_.pop_back();
    }
    b_->loops.pop_back();
    bind(cont);
    read_back();
    emit(step_op, {iv, step, limit, Arg::target(body.id)});
    write_out();
    bind(exit);
    return;
  }
  // Step known only at run time: test its sign on each iteration.
  Slot zero = konst(t, ConstV{ConstV::K::Int, 0, 0, {}}, s.loc);
  Label up_test = new_label(), top = new_label();
  bind(top);
  emit(num_op(Op::JGE_I8, st), {Arg::target(up_test.id), step, zero});
  emit(num_op(Op::JLT_I8, st), {Arg::target(exit.id), iv, limit});
  emit(Op::JMP, {Arg::target(body.id)});
  bind(up_test);
  emit(num_op(Op::JLT_I8, st), {Arg::target(exit.id), limit, iv});
  bind(body);
  write_out();
  b_->loops.push_back({exit, cont});
  uint32_t decision = kNoBranch;
  {
    ArmScope in(b_, branch(s.loc, "FOR", s.loc, &decision, s.body));
    loop_tail_ = nullptr;
    stmts(s.body);
  }
  b_->loops.pop_back();
  bind(cont);
  read_back();
  emit(num_op(Op::ADD_I8, st), {iv, iv, step});
  write_out();
  emit(Op::JMPB, {Arg::target(top.id)});
  bind(exit);
}

// A WHILE's or REPEAT's bottom: the test jumping back to the body when the condition is
// `again`. Laid down after the body, and copied into the arms of a statement ending it
// (loop_tail_), there followed by a jump out of the loop.
void Compiler::bottom_test(const Expr& c, Label body, bool again) {
  const uint32_t top = b_->temp_top;
  mark(c.loc);
  cond_branch(c, body, again);
  b_->temp_top = top;
}

// WHILE and REPEAT test at the bottom: one conditional jump back per iteration instead of
// a test and a jump (the VM and the native tier count a conditional jump back against the
// watchdog, as JMPB). WHILE tests once more on entry, with its own copy of the condition,
// so its coverage id is set once per entry into a loop that runs, not per iteration.
//
// Rule 28: `WHILE moving DO IF j = 0 THEN moving := FALSE; ELSIF items[j - 1].key >
// tmp.key THEN (shift) ELSE moving := FALSE; END_IF; END_WHILE` (IEC's AND evaluates both
// operands, so a flag is how a search loop stops). Where the body starts, the flag is
// TRUE; an arm that ends the body with a copy of the test (loop tails) on a path that did
// not write it (flag_watches: no store of it, no call, no store through a pointer) would
// test TRUE again: it jumps back without the test, counted against the watchdog as the
// test's jump is. When the body starts with a conditional jump on variables (`IF j = 0`),
// the arm ends with a copy of that jump and a jump back past it, which leaves one jump per
// pass where the test and the first jump were two.
std::optional<uint32_t> Compiler::loop_flag(const Expr& cond) {
  if (cond.kind != ExprKind::Name) return std::nullopt;
  const Symbol* v = lookup(canon(static_cast<const NameExpr&>(cond).name.text));
  if (!v || v->kind != SymKind::Var || !v->type || v->type->kind != TypeKind::Bool || v->where != Where::Frame)
    return std::nullopt;
  const Place p = place(cond, false);
  if (!p.ok || p.k != Place::K::Frame || p.sk != SK::Var) return std::nullopt;
  return p.off;
}

void Compiler::watch_writes(Op op, const std::vector<Arg>& args) {
  // Instructions that may store other than into their first operand, by name, once.
  static const std::vector<bool> kAnywhere = [] {
    static constexpr std::string_view kFamilies[] = {"CALL",  "NATIVE", "FBENTER", "STI",     "STG",    "STBIT",
                                                     "INITBLK", "MOVN", "SCPY",    "WSCPY",   "ADVTIME", "ASSERT",
                                                     "SETMOCK", "FNMOCK", "ENTER", "FRAME",   "ROWS",   "TRAP"};
    std::vector<bool> t(static_cast<size_t>(Op::Count_));
    for (size_t i = 0; i < t.size(); ++i) {
      const std::string_view name = op_info(static_cast<Op>(i)).name;
      t[i] = std::any_of(std::begin(kFamilies), std::end(kFamilies), [&](std::string_view f) { return name.starts_with(f); });
    }
    return t;
  }();
  const bool anywhere = kAnywhere[static_cast<size_t>(op)];
  for (auto& w : b_->flag_watches)
    if (anywhere || (!args.empty() && args[0].k != Arg::K::Target && args[0].sk == SK::Var && args[0].v == w.off))
      w.dirty = w.ever = true;
}

std::vector<bool> Compiler::watch_state() const {
  std::vector<bool> s;
  for (const auto& w : b_->flag_watches) s.push_back(w.dirty);
  return s;
}

void Compiler::set_watch_state(const std::vector<bool>& s) {
  for (size_t k = 0; k < s.size() && k < b_->flag_watches.size(); ++k) b_->flag_watches[k].dirty = s[k];
}

void Compiler::merge_watch_state(std::vector<bool>* into, const std::vector<bool>& s) {
  for (size_t k = 0; k < s.size() && k < into->size(); ++k) (*into)[k] = (*into)[k] || s[k];
}

// The conditional jump taken exactly when `op` is not (JMPF/JMPT, JEQ/JNE, JTZ/JTNZ,
// JLT/JGE on integers, JLT/JNLT and JGE/JNGE on REAL and LREAL, where NaN fails both).
static std::optional<Op> inverse_jump(Op op) {
  static const std::vector<std::optional<Op>> table = [] {
    std::map<std::string, Op> by_name;
    for (uint32_t k = 0; k < static_cast<uint32_t>(Op::Count_); ++k) by_name[op_info(static_cast<Op>(k)).name] = static_cast<Op>(k);
    std::vector<std::optional<Op>> t(static_cast<size_t>(Op::Count_));
    auto swap_prefix = [](const std::string& n, const std::string& a, const std::string& b) {
      return n.starts_with(a) ? b + n.substr(a.size()) : std::string();
    };
    for (const auto& [name, o] : by_name) {
      if (!is_conditional_jump(o)) continue;
      const bool real = name.ends_with("_F32") || name.ends_with("_F64");
      std::string inv = name == "JMPF" ? "JMPT" : name == "JMPT" ? "JMPF" : "";
      for (const auto& [a, b] : std::initializer_list<std::pair<const char*, const char*>>{
               {"JEQ_", "JNE_"}, {"JNE_", "JEQ_"}, {"JTZ_", "JTNZ_"}, {"JTNZ_", "JTZ_"}, {"JNLT_", "JLT_"}, {"JNGE_", "JGE_"}}) {
        if (inv.empty()) inv = swap_prefix(name, a, b);
      }
      if (inv.empty()) inv = swap_prefix(name, "JLT_", real ? "JNLT_" : "JGE_");
      if (inv.empty()) inv = swap_prefix(name, "JGE_", real ? "JNGE_" : "JLT_");
      if (auto it = by_name.find(inv); it != by_name.end()) t[static_cast<size_t>(o)] = it->second;
    }
    return t;
  }();
  return table[static_cast<size_t>(op)];
}

void Compiler::jump_back(Label body) {
  const auto& code = b_->code;
  const uint32_t at = b_->label_pos[body.id];
  if (at < code.size() && is_conditional_jump(static_cast<Op>(code[at]))) {
    const uint32_t len = op_length(&code[at]);
    const auto target = std::find_if(b_->target_fix.begin(), b_->target_fix.end(), [&](const auto& f) { return f.first == at + 1; });
    bool plain = at + len <= code.size() && target != b_->target_fix.end();
    for (uint32_t w = at + 2; plain && w < at + len; ++w) plain = kind_at(w) == SK::Var || kind_at(w) == SK::Const;
    if (plain) {
      const Label rest = new_label();
      b_->label_pos[rest.id] = at + len;
      std::vector<Arg> args{Arg::target(target->second)};
      for (uint32_t w = at + 2; w < at + len; ++w) args.push_back(Arg(Slot{code[w], kind_at(w)}));
      if (b_->label_pos[target->second] == UINT32_MAX) {
        // The first jump leads forward (to an arm placed after the others, rule 29): the
        // opposite jump back past it, else back to it. Either way one jump back, counted
        // by the watchdog as the test's was.
        const auto inverse = inverse_jump(static_cast<Op>(code[at]));
        if (inverse) {
          args[0] = Arg::target(rest.id);
          emit_list(*inverse, args);
          emit(Op::JMPB, {Arg::target(body.id)});
          return;
        }
      } else {
        emit_list(static_cast<Op>(code[at]), args);
        emit(Op::JMPB, {Arg::target(rest.id)});
        return;
      }
    }
  }
  emit(Op::JMPB, {Arg::target(body.id)});
}

void Compiler::while_stmt(const WhileStmt& s) {
  Label body = new_label(), test = new_label(), exit = new_label();
  uint32_t saved = b_->temp_top;
  if (!cond_branch(*s.cond, exit, false).ok) return;
  b_->temp_top = saved;
  uint32_t decision = kNoBranch;
  const std::optional<uint32_t> flag = opt_.loop_tails && opt_.flag_loops ? loop_flag(*s.cond) : std::nullopt;
  bool clean = false;
  {
    ArmScope in(b_, branch(s.loc, "WHILE", s.loc, &decision, s.body));
    bind(body);
    b_->loops.push_back({exit, test, s.cond.get()});
    const size_t watch = b_->flag_watches.size();
    if (flag) b_->flag_watches.push_back({*flag, false});
    const std::function<void()> tail = [&] {
      if (flag && !b_->flag_watches.at(watch).dirty) {
        jump_back(body);
        return;
      }
      bottom_test(*s.cond, body, true);
      emit(Op::JMP, {Arg::target(exit.id)});
    };
    loop_tail_ = opt_.loop_tails ? &tail : nullptr;
    stmts(s.body);
    loop_tail_ = nullptr;
    // The body's end, reached by its last statement (not by CONTINUE, a jump to `test`).
    if (flag) {
      clean = !b_->flag_watches.back().dirty && b_->label_refs[test.id] == 0;
      b_->flag_watches.pop_back();
    }
    b_->loops.pop_back();
  }
  if (clean) {
    jump_back(body);
  } else {
    bind_forward(test);
    bottom_test(*s.cond, body, true);
  }
  bind(exit);
}

void Compiler::repeat_stmt(const RepeatStmt& s) {
  Label body = new_label(), cont = new_label(), exit = new_label();
  b_->loops.push_back({exit, cont, s.until.get()});
  uint32_t decision = kNoBranch;
  {
    ArmScope in(b_, branch(s.loc, "REPEAT", s.loc, &decision, s.body));
    bind(body);
    const std::function<void()> tail = [&] {
      bottom_test(*s.until, body, false);
      emit(Op::JMP, {Arg::target(exit.id)});
    };
    loop_tail_ = s.until && opt_.loop_tails ? &tail : nullptr;
    stmts(s.body);
    loop_tail_ = nullptr;
  }
  b_->loops.pop_back();
  bind(cont);
  if (s.until) {
    bottom_test(*s.until, body, false);
  } else {
    emit(Op::JMPB, {Arg::target(body.id)});
  }
  bind(exit);
}

}  // namespace plcfi::st::detail

// Instruction List (IEC 61131-3:2003, 3.2): the reader of IL bodies, and their lowering to
// the statements of ST, so that the compiler, both tiers and every tool after the parser
// see one language.
//
// IL is line-oriented: an instruction is `[label:] operator [operand]` and ends with its
// line (only a formal argument list in parentheses may go on over the next lines). The
// reader first reads the body's lines into instructions, then lowers them in order,
// keeping the current result (CR) as an expression:
//  - an operator that combines (AND, ADD, GT, ...) builds a larger expression over the CR,
//    typed by the compiler as ST types it: by what was loaded;
//  - ST, S, R and the FB input operators (IN T1) write the CR to a variable. The write may
//    change what the CR expression reads, so when a later instruction reads the CR too it
//    is first kept in a hidden variable (AssignStmt::declares_temp: the compiler gives it
//    the expression's type);
//  - a function call (LD a  F b) is made at once into such a variable, so its side
//    effects happen once and in order;
//  - `AND(` saves the CR and starts a new one; `)` combines the two;
//  - CAL, unconditional JMP and RET, and labels (a jump may arrive there) leave the CR
//    undefined: an instruction that reads it then is an error (ST138).
#include <string>
#include <vector>

#include "parser_impl.hpp"

namespace plcfi::st::detail {

namespace {

enum class IlOp { Label, LD, ST, S, R, And, Or, Xor, Not, Add, Sub, Mul, Div, Mod, Gt, Ge, Eq, Ne, Le, Lt, Jmp, Cal, Ret, Close, FbInput, Func };

struct OpSpec {
  const char* text;
  IlOp op;
  bool negate;  // the N modifier
  bool cond;    // the C modifier
};

// The operators written as names (AND, OR, XOR, NOT and MOD are reserved words, & is
// punctuation); the FB input operators store the CR into that input of an instance.
constexpr OpSpec kOps[] = {
    {"LD", IlOp::LD, false, false},      {"LDN", IlOp::LD, true, false},    {"ST", IlOp::ST, false, false},
    {"STN", IlOp::ST, true, false},      {"S", IlOp::S, false, false},      {"R", IlOp::R, false, false},
    {"ANDN", IlOp::And, true, false},    {"ORN", IlOp::Or, true, false},    {"XORN", IlOp::Xor, true, false},
    {"ADD", IlOp::Add, false, false},    {"SUB", IlOp::Sub, false, false},  {"MUL", IlOp::Mul, false, false},
    {"DIV", IlOp::Div, false, false},    {"GT", IlOp::Gt, false, false},    {"GE", IlOp::Ge, false, false},
    {"EQ", IlOp::Eq, false, false},      {"NE", IlOp::Ne, false, false},    {"LE", IlOp::Le, false, false},
    {"LT", IlOp::Lt, false, false},      {"JMP", IlOp::Jmp, false, false},  {"JMPC", IlOp::Jmp, false, true},
    {"JMPCN", IlOp::Jmp, true, true},    {"CAL", IlOp::Cal, false, false},  {"CALC", IlOp::Cal, false, true},
    {"CALCN", IlOp::Cal, true, true},    {"RET", IlOp::Ret, false, false},  {"RETC", IlOp::Ret, false, true},
    {"RETCN", IlOp::Ret, true, true},    {"S1", IlOp::FbInput, false, false}, {"R1", IlOp::FbInput, false, false},
    {"CLK", IlOp::FbInput, false, false}, {"CU", IlOp::FbInput, false, false}, {"CD", IlOp::FbInput, false, false},
    {"PV", IlOp::FbInput, false, false}, {"IN", IlOp::FbInput, false, false}, {"PT", IlOp::FbInput, false, false},
};

const OpSpec* find_op(std::string_view word) {
  for (const auto& o : kOps)
    if (iequals(word, o.text)) return &o;
  return nullptr;
}

// Operators that take the left-parenthesis modifier, and what they combine with.
bool binary_op(IlOp op, BinaryOp* out) {
  switch (op) {
    case IlOp::And: *out = BinaryOp::And; return true;
    case IlOp::Or: *out = BinaryOp::Or; return true;
    case IlOp::Xor: *out = BinaryOp::Xor; return true;
    case IlOp::Add: *out = BinaryOp::Add; return true;
    case IlOp::Sub: *out = BinaryOp::Sub; return true;
    case IlOp::Mul: *out = BinaryOp::Mul; return true;
    case IlOp::Div: *out = BinaryOp::Div; return true;
    case IlOp::Mod: *out = BinaryOp::Mod; return true;
    case IlOp::Gt: *out = BinaryOp::Gt; return true;
    case IlOp::Ge: *out = BinaryOp::Ge; return true;
    case IlOp::Eq: *out = BinaryOp::Eq; return true;
    case IlOp::Ne: *out = BinaryOp::Ne; return true;
    case IlOp::Le: *out = BinaryOp::Le; return true;
    case IlOp::Lt: *out = BinaryOp::Lt; return true;
    default: return false;
  }
}

// One instruction as read.
struct Instr {
  IlOp op = IlOp::Label;
  SourceLoc loc;          // the operator (the label for a label)
  std::string spelling;   // the operator as written, for messages
  bool negate = false, cond = false, paren = false;
  Ident name;             // label, JMP target, FB input, function
  ExprPtr operand;        // may be null (NOT, RET, `AND(` alone, after an error)
  std::vector<ExprPtr> more;  // a function's further non-formal arguments
  std::unique_ptr<CallExpr> call;  // CAL, a function with a formal list
};

ExprPtr clone(const Expr& e);

std::vector<CallArg> clone_args(const std::vector<CallArg>& args) {
  std::vector<CallArg> out;
  for (const auto& a : args) {
    CallArg c;
    c.name = a.name;
    c.is_output = a.is_output;
    c.negate = a.negate;
    c.loc = a.loc;
    if (a.value) c.value = clone(*a.value);
    out.push_back(std::move(c));
  }
  return out;
}

// A copy of an expression the CR holds (operands and what the lowering built of them:
// never an initializer).
ExprPtr clone(const Expr& e) {
  switch (e.kind) {
    case ExprKind::Literal: {
      const auto& x = static_cast<const LiteralExpr&>(e);
      auto c = std::make_unique<LiteralExpr>(x.loc);
      c->lit = x.lit;
      c->type_prefix = x.type_prefix;
      c->int_value = x.int_value;
      c->real_value = x.real_value;
      c->str_value = x.str_value;
      c->time_ns = x.time_ns;
      c->is_long = x.is_long;
      c->beyond_signed = x.beyond_signed;
      return c;
    }
    case ExprKind::EnumLiteral: {
      const auto& x = static_cast<const EnumLiteralExpr&>(e);
      auto c = std::make_unique<EnumLiteralExpr>(x.loc);
      c->type_name = x.type_name;
      c->value = x.value;
      return c;
    }
    case ExprKind::Name: {
      auto c = std::make_unique<NameExpr>(e.loc);
      c->name = static_cast<const NameExpr&>(e).name;
      return c;
    }
    case ExprKind::DirectAddr: return std::make_unique<DirectAddrExpr>(static_cast<const DirectAddrExpr&>(e));
    case ExprKind::Member: {
      const auto& x = static_cast<const MemberExpr&>(e);
      auto c = std::make_unique<MemberExpr>(x.loc);
      c->base = clone(*x.base);
      c->member = x.member;
      return c;
    }
    case ExprKind::BitAccess: {
      const auto& x = static_cast<const BitAccessExpr&>(e);
      auto c = std::make_unique<BitAccessExpr>(x.loc);
      c->base = clone(*x.base);
      c->bit = x.bit;
      return c;
    }
    case ExprKind::Index: {
      const auto& x = static_cast<const IndexExpr&>(e);
      auto c = std::make_unique<IndexExpr>(x.loc);
      c->base = clone(*x.base);
      for (const auto& i : x.indices) c->indices.push_back(clone(*i));
      return c;
    }
    case ExprKind::Deref: {
      auto c = std::make_unique<DerefExpr>(e.loc);
      c->base = clone(*static_cast<const DerefExpr&>(e).base);
      return c;
    }
    case ExprKind::Call: {
      const auto& x = static_cast<const CallExpr&>(e);
      auto c = std::make_unique<CallExpr>(x.loc);
      c->callee = clone(*x.callee);
      c->args = clone_args(x.args);
      c->il_operator = x.il_operator;
      return c;
    }
    case ExprKind::Unary: {
      const auto& x = static_cast<const UnaryExpr&>(e);
      auto c = std::make_unique<UnaryExpr>(x.loc);
      c->op = x.op;
      c->operand = clone(*x.operand);
      return c;
    }
    case ExprKind::Binary: {
      const auto& x = static_cast<const BinaryExpr&>(e);
      auto c = std::make_unique<BinaryExpr>(x.loc);
      c->op = x.op;
      c->lhs = clone(*x.lhs);
      c->rhs = clone(*x.rhs);
      return c;
    }
    case ExprKind::This: return std::make_unique<ThisExpr>(e.loc);
    case ExprKind::Super: return std::make_unique<SuperExpr>(e.loc);
    case ExprKind::ArrayInit: case ExprKind::StructInit: break;
  }
  return error_expr(e.loc);
}

bool has_call(const Expr& e) {
  switch (e.kind) {
    case ExprKind::Call: return true;
    case ExprKind::Member: return has_call(*static_cast<const MemberExpr&>(e).base);
    case ExprKind::BitAccess: return has_call(*static_cast<const BitAccessExpr&>(e).base);
    case ExprKind::Deref: return has_call(*static_cast<const DerefExpr&>(e).base);
    case ExprKind::Unary: return has_call(*static_cast<const UnaryExpr&>(e).operand);
    case ExprKind::Binary: {
      const auto& b = static_cast<const BinaryExpr&>(e);
      return has_call(*b.lhs) || has_call(*b.rhs);
    }
    case ExprKind::Index: {
      const auto& x = static_cast<const IndexExpr&>(e);
      if (has_call(*x.base)) return true;
      for (const auto& i : x.indices)
        if (has_call(*i)) return true;
      return false;
    }
    default: return false;
  }
}

constexpr std::string_view kTempPrefix = "__IL_CR";

bool is_temp(const Expr& e) {
  return e.kind == ExprKind::Name && static_cast<const NameExpr&>(e).name.text.rfind(kTempPrefix, 0) == 0;
}

// The value cannot change before it is read: constants and the CR variables (each written
// once, when declared).
bool stable(const Expr& e) {
  switch (e.kind) {
    case ExprKind::Literal: case ExprKind::EnumLiteral: return true;
    case ExprKind::Name: return is_temp(e);
    case ExprKind::Unary: return stable(*static_cast<const UnaryExpr&>(e).operand);
    case ExprKind::Binary: {
      const auto& b = static_cast<const BinaryExpr&>(e);
      return stable(*b.lhs) && stable(*b.rhs);
    }
    default: return false;
  }
}

// Reading it cannot trap (no division, no index), so an unread CR need not be computed.
bool trap_free(const Expr& e) {
  switch (e.kind) {
    case ExprKind::Literal: case ExprKind::EnumLiteral: case ExprKind::Name: case ExprKind::DirectAddr: return true;
    case ExprKind::Member: return trap_free(*static_cast<const MemberExpr&>(e).base);
    case ExprKind::BitAccess: return trap_free(*static_cast<const BitAccessExpr&>(e).base);
    default: return stable(e);
  }
}

ExprPtr negated(ExprPtr e, SourceLoc loc) {
  auto u = std::make_unique<UnaryExpr>(loc);
  u->op = UnaryOp::Not;
  u->operand = std::move(e);
  return u;
}

ExprPtr literal_bool(bool v, SourceLoc loc) {
  auto l = std::make_unique<LiteralExpr>(loc);
  l->lit = LiteralKind::Bool;
  l->int_value = v ? 1 : 0;
  return l;
}

// Binary chains deeper than this are kept in a variable, so no later stage walks a CR
// thousands of operators deep (`ADD 1` repeated).
constexpr int kMaxCrDepth = 32;

}  // namespace

class IlReader {
 public:
  IlReader(Parser& p, Pou& pou) : p_(p), pou_(pou) {}

  // An SFC transition condition in IL: its value is the current result at the end, which
  // lower_all stores into `var` (a BOOL the chart declares).
  void result_into(std::string var) { result_ = std::move(var); }

  void run() {
    while (!p_.at_terminator()) {
      const size_t before = p_.pos_;
      read_instruction();
      if (p_.pos_ == before) p_.advance();
    }
    lower_all();
  }

 private:
  // ------------------------------------------------------------ reading
  bool same_line(uint32_t line) const { return !p_.at_terminator() && p_.cur().loc.line == line; }

  void skip_line(uint32_t line) {
    while (same_line(line)) p_.advance();
  }

  void read_instruction() {
    const Token& first = p_.cur();
    if (first.kind == Tok::Ident && p_.la(1).kind == Tok::Colon) {
      Instr label;
      label.op = IlOp::Label;
      label.loc = first.loc;
      label.name = Ident{std::string(first.text), first.loc};
      label.spelling = label.name.text + ":";
      p_.advance();
      p_.advance();
      instrs_.push_back(std::move(label));
      if (!same_line(first.loc.line)) return;  // a label on a line of its own
    }
    Instr in;
    const Token& op = p_.cur();
    const uint32_t line = op.loc.line;
    if (!classify(&in)) {
      p_.error("ST135", op.loc, "expected an IL instruction (an operator such as LD, ST, AND, ADD, JMP, CAL or RET, "
                                "a function, or a label), found " + Parser::describe(op));
      skip_line(line);
      return;
    }
    read_operands(&in, line);
    // One instruction per line: whatever follows on it is a mistake.
    if (same_line(p_.prev().end.line)) {
      p_.error("ST136", p_.cur().loc, "unexpected " + Parser::describe(p_.cur()) + " after '" + in.spelling +
                                          "': an IL instruction ends with its line");
      skip_line(p_.cur().loc.line);
    }
    instrs_.push_back(std::move(in));
  }

  // The operator at the cursor, consumed; false (nothing consumed) if it is none.
  bool classify(Instr* in) {
    const Token& t = p_.cur();
    in->loc = t.loc;
    in->spelling = std::string(t.text);
    switch (t.kind) {
      case Tok::And: in->op = IlOp::And; break;
      case Tok::Or: in->op = IlOp::Or; break;
      case Tok::Xor: in->op = IlOp::Xor; break;
      case Tok::Mod: in->op = IlOp::Mod; break;
      case Tok::Not: in->op = IlOp::Not; break;
      case Tok::RParen: in->op = IlOp::Close; break;
      case Tok::Amp:
        in->op = IlOp::And;
        // &N: the N modifier written right after the ampersand.
        if (p_.la(1).kind == Tok::Ident && iequals(p_.la(1).text, "N") && p_.la(1).offset == t.offset + 1) {
          p_.advance();
          in->negate = true;
          in->spelling = "&N";
        }
        break;
      case Tok::Ident:
        if (const OpSpec* o = find_op(t.text)) {
          in->op = o->op;
          in->negate = o->negate;
          in->cond = o->cond;
          if (o->op == IlOp::FbInput) in->name = Ident{std::string(o->text), t.loc};
        } else {
          in->op = IlOp::Func;
          in->name = Ident{std::string(t.text), t.loc};
        }
        break;
      default: return false;
    }
    p_.advance();
    return true;
  }

  void read_operands(Instr* in, uint32_t line) {
    BinaryOp unused;
    switch (in->op) {
      case IlOp::LD: case IlOp::ST: case IlOp::S: case IlOp::R: case IlOp::FbInput:
        in->operand = operand(*in, line);
        return;
      case IlOp::Not: case IlOp::Close: case IlOp::Ret: case IlOp::Label: return;
      case IlOp::Jmp:
        if (same_line(line) && p_.at(Tok::Ident)) {
          in->name = Ident{std::string(p_.cur().text), p_.cur().loc};
          p_.advance();
        } else {
          p_.error("ST136", p_.missing_loc(), "'" + in->spelling + "' needs the label to jump to, found " + Parser::describe(p_.cur()));
        }
        return;
      case IlOp::Cal: read_cal(in, line); return;
      case IlOp::Func: read_function(in, line); return;
      default:
        if (!binary_op(in->op, &unused)) return;
        if (same_line(line) && p_.at(Tok::LParen)) {
          in->paren = true;
          in->spelling += "(";
          p_.advance();
          if (same_line(line)) in->operand = operand(*in, line);  // `AND( x`: the first value inside
          return;
        }
        in->operand = operand(*in, line);
        return;
    }
  }

  // operand := constant | variable   (on the operator's line)
  ExprPtr operand(const Instr& in, uint32_t line) {
    if (!same_line(line)) {
      p_.error("ST136", p_.missing_loc(), "'" + in.spelling + "' needs an operand (a variable or a constant) on its line, found " +
                                               Parser::describe(p_.cur()));
      return nullptr;
    }
    ExprPtr e = p_.at(Tok::Minus) || p_.at(Tok::Plus) ? p_.parse_unary() : p_.parse_postfix();
    if (!valid_operand(*e)) {
      p_.diags_.error("ST136", e->loc, "the operand of '" + in.spelling + "' must be a variable or a constant" +
                                           (has_call(*e) ? std::string(": call a function as an operator (LD a  F b) and a "
                                                                       "function block with CAL")
                                                         : std::string()));
      return nullptr;
    }
    return e;
  }

  static bool valid_operand(const Expr& e) {
    switch (e.kind) {
      case ExprKind::Literal: case ExprKind::EnumLiteral: case ExprKind::Name: case ExprKind::DirectAddr: return true;
      case ExprKind::Unary: {
        const auto& u = static_cast<const UnaryExpr&>(e);
        return u.op != UnaryOp::Not && u.operand->kind == ExprKind::Literal;
      }
      case ExprKind::Member: case ExprKind::BitAccess: case ExprKind::Index: case ExprKind::Deref: return !has_call(e);
      default: return false;
    }
  }

  // CAL instance [( args )]
  void read_cal(Instr* in, uint32_t line) {
    if (!same_line(line) || !p_.at(Tok::Ident)) {
      p_.error("ST136", p_.missing_loc(), "'" + in->spelling + "' needs a function block instance to call, found " +
                                               Parser::describe(p_.cur()));
      return;
    }
    ExprPtr e = p_.parse_postfix();
    if (e->kind == ExprKind::Call) {
      in->call.reset(static_cast<CallExpr*>(e.release()));
    } else if (e->kind == ExprKind::Name || e->kind == ExprKind::Member) {
      in->call = std::make_unique<CallExpr>(e->loc);
      in->call->callee = std::move(e);
    } else {
      p_.diags_.error("ST136", e->loc, "'" + in->spelling + "' calls a function block instance by its name");
    }
  }

  // F [operand {, operand}]   or   F( formal list )
  void read_function(Instr* in, uint32_t line) {
    if (same_line(line) && p_.at(Tok::LParen)) {
      in->call = std::make_unique<CallExpr>(in->loc);
      auto callee = std::make_unique<NameExpr>(in->loc);
      callee->name = in->name;
      in->call->callee = std::move(callee);
      in->call->il_operator = true;
      p_.parse_call_args(in->call->args, in->name.text);  // up to its ')'
      return;
    }
    while (same_line(line)) {
      ExprPtr e = operand(*in, line);
      if (!e) return;
      in->more.push_back(std::move(e));
      if (!same_line(line) || !p_.accept(Tok::Comma)) return;
    }
  }

  // ------------------------------------------------------------ lowering
  struct Paren {
    BinaryOp op;
    bool negate;
    ExprPtr saved;  // the CR before `(`
    SourceLoc loc;
    std::string spelling;
  };

  void lower_all() {
    for (size_t i = 0; i < instrs_.size(); ++i) lower(i);
    const SourceLoc end = instrs_.empty() ? pou_.loc : instrs_.back().loc;
    if (result_.empty()) {
      discard_cr(end);
    } else if (!cr_) {
      p_.diags_.error("ST138", end, "the transition condition ends without a current result (undefined " + undefined_ +
                                        "): its last instruction must leave the condition's value, e.g. LD x");
    } else {
      auto s = std::make_unique<AssignStmt>(end);
      auto n = std::make_unique<NameExpr>(end);
      n->name = Ident{result_, end};
      s->lhs = std::move(n);
      s->rhs = std::move(cr_);
      emit(std::move(s));
    }
    for (const auto& p : parens_)
      p_.diags_.error("ST137", p.loc, "'" + p.spelling + "' is never closed: ')' is missing before the end of the body");
  }

  void emit(StmtPtr s) { pou_.body.push_back(std::move(s)); }

  void set_undefined(std::string why) {
    cr_.reset();
    undefined_ = std::move(why);
  }

  void set_cr(ExprPtr e) {
    cr_ = std::move(e);
    consumed_ = false;
    depth_ = 0;
  }

  // The CR for an instruction that reads it; false (reported) when it is undefined.
  bool read_cr(const Instr& in) {
    if (!cr_) {
      p_.diags_.error("ST138", in.loc, "'" + in.spelling + "' reads the current result, which is undefined " + undefined_);
      set_cr(error_expr(in.loc));  // reported once: what follows reads this stand-in
      consumed_ = true;
      return false;
    }
    consumed_ = true;
    return true;
  }

  // The CR kept in a new hidden variable; the CR is then that variable.
  void materialize(SourceLoc loc) {
    if (!cr_ || stable(*cr_)) return;
    cr_ = keep(std::move(cr_), loc);
    depth_ = 0;
  }

  ExprPtr keep(ExprPtr value, SourceLoc loc) {
    auto a = std::make_unique<AssignStmt>(loc);
    auto name = std::make_unique<NameExpr>(loc);
    name->name = Ident{std::string(kTempPrefix) + std::to_string(++temps_), loc};
    a->lhs = clone(*name);
    a->rhs = std::move(value);
    a->declares_temp = true;
    emit(std::move(a));
    return name;
  }

  // Before a write (or a call) that may change what a saved CR reads.
  void keep_saved() {
    for (auto& p : parens_)
      if (p.saved && !stable(*p.saved)) p.saved = keep(std::move(p.saved), p.loc);
  }

  // The CR is about to be replaced: one nobody read is still computed when computing it can
  // trap (a division, an index), as the instruction that made it would have.
  void discard_cr(SourceLoc loc) {
    if (cr_ && !consumed_ && !trap_free(*cr_)) materialize(loc);
    cr_.reset();
  }

  // Whether the instruction after i reads the CR that i leaves.
  bool read_after(size_t i) const {
    if (i + 1 >= instrs_.size()) return false;
    const Instr& next = instrs_[i + 1];
    switch (next.op) {
      case IlOp::LD: case IlOp::Label: return false;
      case IlOp::Jmp: case IlOp::Cal: case IlOp::Ret: return next.cond;
      case IlOp::Func: return !next.call;  // a formal call does not take the CR
      default: return true;
    }
  }

  // A write of the CR: the CR survives it unchanged.
  void before_write(size_t i) {
    keep_saved();
    if (read_after(i)) materialize(instrs_[i].loc);
  }

  void grow(ExprPtr e) {
    cr_ = std::move(e);
    consumed_ = false;
    if (++depth_ > kMaxCrDepth) materialize(cr_->loc);
  }

  std::unique_ptr<IfStmt> when_cr(const Instr& in) {
    auto s = std::make_unique<IfStmt>(in.loc);
    IfStmt::Arm arm;
    arm.loc = in.loc;
    arm.cond = in.negate ? negated(clone(*cr_), in.loc) : clone(*cr_);
    s->arms.push_back(std::move(arm));
    return s;
  }

  std::string at_line(const Instr& in) const { return "(line " + std::to_string(in.loc.line) + ")"; }

  bool outside_parens(const Instr& in) {
    if (parens_.empty()) return true;
    p_.diags_.error("ST137", in.loc, "'" + in.spelling + "' inside '" + parens_.back().spelling + "' (line " +
                                         std::to_string(parens_.back().loc.line) + "): close the parenthesis with ')' first");
    return false;
  }

  void lower(size_t i) {
    Instr& in = instrs_[i];
    BinaryOp bop = BinaryOp::Add;
    switch (in.op) {
      case IlOp::Label: {
        outside_parens(in);
        discard_cr(in.loc);
        auto l = std::make_unique<LabelStmt>(in.loc);
        l->name = in.name;
        l->from_il = true;
        emit(std::move(l));
        set_undefined("at label '" + in.name.text + "' " + at_line(in) +
                      ": a jump may arrive there, so start with LD");
        return;
      }
      case IlOp::LD:
        discard_cr(in.loc);
        if (!in.operand) return set_cr(error_expr(in.loc));
        return set_cr(in.negate ? negated(std::move(in.operand), in.loc) : std::move(in.operand));
      case IlOp::ST: case IlOp::S: case IlOp::R: case IlOp::FbInput: return lower_write(i);
      case IlOp::Not:
        if (read_cr(in)) grow(negated(std::move(cr_), in.loc));
        return;
      case IlOp::Close: return lower_close(in);
      case IlOp::Jmp: case IlOp::Ret: return lower_control(in);
      case IlOp::Cal: return lower_cal(in);
      case IlOp::Func: return lower_function(in);
      default: break;
    }
    if (!binary_op(in.op, &bop)) return;
    if (!read_cr(in)) return;
    if (in.paren) {
      if (parens_.size() >= static_cast<size_t>(kMaxDepth)) {
        p_.diags_.error("ST117", in.loc, "nesting too deep (more than " + std::to_string(kMaxDepth) + " open parentheses)");
        return;
      }
      parens_.push_back(Paren{bop, in.negate, std::move(cr_), in.loc, in.spelling});
      if (in.operand) return set_cr(std::move(in.operand));
      return set_undefined("after '" + in.spelling + "' " + at_line(in) + " without an operand: the first instruction inside is LD");
    }
    if (!in.operand) return set_cr(error_expr(in.loc));
    auto b = std::make_unique<BinaryExpr>(in.loc);
    b->op = bop;
    b->lhs = std::move(cr_);
    b->rhs = in.negate ? negated(std::move(in.operand), in.loc) : std::move(in.operand);
    grow(std::move(b));
  }

  // ST, STN, S, R and the FB input operators (IN T1: T1.IN := CR).
  void lower_write(size_t i) {
    Instr& in = instrs_[i];
    if (!read_cr(in) || !in.operand) return;
    before_write(i);
    if (in.op == IlOp::S || in.op == IlOp::R) {
      auto s = std::make_unique<IfStmt>(in.loc);
      IfStmt::Arm arm;
      arm.loc = in.loc;
      arm.cond = clone(*cr_);
      auto a = std::make_unique<AssignStmt>(in.loc);
      a->lhs = std::move(in.operand);
      a->rhs = literal_bool(in.op == IlOp::S, in.loc);
      arm.body.push_back(std::move(a));
      s->arms.push_back(std::move(arm));
      return emit(std::move(s));
    }
    auto a = std::make_unique<AssignStmt>(in.loc);
    if (in.op == IlOp::FbInput) {
      auto m = std::make_unique<MemberExpr>(in.operand->loc);
      m->base = std::move(in.operand);
      m->member = in.name;
      a->lhs = std::move(m);
    } else {
      a->lhs = std::move(in.operand);
    }
    a->rhs = in.negate ? negated(clone(*cr_), in.loc) : clone(*cr_);
    emit(std::move(a));
  }

  void lower_close(const Instr& in) {
    if (parens_.empty()) {
      p_.diags_.error("ST137", in.loc, "')' without an open parenthesis (such as 'AND(' or 'ADD(')");
      return;
    }
    Paren p = std::move(parens_.back());
    parens_.pop_back();
    if (!read_cr(in) || !p.saved) return set_cr(error_expr(in.loc));
    auto b = std::make_unique<BinaryExpr>(p.loc);
    b->op = p.op;
    b->lhs = std::move(p.saved);
    b->rhs = p.negate ? negated(std::move(cr_), p.loc) : std::move(cr_);
    grow(std::move(b));
  }

  // JMP, JMPC, JMPCN, RET, RETC, RETCN.
  void lower_control(const Instr& in) {
    if (!outside_parens(in)) return;
    StmtPtr action;
    if (in.op == IlOp::Jmp) {
      auto j = std::make_unique<JumpStmt>(in.loc);
      j->label = in.name;
      j->from_il = true;
      action = std::move(j);
    } else {
      action = std::make_unique<SimpleStmt>(StmtKind::Return, in.loc);
    }
    if (in.cond) {
      if (!read_cr(in)) return;
      auto s = when_cr(in);
      s->arms[0].body.push_back(std::move(action));
      return emit(std::move(s));  // not taken: the CR stays
    }
    discard_cr(in.loc);
    emit(std::move(action));
    set_undefined("after '" + in.spelling + "' " + at_line(in) + ": only a label makes the next instruction reachable");
  }

  void lower_cal(Instr& in) {
    if (!in.call) return;
    keep_saved();
    const std::string what = "after '" + in.spelling + " " + describe_callee(*in.call->callee) + "' " + at_line(in) +
                             ": a function block call leaves the current result undefined; load a value with LD";
    auto call = std::make_unique<CallStmt>(in.loc);
    call->call = std::move(in.call);
    if (in.cond) {
      if (!read_cr(in)) return;
      auto s = when_cr(in);
      s->arms[0].body.push_back(std::move(call));
      emit(std::move(s));
    } else {
      discard_cr(in.loc);
      emit(std::move(call));
    }
    set_undefined(what);
  }

  static std::string describe_callee(const Expr& e) {
    if (e.kind == ExprKind::Name) return static_cast<const NameExpr&>(e).name.text;
    if (e.kind == ExprKind::Member) {
      const auto& m = static_cast<const MemberExpr&>(e);
      return describe_callee(*m.base) + "." + m.member.text;
    }
    return "...";
  }

  // `F a, b` calls F(CR, a, b); `F(x := a)` calls F with its formal list only. The result,
  // kept in a variable, is the new CR.
  void lower_function(Instr& in) {
    keep_saved();
    std::unique_ptr<CallExpr> call;
    if (in.call) {
      discard_cr(in.loc);
      call = std::move(in.call);
    } else {
      if (!read_cr(in)) return;
      call = std::make_unique<CallExpr>(in.loc);
      auto callee = std::make_unique<NameExpr>(in.loc);
      callee->name = in.name;
      call->callee = std::move(callee);
      call->il_operator = true;
      CallArg first;
      first.loc = cr_->loc;
      first.value = std::move(cr_);
      call->args.push_back(std::move(first));
      for (auto& e : in.more) {
        CallArg a;
        a.loc = e->loc;
        a.value = std::move(e);
        call->args.push_back(std::move(a));
      }
    }
    set_cr(keep(std::move(call), in.loc));
  }

  Parser& p_;
  Pou& pou_;
  std::vector<Instr> instrs_;
  ExprPtr cr_;  // null: undefined
  std::string undefined_ = "at the start of the body: load a value with LD first";
  std::string result_;  // see result_into
  bool consumed_ = false;  // an instruction has read cr_
  int depth_ = 0;          // operators cr_ holds since it was loaded or kept
  std::vector<Paren> parens_;
  int temps_ = 0;
};

// The body is IL when its first line is an instruction: `[label:] operator ...` with an IL
// operator that no ST statement can start with (`LD x`, `AND`, `RET` alone on its line).
bool Parser::at_il_body() const { return first_on_line(pos_) && il_line_at(pos_, true); }

// Whether the line at token i reads as an IL instruction; a function call with a formal
// list counts only when `formal_call` (and then the next line must be one too).
bool Parser::il_line_at(size_t i, bool formal_call) const {
  if (tok(i).kind == Tok::Ident && tok(i + 1).kind == Tok::Colon) i += 2;
  const Token& op = tok(i);
  switch (op.kind) {
    case Tok::And: case Tok::Or: case Tok::Xor: case Tok::Mod: case Tok::Not: case Tok::Amp: return true;
    case Tok::Ident: break;
    default: return false;
  }
  const OpSpec* spec = find_op(op.text);
  const Token& next = tok(i + 1);
  if (!spec) return formal_call && next.kind == Tok::LParen && formal_call_line(i + 1);
  if (next.kind == Tok::Eof || next.loc.line != op.loc.line) {
    // Alone on its line (RET, NOT): unless the line goes on as an ST statement would.
    switch (next.kind) {
      case Tok::Assign: case Tok::LParen: case Tok::Dot: case Tok::LBracket: case Tok::Caret: case Tok::RefAssign:
      case Tok::Semi:
        return false;
      default: return true;
    }
  }
  // `JMP label;` is the CODESYS ST jump.
  if (spec->op == IlOp::Jmp && tok(i + 2).kind == Tok::Semi) return false;
  switch (next.kind) {
    case Tok::Ident: case Tok::IntLit: case Tok::RealLit: case Tok::StringLit: case Tok::WStringLit: case Tok::TimeLit:
    case Tok::DirectAddr: case Tok::True: case Tok::False: case Tok::Minus: case Tok::This:
      return true;
    default: return false;
  }
}

// `F(...)` at `open` ends its line without ';': an IL function call with a formal list
// (`LIMIT(MN := 0, IN := x, MX := 10)`), which may span lines.
bool Parser::formal_call_line(size_t open) const {
  int depth = 0;
  for (size_t k = open; k < open + 4096; ++k) {
    const Token& t = tok(k);
    if (t.kind == Tok::Eof) return false;
    if (t.kind == Tok::LParen) ++depth;
    if (t.kind == Tok::RParen && --depth == 0) {
      const Token& after = tok(k + 1);
      if (after.kind == Tok::Eof || is_unit_end(after.kind)) return true;
      return after.loc.line != t.loc.line && il_line_at(k + 1, false);
    }
  }
  return false;
}

void Parser::parse_il_body(Pou& pou) { IlReader(*this, pou).run(); }

void Parser::parse_il_into(Pou& holder, const std::string& result_var) {
  IlReader r(*this, holder);
  if (!result_var.empty()) r.result_into(result_var);
  r.run();
}

}  // namespace plcfi::st::detail

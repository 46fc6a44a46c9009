// The ST abstract syntax tree: what the parser produces. The compiler reads it and never
// writes to it: what it learns (types, symbols) lives in its own tables. Every node
// carries the location of its first token. Names keep their spelling; compare them with
// iequals()/canon().
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kinds.hpp"
#include "source.hpp"

namespace plcfi::st {

struct Ident {
  std::string text;
  SourceLoc loc;
};

// std::optional's interface for a field that is nearly always empty, one pointer wide: the
// value, when there is one, lives on the heap. A program of 2,000 FBs has some 30,000
// declarations; an inline optional<DirectAddrExpr> would make each 88 bytes bigger.
template <class T>
class OptionalBox {
 public:
  OptionalBox() = default;
  OptionalBox(std::nullopt_t) {}
  OptionalBox(T v) : p_(std::make_unique<T>(std::move(v))) {}
  OptionalBox(const OptionalBox& o) : p_(o.p_ ? std::make_unique<T>(*o.p_) : nullptr) {}
  OptionalBox(OptionalBox&&) noexcept = default;
  OptionalBox& operator=(const OptionalBox& o) {
    if (this != &o) p_ = o.p_ ? std::make_unique<T>(*o.p_) : nullptr;
    return *this;
  }
  OptionalBox& operator=(OptionalBox&&) noexcept = default;
  OptionalBox& operator=(std::nullopt_t) {
    p_.reset();
    return *this;
  }
  OptionalBox& operator=(T v) {
    p_ = std::make_unique<T>(std::move(v));
    return *this;
  }
  template <class... A>
  T& emplace(A&&... a) {
    p_ = std::make_unique<T>(std::forward<A>(a)...);
    return *p_;
  }
  void reset() { p_.reset(); }
  bool has_value() const { return p_ != nullptr; }
  explicit operator bool() const { return p_ != nullptr; }
  T& operator*() { return *p_; }
  const T& operator*() const { return *p_; }
  T* operator->() { return p_.get(); }
  const T* operator->() const { return p_.get(); }
  T& value() { return *p_; }
  const T& value() const { return *p_; }

 private:
  std::unique_ptr<T> p_;
};

// ---------------------------------------------------------------- expressions

enum class ExprKind {
  Literal,       // 42, 2#1010, INT#5, 1.5e3, TRUE, 'abc', T#1s, DATE#2024-01-01, ...
  EnumLiteral,   // Color#Red (type may also be a typed literal of an enum)
  Name,          // x
  DirectAddr,    // %IX0.3, %QW2, %MD10
  Member,        // a.b
  BitAccess,     // w.3
  Index,         // a[i, j]
  Deref,         // r^
  Call,          // f(a, b), fb(IN := x, Q => y), obj.method(...)
  Unary,         // -x, NOT x
  Binary,        // a + b
  This,          // THIS
  Super,         // SUPER
  ArrayInit,     // [1, 2, 3(0)] (only as initializer)
  StructInit,    // (a := 1, b := 2) (only as initializer)
};

enum class LiteralKind { Int, Real, Bool, String, WString, Time, Date, TimeOfDay, DateTime };

enum class UnaryOp { Neg, Not, Plus };

enum class BinaryOp {
  Pow,                   // **
  Mul, Div, Mod,         // * / MOD
  Add, Sub,              // + -
  Lt, Gt, Le, Ge,        // < > <= >=
  Eq, Ne,                // = <>
  And,                   // AND, &
  Xor,                   // XOR
  Or,                    // OR
  AndThen, OrElse,       // AND_THEN, OR_ELSE (CODESYS): the right operand only when needed
};
// The operator as written in ST ("<=", "MOD", "AND").
const char* op_text(BinaryOp op);

struct Expr {
  explicit Expr(ExprKind k, SourceLoc l) : kind(k), loc(l) {}
  virtual ~Expr() = default;
  ExprKind kind;
  SourceLoc loc;
};
using ExprPtr = std::unique_ptr<Expr>;

struct LiteralExpr : Expr {
  explicit LiteralExpr(SourceLoc l) : Expr(ExprKind::Literal, l) {}
  LiteralKind lit = LiteralKind::Int;
  std::string type_prefix;  // "INT" in INT#5, "" when untyped; for T#/TIME#/LTIME# the prefix as written
  uint64_t int_value = 0;   // magnitude for Int, 0/1 for Bool; a leading '-' is a Unary Neg
  double real_value = 0;
  std::string str_value;    // decoded ($ escapes resolved) for String/WString
  int64_t time_ns = 0;      // Time: duration; Date/TimeOfDay/DateTime: ns since 1970-01-01 / midnight
  bool is_long = false;     // LTIME#, LDATE#, ... forms
  bool beyond_signed = false;  // LTIME# above INT64_MAX (time_ns: the unsigned bits; CODESYS only)
};

struct EnumLiteralExpr : Expr {
  explicit EnumLiteralExpr(SourceLoc l) : Expr(ExprKind::EnumLiteral, l) {}
  Ident type_name;
  Ident value;
};

struct NameExpr : Expr {
  explicit NameExpr(SourceLoc l) : Expr(ExprKind::Name, l) {}
  Ident name;
};

// %[IQM][XBWDL]?a.b.c
struct DirectAddrExpr : Expr {
  explicit DirectAddrExpr(SourceLoc l) : Expr(ExprKind::DirectAddr, l) {}
  std::string text;       // "%IX0.3" as written
  char area = 'I';        // 'I', 'Q', 'M'
  char size = 'X';        // 'X' (bit, also when omitted), 'B', 'W', 'D', 'L'
  std::vector<uint32_t> parts;  // 0.3 -> {0, 3}; %QW2 -> {2}
};

// `AT %I*`, `AT %Q*`, `AT %M*`: the address is left to the I/O mapping (TwinCAT, CODESYS).
// plcfi keeps such a variable in ordinary storage; io maps, plant files and campaign
// bindings reach it by its path (Main.start).
inline bool is_unmapped(const DirectAddrExpr& a) { return a.parts.empty() && !a.text.empty() && a.text.back() == '*'; }

struct MemberExpr : Expr {
  explicit MemberExpr(SourceLoc l) : Expr(ExprKind::Member, l) {}
  ExprPtr base;
  Ident member;
};

struct BitAccessExpr : Expr {
  explicit BitAccessExpr(SourceLoc l) : Expr(ExprKind::BitAccess, l) {}
  ExprPtr base;
  uint32_t bit = 0;
};

struct IndexExpr : Expr {
  explicit IndexExpr(SourceLoc l) : Expr(ExprKind::Index, l) {}
  ExprPtr base;
  std::vector<ExprPtr> indices;
};

struct DerefExpr : Expr {
  explicit DerefExpr(SourceLoc l) : Expr(ExprKind::Deref, l) {}
  ExprPtr base;
};

struct CallArg {
  std::optional<Ident> name;  // formal name, or none for positional
  bool is_output = false;     // name => var
  bool negate = false;        // NOT name => var
  ExprPtr value;              // may be null for an empty output capture `Q =>`
  SourceLoc loc;
};

struct CallExpr : Expr {
  explicit CallExpr(SourceLoc l) : Expr(ExprKind::Call, l) {}
  ExprPtr callee;  // Name (function, FB instance, program instance) or Member (method, nested FB)
  std::vector<CallArg> args;
  // Instruction List: the callee was written as an operator (`LD a  MYFUN b`), so a name
  // that is no function is an unknown IL operator rather than an unknown function.
  bool il_operator = false;
};

struct UnaryExpr : Expr {
  explicit UnaryExpr(SourceLoc l) : Expr(ExprKind::Unary, l) {}
  UnaryOp op = UnaryOp::Neg;
  ExprPtr operand;
};

struct BinaryExpr : Expr {
  explicit BinaryExpr(SourceLoc l) : Expr(ExprKind::Binary, l) {}
  // A chain of 10,000 terms is a left spine 10,000 deep: freed in a loop, not by recursion.
  ~BinaryExpr() override {
    ExprPtr next = std::move(lhs);
    while (next && next->kind == ExprKind::Binary) {
      ExprPtr below = std::move(static_cast<BinaryExpr&>(*next).lhs);
      next = std::move(below);
    }
  }
  BinaryExpr(const BinaryExpr&) = delete;
  BinaryExpr& operator=(const BinaryExpr&) = delete;
  BinaryOp op = BinaryOp::Add;
  ExprPtr lhs, rhs;
};

struct ThisExpr : Expr {
  explicit ThisExpr(SourceLoc l) : Expr(ExprKind::This, l) {}
};
struct SuperExpr : Expr {
  explicit SuperExpr(SourceLoc l) : Expr(ExprKind::Super, l) {}
};

// [1, 2, 3(0)]: items with an optional repeat count (3(0) = three zeros).
struct ArrayInitExpr : Expr {
  explicit ArrayInitExpr(SourceLoc l) : Expr(ExprKind::ArrayInit, l) {}
  struct Item {
    ExprPtr repeat;  // null when no repeat count
    ExprPtr value;   // may be null for `3()` (repeat default value)
  };
  std::vector<Item> items;
};

struct StructInitExpr : Expr {
  explicit StructInitExpr(SourceLoc l) : Expr(ExprKind::StructInit, l) {}
  struct Item {
    Ident field;
    ExprPtr value;
  };
  std::vector<Item> items;
};

// ---------------------------------------------------------------- types

enum class TypeSpecKind {
  Named,     // INT, MyStruct, STRING, STRING[20], STRING(20), WSTRING[10]
  Array,     // ARRAY [1..10, 0..2] OF T   (ARRAY[*] not supported)
  Struct,    // STRUCT ... END_STRUCT (also UNION ... END_UNION, is_union)
  Enum,      // (A, B := 5, C)  or  INT (A := 1, B := 2)  or  (A, B) INT
  Subrange,  // INT (0..100)
  Ref,       // REF_TO T (also POINTER TO T, and REFERENCE TO T)
};

struct VarDecl;

struct TypeSpec {
  TypeSpecKind kind = TypeSpecKind::Named;
  SourceLoc loc;
  // Named:
  Ident name;
  ExprPtr string_length;  // STRING[n] / STRING(n): n, else null
  // Array:
  struct Range {
    ExprPtr lo, hi;
    bool open = false;  // `*` (ARRAY[*], a VAR_IN_OUT whose bounds are the argument's)
  };
  std::vector<Range> dims;
  std::unique_ptr<TypeSpec> element;  // Array element, Ref target, Subrange/Enum base (may be null for enums)
  // Struct:
  std::vector<VarDecl> members;
  // Enum:
  struct EnumValue {
    Ident name;
    ExprPtr value;  // may be null
  };
  std::vector<EnumValue> enum_values;
  // Subrange:
  ExprPtr sub_lo, sub_hi;
  bool is_pointer = false;  // Ref spelt POINTER TO
  bool is_union = false;      // Struct spelt UNION ... END_UNION (CODESYS): every member at offset 0
  OptionalBox<Ident> struct_base;  // TYPE T EXTENDS B : STRUCT (CODESYS): B's members first
  bool is_reference = false;  // Ref spelt REFERENCE TO (CODESYS): dereferenced implicitly on every use
  // Named: `fb : FB_X(a := 1)` in a VAR block (CODESYS): the arguments of the instance's
  // FB_init, called at every restart.
  bool has_init_args = false;
  std::vector<CallArg> init_args;
};
using TypeSpecPtr = std::unique_ptr<TypeSpec>;

// ---------------------------------------------------------------- declarations


// One declaration line: `a, b AT %IX0.0 : INT := 5;` (AT only with a single name).
struct VarDecl {
  std::vector<Ident> names;
  OptionalBox<DirectAddrExpr> location;  // AT %IX0.0 (may be partly specified: %I*)
  TypeSpecPtr type;
  ExprPtr init;             // may be null
  VarSection section = VarSection::Var;
  bool constant = false;    // from VAR CONSTANT
  bool retain = false;      // from VAR RETAIN / PERSISTENT
  SourceLoc loc;
};

struct VarBlock {
  VarSection section = VarSection::Var;
  bool constant = false;
  bool retain = false;
  SourceLoc loc;
  std::vector<VarDecl> decls;
};

// ---------------------------------------------------------------- statements

enum class StmtKind {
  Assign,     // lhs := rhs   (also lhs REF= rhs, S=, R=)
  Call,       // f(...); fb(...); obj.m(...);
  If,
  Case,
  For,
  While,
  Repeat,
  Exit,
  Continue,
  Return,
  Empty,      // ;
  Mock,       // test files: MOCK path;
  MockFunction,  // test files: MOCK_FUNCTION Name RETURNS expr;
  Label,      // name:   (a jump target: Instruction List, and CODESYS ST)
  Jump,       // JMP name;
};

struct Stmt {
  explicit Stmt(StmtKind k, SourceLoc l) : kind(k), loc(l) {}
  virtual ~Stmt() = default;
  StmtKind kind;
  SourceLoc loc;
};
using StmtPtr = std::unique_ptr<Stmt>;
using StmtList = std::vector<StmtPtr>;

struct AssignStmt : Stmt {
  explicit AssignStmt(SourceLoc l) : Stmt(StmtKind::Assign, l) {}
  ExprPtr lhs, rhs;
  bool is_ref_assign = false;  // REF=
  char set_reset = 0;          // 'S' for S= (CODESYS: lhs := TRUE when rhs), 'R' for R= (lhs := FALSE)
  bool chained = false;        // `b := c` of `a := b := c` (CODESYS), split into `b := c; a := b;`
  // Instruction List: lhs is a Name the body has not declared, a hidden variable that this
  // assignment declares with the type of rhs (the current result kept for later
  // instructions; only the compiler knows its type).
  bool declares_temp = false;
};

struct CallStmt : Stmt {
  explicit CallStmt(SourceLoc l) : Stmt(StmtKind::Call, l) {}
  std::unique_ptr<CallExpr> call;
};

struct IfStmt : Stmt {
  explicit IfStmt(SourceLoc l) : Stmt(StmtKind::If, l) {}
  struct Arm {
    ExprPtr cond;
    StmtList body;
    SourceLoc loc;      // the IF / ELSIF keyword
    std::string label;  // coverage: what the arm means when generated (an SFC transition fires); empty: IF/ELSIF
  };
  std::vector<Arm> arms;  // IF then ELSIFs
  std::optional<StmtList> else_body;
  SourceLoc else_loc;
};

struct CaseLabel {
  ExprPtr lo;  // single value: lo only
  ExprPtr hi;  // range lo..hi: hi non-null
};

struct CaseStmt : Stmt {
  explicit CaseStmt(SourceLoc l) : Stmt(StmtKind::Case, l) {}
  ExprPtr selector;
  struct Arm {
    std::vector<CaseLabel> labels;
    StmtList body;
    SourceLoc loc;  // first label
  };
  std::vector<Arm> arms;
  std::optional<StmtList> else_body;
  SourceLoc else_loc;
};

struct ForStmt : Stmt {
  explicit ForStmt(SourceLoc l) : Stmt(StmtKind::For, l) {}
  ExprPtr var;  // a Name (control variable)
  ExprPtr from, to, by;  // by may be null
  StmtList body;
};

struct WhileStmt : Stmt {
  explicit WhileStmt(SourceLoc l) : Stmt(StmtKind::While, l) {}
  ExprPtr cond;
  StmtList body;
};

struct RepeatStmt : Stmt {
  explicit RepeatStmt(SourceLoc l) : Stmt(StmtKind::Repeat, l) {}
  StmtList body;
  ExprPtr until;
};

struct SimpleStmt : Stmt {  // Exit, Continue, Return, Empty
  SimpleStmt(StmtKind k, SourceLoc l) : Stmt(k, l) {}
};

struct MockStmt : Stmt {
  explicit MockStmt(SourceLoc l) : Stmt(StmtKind::Mock, l) {}
  ExprPtr target;  // path to an FB instance (Name / Member chain)
};

struct MockFunctionStmt : Stmt {
  explicit MockFunctionStmt(SourceLoc l) : Stmt(StmtKind::MockFunction, l) {}
  Ident function;
  ExprPtr value;
};

// `name:` and `JMP name;`. Labels belong to the outermost statement list of a body; a jump
// may leave blocks but not enter one.
struct LabelStmt : Stmt {
  explicit LabelStmt(SourceLoc l) : Stmt(StmtKind::Label, l) {}
  Ident name;
  // Written in Instruction List or generated from an LD/FBD jump (IEC), not ST (CODESYS only).
  bool from_il = false;
  // Characters of name.text a lowering put before the user's name (an SFC action's labels
  // are its own): messages show the rest.
  size_t hidden_prefix = 0;
  std::string shown() const { return name.text.substr(std::min(hidden_prefix, name.text.size())); }
};

struct JumpStmt : Stmt {
  explicit JumpStmt(SourceLoc l) : Stmt(StmtKind::Jump, l) {}
  Ident label;
  bool from_il = false;
  size_t hidden_prefix = 0;  // as LabelStmt's
  std::string shown() const { return label.text.substr(std::min(hidden_prefix, label.text.size())); }
};

// ---------------------------------------------------------------- SFC

// A textual Sequential Function Chart (IEC 61131-3, the textual form of SFC): what the
// parser read. The parser lowers it into the POU's variables and statements (see
// sfc_lower.hpp); what stays here describes the chart (names and locations) for the tools.
struct SfcAssociation {   // Fill(N), Timer(D, T#5s), Lamp(S, ind)
  Ident action;
  std::string qualifier = "N";  // N R S P P1 P0 L D SD DS SL
  SourceLoc qualifier_loc;
  ExprPtr time;                 // L, D, SD, DS, SL: the duration; moved out by the lowering
  std::vector<Ident> indicators;
  SourceLoc loc;
};

struct SfcStep {
  Ident name;
  bool initial = false;
  std::vector<SfcAssociation> actions;
  SourceLoc loc;
};

struct SfcTransition {
  std::optional<Ident> name;
  std::optional<int64_t> priority;  // (PRIORITY := n): lower numbers are tried first
  std::vector<Ident> from, to;
  ExprPtr condition;                // moved out by the lowering
  StmtList condition_body;          // a condition in IL: its statements, which set `condition` (a name)
  SourceLoc loc;
};

struct SfcAction {
  Ident name;
  StmtList body;                    // moved out by the lowering
  SourceLoc loc;
};

struct SfcChart {
  std::vector<SfcStep> steps;
  std::vector<SfcTransition> transitions;
  std::vector<SfcAction> actions;
  SourceLoc loc;                    // the first element
};

// ---------------------------------------------------------------- POUs


struct PropertyDecl;

struct Pou {
  PouKind kind = PouKind::Program;
  Ident name;
  SourceLoc loc;
  SourceLoc end_loc;               // the END_* keyword
  TypeSpecPtr return_type;         // Function / Method; null when none
  std::vector<VarBlock> var_blocks;
  StmtList body;
  // FUNCTION_BLOCK / INTERFACE:
  std::optional<Ident> extends;    // FB: one base; interface: see extends_list
  std::vector<Ident> implements;   // FB: IMPLEMENTS I1, I2; INTERFACE: EXTENDS I1, I2
  bool is_abstract = false;
  bool is_final = false;
  std::vector<std::unique_ptr<Pou>> methods;      // METHOD ... END_METHOD inside FB/interface
  std::vector<std::unique_ptr<PropertyDecl>> properties;
  // PROGRAM / FUNCTION_BLOCK written in SFC: the chart (already lowered into body).
  std::unique_ptr<SfcChart> sfc;
  // Method:
  Access access = Access::Public;
  bool has_body = true;            // interface methods: false
};
using PouPtr = std::unique_ptr<Pou>;

// PROPERTY Name : T  GET ... END_GET  SET ... END_SET  END_PROPERTY
// Each accessor is a Method-kind Pou (getter returns T; setter has the implicit input Name).
struct PropertyDecl {
  Ident name;
  SourceLoc loc;
  TypeSpecPtr type;
  Access access = Access::Public;
  PouPtr getter;  // may be null
  PouPtr setter;  // may be null
};

struct TypeDecl {
  Ident name;
  SourceLoc loc;
  TypeSpecPtr spec;
  ExprPtr init;  // TYPE T : INT := 5; END_TYPE
};

struct TaskDecl {
  Ident name;
  SourceLoc loc;
  ExprPtr interval;  // INTERVAL := T#10ms (may be null: event task, unsupported)
  ExprPtr priority;  // PRIORITY := 1
  ExprPtr single;    // SINGLE := trigger (parsed, rejected by sema)
};

struct ProgramInstDecl {
  Ident instance;
  SourceLoc loc;
  std::optional<Ident> task;  // WITH task
  Ident type;
  std::vector<CallArg> args;  // optional (in := x, out => y)
};

struct ResourceDecl {
  Ident name;
  SourceLoc loc;
  Ident on;  // ON PLC
  std::vector<VarBlock> globals;
  std::vector<TaskDecl> tasks;
  std::vector<ProgramInstDecl> programs;
};

struct ConfigDecl {
  Ident name;
  SourceLoc loc;
  std::vector<VarBlock> globals;
  std::vector<ResourceDecl> resources;
};

// One parsed source file (program sources and test files alike).
struct CompilationUnit {
  uint32_t file = 0;
  std::vector<PouPtr> pous;            // PROGRAM, FUNCTION_BLOCK, FUNCTION, INTERFACE
  std::vector<TypeDecl> types;         // TYPE ... END_TYPE
  std::vector<VarBlock> globals;       // top-level VAR_GLOBAL ... END_VAR (CODESYS GVL)
  std::vector<ConfigDecl> configs;
};

// ---------------------------------------------------------------- test files

struct TestCase {
  std::string name;
  SourceLoc loc;
  std::vector<VarBlock> var_blocks;  // optional VAR ... END_VAR
  StmtList body;                     // ASSERT_* and ADVANCE_TIME are ordinary calls here
};

struct TestFile {
  uint32_t file = 0;
  std::optional<TestCase> setup;     // name "SETUP"; its VAR block is visible in all tests
  std::optional<TestCase> teardown;  // name "TEARDOWN"
  std::vector<TestCase> tests;
  // A test file may also declare helper POUs and types of its own.
  CompilationUnit decls;
};

}  // namespace plcfi::st

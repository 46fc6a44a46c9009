// Internal state of the ST compiler, shared by its translation units (declarations,
// expressions, places, statements, calls, standard functions). Not part of the
// engine's public interface.
//
// The compiler works in two stages over the AST: declarations (types, POU signatures,
// layouts, globals) are indexed first; then each POU body is type-checked and translated
// to bytecode in one walk (like Lua's and Wirth's compilers), POUs compiled on demand so
// that an FB's instance size or a function's frame size is known before a caller needs it.
#pragma once

#include <functional>
#include <map>
#include <tuple>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "codegen/compiler.hpp"
#include "vm/cpp_functions.hpp"
#include "vm/vm.hpp"
#include "vm/wide.hpp"

namespace plcfi::st {
struct StdFunc;
struct ConversionName;
}  // namespace plcfi::st

namespace plcfi::st::detail {

// A frame operand: a declared variable's offset, a temporary, or a constant-pool entry.
// Temporaries and constants get their final offsets when the body is finished
// (frame layout: [variables][hidden state][constants][temporaries]).
enum class SK : uint8_t { Var, Temp, Const, Hidden };
struct Slot {
  uint32_t off = 0;
  SK kind = SK::Var;
  Slot plus(uint32_t d) const { return Slot{off + d, kind}; }
  bool operator==(const Slot&) const = default;
};

// Which code of a POU a call goes to: its body, or (FB/PROGRAM) the entry that runs
// FB_init or FB_exit of the instances it holds.
enum class EntryKind : uint8_t { Body, Init, Exit };
struct EntryFix {
  uint32_t at;  // code index of the operand
  PouInfo* pou;
  EntryKind kind;
};

// One instruction operand word.
struct Arg {
  enum class K : uint8_t { Imm, Slot, Target, Entry } k = K::Imm;
  uint32_t v = 0;
  SK sk = SK::Var;
  PouInfo* pou = nullptr;
  Arg(uint32_t x) : v(x) {}  // NOLINT: immediates read naturally at call sites
  Arg(int x) : v(static_cast<uint32_t>(x)) {}  // NOLINT
  Arg(Slot s) : k(K::Slot), v(s.off), sk(s.kind) {}  // NOLINT
  static Arg target(uint32_t label) {
    Arg a(label);
    a.k = K::Target;
    return a;
  }
  static Arg entry(PouInfo* p, EntryKind which = EntryKind::Body) {
    Arg a(static_cast<uint32_t>(which));
    a.k = K::Entry;
    a.pou = p;
    return a;
  }
};

// A compile-time constant (literals, CONSTANT variables, folded expressions).
struct ConstV {
  enum class K : uint8_t { None, Int, Real, Bool, Str } k = K::None;
  int64_t i = 0;
  double r = 0;
  std::string s;
};

// An rvalue: a constant, or a frame slot holding the value. type == null with a constant
// of kind Int/Real is an untyped literal that adapts to its context (IEC ANY_INT/ANY_REAL).
struct Val {
  const Type* type = nullptr;
  bool ok = true;
  bool is_const = false;
  ConstV c;
  Slot slot;
  // --dialect codesys: the IEC type of an integer result held wider, as CODESYS keeps
  // intermediate results in (at least) 32-bit registers; `type` is the register's type.
  // A store to the nominal type (or wider) converts without a warning.
  const Type* nominal = nullptr;
};

// One of the six comparisons (=, <>, <, >, <=, >=).
inline bool is_cmp(BinaryOp op) {
  return op == BinaryOp::Lt || op == BinaryOp::Gt || op == BinaryOp::Le || op == BinaryOp::Ge ||
         op == BinaryOp::Eq || op == BinaryOp::Ne;
}

// The value of type t held in slot s.
inline Val slot_val(const Type* t, Slot s) {
  Val out;
  out.type = t;
  out.slot = s;
  return out;
}

// An lvalue.
struct Place {
  enum class K : uint8_t { Frame, Abs, AbsBit, Ind, FrameIdx, Bit } k = K::Frame;
  const Type* type = nullptr;
  uint32_t off = 0;   // Frame: offset; Abs/AbsBit: address; Ind: displacement; FrameIdx: array offset
  SK sk = SK::Var;    // Frame/FrameIdx: what off is relative to
  Slot ptr;           // Ind: slot holding the address
  Slot idx;           // FrameIdx: DINT index slot
  int32_t lo = 0;     // FrameIdx
  uint32_t count = 0; // FrameIdx
  uint32_t stride = 0;  // FrameIdx: element size (0: the value's own size, an array of scalars)
  uint32_t field = 0;   // FrameIdx: offset of the scalar inside the element
  uint32_t idx_cvt = UINT32_MAX;  // FrameIdx: where this place emitted the conversion of its index to DINT
  bool has_idx16 = false;  // FrameIdx: idx not made yet; the index is the INT variable idx16 (stores: STXH)
  Slot idx16;
  // FrameIdx with a second variable index (LDXX/STXX): stride is the first index's,
  // these the second's.
  bool two = false;
  Slot idx2;
  int32_t lo2 = 0;
  uint32_t count2 = 0, stride2 = 0;
  // FrameIdx of a rank-1 array of scalars whose DINT index is x * m + y, each a variable
  // or a constant (LDXL/STXL): idx not made yet, one bounds check on the wrapped sum.
  bool has_lin = false;
  Slot lin_x, lin_m, lin_y;
  // has_lin with x * m + y known inside the dimension: one of x and m a constant, the
  // other and y counters of proven FOR loops (see linear_in_range). A row offset may
  // then reach the element (row_for).
  bool lin_proven = false;
  // FrameIdx whose index was v + shift (v the DINT variable in idx, shift a small integer
  // constant): lo holds the dimension's lower bound minus shift, so the access computes
  // v - lo without the addition (see displaced_index).
  int32_t shift = 0;
  // FrameIdx with two indices, each a FOR counter proven to stay inside its dimension
  // (LDXXN/STXXN: no check at run time).
  bool proven = false;
  uint32_t arr_bytes = 0;  // FrameIdx: the whole array's size, from off
  // FrameIdx with two indices: the element's offset from off when both index variables
  // are 0 (the lower bounds folded in), as LDXXN/STXXN and the row offsets use it.
  int64_t unchecked_disp() const { return int64_t{field} - int64_t{lo} * stride - int64_t{lo2} * stride2; }
  uint8_t bit = 0;    // AbsBit, Bit
  std::shared_ptr<Place> inner;  // Bit: the word
  bool readonly = false;
  const Symbol* sym = nullptr;
  bool ok = true;
};

struct Label {
  uint32_t id;
};

struct Body {
  PouInfo* pou = nullptr;
  uint32_t file = 0;
  std::vector<uint32_t> code;
  std::vector<std::pair<uint32_t, SourceLoc>> lines;
  std::vector<uint32_t> label_pos;                         // label id -> body-relative pc
  std::vector<uint32_t> label_refs;                        // label id -> jumps emitted to it
  std::vector<std::pair<uint32_t, uint32_t>> target_fix;   // (code index, label id)
  std::vector<std::pair<uint32_t, SK>> slot_fix;           // (code index, kind) for Temp/Const
  std::vector<EntryFix> entry_fix;
  std::vector<uint32_t> template_fix;                      // code index -> this POU's template address
  std::vector<std::pair<uint32_t, int32_t>> index_shifts;  // (code index, shift) of displaced accesses
  std::vector<uint8_t> consts;
  std::map<std::pair<std::string, uint32_t>, uint32_t> const_index;
  uint32_t vars_end = 0;
  uint32_t temp_top = 0, temp_max = 0;
  // The last instruction that only defined a temporary, so a following store can
  // retarget it to the variable instead of copying (x := a + b is one ADD).
  uint32_t last_def_pos = UINT32_MAX;
  uint32_t last_def_operand = 1;
  Slot last_def;
  uint32_t last_label_pos = 0;
  // The last store into an element of a frame array of scalars (STX..., see
  // stored_element): a load of the same element right after it reads the stored value.
  uint32_t last_elem_store = UINT32_MAX;
  uint32_t last_instr = UINT32_MAX;
  uint32_t prev_instr = UINT32_MAX;  // the instruction before last_instr, while both stand
  uint32_t prev2_instr = UINT32_MAX;  // the instruction before prev_instr, while all three stand
  // The last two element reads compiled as a load into a temporary: the expression and
  // the load's position (rule 27, compared_elements).
  std::pair<const Expr*, uint32_t> elem_loads[2] = {{nullptr, UINT32_MAX}, {nullptr, UINT32_MAX}};
  // Conversions already done in the statement being compiled (an index used twice).
  std::map<std::tuple<uint32_t, SK, Storage, Storage>, Slot> cvt_cache;
  std::unordered_map<std::string, Symbol*> locals;  // canon name -> symbol (frame or This)
  bool is_method = false;
  bool in_test = false;             // a TEST/SETUP/TEARDOWN body: asserts and mocks allowed
  const Type* this_type = nullptr;  // FB type whose members are reachable (body or method)
  struct Loop {
    Label exit, cont;
    const Expr* cond = nullptr;  // WHILE: the condition; REPEAT: the UNTIL expression (rule 29)
  };
  std::vector<Loop> loops;
  uint32_t arm = kNoBranch;  // the branch id whose arm is being compiled (coverage nesting)
  // JMP targets: the labels of the outermost statement list being compiled (canon name ->
  // label, where declared), and how deep in statement lists the compiler is (1: outermost).
  std::unordered_map<std::string, std::pair<Label, SourceLoc>> goto_labels;
  int stmt_depth = 0;
  std::vector<std::unique_ptr<Symbol>> owned;  // This-symbols made for methods
  // Monitors: state of temporal operators (current and previous value of each argument).
  uint32_t hidden_size = 0;
  struct Edge {
    Slot cur, prev;
    uint32_t size;
  };
  std::vector<Edge> edges;
  std::optional<Slot> started;  // TRUE once a state has been committed
  std::optional<Slot> state_seen;  // the last __state evaluated
  // Rule 28: the BOOL variables (frame offsets) that enclosing WHILE loops test, and
  // whether the path being compiled may have written one since its loop's test passed
  // (an instruction storing it, or one that may store anywhere: a call, a store through
  // a pointer, ...; see watch_writes).
  struct FlagWatch {
    uint32_t off;
    bool dirty;
    bool ever = false;  // written anywhere since the innermost loop being compiled began
  };
  std::vector<FlagWatch> flag_watches;
};

// What the compiler knows of a POU beyond the compiled program: its declaration in the
// syntax tree and how far its compilation got. The POUs of a program that a second unit
// is linked onto have none: they are finished.
struct PouSource {
  const Pou* decl = nullptr;
  std::vector<const VarBlock*> blocks;     // declaration blocks (tests merge SETUP's)
  const PropertyDecl* property = nullptr;  // getter/setter of this property
  bool declared = false;                   // signature and variable layout done
  bool late = false;                       // compiled after the program instances (monitors)
};

// A variable's declaration (initializer, for constants) and its uses, for the "never
// used" warnings.
struct SymbolSource {
  const VarDecl* decl = nullptr;
  uint32_t reads = 0, writes = 0;
};

class Compiler {
 public:
  Compiler(const SourceManager& sm, DiagEngine& diags, const CompileOptions& opt);
  std::unique_ptr<Application> run(const std::vector<const CompilationUnit*>& units,
                                   const std::vector<const TestFile*>& tests);
  bool link(Application& app, const std::vector<const CompilationUnit*>& units);

  // ---- the stages of a run (compiler.cpp)
  void start_program();
  // Appends file `i` of the source manager to app's file table (path, library or not).
  void add_file_path(Application& app, uint32_t i) const {
    app.file_paths.push_back(sm_.file(i).path);
    app.library_files.push_back(sm_.file(i).library || is_library_path(sm_.file(i).path));
  }
  void start_from(Application& app);
  void declare_units(const std::vector<const CompilationUnit*>& all, size_t first_pou);
  void check_interfaces(size_t first_pou);
  void configure(const std::vector<const CompilationUnit*>& units);
  void finish_link();

  // ---- declarations (decls.cpp)
  void index_unit(const CompilationUnit& u, bool stdlib);
  void index_pou(const Pou& p, uint32_t file, bool stdlib, PouInfo* owner);
  const Type* resolve_type(const TypeSpec& spec, uint32_t file, const std::string& name_hint = "");
  const Type* named_type(const Ident& name, uint32_t file, bool report = true);
  void layout_struct(Type* t, const std::vector<VarDecl>& members, uint32_t file);
  void declare_vars(PouInfo* p);
  void order_positional(PouInfo* p);
  bool positional_after_named_ok(SourceLoc loc);
  std::vector<Symbol*> positional_params(const PouInfo* p) const;
  // The name under which a method's VAR_INST variable is kept in its owner's instance.
  static std::string inst_var_name(const PouInfo* method, const std::string& var);
  void declare_globals(const std::vector<VarBlock>& blocks, const std::string& scope, uint32_t file);
  std::optional<ConstV> const_eval(const Expr& e, uint32_t file, bool report = true);
  // `Colour.Red`: an enumeration value qualified by its type's name (CODESYS, TwinCAT),
  // when the base names no variable or instance. Null when m is no such thing; a type
  // without that value is reported (once) and gives null too, with *reported set.
  struct EnumValueRef {
    const Type* type;
    int64_t value;
  };
  std::optional<EnumValueRef> qualified_enum(const MemberExpr& m, uint32_t file, bool report, bool* reported = nullptr);
  std::optional<int64_t> const_int(const Expr& e, uint32_t file);
  void write_init(std::vector<uint8_t>& image, uint32_t offset, const Type* t, const Expr* init, uint32_t file);
  bool write_const(uint8_t* dst, const Type* t, const ConstV& c, SourceLoc loc);
  bool locate(const DirectAddrExpr& a, const Type* t, uint32_t* addr, uint8_t* bit, bool* is_bit);
  uint32_t alloc(uint32_t size, uint32_t align);
  void ensure_compiled(PouInfo* p, SourceLoc use);
  void declare_pou(PouInfo* p);
  void ensure_layout(PouInfo* p, SourceLoc use);
  bool implements(const PouInfo* fb, const PouInfo* itf) const;
  // An instance of `from` may stand where `to` is expected: the same FB type or one
  // derived from it (EXTENDS, any depth), as the 3rd edition allows for VAR_IN_OUT and
  // references.
  bool derives(const Type* from, const Type* to) const;
  // The dialect's implicit conversions (see CompileOptions::dialect).
  bool dialect_converts(const Type* from, const Type* to) const;
  Val implicit_conversion(const Val& v, const Type* to, SourceLoc loc, const char* what);
  std::optional<Val> pointer_conversion(const Val& v, const Type* to, SourceLoc loc);
  const Type* dialect_common_type(const Type* a, const Type* b) const;
  // Whether some FB extends `fb`: then an instance reached through a reference or a
  // VAR_IN_OUT may be of a derived type, and its methods dispatch at run time.
  bool has_derived(const PouInfo* fb) const;
  uint32_t selector(const std::string& method_canon);

  // ---- bodies (compiler.cpp)
  void compile_pou(PouInfo* p);
  void compile_test(const TestFile& tf, const TestCase& tc);
  void finish_body(Body& b, PouInfo* p, std::vector<uint32_t>* entries);
  void emit(Op op, std::initializer_list<Arg> args);
  void emit_list(Op op, const std::vector<Arg>& args);
  void def(Slot dst, uint32_t operand = 1);  // the instruction just emitted only wrote dst (its n-th operand)
  bool retarget(Slot from, Slot to);
  Val expr_for(const Expr& e, const Type* target);
  Label new_label();
  void bind(Label l);
  // Binds a label that only jumps emitted before it can reach (an IF's end, a WHILE's
  // CONTINUE target). With none, its position is no jump target: what the code before
  // it did stays known to the code after it (the peepholes that look back).
  void bind_forward(Label l);
  void mark(SourceLoc loc);
  Slot temp(uint32_t size, uint32_t align = 8);
  Slot temp_for(const Type* t) { return temp(t->size ? t->size : 1, t->align < 8 ? t->align : 8); }
  Slot konst(const Type* t, const ConstV& c, SourceLoc loc);
  Slot konst_bytes(const void* data, uint32_t size, uint32_t align);
  Slot konst_i64(int64_t v);
  Slot konst_u32(uint32_t v);
  Slot hidden(uint32_t size, uint32_t align);

  // ---- statements (stmt.cpp)
  void stmts(const StmtList& list);
  void stmt(const Stmt& s);
  void assign_stmt(const AssignStmt& s);
  void if_stmt(const IfStmt& s);
  bool leaves_loop(const StmtList& body) const;
  void case_stmt(const CaseStmt& s);
  void for_stmt(const ForStmt& s);
  void while_stmt(const WhileStmt& s);
  void repeat_stmt(const RepeatStmt& s);
  // Labels and JMP (Instruction List, CODESYS ST); the current-result variables IL declares.
  void declare_labels(const StmtList& list);
  void label_stmt(const LabelStmt& s);
  void jump_stmt(const JumpStmt& s);
  void declare_temp(const AssignStmt& s);
  // A coverage id for an arm (BranchPoint): `decision` holds the statement's first arm id
  // (kNoBranch before it); the arm's body is to be compiled inside an ArmScope.
  uint32_t branch(SourceLoc loc, const char* kind, SourceLoc stmt, uint32_t* decision, const StmtList& body);

  // ---- expressions, rvalues (expr.cpp)
  Val expr(const Expr& e, const Type* expected = nullptr);
  Val binary(const BinaryExpr& e, const Type* expected);
  Val short_circuit(const BinaryExpr& e, const Val& l);
  const Type* register_nominal(const std::vector<Val>& vals, const Type* t);
  Val combine(BinaryOp op, const Val& l, const Val& r, SourceLoc loc);
  Val unary(const UnaryExpr& e, const Type* expected);
  Val literal(const LiteralExpr& e, const Type* expected);
  Val coerce(const Val& v, const Type* to, SourceLoc loc, const char* what);
  Slot to_slot(const Val& v, const Type* t, SourceLoc loc);
  Slot convert(Slot s, const Type* from, const Type* to);
  // A string in the other representation (STRING <-> WSTRING, UTF-8 <-> UTF-16).
  Val restring(Slot s, const Type* from, bool wide);
  // A string value (a constant too) as a STRING or, wide, a WSTRING: mixing the two
  // converts the text, never reinterprets its bytes.
  Slot string_slot(const Val& v, bool wide, SourceLoc loc);
  Val cond(const Expr& e);
  // Emits "jump to target when the condition is false (or true)"; a comparison that was
  // just computed into a temporary becomes one fused compare-and-jump instruction.
  // (Defined in stmt.cpp.)
  void branch_on(const Val& c, SourceLoc loc, Label target, bool when_true);
  // Compiles the condition e and jumps to target when it is when_true; what cond() and
  // branch_on() do, but an AND or OR whose later operands only read variables and cannot
  // fail is a chain of jumps (the operands after the one that decides are not evaluated,
  // which nothing can observe). The value: cond()'s, or BOOL and not constant for a chain.
  Val cond_branch(const Expr& e, Label target, bool when_true);
  // Whether e is such an AND or OR (with CompileOptions::condition_jumps); its terms in
  // evaluation order.
  bool chain_terms(const Expr& e, std::vector<const Expr*>* terms);
  // The type of e when evaluating it only reads variables and cannot fail (no call,
  // property, dereference, VAR_IN_OUT or division by a variable; each array index a
  // constant or the same access as one in `checked`, evaluated before; null `checked`:
  // any index, e may fail a bounds check), else null.
  const Type* plain_read_type(const Expr& e, const std::vector<const IndexExpr*>* checked, int depth);
  bool test_bits(uint32_t cmp_at, uint32_t type_idx, Label target, bool if_zero);
  // The instruction before the comparison at cmp_at (integer storage type_idx), when it
  // defines a temporary the comparison reads against a constant 0, in the same line and
  // block: its position (test_bits, single_bit).
  std::optional<uint32_t> zero_tested_temp(uint32_t cmp_at, uint32_t type_idx) const;
  // Rule 26: an IF on a test of bits whose arms assign one variable values that cannot
  // fail, compiled as a select (CompileOptions::if_selects; see stmt.cpp). False:
  // nothing emitted, the IF is compiled with jumps.
  bool select_if(const IfStmt& s);
  // Rule 27: the elements a condition just compiled as `a <cmp> b` loaded into temporaries
  // its one jump to `next` reads, or that `carried` held for it (see if_stmt).
  struct HeldElement {
    const Expr* e = nullptr;
    Slot slot;
    const Type* type = nullptr;
  };
  using Held = std::vector<HeldElement>;
  Held compared_elements(const Expr& cond, Label next, const Held& carried);
  // The comparison of one bit with 0 just emitted as a value, as one GETBIT (see stmt.cpp).
  std::optional<Slot> single_bit(bool* inverted);
  // Whether evaluating e only reads variables, calls standard functions that compute a
  // value from their inputs (shifts, MIN, MAX, LIMIT, MOVE, numeric conversions) and
  // cannot fail (the rules of plain_read_type).
  bool select_safe(const Expr& e, const std::vector<const IndexExpr*>* checked, int depth);
  // For the peepholes that read code just emitted: the slot kind of the operand at a code
  // word, and the value of a constant pool slot of `width` bytes there (nullopt: none).
  SK kind_at(uint32_t word) const;
  std::optional<uint64_t> const_at(uint32_t word, uint32_t width) const;
  std::pair<Arg, Arg> unemit(uint32_t at);
  Val bad() {
    Val v;
    v.ok = false;
    return v;
  }
  const Type* default_type(const ConstV& c) const;
  const Type* elem(TypeKind k) const { return tt_->elementary(k); }

  // ---- places, lvalues (places.cpp)
  // The variable e denotes; a REFERENCE TO is followed to its target.
  Place place(const Expr& e, bool for_write);
  // The same, but a REFERENCE TO is the reference itself (REF=, __ISVALIDREF, binding an input).
  Place place_ref(const Expr& e, bool for_write);
  // p, or the target of p when p is a REFERENCE TO (an unbound one traps at the access).
  Place implicit_deref(const Place& p, SourceLoc loc);
  // dst (a REFERENCE TO) REF= the variable e denotes; false after an error.
  bool bind_reference(const Place& dst, const Expr& e, SourceLoc loc);
  // The address of the variable e denotes, as a value of the reference type ref (REF=, and
  // an argument for a REFERENCE TO input); bad() after an error (not a variable, a
  // constant, another type).
  Val reference_to_var(const Type* ref, const Expr& e);
  static bool is_reference(const Type* t) { return t && t->kind == TypeKind::Ref && t->implicit_deref; }
  Place frame_place(Slot s, const Type* t) {
    Place p;
    p.k = Place::K::Frame;
    p.type = t;
    p.off = s.off;
    p.sk = s.kind;
    return p;
  }
  Place this_place(SourceLoc loc);
  Place program_place(PouInfo* p, SourceLoc loc);
  // PROGRAMs named from other POUs: their instance's address, and where first named.
  std::unordered_map<const PouInfo*, std::pair<uint32_t, SourceLoc>> program_addr_;
  Place symbol_place(const Symbol* s, SourceLoc loc);
  Place member_place(Place base, const Ident& member, SourceLoc loc);
  Place index_place(Place base, const IndexExpr& e, bool for_write);
  bool take_linear_index(Slot idx, Place* p);
  struct Displaced {
    const Expr* var;
    int64_t k;
  };
  std::optional<Displaced> displaced_index(const Expr& e);
  std::optional<Val> bit_of_shift(bool whole_condition);
  void note_shift(const Place& p);
  std::optional<Val> multiply_add(Slot a, Slot b, const Type* t);
  std::optional<Val> shifted_operand(Op bitop, Slot a, Slot b, const Type* t);
  Place deref_place(Val ptr, const Type* target, SourceLoc loc);
  Val load(const Place& p);
  std::optional<Slot> stored_element(Op load_op, const std::vector<Arg>& addr, const Place& p);
  Val load_once(const Place& p);
  Slot frame_idx(const Place& p);  // FrameIdx: the DINT index slot (made here when deferred)
  const Expr* cond_top_ = nullptr;  // the condition cond() is compiling
  bool defer_index_cvt_ = false;  // the next index_place may leave an INT variable index as it is  // load of a place used only here (may fold its index conversion)
  void store(const Place& p, Slot src);
  void assign(const Place& dst, const Val& v, SourceLoc loc);
  Slot addr_of(const Place& p, SourceLoc loc);
  const Symbol* lookup(const std::string& canon_name) const;

  // ---- calls of user code (calls.cpp)
  Val call(const CallExpr& c, bool as_statement);
  // A call with EN/ENO (a statement, or the value of an assignment): IF EN THEN ... END_IF
  // and ENO := EN. False when the call has no EN/ENO of the implicit kind.
  bool enabled_call(const CallExpr& c, const AssignStmt* assignment);
  // A call with EN inside an expression: its value when EN holds, else the result type's
  // initial value.
  Val enabled_value(const CallExpr& c);
  bool implicit_enable(const CallExpr& c, const CallArg** en, const CallArg** eno);
  bool enable_flag(const CallExpr& c, const CallArg* en, Val* enabled);
  void without_enable(const CallExpr& c, const CallArg* en, const CallArg* eno, const std::function<void()>& body);
  void capture_eno(const CallExpr& c, const Val& enabled);
  const PouInfo* callee_pou(const Expr& callee);
  bool may_call(const Expr& e) const;
  const Type* field_path_type(const Expr& e) const;
  // Bounds-check elimination: the values a FOR loop's counter takes inside its body, when
  // the body can change it by no means (stmt.cpp). index_place asks proven_range.
  struct CounterRange {
    Slot slot;
    int64_t lo = 0, hi = 0;
    std::string name;  // canonical
  };
  std::vector<CounterRange> counters_;
  const CounterRange* proven_range(Slot s) const;
  bool keeps_counter(const StmtList& body, const std::string& counter) const;
  // Rows (stmt.cpp): in a FOR loop over a proven counter, a rank-2 access indexed by the
  // counter and by a counter of an enclosing loop, or a rank-1 access whose index is
  // linear in the two and proven inside the array (`a[i * 8 + k]`), reads the offset of
  // its row (the part the loop does not change) from a slot ROWS sets on the loop's entry
  // (LDXR/STXR).
  struct RowOffset {
    int64_t k = 0;   // offset (of the field, in its element) when both counters are 0
    Slot v;          // the outer counter
    int64_t m = 0;   // its stride
  };
  struct RowLoop {
    Slot counter;
    size_t depth = 0;           // the loop's entry in counters_
    uint32_t at = 0;            // code index of its ROWS
    std::vector<Slot> slots;    // reserved before the body
    std::vector<RowOffset> used;
  };
  std::vector<RowLoop> row_loops_;
  // Set while the statement being compiled is the last of a loop body, or the last of an
  // arm of an IF or CASE that is: where an arm would jump to the statement's end (the
  // loop's bottom), this emits the bottom itself instead (the back edge, then a jump to
  // the loop's exit), which spares the jump on every pass through the arm. Null elsewhere.
  const std::function<void()>* loop_tail_ = nullptr;
  void arm_end(Label end);
  void bottom_test(const Expr& c, Label body, bool again);
  // Rule 28 (see while_stmt): the frame offset of a WHILE condition that is a BOOL
  // variable of the frame; what an instruction about to be emitted may write of the
  // watched ones; their states, to follow the arms of an IF or CASE; the jump back to a
  // loop's body from an arm that left its flag TRUE.
  std::optional<uint32_t> loop_flag(const Expr& cond);
  void watch_writes(Op op, const std::vector<Arg>& args);
  std::vector<bool> watch_state() const;
  void set_watch_state(const std::vector<bool>& s);
  static void merge_watch_state(std::vector<bool>* into, const std::vector<bool>& s);
  void jump_back(Label body);
  // What row_candidates looks for: accesses by `counter` and one of `outer` (the counters
  // of the proven loops around it), none by `inner` (counters of loops nested in it, whose
  // accesses those loops keep rows for).
  struct RowScan {
    std::string counter;
    std::vector<std::string> outer, inner;
  };
  static size_t row_candidates(const StmtList& body, RowScan& scan);
  struct RowAccess {
    Slot row, counter;
    int64_t m = 0;
  };
  // How a proven rank-2 access reaches its element through a loop's row slot, if one can.
  std::optional<RowAccess> row_for(const Place& p);
  bool linear_in_range(const Place& p, int64_t lo, int64_t hi) const;
  Val call_function(PouInfo* f, const CallExpr& c);
  // The frame set-up of a FUNCTION call: the template's bytes this call needs (calls.cpp).
  void init_function_frame(PouInfo* f, Slot frame, const std::vector<const Symbol*>& stored);
  const std::vector<std::pair<uint32_t, uint32_t>>& written_first(PouInfo* f);
  std::map<const PouInfo*, std::vector<std::pair<uint32_t, uint32_t>>> written_first_;
  Val call_fb(const Place& inst, PouInfo* fb, const CallExpr& c, PouInfo* body_of = nullptr);
  Val call_method(const CallExpr& c, PouInfo* m, const Place* inst, Slot this_ptr, bool virt);
  Val query_interface(const CallExpr& c, bool pointer);  // __QUERYINTERFACE, __QUERYPOINTER
  // A value the compiler passes for a parameter (FB_init's bInitRetains and bInCopyCode):
  // no argument may name it, and positional arguments start after it.
  struct FixedArg {
    Symbol* param;
    Val v;
  };
  Val call_method(const std::vector<CallArg>& args, SourceLoc loc, PouInfo* m, Slot this_ptr, bool virt,
                  const std::vector<FixedArg>& fixed);
  void store_outputs(const std::vector<std::pair<Symbol*, const CallArg*>>& outs, const std::vector<Val>& out_vals);
  // ---- FB_init and FB_exit (lifecycle.cpp)
  // Whether an instance of t (an FB, or an array or structure holding FBs) has FB_init
  // (exit: FB_exit) to run, itself or in what it holds. Only under --dialect codesys.
  bool lifecycle_needed(const Type* t, bool exit);
  // Whether the instances p holds (its own variables and its base FB's) need it.
  bool members_need(PouInfo* p, bool exit);
  // ---- ARRAY[*] (places.cpp): a VAR_IN_OUT slot holds the address, then for an open
  // array LOWER and UPPER (DINT) of each dimension.
  static uint32_t inout_slot_size(const Type* t) { return t && t->open ? 4 + 8 * static_cast<uint32_t>(t->dims.size()) : 4; }
  // The DINT slot of dimension `dim`'s bound in an open array's descriptor (the place of
  // the in-out itself); false, after an error, where the place has no descriptor.
  bool open_bound(const Place& arr, size_t dim, bool upper, SourceLoc loc, Place* out);
  // Binds a VAR_IN_OUT's slot (the place of its address) to an argument: the address,
  // and for ARRAY[*] the argument's bounds.
  bool bind_inout(const Place& slot, const Symbol* param, const Expr& arg);
  // The same in two steps (a METHOD's arguments are evaluated before its frame exists).
  bool stage_inout(const Symbol* param, const Expr& arg, Slot* addr, std::vector<Slot>* bounds);
  void store_inout(const Place& slot, Slot addr, const std::vector<Slot>& bounds);
  Place open_index_place(const Place& base, const IndexExpr& e);
  // CODESYS computes an initial value that is not a constant expression (other variables,
  // ADR(x)) when the variable is initialised, in declaration order: an FB's or PROGRAM's
  // in its init entry (before the FB_init of what it holds), a FUNCTION's or METHOD's on
  // every call, a global's in the application's init routine. Warning ST407 names each.
  bool runtime_init(const Symbol* v, const VarDecl* d, uint32_t file, bool report, const PouInfo* pou);
  bool reads_variables(const Expr& e, const PouInfo* pou);  // pou: null for a global's
  const std::vector<const Symbol*>& runtime_inits(PouInfo* p);
  void emit_runtime_inits(const std::vector<const Symbol*>& vars);
  // Calls the init or exit entry of pou on the instance at `at` (a frame or global place).
  void call_entry(const Place& at, PouInfo* pou, EntryKind which);
  // FB_init (FB_exit) of the instance at `at` of type t and of all it holds; d: its
  // declaration, whose arguments FB_init gets.
  void instance_lifecycle(const Place& at, const Type* t, const VarDecl* d, bool exit, SourceLoc loc);
  // A declaration `fb : FB_X(args)`: errors when args are not allowed there (allowed:
  // what the caller of resolve_type said in init_args_ok_), t is no FB or has no FB_init.
  void check_init_args(const TypeSpec& spec, const Type* t, bool allowed);
  bool init_args_ok_ = false;
  // The BOOL the restart sets for bInitRetains.
  uint32_t init_flag_addr();
  // p's init and exit entries, after its body; their indices in *entries.
  void lifecycle_entries(PouInfo* p, std::vector<uint32_t>* entries, size_t* init_at, size_t* exit_at);
  // The application's routine over program instances and globals.
  void compile_lifecycle();
  std::unordered_map<const Type*, bool> lifecycle_memo_[2];

  // ---- TcUnit and FB_ASSERT (tcunit.cpp, with stdlib/tcunit.cpp)
  // A method of the library's FB_TestSuite or FB_ASSERT (they take the call's location).
  static bool is_tcunit_method(const PouInfo* m);
  // The call's location as the LINT the library's hidden input _tcuAt takes.
  static int64_t pack_location(SourceLoc loc);
  // AssertEquals (ANY) becomes AssertEquals_<type of Actual>; AssertArray*Equals_<T>
  // compares the arrays (native ARRAY_DIFF). The arguments are evaluated here and their
  // values left in preset_. Other methods come back unchanged; nullptr after an error.
  PouInfo* tcunit_lowering(const CallExpr& c, PouInfo* m);
  PouInfo* memory_lowering(const CallExpr& c, PouInfo* m, const CallArg* e, const CallArg* a, const CallArg* size,
                           const std::vector<const CallArg*>& in_order);
  // Values already computed for these expressions: expr() takes them (once) instead of
  // compiling the expression again.
  std::unordered_map<const Expr*, Val> preset_;
  Val property_get(const Place& inst, PouInfo* getter, Slot this_ptr, SourceLoc loc);
  void property_set(PouInfo* setter, Slot this_ptr, const Val& v, SourceLoc loc);
  const Type* call_expected_ = nullptr;  // the type the context expects of the call being compiled

  // ---- standard functions, conversions, test built-ins (builtins.cpp); signatures in sema/stdfuncs
  // A call of the standard function `name` (canonical), or nullopt when there is none.
  std::optional<Val> builtin(const std::string& name, const CallExpr& c);
  std::optional<Val> conversion(const std::string& name, const ConversionName& conv, const CallExpr& c);
  std::vector<const Expr*> positional(const CallExpr& c, size_t min, size_t max, std::string_view name);
  std::vector<const Expr*> positional(const CallExpr& c, const StdFunc& f);  // f's argument counts
  Val native(Native n, const Type* result, std::initializer_list<Slot> args, uint32_t cap = 0);
  Val to_string_text(Slot s, const Type* from);
  Val native_list(Native n, const Type* result, const std::vector<Slot>& args, uint32_t cap = 0);
  // One emitter per StdFamily (SEL and MUX share one).
  std::optional<Val> emit_math(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_expt(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_abs(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_extremum(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_select(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_operator(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_concat_date_tod(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_move(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_shift(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_string(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_concat(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_replace(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_address_of(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_sizeof(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_bound(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_is_valid_ref(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_now(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_temporal(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_advance_time(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_assert(const StdFunc& f, const CallExpr& c);
  std::optional<Val> emit_system(const StdFunc& f, const CallExpr& c);

  // ---- side tables: the compiler's knowledge of the syntax tree, kept out of the program
  PouSource& src(const PouInfo* p) { return pou_src_[p]; }
  const Pou* decl_of(const PouInfo* p) const {
    auto it = pou_src_.find(p);
    return it == pou_src_.end() ? nullptr : it->second.decl;
  }
  bool is_late(const PouInfo* p) const {
    auto it = pou_src_.find(p);
    return it != pou_src_.end() && it->second.late;
  }
  SymbolSource& sym_src(const Symbol* s) { return sym_src_[s]; }
  const VarDecl* decl_of(const Symbol* s) const {
    auto it = sym_src_.find(s);
    return it == sym_src_.end() ? nullptr : it->second.decl;
  }
  std::unordered_map<const PouInfo*, PouSource> pou_src_;
  std::unordered_map<const Symbol*, SymbolSource> sym_src_;

  // ---- state
  const SourceManager& sm_;
  DiagEngine& diags_;
  CompileOptions opt_;
  std::unique_ptr<Application> owned_;  // the program being built by run()
  Application* app_ = nullptr;          // that one, or the one link() adds to
  TypeTable* tt_ = nullptr;
  uint32_t file_ = 0;  // file of the body being compiled (for diagnostics)

  struct TypeEntry {
    const TypeDecl* decl = nullptr;
    uint32_t file = 0;
    const Type* type = nullptr;
    bool resolving = false;
  };
  std::unordered_map<std::string, TypeEntry> types_;
  std::unordered_map<std::string, PouInfo*> pous_;
  std::unordered_map<std::string, Symbol*> globals_;
  std::unordered_map<std::string, std::vector<const Type*>> enum_values_;
  std::unordered_map<std::string, uint32_t> selectors_;
  uint32_t next_selector_ = 0;
  std::vector<PouInfo*> all_methods_;
  std::vector<EntryFix> entry_fix_;  // absolute code index -> POU entry
  mutable std::unordered_map<std::string, std::unique_ptr<Symbol>> enum_syms_;  // made on first lookup
  const Type* null_type_ = nullptr;
  const PouInfo* decl_pou_ = nullptr;  // POU whose declarations are being laid out
  std::unordered_map<std::string, std::pair<const VarDecl*, uint32_t>> global_consts_;
  std::unordered_map<const PouInfo*, std::vector<const Symbol*>> runtime_inits_;
  std::vector<const Symbol*> global_runtime_inits_;  // declaration order
  bool open_array_ok_ = false;  // resolving a VAR_IN_OUT's type: ARRAY[*] allowed
  std::vector<std::unique_ptr<Body>> bodies_;  // finished bodies waiting for final layout
  std::vector<std::pair<Body*, std::vector<uint32_t>*>> pending_;
  Body* b_ = nullptr;  // body being compiled
  std::vector<PouInfo*> compiling_;
  std::vector<std::unique_ptr<std::vector<uint32_t>>> entry_lists_;
  std::vector<std::unique_ptr<PouInfo>> test_pous_;
  std::vector<std::unique_ptr<Pou>> synthetic_;
  uint32_t next_type_id_ = 1;
  bool instance_paths_ = false;
  uint32_t const_depth_ = 0;  // const_eval() recursion (constants defined through constants)
  bool const_depth_reported_ = false;  // each depth error once per compilation: every
                                      // declaration along a long chain would hit it again
  static constexpr uint32_t kMaxConstDepth = 512;
  uint32_t const_depth_hits_ = 0;
  std::unordered_set<const Expr*> too_deep_consts_;  // constant initializers that hit kMaxConstDepth
  uint32_t type_depth_ = 0;  // resolve_type() recursion (named types holding named types)
  bool type_depth_reported_ = false;
  static constexpr uint32_t kMaxTypeDepth = 256;
  std::vector<const Type*> laying_out_;  // STRUCTs whose members are being laid out
  bool pou_depth_reported_ = false;
  static constexpr size_t kMaxPouDepth = 128;  // while compiling late units: Main.x names an instance variable
};

std::optional<ConstV> fold_binary(BinaryOp op, const ConstV& l, const ConstV& r, std::string* err);

inline uint32_t align_up(uint32_t v, uint32_t a) { return a <= 1 ? v : (v + a - 1) / a * a; }

// A type's name in diagnostics (expr.cpp, places.cpp); null is an untyped literal.
inline std::string tname(const Type* t) { return t ? t->name : "an untyped literal"; }

// Opcode families are laid out per storage type (see opcodes.def); these pick the member.
uint32_t storage_index(Storage s);  // I8..F64 -> 0..9
Op num_op(Op i8_variant, Storage s);
Op int_op(Op i8_variant, Storage s);
Op cvt_op(Storage from, Storage to);
Op mov_op(uint32_t size);  // 1, 2, 4, 8; else MOVN
Op sel_op(uint32_t size);  // SEL1, SEL2, SEL4, SEL8 (size 1, 2, 4, 8)
ValueKind value_kind(const Type* t);
// The copy of a string of type t into a string of its kind: SCPY bytes, WSCPY code units.
inline Op string_copy_op(const Type* t) { return t->kind == TypeKind::WString ? Op::WSCPY : Op::SCPY; }

}  // namespace plcfi::st::detail

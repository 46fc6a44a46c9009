// The compiled application: bytecode, its line table, the cold-start memory image, the
// layout of every POU and variable, tasks and program instances. It stands alone: nothing
// in it points into the syntax tree or holds the compiler's bookkeeping, so it outlives
// the sources it came from. Immutable once built (a second compilation unit may be linked
// onto it, see codegen/compiler.hpp); any number of Machines can run it.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sema/types.hpp"
#include "syntax/kinds.hpp"
#include "syntax/source.hpp"

namespace plcfi::st {

enum class Op : uint32_t {
#define OP(name, nargs, rtl) name,
#include "opcodes.def"
#undef OP
  Count_
};

struct OpInfo {
  const char* name;
  uint8_t nargs;
  const char* rtl;
};
const OpInfo& op_info(Op op);
// Operand words that follow the opcode (JTAB adds its table).
uint32_t op_length(const uint32_t* code);
// A conditional jump whose first operand is its target: JMPF, JMPT and the
// compare-and-jump and bit-test families (JLT_, JGE_, JEQ_, JNE_, JNLT_, JNGE_, JTZ_, JTNZ_).
bool is_conditional_jump(Op op);

// Where a variable lives.
enum class Where : uint8_t {
  Frame,    // base-relative: POU instance vars, function/method frame vars
  Abs,      // absolute: globals, located variables on byte/word addresses
  AbsBit,   // absolute bit: located BOOL on %IX/%QX/%MX
  InOut,    // base-relative slot holding the address (VAR_IN_OUT)
  This,     // instance member seen from a method: THIS pointer slot + offset
};

enum class SymKind : uint8_t { Var, EnumValue, Pou, TypeName };

struct Symbol {
  std::string name;
  SymKind kind = SymKind::Var;
  const Type* type = nullptr;
  Where where = Where::Frame;
  uint32_t offset = 0;  // frame offset, absolute address, or field offset (This)
  uint8_t bit = 0;      // AbsBit
  VarSection section = VarSection::Var;
  bool constant = false;
  bool retain = false;
  SourceLoc loc;
  int64_t enum_value = 0;      // EnumValue
  PouInfo* pou = nullptr;      // Pou
  std::vector<uint8_t> init;   // METHOD input: the value an omitted argument gets
};

// A VAR_INPUT, VAR_IN_OUT or VAR_OUTPUT: its value comes from (or goes to) each call.
inline bool is_parameter(const Symbol& s) {
  return s.section == VarSection::Input || s.section == VarSection::InOut || s.section == VarSection::Output;
}

// Layout and code of one POU (FUNCTION, FUNCTION_BLOCK, PROGRAM, METHOD, INTERFACE).
// A monitor PROGRAM's state shift (previous := current of each temporal operator, at the
// first evaluation of a new __state): frame offsets, so a caller may do it natively
// before the call and spare the VM the work. Same effect as the program's own shift.
struct StateShift {
  bool present = false;
  uint32_t seen = 0;     // LINT: the last state evaluated (-1: none yet)
  int32_t started = -1;  // BOOL: a state has been committed (-1: no temporal operator)
  std::vector<std::array<uint32_t, 3>> moves;  // {current, previous, size}
};

struct PouInfo {
  PouKind kind = PouKind::Program;
  std::string name;
  SourceLoc loc;       // of the declaration
  uint32_t file = 0;
  Type* type = nullptr;           // FB/PROGRAM/INTERFACE: instance type
  const Type* result = nullptr;   // FUNCTION/METHOD: result type (Void when none)
  PouInfo* base = nullptr;        // EXTENDS
  PouInfo* owner = nullptr;       // METHOD: the FB or interface it belongs to
  std::vector<PouInfo*> interfaces;
  std::vector<std::unique_ptr<Symbol>> vars;   // declaration order; parameters first
  std::vector<Symbol*> inputs, outputs, inouts;
  // This POU's own VAR_INPUT, VAR_IN_OUT and VAR_OUTPUT in declaration order, whatever the
  // sections' order: the order a non-formal call binds its arguments in (IEC 61131-3
  // 6.6.1.4.2, as CODESYS and TwinCAT do). An FB's inherited parameters come before these.
  std::vector<Symbol*> positional;
  std::vector<std::unique_ptr<PouInfo>> methods;
  std::string property;     // property getter/setter: the property's name
  bool is_setter = false;
  bool has_body = true;     // METHOD: false when abstract or declared by an interface
  Access access = Access::Public;  // METHOD
  bool is_abstract = false;        // FUNCTION_BLOCK
  uint32_t type_id = 0;     // FB/PROGRAM: index into the dispatch table
  uint32_t frame_size = 0;  // instance size (FB/PROGRAM) or frame size (FUNCTION/METHOD)
  uint32_t result_offset = 0;
  uint32_t init_from = 0, init_to = 0;  // FUNCTION/METHOD: frame part initialized on entry
  uint32_t tmpl_from = 0, tmpl_to = 0;  // frame part (re)initialized per call, from a template
  uint32_t template_addr = 0;           // absolute address of that template
  uint32_t entry = 0;       // code index of the body
  uint32_t code_begin = 0, code_end = 0;  // the body's range in the code
  // The frame's constant pool [const_from, const_from + consts.size()): read-only slots
  // holding literals (the native tier folds them into its code).
  uint32_t const_from = 0;
  std::vector<uint8_t> consts;
  uint32_t selector = 0;    // METHOD: global selector for dynamic dispatch
  uint32_t mock_addr = 0;   // FUNCTION in test builds: {flag, pad, value} block
  bool compiled = false;    // has code (entry, frame layout)
  StateShift shift;         // late PROGRAMs with __state
  bool is_stdlib = false;
  bool is_test = false;     // a TEST of a test file: its entries are in Application::tests
  // FB/PROGRAM (CODESYS): entries after the body, on an instance as base, that run FB_init
  // (FB_exit) of the instances it holds (the base FB's first), not the instance's own.
  bool has_init = false, has_exit = false;
  uint32_t init_entry = 0, exit_entry = 0;

  Symbol* find_var(std::string_view name) const;
  PouInfo* find_method(std::string_view name) const;  // searches bases too
};

inline constexpr uint32_t kNoBranch = UINT32_MAX;

// One arm of a decision. An IF statement's arms (IF, ELSIF..., ELSE) and a CASE
// statement's (one per label list, ELSE) share `decision`; a loop is a decision of its own
// with one arm, its body. An IF or CASE without ELSE has no id for "no arm taken", a
// FOR/WHILE none for "body skipped".
struct BranchPoint {
  SourceLoc loc;
  std::string kind;  // IF, ELSIF, ELSE, CASE, FOR, WHILE, REPEAT
  std::string pou;
  uint32_t decision = kNoBranch;  // branch id of the statement's first arm
  SourceLoc stmt;                 // the statement (IF, CASE, loop keyword)
  SourceLoc body;                 // the arm's first statement; invalid when the arm is empty
  uint32_t parent = kNoBranch;    // the arm whose body holds the statement; none at POU level
};

struct ProgramInstance {
  std::string name;
  PouInfo* pou = nullptr;
  uint32_t addr = 0;
  std::string task;  // empty without a configuration
};

struct TaskInfo {
  std::string name;
  int64_t interval_ns = 0;
  int64_t priority = 0;
  SourceLoc loc;
  std::vector<size_t> programs;  // indices into Application::programs
};

struct TestEntry {
  std::string name;
  SourceLoc loc;
  uint32_t instance_addr = 0;
  uint32_t setup_entry = 0, body_entry = 0, teardown_entry = 0;
  bool has_setup = false, has_teardown = false;
  // FB_init (FB_exit) of the instances the test's frame holds (CODESYS): run by the test
  // runner after the restart (after TEARDOWN).
  bool has_init = false, has_exit = false;
  uint32_t init_entry = 0, exit_entry = 0;
};

struct GlobalVar {
  std::string scope;  // GVL file stem or configuration/resource name
  Symbol* sym = nullptr;
};

struct ImageArea {
  char area;
  uint32_t addr;
  uint32_t size;
  uint32_t used = 0;  // bytes from the start that located variables or direct addresses touch
};

class Application {
 public:
  std::vector<uint32_t> code;
  std::vector<std::pair<uint32_t, SourceLoc>> lines;  // (first pc, location), sorted by pc
  // (pc, K) of an element access whose index was v + K for a DINT variable v: the
  // instruction checks v against its bounds minus K. A trap's message adds K back, to
  // name the index and bounds the source has. Sorted by pc.
  std::vector<std::pair<uint32_t, int32_t>> index_shifts;
  std::vector<uint8_t> init_image;                     // memory at cold start
  std::vector<std::pair<uint32_t, uint32_t>> retain_ranges;  // (addr, size)
  std::vector<BranchPoint> branches;                   // index = branch id
  std::vector<uint32_t> vtable;                        // [selector * n_types + type_id] -> entry
  uint32_t n_types = 0;
  std::vector<ProgramInstance> programs;
  std::vector<ProgramInstance> observers;  // instances of late units' PROGRAMs (monitors)
  std::vector<TaskInfo> tasks;
  std::vector<TestEntry> tests;
  std::vector<GlobalVar> globals;
  std::vector<std::unique_ptr<Symbol>> global_syms;
  std::vector<std::unique_ptr<PouInfo>> pous;
  std::vector<std::string> file_paths;  // file index -> path
  // file index -> a library's (the built-in ones or --library): no coverage or listing
  std::vector<bool> library_files;
  uint32_t mstack_addr = 0, mstack_size = 0;  // method frames (dynamic)
  ImageArea image_i{'I', 0, 0}, image_q{'Q', 0, 0}, image_m{'M', 0, 0};
  std::unique_ptr<TypeTable> types;
  std::vector<std::pair<std::string, const Type*>> type_names;  // declared TYPEs, as spelt
  bool has_configuration = false;
  // Some IF, WHILE or REPEAT condition is a chain of conditional jumps, not one jump on its
  // value (CompileOptions::condition_jumps): mutation analysis needs the one jump.
  bool condition_chains = false;
  // Some assignment is compiled more than once, copied into the arms of an IF or CASE
  // before a loop's bottom (CompileOptions::loop_tails): mutation analysis needs one store.
  bool copied_statements = false;
  // Some IF is a select instruction, not a jump (CompileOptions::if_selects): mutation
  // analysis needs the jump.
  bool if_selects = false;
  // Some ELSIF condition reads an element the condition before it loaded
  // (CompileOptions::elsif_reuse): mutation analysis negates conditions one at a time.
  bool elsif_reuse = false;
  // Some IF that ends a loop body has an arm placed after the others, its condition
  // jumping there when it holds (CompileOptions::cold_arms): mutation analysis negates
  // each IF's jump to its next arm.
  bool cold_arms = false;
  // FB_init/FB_exit (CODESYS): a routine over every program instance and global instance,
  // run by Machine::cold_restart/warm_restart on the frame at lifecycle_addr.
  // The byte at init_flag_addr is what FB_init gets as bInitRetains.
  bool has_init = false, has_exit = false;
  uint32_t init_entry = 0, exit_entry = 0, lifecycle_addr = 0, init_flag_addr = 0;

  SourceLoc loc_of(uint32_t pc) const;
  int32_t index_shift(uint32_t pc) const;  // K at pc (index_shifts), 0 when none
  // "index I outside L..H" for the access at pc that found the index value v (as the
  // instruction reads it) outside lo .. lo + count - 1 (as its operands say).
  std::string index_message(uint32_t pc, int64_t v, int32_t lo, uint32_t count) const;
  std::string where(SourceLoc loc) const;  // "file:line:col"
  bool is_library_file(uint32_t file) const { return file < library_files.size() && library_files[file]; }
  PouInfo* find_pou(std::string_view name) const;
  const ImageArea* image(char area) const;
};

}  // namespace plcfi::st

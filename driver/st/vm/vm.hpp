// The bytecode virtual machine: runs entries of an Application over flat memory.
// Contract: single-threaded; call() never allocates on the heap unless a trap or a failed
// assertion has to be described; every runtime error becomes a Trap with the ST location.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "program.hpp"

namespace plcfi::st {

enum class TrapKind : uint8_t {
  None,
  DivisionByZero,
  IndexOutOfRange,
  RangeError,       // subrange violation
  NullReference,
  Watchdog,         // instruction budget of the scan exhausted
  CallDepth,
  AssertFailed,     // test files
  NotImplemented,   // abstract method or interface without an implementation
  BadAddress,       // an address outside VM memory (corrupt reference)
};
const char* trap_name(TrapKind k);

struct Trap {
  TrapKind kind = TrapKind::None;
  uint32_t pc = 0;
  SourceLoc loc;
  std::string message;  // the what, without the location
};

class Machine;
class NativeCode;
// Natives implement the standard functions the compiler does not open-code
// (string functions, transcendental math, conversions to and from text).
using NativeFn = void (*)(Machine& m, uint32_t cap, uint8_t* a, uint8_t* b, uint8_t* c, uint8_t* d);
// Native ARRAY_DIFF (TcUnit's AssertArrayEquals_<T>): a := '' when the arrays are equal,
// else the first difference (sizes, or an element) as TcUnit words it. b: the run-time
// block {UDINT address of the expected array, UDINT of the actual one, LREAL delta};
// c: the constant ArrayDiffShape.
struct ArrayDiffShape {
  uint32_t count_e, count_a;  // elements
  uint32_t elem_size, elem_size_a;  // bytes per element, expected and actual
  uint32_t kind;              // ValueKind of an element
  uint32_t ndims;             // 1..3: the expected array's dimensions, to name an element
  int32_t lo[3];
  uint32_t extent[3];
  // 1: TcUnit's AssertArray*Equals (stdlib/tcunit_abi.hpp: a record of the verdict, EXP,
  // ACT and the key; indices in each array's own bounds); 0: plcfi's words.
  uint32_t style;
  uint32_t hex_digits;        // style 1: a bit string, shown as 0x and this many digits
  int32_t lo_a[3];            // style 1: the actual array's bounds
  uint32_t extent_a[3];
};
void array_difference(Machine& m, uint32_t cap, uint8_t* a, uint8_t* b, uint8_t* c, uint8_t* d);
NativeFn native(uint32_t id);
const char* native_name(uint32_t id);

// Value kinds named in ASSERT instructions so failures print readable values.
// UTime: CODESYS's unsigned LTIME.
enum class ValueKind : uint8_t { Bool, I8, I16, I32, I64, U8, U16, U32, U64, F32, F64, Time, Date, Tod, Dt, String, Enum, Ref, UTime, WString };
enum class AssertKind : uint8_t { Eq, Neq, True, False, Gt, Lt, Ge, Le, Near, Called, CallCount };

class Machine;

// What a host running a built-in library's runner (TcUnit) answers the library's calls
// with (native TCUNIT); installed with Machine::set_hook.
class LibraryHook {
 public:
  virtual ~LibraryHook() = default;
  // A TcUnit event (stdlib/tcunit_abi.hpp) of the suite instance at address `suite`.
  virtual int32_t tcunit(Machine& m, int32_t event, uint32_t suite) = 0;
};

class Machine {
 public:
  explicit Machine(const Application& app);

  // Memory := the application's cold-start image (all variables to initial values); then,
  // in a CODESYS program, FB_init of every instance (bInitRetains = TRUE). An application
  // that ran before gets FB_exit of every instance first. False when one of them trapped
  // (see trap()): the memory is reset all the same.
  bool cold_restart();
  // Like cold_restart, but RETAIN variables keep their values (bInitRetains = FALSE).
  bool warm_restart();

  // Runs code at `entry` with base = absolute address `base_addr` until it returns.
  // Returns false on a trap (see trap()); memory stays consistent and the machine usable.
  bool call(uint32_t entry, uint32_t base_addr);
  const Trap& trap() const { return trap_; }

  int64_t now() const { return now_ns_; }
  void set_now(int64_t ns) { now_ns_ = ns; }
  // The 1-based index of the task whose programs run (GETCURTASKINDEX); the runtime sets
  // it before each task, and it stays 1 where nothing sets it (tests, a single program).
  uint8_t task_index() const { return task_index_; }
  void set_task_index(uint8_t index) { task_index_ = index; }

  // The messages the program logged (ADSLOGSTR and the like), in order, until the host
  // takes them: level is "hint", "warn" or "error". Kept here, not printed, so a campaign
  // or a test can decide where they go; `plcfi run` prints them to stderr.
  struct LogEntry {
    std::string level;
    std::string text;
  };
  std::vector<LogEntry>& log() { return log_; }

  // The runner of a built-in library, if one runs (TcUnit's); not owned.
  LibraryHook* hook() const { return hook_; }
  void set_hook(LibraryHook* h) { hook_ = h; }

  // Called by a native helper that found a runtime error (MEMCPY outside the memory): the
  // NATIVE instruction that called it then traps with this kind and message, at its own
  // source location. The helper returns normally and must leave memory untouched.
  void native_trap(TrapKind k, std::string msg) {
    native_trap_kind_ = k;
    native_trap_msg_ = std::move(msg);
  }
  // Backward jumps and loop iterations allowed per call() before a Watchdog trap.
  void set_budget(uint64_t budget) { budget_limit_ = budget; }

  // What a machine needs to go on from where it was: memory, cumulative coverage, the
  // trap that stopped it, whether it has started (an FMU's saved state).
  struct State {
    std::vector<uint8_t> mem;
    std::vector<uint64_t> covered;
    Trap trap;
    bool started = false;
  };
  State save_state() const { return State{mem_, covered_, trap_, started_}; }
  // The state must come from a machine of the same application.
  void restore_state(const State& s) {
    mem_ = s.mem;
    covered_ = s.covered;
    trap_ = s.trap;
    started_ = s.started;
  }

  uint8_t* mem() { return mem_.data(); }
  const uint8_t* mem() const { return mem_.data(); }
  size_t mem_size() const { return mem_.size(); }
  const Application& app() const { return *app_; }

  // Branch coverage: bit i set when branch id i was taken since the last clear.
  const std::vector<uint64_t>& taken() const { return taken_; }
  void clear_taken();
  // Cumulative coverage since construction (merged by merge_coverage()).
  const std::vector<uint64_t>& covered() const { return covered_; }
  void merge_coverage();
  // Hit counts for coverage exports (lcov, Cobertura): while on, merge_coverage() also adds
  // one to hits()[i] for each branch id i taken since the last clear, so a count says in
  // how many scans (test executions, cycles) the branch was taken, not how often. Off by
  // default: merge_coverage() then costs what it did. Restarts keep the counts.
  void set_count_hits(bool on);
  const std::vector<uint64_t>& hits() const { return hits_; }

  // Assertion bookkeeping for the test runner.
  const std::string& assert_message() const { return assert_message_; }

  // The superinstructions the interpreter runs (see run()): (pc of the first instruction,
  // the instructions it runs, as "MADD_I32+MODK_I32"). Empty until the first call.
  std::vector<std::pair<uint32_t, std::string>> superinstructions() const;

  // The native tier (native/native.hpp): entries it has run natively, the rest in the
  // interpreter. nullptr: interpreter only. The code must outlive the machine's use of it.
  void set_native(const NativeCode* code) { native_ = code; }
  const NativeCode* native_code() const { return native_; }

 private:
  friend struct VmAccess;
  friend struct NativeBridge;
  bool restart(bool warm);
  bool fail(TrapKind k, const uint32_t* pc, std::string msg);
  // The trap a native helper asked for (native_trap), at the NATIVE instruction pc.
  bool fail_native(const uint32_t* pc);
  // Interprets from pc until the matching RET. mtop: the method stack top; budget: the
  // backward jumps left (read and, on a normal return, written back).
  bool run(uint32_t entry, uint8_t* base, uint32_t mtop, int64_t* budget);
  // run() itself, in two builds: with Coverage, a jump into an arm marks the arm's COV as
  // it passes it; without, for code that holds no COV (compiled without coverage), the
  // jumps do not look for one.
  template <bool Coverage>
  bool run_impl(uint32_t entry, uint8_t* base, uint32_t mtop, int64_t* budget);
  // Builds exec_ from the application's code (see run()): each opcode word becomes its
  // handler's offset, or a superinstruction's when the instruction and the next (and the
  // one after, for a triple) fit one of `rules` (operand: 0, or the word of the second
  // instruction that must name the slot the first writes: 2 = its operand b, 3 = c).
  // A rule that yields applies only where the second instruction heads no rule that does
  // not yield (a pair of its own is worth more than being the tail of this one).
  struct FusedRule {
    Op head, tail, third;  // third: Op::Count_ for a pair
    uint32_t operand, operand2;  // operand2: the same for the third and the second
    int32_t offset;
    bool yields = false;
    // Only where the instruction after the pair names no word equal to the head's
    // destination: the head's store into its temporary is then left out (a temporary is
    // scratch within its statement, see scratch_ranges; the pair ends an assignment, so
    // that test is a conservative one for any later reader).
    bool dead_head = false;
  };
  void thread_code(const int32_t* offsets, int32_t invalid, const FusedRule* rules, size_t n_rules,
                   int32_t reduction);
  // The first of `rules` that fits the instruction at `at` and those after it, those that
  // yield only if `yielding`; null when none does. heads[op]: some rule starts with op.
  static const FusedRule* first_fit(const std::vector<uint32_t>& code, const std::vector<uint8_t>& heads,
                                    const FusedRule* rules, size_t n_rules, uint32_t at, bool yielding);
  // A reduction loop (see find_reductions): a FOR loop whose body accumulates one or two
  // elements indexed by its counter, `s := s + a[i]` or `s := s + a[i] * b[i]` (DINT or
  // REAL), run as a whole by one handler. Decoded from the code when it is threaded.
 public:
  struct Reduction {
    enum Kind : uint8_t { SumI32, MacI32, SumF32, MacF32 };
    struct Load {
      uint32_t pc, dst;
      uint32_t at;       // frame offset of element `lo` (a field's offset included)
      uint32_t row;      // the slot holding the row's frame offset (LDXR), else kNoRow
      int32_t lo;        // the index of the first element
      uint64_t n;        // elements; UINT64_MAX when the compiler proved the index in range
      int64_t stride;
    };
    static constexpr uint32_t kNoRow = UINT32_MAX;
    uint32_t head, loop;  // the first load and the loop instruction (LOOPUP/LOOPDN)
    Kind kind;
    bool i16, down;       // the counter is an INT; the loop counts down
    bool sum_first;       // the addition reads s as its first operand (REAL keeps the order)
    bool swap_mul;        // the product reads the second load first
    Load load[2];
    uint32_t sum, product;  // s; the REAL product's temporary (MacF32)
    uint32_t counter, step, limit;
  };

 private:
  void find_reductions(int32_t offset);
  bool call_native(const void* fn, uint8_t* base);
  bool do_assert(const uint32_t* pc, uint8_t* base);

  const Application* app_;
  // The code as the interpreter runs it (direct threading): the application's code with
  // each opcode word replaced by its handler's offset from the first handler (a
  // superinstruction's at the first instruction of a sequence it runs). Operands,
  // positions and length are the application's, so a pc means the same in both. Built on
  // the first call: the application's code must not change while the machine is used
  // (mutation analysis patches it before it makes the machines that run the mutant).
  std::vector<uint32_t> exec_;
  bool marks_no_branch() const;
  bool code_has_cov_ = false;  // the application's code holds a COV (set when exec_ is built)
  std::vector<std::pair<uint32_t, const FusedRule*>> fused_;  // the heads rewritten in exec_
  std::vector<Reduction> reductions_;  // by head, ascending; their heads rewritten in exec_
  std::vector<uint8_t> mem_;
  std::vector<uint64_t> taken_, covered_;
  std::vector<uint64_t> hits_;  // index = branch id; sized by set_count_hits(true)
  bool count_hits_ = false;
  int64_t now_ns_ = 0;
  uint8_t task_index_ = 1;
  std::vector<LogEntry> log_;
  LibraryHook* hook_ = nullptr;
  TrapKind native_trap_kind_ = TrapKind::None;
  std::string native_trap_msg_;
  uint64_t budget_limit_ = 100'000'000;
  Trap trap_;
  std::string assert_message_;
  const NativeCode* native_ = nullptr;
  bool started_ = false;  // restarted at least once: FB_exit is due before the next restart
  struct Frame {
    const uint32_t* pc;
    uint8_t* base;
    uint32_t mstack_top;
  };
  static constexpr size_t kMaxDepth = 256;
  Frame stack_[kMaxDepth];
};

}  // namespace plcfi::st

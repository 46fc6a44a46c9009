// The VM's dispatch loop (computed goto over opcodes.def) and its trap handling.
#include "memory.hpp"
#include "ops.hpp"
#include "vm.hpp"
#include "native/native.hpp"
#include "cpp_functions.hpp"
#include "wide.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include <fmt/format.h>

namespace plcfi::st {

using namespace ops;  // NOLINT: the instruction semantics

namespace {
// Superinstructions (see run()): which operand of the second instruction takes the first's
// result, as its word index.
constexpr uint32_t FUSE_B = 2, FUSE_C = 3;
template <class T> inline T fadd(T a, T b) { return a + b; }
template <class T> inline T fmul(T a, T b) { return a * b; }
template <class T> inline T band(T a, T b) { return static_cast<T>(a & b); }
template <class T> inline bool jge(T a, T b) { return a >= b; }
inline bool jnlt(float a, float b) { return !(a < b); }
// The watchdog's trap message: a loop jumped back more often than `limit` allows.
std::string watchdog_message(uint64_t limit) {
  return fmt::format("more than {} loop iterations in one call (endless loop?)", limit);
}

// SCMP and WSCMP: whether compare() result c satisfies relation rel (0 =, 1 <>, 2 <,
// 3 <=, 4 >, 5 >=).
inline bool relation_holds(int c, uint32_t rel) {
  switch (rel) {
    case 0: return c == 0;
    case 1: return c != 0;
    case 2: return c < 0;
    case 3: return c <= 0;
    case 4: return c > 0;
    default: return c >= 0;
  }
}

constexpr OpInfo kOps[] = {
#define OP(name, nargs, rtl) {#name, nargs, rtl},
#include "opcodes.def"
#undef OP
};

}  // namespace

const OpInfo& op_info(Op op) { return kOps[static_cast<uint32_t>(op)]; }

bool is_conditional_jump(Op op) {
  static const std::vector<bool> table = [] {
    std::vector<bool> t(static_cast<size_t>(Op::Count_));
    static constexpr std::string_view kFamilies[] = {"JLT_", "JGE_", "JEQ_", "JNE_", "JNLT_", "JNGE_", "JTZ_", "JTNZ_"};
    for (size_t i = 0; i < t.size(); ++i) {
      std::string_view n = kOps[i].name;
      bool family = false;
      for (std::string_view f : kFamilies) family = family || n.rfind(f, 0) == 0;
      t[i] = family || n == "JMPF" || n == "JMPT";
    }
    return t;
  }();
  return table[static_cast<size_t>(op)];
}

uint32_t op_length(const uint32_t* code) {
  Op op = static_cast<Op>(code[0]);
  if (op == Op::JTAB) return 1 + 4 + code[3];
  if (op == Op::ROWS) return 1 + code[1];
  return 1 + kOps[code[0]].nargs;
}

const char* trap_name(TrapKind k) {
  switch (k) {
    case TrapKind::None: return "none";
    case TrapKind::DivisionByZero: return "division by zero";
    case TrapKind::IndexOutOfRange: return "array index out of range";
    case TrapKind::RangeError: return "subrange violation";
    case TrapKind::NullReference: return "null reference";
    case TrapKind::Watchdog: return "watchdog: instruction budget exhausted";
    case TrapKind::CallDepth: return "call depth exceeded";
    case TrapKind::AssertFailed: return "assertion failed";
    case TrapKind::NotImplemented: return "method not implemented";
    case TrapKind::BadAddress: return "address outside memory";
  }
  return "?";
}

Machine::Machine(const Application& app) : app_(&app) {
  mem_ = app.init_image;
  size_t words = (app.branches.size() + 63) / 64;
  taken_.assign(words, 0);
  covered_.assign(words, 0);
}

bool Machine::cold_restart() { return restart(false); }
bool Machine::warm_restart() { return restart(true); }

bool Machine::restart(bool warm) {
  bool ok = true;
  Trap first;
  // FB_exit of the instances that ran, while their memory is still theirs.
  if (app_->has_exit && started_ && !call(app_->exit_entry, app_->lifecycle_addr)) {
    ok = false;
    first = trap_;
  }
  std::vector<uint8_t> keep;
  if (warm)
    for (auto [addr, size] : app_->retain_ranges) keep.insert(keep.end(), mem_.begin() + addr, mem_.begin() + addr + size);
  std::memcpy(mem_.data(), app_->init_image.data(), mem_.size());
  size_t pos = 0;
  if (warm)
    for (auto [addr, size] : app_->retain_ranges) {
      std::memcpy(mem_.data() + addr, keep.data() + pos, size);
      pos += size;
    }
  started_ = true;
  if (app_->has_init) {
    mem_[app_->init_flag_addr] = warm ? 0 : 1;
    if (!call(app_->init_entry, app_->lifecycle_addr) && ok) {
      ok = false;
      first = trap_;
    }
  }
  trap_ = ok ? Trap{} : first;
  return ok;
}

// Code threaded as it is now and without a COV instruction marks no branch: nothing to
// clear or merge (every scan of a run without coverage asks).
bool Machine::marks_no_branch() const { return exec_.size() == app_->code.size() && !code_has_cov_; }

void Machine::clear_taken() {
  if (marks_no_branch()) return;
  std::fill(taken_.begin(), taken_.end(), 0);
}

void Machine::merge_coverage() {
  if (marks_no_branch()) return;
  for (size_t i = 0; i < taken_.size(); ++i) covered_[i] |= taken_[i];
  if (!count_hits_) return;
  for (size_t w = 0; w < taken_.size(); ++w)
    for (uint64_t bits = taken_[w]; bits != 0; bits &= bits - 1) ++hits_[w * 64 + static_cast<size_t>(std::countr_zero(bits))];
}

void Machine::set_count_hits(bool on) {
  count_hits_ = on;
  if (on) hits_.resize(app_->branches.size(), 0);
}

bool Machine::fail(TrapKind k, const uint32_t* pc, std::string msg) {
  trap_.kind = k;
  // pc points into the threaded copy (the interpreter) or into the application's code (the
  // native tier's assertions); both have the same layout.
  const uint32_t* code = !exec_.empty() && pc >= exec_.data() && pc < exec_.data() + exec_.size() ? exec_.data() : app_->code.data();
  trap_.pc = static_cast<uint32_t>(pc - code);
  trap_.loc = app_->loc_of(trap_.pc);
  trap_.message = std::move(msg);
  return false;
}

bool Machine::fail_native(const uint32_t* pc) {
  TrapKind k = native_trap_kind_;
  native_trap_kind_ = TrapKind::None;
  return fail(k, pc, std::move(native_trap_msg_));
}

bool Machine::call(uint32_t entry, uint32_t base_addr) {
  trap_.kind = TrapKind::None;  // the message is only meaningful after a failed call
  if (entry >= app_->code.size() || base_addr > mem_.size())
    return fail(TrapKind::BadAddress, app_->code.data(), "entry or base outside the application");
  if (native_)
    if (native_abi::Fn fn = native_->find(entry)) return call_native(reinterpret_cast<const void*>(fn), mem_.data() + base_addr);
  int64_t budget = static_cast<int64_t>(budget_limit_);
  return run(entry, mem_.data() + base_addr, app_->mstack_addr, &budget);
}

// ----------------------------------------------------------------- native tier

struct NativeBridge {
  static Machine& m(native_abi::Ctx* c) { return *static_cast<Machine*>(c->host); }

  // The message of the trap, as the interpreter words it for the same instruction.
  static int trap(native_abi::Ctx* c, uint32_t kind, uint32_t pc, int64_t a, int64_t b, int64_t cc) {
    Machine& vm = m(c);
    const uint32_t* w = vm.app_->code.data() + pc;
    auto k = static_cast<TrapKind>(kind);
    auto op = static_cast<Op>(w[0]);
    std::string_view name = op_info(op).name;
    std::string msg;
    auto range = [&](int lo_at, int count_at) {
      return vm.app_->index_message(pc, a, static_cast<int32_t>(w[lo_at]), w[count_at]);
    };
    bool u64 = name.size() > 4 && name.substr(name.size() - 4) == "_U64";
    auto num = [&](int64_t v) { return u64 ? std::to_string(static_cast<uint64_t>(v)) : std::to_string(v); };
    if (op == Op::TRAP) {
      msg = trap_name(k);
    } else {
      switch (k) {
        case TrapKind::DivisionByZero: msg = a == 1 ? "MOD by zero" : "integer division by zero"; break;
        case TrapKind::IndexOutOfRange:
          if (name.rfind("CHK_", 0) == 0) msg = fmt::format("index {} outside {}..{}", num(a), num(b), num(cc));
          // LDXX/STXX: b says which of the two indices is outside.
          else if (name.rfind("LDXX", 0) == 0) msg = b == 0 ? range(4, 5) : range(8, 9);
          else if (name.rfind("STXX", 0) == 0) msg = b == 0 ? range(3, 4) : range(7, 8);
          else if (name.rfind("LDXL", 0) == 0) msg = range(6, 7);
          else if (name.rfind("STXL", 0) == 0) msg = range(5, 6);
          else if (op == Op::ELEM || name.rfind("LDX", 0) == 0) msg = range(4, 5);
          else msg = range(3, 4);  // STX, STXS
          break;
        case TrapKind::RangeError: msg = fmt::format("value {} outside subrange {}..{}", num(a), num(b), num(cc)); break;
        case TrapKind::NullReference: msg = "dereference of a null reference"; break;
        case TrapKind::Watchdog: msg = watchdog_message(vm.budget_limit_); break;
        case TrapKind::CallDepth: msg = a == 1 ? "method stack overflow (recursion?)" : "call depth exceeded (recursion?)"; break;
        case TrapKind::NotImplemented: msg = "the instance's type does not implement this method"; break;
        case TrapKind::BadAddress: msg = fmt::format("address {} outside memory", static_cast<uint64_t>(a)); break;
        default: msg = trap_name(k); break;
      }
    }
    vm.fail(k, w, std::move(msg));
    return native_abi::kTrap;
  }

  static int call_entry(native_abi::Ctx* c, uint32_t entry, uint8_t* base) {
    Machine& vm = m(c);
    if (native_abi::Fn fn = vm.native_->find(entry)) return fn(c, base);
    int64_t budget = c->budget;
    bool ok = vm.run(entry, base, c->mtop, &budget);
    c->budget = budget;
    return ok ? native_abi::kOk : native_abi::kTrap;
  }

  static int native_fn(native_abi::Ctx* c, uint32_t pc, uint32_t id, uint8_t* a, uint8_t* b, uint8_t* cc, uint8_t* d) {
    Machine& vm = m(c);
    native(id & 0xffffu)(vm, id >> 16, a, b, cc, d);
    if (vm.native_trap_kind_ == TrapKind::None) return native_abi::kOk;
    vm.fail_native(vm.app_->code.data() + pc);
    return native_abi::kTrap;
  }

  static int assert_fn(native_abi::Ctx* c, uint32_t pc, uint8_t* base) {
    Machine& vm = m(c);
    return vm.do_assert(vm.app_->code.data() + pc, base) ? native_abi::kOk : native_abi::kTrap;
  }
};

bool Machine::call_native(const void* fn, uint8_t* base) {
  native_abi::Ctx c{};
  c.mem = mem_.data();
  c.msize = mem_.size();
  c.taken = taken_.data();
  c.now = &now_ns_;
  c.vtable = app_->vtable.data();
  c.budget = static_cast<int64_t>(budget_limit_);
  c.depth = 0;
  c.mtop = app_->mstack_addr;
  c.mend = app_->mstack_addr + app_->mstack_size;
  c.host = this;
  c.trap = &NativeBridge::trap;
  c.call_entry = &NativeBridge::call_entry;
  c.native_fn = &NativeBridge::native_fn;
  c.assert_fn = &NativeBridge::assert_fn;
  return reinterpret_cast<native_abi::Fn>(const_cast<void*>(fn))(&c, base) != native_abi::kTrap;
}

// Dispatch uses computed goto (a GNU extension, as CPython's and Lua's fast paths do) on
// the threaded code: one indirect jump per instruction or superinstruction, predicted per
// handler, to the handler whose offset the opcode word holds.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
// Superinstructions: two or three adjacent instructions in one handler (interpreter only).
//
// thread_code() rewrites the opcode word of the first instruction of a sequence listed
// here to the sequence's handler; the others keep their own words, so a jump to one of
// them runs it alone, and all keep their operands and positions: a pc, a trap's location
// and the branch taken are the same as with the instructions run one by one. Every store
// is done as the plain instructions do it.
//   P(H, T), P3(H, T, U)  run H (and T) and go on straight to the last one's handler,
//                         without a dispatch;
//   F(H, T, B|C)          T reads the slot H has just written, as its operand b or c: the
//                         value is handed to T in a register, which spares T the reload
//                         (store-to-load latency is most of the cost of a chain);
//   FF3(H, T, B|C, U, B|C)  the same along a chain of three;
// The sequences are the most frequent ones in the MATIEC kernels and the stamping program
// (counted per dispatch): argument moves and calls, loop bodies, arithmetic chains, REAL
// compare-and-jump with its coverage bit. (A DINT product added in the same expression is
// one MADD_I32, which stands for the MUL_I32+ADD_I32 pairs and triples counted there.)
#define PLCFI_FUSED(P, F, P3, FF3)                                                          \
  FF3(MUL_I32, DIVK_I32, B, JGE_I32, B) FF3(MUL_I32, DIVK_I32, B, JGE_I32, C)             \
  FF3(SUB_F32, MUL_F32, C, ADD_F32, C)                                                    \
  FF3(MUL_F32, ADD_F32, B, JNLT_F32, C) FF3(MUL_F32, ADD_F32, B, JNLT_F32, B)             \
  P3(MOV4, MOV4, CALL) P3(MOV1, MOV8, RET) P3(MOV1, MOV8, CALL)                           \
  F(MADD_I32, MODK_I32, B) F(CVT_I16_I32, MADD_I32, B) F(CVT_I16_I32, MADD_I32, C)        \
  F(ADD_I32, MODK_I32, B)                                                                 \
  F(MODK_I32, SUB_I32, B) F(MODK_I32, ADD_I32, B) F(MODK_I32, ADD_I32, C)                 \
  F(MUL_I32, DIVK_I32, B) F(DIVK_I32, JGE_I32, B) F(DIVK_I32, JGE_I32, C)                 \
  F(LDXH4, ADD_I32, B) F(LDXH4, ADD_I32, C) F(LDXH4, JGE_I32, B) F(LDXH4, JGE_I32, C)     \
  F(CVT_I16_I32, MUL_I32, B) F(CVT_I16_I32, MUL_I32, C)                                   \
  F(SUB_F32, MUL_F32, B) F(SUB_F32, MUL_F32, C) F(MUL_F32, ADD_F32, B)                    \
  F(MUL_F32, ADD_F32, C) F(ADD_F32, JNLT_F32, B) F(ADD_F32, JNLT_F32, C)                  \
  F(EQ_I16, BAND, B) F(EQ_I16, BAND, C) F(BNOT, BAND, B) F(BNOT, BAND, C)                 \
  P(MOV1, MOV1) P(MOV1, MOV4) P(MOV1, MOV8) P(MOV1, CALL) P(MOV1, RET)                    \
  P(MOV4, MOV1) P(MOV4, MOV4) P(MOV4, CALL) P(MOV4, RET)                                  \
  P(MOV8, CALL) P(MOV8, RET) P(MOV2, CALL)                                                \
  P(COV, MOV1) P(COV, MOV4) P(COV, ADD_I32)                                               \
  P(JMPF, COV) P(JGE_I32, COV) P(JNLT_F32, COV)                                           \
  P(ADD_I32, LOOPUP_I16) P(ADD_I32, LOOPUP_I32) P(ADD_F32, MOV4) P(SUB_I32, MOV4)         \
  P(LDXH4, LDXH4) P(EQ_I16, MOV8) P(BAND, MOV1)

// Rules 20 and 22, an array element loaded for the instruction after it: a conditional
// jump (IF flags[i] THEN, IF a[j - 1].key > x THEN, WHILE buf[k] <> 0 DO, IF (data[i] AND
// 16#80) <> 0 THEN) on a BOOL or an integer, or a widening conversion (WORD_TO_DWORD(w[i]),
// INT_TO_DINT(a[i])). An element load of any form the compiler emits for a rank-1 array (a
// DINT index, checked, proven or linear over two counters; an elementary element or a
// field of a structure element) or a row of a rank-2 array in a FOR loop, of 1, 2 or 4
// bytes, followed by an instruction of the same width from the list: one handler loads
// the element as the load does and goes on straight to the next instruction's handler,
// without a dispatch. (It is what the two do one after the other, whichever operands the
// second reads.) The rule yields to a superinstruction the second instruction heads.
// Not in the list, measured as a loss: arithmetic and bitwise operations, REAL jumps. With
// them, gcc no longer kept the code base and the coverage bits in registers across run()
// and every kernel took 3 % to 5 % more instructions per scan, those without such pairs
// too. (run() reads the rarely used machine state, the memory size, the method stack's
// end and the vtable, where it needs it rather than holding it from the start, which
// leaves the registers to the rest.)
//   PLCFI_ELEM_USES(X)   X(L, N, J): the load L of N bytes, then the instruction J.
#define PLCFI_ELEM_USES(X)                                                                                      \
  PLCFI_ELEM_USES_OF(X, LDX) PLCFI_ELEM_USES_OF(X, LDXN) PLCFI_ELEM_USES_OF(X, LDXS) PLCFI_ELEM_USES_OF(X, LDXSN) \
  PLCFI_ELEM_USES_OF(X, LDXL) PLCFI_ELEM_USES_OF(X, LDXR)
#define PLCFI_ELEM_USES_OF(X, L)                                                                                      \
  X(L, 1, JMPF) X(L, 1, JMPT) PLCFI_ELEM_JUMP(X, L, 1, I8) PLCFI_ELEM_JUMP(X, L, 1, U8) PLCFI_ELEM_TEST(X, L, 1, I8)  \
  PLCFI_ELEM_TEST(X, L, 1, U8) X(L, 1, CVT_U8_U16) X(L, 1, CVT_U8_U32) X(L, 1, CVT_U8_I16) X(L, 1, CVT_U8_I32)       \
  X(L, 1, CVT_I8_I16) X(L, 1, CVT_I8_I32) PLCFI_ELEM_JUMP(X, L, 2, I16) PLCFI_ELEM_JUMP(X, L, 2, U16)               \
  PLCFI_ELEM_TEST(X, L, 2, I16) PLCFI_ELEM_TEST(X, L, 2, U16) X(L, 2, CVT_I16_I32) X(L, 2, CVT_U16_U32)              \
  X(L, 2, CVT_U16_I32) PLCFI_ELEM_JUMP(X, L, 4, I32) PLCFI_ELEM_JUMP(X, L, 4, U32) PLCFI_ELEM_TEST(X, L, 4, I32)     \
  PLCFI_ELEM_TEST(X, L, 4, U32)
#define PLCFI_ELEM_JUMP(X, L, N, TN) X(L, N, JEQ_##TN) X(L, N, JNE_##TN) X(L, N, JLT_##TN) X(L, N, JGE_##TN)
#define PLCFI_ELEM_TEST(X, L, N, TN) X(L, N, JTZ_##TN) X(L, N, JTNZ_##TN)

// The length of the instruction at pc, or 0 when the word there is no opcode or the
// instruction runs past the end of the code.
static uint32_t instruction_length(const std::vector<uint32_t>& code, uint32_t pc) {
  const uint32_t op = code[pc];
  const uint32_t len = op < static_cast<uint32_t>(Op::Count_) ? op_length(&code[pc]) : 0;
  return len <= code.size() - pc ? len : 0;
}

const Machine::FusedRule* Machine::first_fit(const std::vector<uint32_t>& code, const std::vector<uint8_t>& heads,
                                             const FusedRule* rules, size_t n_rules, uint32_t at, bool yielding) {
  const auto n = static_cast<uint32_t>(code.size());
  const uint32_t next = at + instruction_length(code, at);
  const uint32_t second_len = next < n ? instruction_length(code, next) : 0;
  const uint32_t third = next + second_len;
  for (size_t r = 0; second_len != 0 && r < n_rules; ++r) {
    const FusedRule& f = rules[r];
    if (code[at] != static_cast<uint32_t>(f.head) || code[next] != static_cast<uint32_t>(f.tail)) continue;
    if (f.yields && !yielding) continue;
    if (f.operand != 0 && (f.operand >= second_len || code[next + f.operand] != code[at + 1])) continue;
    if (f.third != Op::Count_ &&
        (third >= n || instruction_length(code, third) == 0 || code[third] != static_cast<uint32_t>(f.third)))
      continue;
    if (f.operand2 != 0 && code[third + f.operand2] != code[next + 1]) continue;
    if (f.yields && heads[code[next]] && first_fit(code, heads, rules, n_rules, next, false)) continue;
    if (f.dead_head) {
      const uint32_t len3 = third < n ? instruction_length(code, third) : 0;
      if (len3 == 0 || std::find(code.begin() + third, code.begin() + third + len3, code[at + 1]) != code.begin() + third + len3)
        continue;
    }
    return &f;
  }
  return nullptr;
}

void Machine::thread_code(const int32_t* offsets, int32_t invalid, const FusedRule* rules, size_t n_rules,
                          int32_t reduction) {
  const std::vector<uint32_t>& code = app_->code;
  exec_ = code;
  fused_.clear();
  const auto n = static_cast<uint32_t>(code.size());
  std::vector<uint8_t> heads(static_cast<size_t>(Op::Count_), 0);  // ops that start some rule
  for (size_t r = 0; r < n_rules; ++r) heads[static_cast<size_t>(rules[r].head)] = 1;
  auto length = [&](uint32_t pc) { return instruction_length(code, pc); };
  uint32_t pc = 0;
  while (pc < n) {
    uint32_t len = length(pc);
    if (len == 0) {
      // Not an instruction the compiler emits: from here on every word stops the VM.
      for (; pc < n; ++pc) exec_[pc] = static_cast<uint32_t>(invalid);
      break;
    }
    exec_[pc] = static_cast<uint32_t>(offsets[code[pc]]);
    uint32_t next = pc + len;
    // The first rule that fits (triples come first). Every instruction may head one: the
    // second of a pair keeps a word of its own for jumps to it.
    if (const FusedRule* f = heads[code[pc]] ? first_fit(code, heads, rules, n_rules, pc, true) : nullptr) {
      exec_[pc] = static_cast<uint32_t>(f->offset);
      fused_.emplace_back(pc, f);
    }
    pc = next;
  }
  find_reductions(reduction);
}

// Reduction loops: a FOR loop (LOOPUP/LOOPDN back to the first instruction of its body)
// whose body is nothing but one or two element loads indexed by the counter and the
// accumulation of what they loaded into one variable s:
//   DINT  s := s + a[i]           ADD_I32            s := s + a[i] * b[i]   MADD_I32
//   REAL  s := s + a[i]           ADD_F32            s := s + a[i] * b[i]   MUL_F32, ADD_F32
// with any of the element accesses the compiler emits for 4-byte elements (checked or
// proven rank 1, a field of a structure element, a row of a rank-2 array in a FOR). Such
// a loop runs in one handler that keeps the counter and s in registers from one
// iteration to the next (run_reduction). It stores what the instructions store, in their
// order, every iteration, so memory is exact whenever the loop ends; an index the check
// refuses hands over to the plain instruction at that point, which traps as ever.
// Only when nothing the loop stores overlaps what it reads besides (the step, the limit,
// a row's offset, the arrays' bytes): then those stay as read on entry.
void Machine::find_reductions(int32_t offset) {
  reductions_.clear();
  const std::vector<uint32_t>& code = app_->code;
  const auto n = static_cast<uint32_t>(code.size());
  auto op_at = [&](uint32_t pc) { return static_cast<Op>(code[pc]); };
  auto length = [&](uint32_t pc) { return instruction_length(code, pc); };
  // One element load of the body at pc, indexed by `counter`: its extent in the frame.
  auto element = [&](uint32_t pc, bool i16, uint32_t counter, Reduction::Load* l, uint32_t* from, uint64_t* bytes) {
    const uint32_t* w = &code[pc];
    const Op op = op_at(pc);
    const bool h = op == Op::LDXH4 || op == Op::LDXSH4;
    if (h != i16) return false;
    l->pc = pc;
    l->dst = w[1];
    l->row = Reduction::kNoRow;
    switch (op) {
      case Op::LDX4: case Op::LDXH4: case Op::LDXN4:
        l->at = w[2];
        l->lo = static_cast<int32_t>(w[4]);
        l->n = op == Op::LDXN4 ? UINT64_MAX : w[5];
        l->stride = 4;
        *from = w[2];
        *bytes = uint64_t{w[5]} * 4;
        break;
      case Op::LDXS4: case Op::LDXSH4: case Op::LDXSN4:
        l->at = w[2] + w[7];
        l->lo = static_cast<int32_t>(w[4]);
        l->n = op == Op::LDXSN4 ? UINT64_MAX : w[5];
        l->stride = w[6];
        *from = w[2];
        *bytes = uint64_t{w[5]} * w[6];
        break;
      case Op::LDXR4:
        l->at = 0;
        l->row = w[2];
        l->lo = 0;
        l->n = UINT64_MAX;
        l->stride = static_cast<int32_t>(w[4]);
        *from = w[5];
        *bytes = w[6];
        break;
      default:
        return false;
    }
    return w[3] == counter;
  };
  uint32_t pc = 0;
  while (pc < n) {
    const uint32_t len = length(pc);
    if (len == 0) break;
    const Op op = op_at(pc);
    const uint32_t loop = pc;
    pc += len;
    const bool up = op == Op::LOOPUP_I32 || op == Op::LOOPUP_I16;
    if (!up && op != Op::LOOPDN_I32 && op != Op::LOOPDN_I16) continue;
    const uint32_t* lw = &code[loop];
    const uint32_t head = lw[4];
    if (head >= loop) continue;
    Reduction r{};
    r.head = head;
    r.loop = loop;
    r.i16 = op == Op::LOOPUP_I16 || op == Op::LOOPDN_I16;
    r.down = !up;
    r.counter = lw[1];
    r.step = lw[2];
    r.limit = lw[3];
    // The body: loads, then the accumulation, ending right at the loop instruction.
    struct Extent { uint32_t from; uint64_t bytes; };
    std::vector<Extent> reads;  // what must not be stored to: arrays, rows, step, limit
    uint32_t at = head, loads = 0;
    while (loads < 2 && at < loop && length(at) != 0) {
      uint32_t from = 0;
      uint64_t bytes = 0;
      if (!element(at, r.i16, r.counter, &r.load[loads], &from, &bytes)) break;
      reads.push_back({from, bytes});
      if (r.load[loads].row != Reduction::kNoRow) reads.push_back({r.load[loads].row, 4});
      ++loads;
      at += length(at);
    }
    if (loads == 0 || at >= loop || length(at) == 0) continue;
    const uint32_t* aw = &code[at];
    const Op acc = op_at(at);
    const uint32_t t0 = r.load[0].dst, t1 = loads == 2 ? r.load[1].dst : UINT32_MAX;
    auto is_pair = [&](uint32_t x, uint32_t y) { return (x == t0 && y == t1) || (x == t1 && y == t0); };
    std::vector<Extent> stores = {{r.counter, r.i16 ? 2u : 4u}, {t0, 4}};
    if (loads == 2) stores.push_back({t1, 4});
    uint32_t after = at + length(at);
    if (loads == 1 && (acc == Op::ADD_I32 || acc == Op::ADD_F32) && aw[1] != t0 &&
        ((aw[2] == aw[1] && aw[3] == t0) || (aw[2] == t0 && aw[3] == aw[1]))) {
      r.kind = acc == Op::ADD_I32 ? Reduction::SumI32 : Reduction::SumF32;
      r.sum = aw[1];
      r.sum_first = aw[2] == aw[1];
    } else if (loads == 2 && acc == Op::MADD_I32 && aw[1] == aw[4] && is_pair(aw[2], aw[3])) {
      r.kind = Reduction::MacI32;
      r.sum = aw[1];
      r.swap_mul = aw[2] == t1;
    } else if (loads == 2 && acc == Op::MUL_F32 && is_pair(aw[2], aw[3]) && after < loop && length(after) != 0 &&
               op_at(after) == Op::ADD_F32) {
      const uint32_t* bw = &code[after];
      const uint32_t u = aw[1];
      if (!((bw[2] == bw[1] && bw[3] == u) || (bw[2] == u && bw[3] == bw[1]))) continue;
      r.kind = Reduction::MacF32;
      r.product = u;
      r.swap_mul = aw[2] == t1;
      r.sum = bw[1];
      r.sum_first = bw[2] == bw[1];
      stores.push_back({u, 4});
      after += length(after);
    } else {
      continue;
    }
    if (after != loop) continue;
    stores.push_back({r.sum, 4});
    reads.push_back({r.step, r.i16 ? 2u : 4u});
    reads.push_back({r.limit, r.i16 ? 2u : 4u});
    auto hits = [](const Extent& a, const Extent& b) {
      return uint64_t{a.from} < uint64_t{b.from} + b.bytes && uint64_t{b.from} < uint64_t{a.from} + a.bytes;
    };
    bool disjoint = true;
    for (size_t i = 0; i < stores.size(); ++i) {
      for (size_t j = i + 1; j < stores.size(); ++j) disjoint = disjoint && !hits(stores[i], stores[j]);
      for (const Extent& e : reads) disjoint = disjoint && !hits(stores[i], e);
    }
    if (!disjoint) continue;
    exec_[head] = static_cast<uint32_t>(offset);
    std::erase_if(fused_, [&](const auto& f) { return f.first == head; });
    reductions_.push_back(r);
  }
  std::sort(reductions_.begin(), reductions_.end(), [](const Reduction& a, const Reduction& b) { return a.head < b.head; });
}

std::vector<std::pair<uint32_t, std::string>> Machine::superinstructions() const {
  std::vector<std::pair<uint32_t, std::string>> out;
  for (auto [pc, f] : fused_) {
    std::string name = std::string(op_info(f->head).name) + "+" + op_info(f->tail).name;
    if (f->third != Op::Count_) name += std::string("+") + op_info(f->third).name;
    if (f->dead_head) name += " (no temporary)";
    out.emplace_back(pc, std::move(name));
  }
  // A reduction loop is named by the instructions it runs, the loop's included.
  for (const Reduction& r : reductions_) {
    std::string name;
    for (uint32_t pc = r.head; pc <= r.loop; pc += op_length(&app_->code[pc]))
      name += (name.empty() ? "" : "+") + std::string(op_info(static_cast<Op>(app_->code[pc])).name);
    out.emplace_back(r.head, std::move(name));
  }
  std::sort(out.begin(), out.end());
  return out;
}

namespace {
// How a reduction loop handed back: past the loop (pc after it), to the plain instruction
// at pc (an index its check refuses), or out of loop budget at the loop instruction.
struct ReductionExit {
  enum How : uint8_t { Done, Plain, Watchdog };
  uint32_t pc;
  How how;
};

// One iteration's accumulation of the loaded words v into s (u: the REAL product).
template <Machine::Reduction::Kind K, class S>
inline void accumulate(const Machine::Reduction& r, const uint32_t* v, S& s, float& u) {
  using R = Machine::Reduction;
  if constexpr (K == R::SumI32) {
    s = wadd<int32_t>(s, static_cast<int32_t>(v[0]));
  } else if constexpr (K == R::MacI32) {
    s = wadd<int32_t>(wmul<int32_t>(static_cast<int32_t>(v[0]), static_cast<int32_t>(v[1])), s);
  } else if constexpr (K == R::SumF32) {
    const float t = std::bit_cast<float>(v[0]);
    s = r.sum_first ? s + t : t + s;
  } else {
    u = std::bit_cast<float>(v[r.swap_mul ? 1 : 0]) * std::bit_cast<float>(v[r.swap_mul ? 0 : 1]);
    s = r.sum_first ? s + u : u + s;
  }
  (void)u;
}

// The frame offset of a load's element `lo`: a row's comes from its slot.
inline int64_t element_base(const Machine::Reduction::Load& d, const uint8_t* base) {
  return d.row != Machine::Reduction::kNoRow ? int64_t{ld<int32_t>(base + d.row)} : int64_t{d.at};
}

// Runs a reduction loop (Machine::find_reductions) from its first load; C is the
// counter's type. The step, the limit and the rows are read on entry (nothing in the
// loop stores to them). When the indices of all the runs of the body from here and its
// jumps back are known on entry to lie inside the arrays and the budget, the loop runs
// without checks and stores what its last iteration stored when it ends (nothing else
// runs in between). Otherwise it stores every iteration's values as the instructions do,
// and hands an index its check refuses to the plain instruction, which traps.
template <class C, bool Down, Machine::Reduction::Kind K>
ReductionExit run_reduction(const Machine::Reduction& r, uint8_t* base, int64_t& budget) {
  using R = Machine::Reduction;
  constexpr int kLoads = K == R::SumI32 || K == R::SumF32 ? 1 : 2;
  using S = std::conditional_t<K == R::SumI32 || K == R::MacI32, int32_t, float>;
  const C step = ld<C>(base + r.step), limit = ld<C>(base + r.limit);
  C i = ld<C>(base + r.counter);
  S s = ld<S>(base + r.sum);
  float u = 0;
  uint32_t v[2] = {};
  const uint8_t* at[2] = {};  // element `lo` of each access
  for (int l = 0; l < kLoads; ++l) at[l] = base + element_base(r.load[l], base);
  if (Down ? step < 0 : step > 0) {
    const int64_t i0 = i, by = step, diff = Down ? i0 - limit : int64_t{limit} - i0;
    const int64_t more = diff <= 0 ? 0 : by == 1 || by == -1 ? diff : diff / (Down ? -by : by);
    const int64_t last = i0 + more * by;
    bool inside = more <= budget;
    for (int l = 0; l < kLoads; ++l) {
      const R::Load& d = r.load[l];
      const int64_t e0 = i0 - d.lo, e1 = last - d.lo;
      if (d.n != UINT64_MAX) inside = inside && std::min(e0, e1) >= 0 && static_cast<uint64_t>(std::max(e0, e1)) < d.n;
    }
    if (inside) {
      const uint8_t* first[2] = {};
      int64_t dd[2] = {};
      for (int l = 0; l < kLoads; ++l) {
        first[l] = at[l] + (i0 - r.load[l].lo) * r.load[l].stride;
        dd[l] = by * r.load[l].stride;
      }
      for (int64_t k = 0; k <= more; ++k) {
        for (int l = 0; l < kLoads; ++l) v[l] = ld<uint32_t>(first[l] + k * dd[l]);
        accumulate<K>(r, v, s, u);
      }
      for (int l = 0; l < kLoads; ++l) st<uint32_t>(base + r.load[l].dst, v[l]);
      if constexpr (K == R::MacF32) st<float>(base + r.product, u);
      st<S>(base + r.sum, s);
      C next;
      (void)__builtin_add_overflow(static_cast<C>(last), step, &next);  // stored wrapped, as the loop does
      st<C>(base + r.counter, next);
      budget -= more;
      return {r.loop + 5, ReductionExit::Done};
    }
  }
  for (;;) {
    for (int l = 0; l < kLoads; ++l) {
      const R::Load& d = r.load[l];
      const int64_t e = int64_t{i} - d.lo;
      if (static_cast<uint64_t>(e) >= d.n) return {d.pc, ReductionExit::Plain};
      v[l] = ld<uint32_t>(at[l] + e * d.stride);
      st<uint32_t>(base + d.dst, v[l]);
    }
    accumulate<K>(r, v, s, u);
    if constexpr (K == R::MacF32) st<float>(base + r.product, u);
    st<S>(base + r.sum, s);
    C next;
    const bool ovf = __builtin_add_overflow(i, step, &next);
    st<C>(base + r.counter, next);
    if (ovf || (Down ? next < limit : next > limit)) return {r.loop + 5, ReductionExit::Done};
    if (--budget < 0) return {r.loop, ReductionExit::Watchdog};
    i = next;
  }
}

template <class C, bool Down>
ReductionExit run_reduction(const Machine::Reduction& r, uint8_t* base, int64_t& budget) {
  using R = Machine::Reduction;
  switch (r.kind) {
    case R::SumI32: return run_reduction<C, Down, R::SumI32>(r, base, budget);
    case R::MacI32: return run_reduction<C, Down, R::MacI32>(r, base, budget);
    case R::SumF32: return run_reduction<C, Down, R::SumF32>(r, base, budget);
    case R::MacF32: break;
  }
  return run_reduction<C, Down, R::MacF32>(r, base, budget);
}

ReductionExit run_reduction(const Machine::Reduction& r, uint8_t* base, int64_t& budget) {
  if (r.i16) return r.down ? run_reduction<int16_t, true>(r, base, budget) : run_reduction<int16_t, false>(r, base, budget);
  return r.down ? run_reduction<int32_t, true>(r, base, budget) : run_reduction<int32_t, false>(r, base, budget);
}
}  // namespace

bool Machine::run(uint32_t entry, uint8_t* base, uint32_t mtop, int64_t* budget_io) {
  if (exec_.size() != app_->code.size()) [[unlikely]] {
    // Which build of run_impl runs this code (the one that threads it, too).
    const std::vector<uint32_t>& code = app_->code;
    code_has_cov_ = false;
    for (uint32_t pc = 0, len = 0; pc < code.size() && !code_has_cov_; pc += len) {
      len = instruction_length(code, pc);
      if (len == 0) break;
      code_has_cov_ = code[pc] == static_cast<uint32_t>(Op::COV);
    }
  }
  return code_has_cov_ ? run_impl<true>(entry, base, mtop, budget_io) : run_impl<false>(entry, base, mtop, budget_io);
}

template <bool Coverage>
bool Machine::run_impl(uint32_t entry, uint8_t* base, uint32_t mtop, int64_t* budget_io) {
  // Handler addresses as offsets from the first handler, one per opcode.
#define LABEL_OFFSET(l) static_cast<int32_t>(reinterpret_cast<intptr_t>(&&l) - reinterpret_cast<intptr_t>(&&L_NOP))
  static const int32_t kOffsets[] = {
#define OP(name, nargs, rtl) LABEL_OFFSET(L_##name),
#include "opcodes.def"
#undef OP
  };
  static const FusedRule kFused[] = {
#define RULE_P(H, T) {Op::H, Op::T, Op::Count_, 0, 0, LABEL_OFFSET(L_P_##H##_##T)},
#define RULE_F(H, T, K) {Op::H, Op::T, Op::Count_, FUSE_##K, 0, LABEL_OFFSET(L_F_##H##_##T##_##K)},
#define RULE_P3(H, T, U) {Op::H, Op::T, Op::U, 0, 0, LABEL_OFFSET(L_P3_##H##_##T##_##U)},
#define RULE_FF3(H, T, K, U, K2) {Op::H, Op::T, Op::U, FUSE_##K, FUSE_##K2, LABEL_OFFSET(L_FF3_##H##_##T##_##K##_##U##_##K2)},
      PLCFI_FUSED(RULE_P, RULE_F, RULE_P3, RULE_FF3)
// Rules 20 and 22 (yielding, whichever operands the second instruction reads).
#define RULE_EU(L, N, J) {Op::L##N, Op::J, Op::Count_, 0, 0, LABEL_OFFSET(L_EU_##L##N##_##J), true},
      PLCFI_ELEM_USES(RULE_EU)
#undef RULE_EU
      // Rule 21: one structure element assigned from another (the STXB stores the block the
      // LDXB loaded: its operand g).
      // Rule 31: the same, without the copy into the temporary when nothing reads it back.
      {Op::LDXB, Op::STXB, Op::Count_, 7, 0, LABEL_OFFSET(L_EB_LDXB_STXB_DIRECT), false, true},
      {Op::LDXB, Op::STXB, Op::Count_, 7, 0, LABEL_OFFSET(L_EB_LDXB_STXB)},
      // Rule 30: a CASE on an INT, UINT, SINT, USINT, BYTE, WORD or enumerated selector
      // (the jump table's DINT operand a is the conversion's result).
      {Op::CVT_I16_I32, Op::JTAB, Op::Count_, 1, 0, LABEL_OFFSET(L_CJ_I16)},
      {Op::CVT_U16_I32, Op::JTAB, Op::Count_, 1, 0, LABEL_OFFSET(L_CJ_U16)},
      {Op::CVT_I8_I32, Op::JTAB, Op::Count_, 1, 0, LABEL_OFFSET(L_CJ_I8)},
      {Op::CVT_U8_I32, Op::JTAB, Op::Count_, 1, 0, LABEL_OFFSET(L_CJ_U8)},
#undef RULE_FF3
#undef RULE_P
#undef RULE_F
#undef RULE_P3
  };
  if (exec_.size() != app_->code.size()) [[unlikely]]
    thread_code(kOffsets, LABEL_OFFSET(L_INVALID), kFused, std::size(kFused), LABEL_OFFSET(L_REDUCE));
  const char* const handlers = static_cast<const char*>(&&L_NOP);
  uint8_t* const mem = mem_.data();
  const uint32_t* const code = exec_.data();
  const uint32_t* pc = code + entry;
  uint64_t* const taken = taken_.data();
  size_t sp = 0;
  int64_t budget = *budget_io;

#define DISPATCH() goto* static_cast<const void*>(handlers + static_cast<int32_t>(*pc))
#define NEXT(n)  \
  do {           \
    pc += 1 + n; \
    DISPATCH();  \
  } while (0)
#define R(T, i) ld<T>(base + pc[i])
#define W(T, i, v) st<T>(base + pc[i], (v))
  // Resolves the address held in slot i, checking null and bounds for n bytes.
#define PTR(dst, i, disp, n)                                                                  \
  uint64_t dst = static_cast<uint64_t>(ld<uint32_t>(base + pc[i])) + (disp);                  \
  if (ld<uint32_t>(base + pc[i]) == 0) return fail(TrapKind::NullReference, pc, "dereference of a null reference"); \
  if (dst + (n) > mem_.size()) return fail(TrapKind::BadAddress, pc, fmt::format("address {} outside memory", dst))
#define BACKJUMP()                                                                              \
  if (--budget < 0)                                                                             \
    return fail(TrapKind::Watchdog, pc,                                                         \
                watchdog_message(budget_limit_))
  // A taken conditional jump to an earlier instruction is a loop's back edge (WHILE and
  // REPEAT test at the bottom): it counts against the watchdog, as JMPB does.
#define TAKE(k)                                  \
  do {                                           \
    const uint32_t* to_ = code + pc[k];          \
    if (to_ <= pc) {                             \
      BACKJUMP();                                \
    }                                            \
    COVER(to_);                                  \
    pc = to_;                                    \
    DISPATCH();                                  \
  } while (0)
  // A branch marks the coverage of the arm it enters: a COV where a conditional jump or a
  // CASE table leads (taken or not) is done there and skipped, which spares every arm a
  // dispatch. The same bit is set as by the COV itself.
  // (A COV that heads a superinstruction is left to it.) The word is compared with the
  // static table's, which keeps no further pointer live across the handlers. Code without
  // a COV runs in the build without Coverage, whose jumps leave the test out.
#define COVER(p)                                                                                   \
  if (Coverage && *(p) == static_cast<uint32_t>(kOffsets[static_cast<uint32_t>(Op::COV)])) {     \
    taken[(p)[1] >> 6] |= uint64_t(1) << ((p)[1] & 63);           \
    (p) += 2;                                                     \
  }
  // The fall-through of a conditional jump of n operands.
#define FALL(n)  \
  do {           \
    pc += 1 + n; \
    COVER(pc);   \
    DISPATCH();  \
  } while (0)

  DISPATCH();

L_NOP:
  NEXT(0);
L_HALT:
  *budget_io = budget;
  return true;
L_RET:
  if (sp == 0) {
    *budget_io = budget;
    return true;
  }
  --sp;
  pc = stack_[sp].pc;
  base = stack_[sp].base;
  mtop = stack_[sp].mstack_top;
  DISPATCH();
L_JMP:
  pc = code + pc[1];
  DISPATCH();
L_JMPB:
  BACKJUMP();
  pc = code + pc[1];
  DISPATCH();
L_JMPF:
  if (!ld<uint8_t>(base + pc[2])) TAKE(1);
  FALL(2);
L_JMPT:
  if (ld<uint8_t>(base + pc[2])) TAKE(1);
  FALL(2);
L_CALL:
  if (sp == kMaxDepth) return fail(TrapKind::CallDepth, pc, "call depth exceeded (recursion?)");
  stack_[sp++] = {pc + 3, base, mtop};
  base += pc[1];
  pc = code + pc[2];
  DISPATCH();
L_CALLA:
  if (sp == kMaxDepth) return fail(TrapKind::CallDepth, pc, "call depth exceeded (recursion?)");
  stack_[sp++] = {pc + 3, base, mtop};
  base = mem + pc[1];
  pc = code + pc[2];
  DISPATCH();
L_CALLP: {
  if (sp == kMaxDepth) return fail(TrapKind::CallDepth, pc, "call depth exceeded (recursion?)");
  PTR(addr, 1, 0, 8);
  stack_[sp++] = {pc + 3, base, mtop};
  base = mem + addr;
  pc = code + pc[2];
  DISPATCH();
}
L_FRAME:
  W(uint32_t, 1, mtop);
  NEXT(1);
L_ENTER: {
  uint64_t top = static_cast<uint64_t>(base - mem) + pc[1];
  if (top > app_->mstack_addr + app_->mstack_size) return fail(TrapKind::CallDepth, pc, "method stack overflow (recursion?)");
  mtop = static_cast<uint32_t>(top);
  NEXT(1);
}
L_CALLS: {
  if (sp == kMaxDepth) return fail(TrapKind::CallDepth, pc, "call depth exceeded (recursion?)");
  stack_[sp++] = {pc + 3, base, mtop};
  base = mem + ld<uint32_t>(base + pc[1]);
  pc = code + pc[2];
  DISPATCH();
}
L_CALLV: {
  if (sp == kMaxDepth) return fail(TrapKind::CallDepth, pc, "call depth exceeded (recursion?)");
  PTR(inst, 2, 0, 8);
  uint32_t type = ld<uint16_t>(mem + inst);
  const uint32_t n_types = app_->n_types;
  uint32_t target = type < n_types ? app_->vtable[pc[3] * n_types + type] : 0;
  if (target == 0) return fail(TrapKind::NotImplemented, pc, "the instance's type does not implement this method");
  uint8_t* frame = mem + ld<uint32_t>(base + pc[1]);
  st<uint32_t>(frame + 8, static_cast<uint32_t>(inst));
  stack_[sp++] = {pc + 4, base, mtop};
  base = frame;
  pc = code + target;
  DISPATCH();
}
L_JTAB: {
  int64_t i = static_cast<int64_t>(ld<int32_t>(base + pc[1])) - static_cast<int32_t>(pc[2]);
  if (i >= 0 && i < static_cast<int64_t>(pc[3])) pc = code + pc[5 + i];
  else pc = code + pc[4];
  COVER(pc);
  DISPATCH();
}
L_COV:
  taken[pc[1] >> 6] |= uint64_t(1) << (pc[1] & 63);
  NEXT(1);
L_FBENTER: {
  st<uint32_t>(base + 4, ld<uint32_t>(base + 4) + 1);
  if (base[2]) goto L_RET;
  NEXT(0);
}
L_FNMOCK:
  if (mem[pc[1]]) {
    std::memcpy(base + pc[2], mem + pc[1] + 8, pc[3]);
    goto L_RET;
  }
  NEXT(3);
L_TRAP:
  return fail(static_cast<TrapKind>(pc[1]), pc, trap_name(static_cast<TrapKind>(pc[1])));
L_INVALID:
  return fail(TrapKind::BadAddress, pc, "not an instruction");

L_MOV1: W(uint8_t, 1, R(uint8_t, 2)); NEXT(2);
L_MOV2: W(uint16_t, 1, R(uint16_t, 2)); NEXT(2);
L_MOV4: W(uint32_t, 1, R(uint32_t, 2)); NEXT(2);
L_MOV8: W(uint64_t, 1, R(uint64_t, 2)); NEXT(2);
L_MOVN: move_block(base + pc[1], base + pc[2], pc[3]); NEXT(3);
  // A select reads both values and picks one by a mask, without a branch to mispredict
  // (written as `c ? yes : no`, the compiler made it a jump around a move).
#define SEL_IMPL(NAME, T)                                                           \
  L_##NAME: {                                                                       \
    const T yes = R(T, 3), no = R(T, 4);                                            \
    const T take = static_cast<T>(T{0} - static_cast<T>(R(uint8_t, 2) != 0));       \
    W(T, 1, static_cast<T>((yes & take) | (no & static_cast<T>(~take))));           \
    NEXT(4);                                                                        \
  }
  SEL_IMPL(SEL1, uint8_t)
  SEL_IMPL(SEL2, uint16_t)
  SEL_IMPL(SEL4, uint32_t)
  SEL_IMPL(SEL8, uint64_t)
#undef SEL_IMPL
L_LDG1: W(uint8_t, 1, ld<uint8_t>(mem + pc[2])); NEXT(2);
L_LDG2: W(uint16_t, 1, ld<uint16_t>(mem + pc[2])); NEXT(2);
L_LDG4: W(uint32_t, 1, ld<uint32_t>(mem + pc[2])); NEXT(2);
L_LDG8: W(uint64_t, 1, ld<uint64_t>(mem + pc[2])); NEXT(2);
L_LDGN: move_block(base + pc[1], mem + pc[2], pc[3]); NEXT(3);
L_STG1: st<uint8_t>(mem + pc[1], R(uint8_t, 2)); NEXT(2);
L_STG2: st<uint16_t>(mem + pc[1], R(uint16_t, 2)); NEXT(2);
L_STG4: st<uint32_t>(mem + pc[1], R(uint32_t, 2)); NEXT(2);
L_STG8: st<uint64_t>(mem + pc[1], R(uint64_t, 2)); NEXT(2);
L_STGN: move_block(mem + pc[1], base + pc[2], pc[3]); NEXT(3);
L_LDI1: { PTR(p, 2, pc[3], 1); W(uint8_t, 1, ld<uint8_t>(mem + p)); NEXT(3); }
L_LDI2: { PTR(p, 2, pc[3], 2); W(uint16_t, 1, ld<uint16_t>(mem + p)); NEXT(3); }
L_LDI4: { PTR(p, 2, pc[3], 4); W(uint32_t, 1, ld<uint32_t>(mem + p)); NEXT(3); }
L_LDI8: { PTR(p, 2, pc[3], 8); W(uint64_t, 1, ld<uint64_t>(mem + p)); NEXT(3); }
L_LDIN: { PTR(p, 2, pc[3], pc[4]); move_block(base + pc[1], mem + p, pc[4]); NEXT(4); }
L_STI1: { PTR(p, 1, pc[2], 1); st<uint8_t>(mem + p, R(uint8_t, 3)); NEXT(3); }
L_STI2: { PTR(p, 1, pc[2], 2); st<uint16_t>(mem + p, R(uint16_t, 3)); NEXT(3); }
L_STI4: { PTR(p, 1, pc[2], 4); st<uint32_t>(mem + p, R(uint32_t, 3)); NEXT(3); }
L_STI8: { PTR(p, 1, pc[2], 8); st<uint64_t>(mem + p, R(uint64_t, 3)); NEXT(3); }
L_STIN: { PTR(p, 1, pc[2], pc[4]); move_block(mem + p, base + pc[3], pc[4]); NEXT(4); }
L_LDBIT: W(uint8_t, 1, static_cast<uint8_t>((mem[pc[2]] >> pc[3]) & 1u)); NEXT(3);
L_STBIT: {
  uint8_t m = static_cast<uint8_t>(1u << pc[2]);
  mem[pc[1]] = static_cast<uint8_t>(R(uint8_t, 3) ? (mem[pc[1]] | m) : (mem[pc[1]] & ~m));
  NEXT(3);
}
L_ADDR: W(uint32_t, 1, static_cast<uint32_t>(base - mem + pc[2])); NEXT(2);
L_ADDRI: { PTR(p, 2, pc[3], 0); W(uint32_t, 1, static_cast<uint32_t>(p)); NEXT(3); }
L_ADDRK: W(uint32_t, 1, pc[2]); NEXT(2);
L_ELEM: {
  int64_t i = static_cast<int64_t>(R(int32_t, 3)) - static_cast<int32_t>(pc[4]);
  if (i < 0 || i >= static_cast<int64_t>(pc[5]))
    return fail(TrapKind::IndexOutOfRange, pc,
                app_->index_message(static_cast<uint32_t>(pc - code), R(int32_t, 3), static_cast<int32_t>(pc[4]), pc[5]));
  PTR(p, 2, static_cast<uint64_t>(i) * pc[6], 0);
  W(uint32_t, 1, static_cast<uint32_t>(p));
  NEXT(6);
}
L_INITBLK: move_block(base + pc[1], mem + pc[2], pc[3]); NEXT(3);
L_NOW: W(int64_t, 1, now_ns_); NEXT(1);
L_ADVTIME: now_ns_ += R(int64_t, 1); NEXT(1);
L_SETMOCK: { PTR(p, 1, 0, 8); mem[p + 2] = 1; NEXT(1); }
L_NATIVE:
  native(pc[1] & 0xffffu)(*this, pc[1] >> 16, base + pc[2], base + pc[3], base + pc[4], base + pc[5]);
  if (native_trap_kind_ != TrapKind::None) [[unlikely]] return fail_native(pc);
  NEXT(5);
L_ASSERT:
  if (!do_assert(pc, base)) return false;
  NEXT(5);
L_SCPY: {
  const char* src = reinterpret_cast<const char*>(base + pc[2]);
  size_t n = strnlen(src, pc[3]);
  std::memmove(base + pc[1], src, n);
  base[pc[1] + n] = 0;
  NEXT(3);
}
L_SCMP:
  W(uint8_t, 1, relation_holds(std::strcmp(reinterpret_cast<const char*>(base + pc[2]), reinterpret_cast<const char*>(base + pc[3])), pc[4]));
  NEXT(4);
L_WSCPY: ops::wscpy(base + pc[1], base + pc[2], pc[3]); NEXT(3);
L_WSCMP: W(uint8_t, 1, relation_holds(ops::wscmp(base + pc[2], base + pc[3]), pc[4])); NEXT(4);
L_GETBIT1: W(uint8_t, 1, static_cast<uint8_t>((R(uint8_t, 2) >> pc[3]) & 1u)); NEXT(3);
L_GETBIT2: W(uint8_t, 1, static_cast<uint8_t>((R(uint16_t, 2) >> pc[3]) & 1u)); NEXT(3);
L_GETBIT4: W(uint8_t, 1, static_cast<uint8_t>((R(uint32_t, 2) >> pc[3]) & 1u)); NEXT(3);
L_GETBIT8: W(uint8_t, 1, static_cast<uint8_t>((R(uint64_t, 2) >> pc[3]) & 1u)); NEXT(3);
#define SETBIT_IMPL(T)                                         \
  {                                                            \
    T m = static_cast<T>(T(1) << pc[2]);                       \
    T v = R(T, 1);                                             \
    W(T, 1, static_cast<T>(R(uint8_t, 3) ? (v | m) : (v & static_cast<T>(~m)))); \
    NEXT(3);                                                   \
  }
L_SETBIT1: SETBIT_IMPL(uint8_t)
L_SETBIT2: SETBIT_IMPL(uint16_t)
L_SETBIT4: SETBIT_IMPL(uint32_t)
L_SETBIT8: SETBIT_IMPL(uint64_t)
#undef SETBIT_IMPL

L_BAND: W(uint8_t, 1, static_cast<uint8_t>(R(uint8_t, 2) & R(uint8_t, 3))); NEXT(3);
L_BOR: W(uint8_t, 1, static_cast<uint8_t>(R(uint8_t, 2) | R(uint8_t, 3))); NEXT(3);
L_BXOR: W(uint8_t, 1, static_cast<uint8_t>(R(uint8_t, 2) ^ R(uint8_t, 3))); NEXT(3);
L_BNOT: W(uint8_t, 1, static_cast<uint8_t>(R(uint8_t, 2) ^ 1u)); NEXT(2);
L_RISE: W(uint8_t, 1, static_cast<uint8_t>(R(uint8_t, 2) & (R(uint8_t, 3) ^ 1u) & R(uint8_t, 4))); NEXT(4);
L_FALL: W(uint8_t, 1, static_cast<uint8_t>((R(uint8_t, 2) ^ 1u) & R(uint8_t, 3) & R(uint8_t, 4))); NEXT(4);
L_STEADY_HIGH: W(uint8_t, 1, static_cast<uint8_t>(R(uint8_t, 2) & R(uint8_t, 3) & R(uint8_t, 4))); NEXT(4);
L_STEADY_LOW: W(uint8_t, 1, static_cast<uint8_t>((R(uint8_t, 2) ^ 1u) & (R(uint8_t, 3) ^ 1u) & R(uint8_t, 4))); NEXT(4);
L_TOBOOL8: W(uint8_t, 1, R(uint8_t, 2) != 0); NEXT(2);
L_TOBOOL16: W(uint8_t, 1, R(uint16_t, 2) != 0); NEXT(2);
L_TOBOOL32: W(uint8_t, 1, R(uint32_t, 2) != 0); NEXT(2);
L_TOBOOL64: W(uint8_t, 1, R(uint64_t, 2) != 0); NEXT(2);

#define NUM_IMPL(TN, C)                                                                 \
  L_ADD_##TN: W(C, 1, wadd<C>(R(C, 2), R(C, 3))); NEXT(3);                              \
  L_SUB_##TN: W(C, 1, wsub<C>(R(C, 2), R(C, 3))); NEXT(3);                              \
  L_MUL_##TN: W(C, 1, wmul<C>(R(C, 2), R(C, 3))); NEXT(3);                              \
  L_DIV_##TN: {                                                                         \
    C d = R(C, 3);                                                                      \
    if constexpr (std::is_integral_v<C>) {                                              \
      if (d == C(0)) return fail(TrapKind::DivisionByZero, pc, "integer division by zero"); \
      W(C, 1, wdiv<C>(R(C, 2), d));                                                     \
    } else {                                                                            \
      W(C, 1, static_cast<C>(R(C, 2) / d));                                             \
    }                                                                                   \
    NEXT(3);                                                                            \
  }                                                                                     \
  L_NEG_##TN: W(C, 1, wneg<C>(R(C, 2))); NEXT(2);                                       \
  L_EQ_##TN: W(uint8_t, 1, R(C, 2) == R(C, 3)); NEXT(3);                                \
  L_NE_##TN: W(uint8_t, 1, R(C, 2) != R(C, 3)); NEXT(3);                                \
  L_LT_##TN: W(uint8_t, 1, R(C, 2) < R(C, 3)); NEXT(3);                                 \
  L_LE_##TN: W(uint8_t, 1, R(C, 2) <= R(C, 3)); NEXT(3);                                \
  L_GT_##TN: W(uint8_t, 1, R(C, 2) > R(C, 3)); NEXT(3);                                 \
  L_GE_##TN: W(uint8_t, 1, R(C, 2) >= R(C, 3)); NEXT(3);                                \
  L_JLT_##TN: if (R(C, 2) < R(C, 3)) TAKE(1); FALL(3);        \
  L_JGE_##TN: if (R(C, 2) >= R(C, 3)) TAKE(1); FALL(3);       \
  L_JEQ_##TN: if (R(C, 2) == R(C, 3)) TAKE(1); FALL(3);       \
  L_JNE_##TN: if (R(C, 2) != R(C, 3)) TAKE(1); FALL(3);       \
  L_MIN_##TN: { C x = R(C, 2), y = R(C, 3); W(C, 1, y < x ? y : x); NEXT(3); }          \
  L_MAX_##TN: { C x = R(C, 2), y = R(C, 3); W(C, 1, x < y ? y : x); NEXT(3); }          \
  L_ABS_##TN: W(C, 1, wabs<C>(R(C, 2))); NEXT(2);                                       \
  L_CVT_##TN##_I8: W(int8_t, 1, cvt<int8_t>(R(C, 2))); NEXT(2);                         \
  L_CVT_##TN##_I16: W(int16_t, 1, cvt<int16_t>(R(C, 2))); NEXT(2);                      \
  L_CVT_##TN##_I32: W(int32_t, 1, cvt<int32_t>(R(C, 2))); NEXT(2);                      \
  L_CVT_##TN##_I64: W(int64_t, 1, cvt<int64_t>(R(C, 2))); NEXT(2);                      \
  L_CVT_##TN##_U8: W(uint8_t, 1, cvt<uint8_t>(R(C, 2))); NEXT(2);                       \
  L_CVT_##TN##_U16: W(uint16_t, 1, cvt<uint16_t>(R(C, 2))); NEXT(2);                    \
  L_CVT_##TN##_U32: W(uint32_t, 1, cvt<uint32_t>(R(C, 2))); NEXT(2);                    \
  L_CVT_##TN##_U64: W(uint64_t, 1, cvt<uint64_t>(R(C, 2))); NEXT(2);                    \
  L_CVT_##TN##_F32: W(float, 1, cvt<float>(R(C, 2))); NEXT(2);                          \
  L_CVT_##TN##_F64: W(double, 1, cvt<double>(R(C, 2))); NEXT(2);
  PLCFI_NUM_TYPES(NUM_IMPL)
#undef NUM_IMPL

#define INT_IMPL(TN, C)                                                                  \
  L_MOD_##TN: {                                                                          \
    C d = R(C, 3);                                                                       \
    if (d == C(0)) return fail(TrapKind::DivisionByZero, pc, "MOD by zero");             \
    W(C, 1, wmod<C>(R(C, 2), d));                                                        \
    NEXT(3);                                                                             \
  }                                                                                      \
  L_MODZ_##TN: {                                                                         \
    C d = R(C, 3);                                                                       \
    W(C, 1, d == C(0) ? C(0) : wmod<C>(R(C, 2), d));                                     \
    NEXT(3);                                                                             \
  }                                                                                      \
  L_AND_##TN: W(C, 1, static_cast<C>(R(C, 2) & R(C, 3))); NEXT(3);                       \
  L_JTZ_##TN: if ((R(C, 2) & R(C, 3)) == 0) TAKE(1); FALL(3);                              \
  L_JTNZ_##TN: if ((R(C, 2) & R(C, 3)) != 0) TAKE(1); FALL(3);                             \
  L_OR_##TN: W(C, 1, static_cast<C>(R(C, 2) | R(C, 3))); NEXT(3);                        \
  L_XOR_##TN: W(C, 1, static_cast<C>(R(C, 2) ^ R(C, 3))); NEXT(3);                       \
  L_NOT_##TN: W(C, 1, static_cast<C>(~R(C, 2))); NEXT(2);                                \
  L_SHL_##TN: W(C, 1, shl<C>(R(C, 2), R(uint64_t, 3))); NEXT(3);                         \
  L_SHR_##TN: W(C, 1, shr<C>(R(C, 2), R(uint64_t, 3))); NEXT(3);                         \
  L_ROL_##TN: W(C, 1, rol<C>(R(C, 2), R(uint64_t, 3))); NEXT(3);                         \
  L_ROR_##TN: W(C, 1, ror<C>(R(C, 2), R(uint64_t, 3))); NEXT(3);                         \
  L_SHLD_##TN: W(C, 1, shl<C>(R(C, 2), dint_count(R(int32_t, 3)))); NEXT(3);             \
  L_SHRD_##TN: W(C, 1, shr<C>(R(C, 2), dint_count(R(int32_t, 3)))); NEXT(3);             \
  L_ROLD_##TN: W(C, 1, rol<C>(R(C, 2), dint_count(R(int32_t, 3)))); NEXT(3);             \
  L_RORD_##TN: W(C, 1, ror<C>(R(C, 2), dint_count(R(int32_t, 3)))); NEXT(3);             \
  L_GETBITD_##TN:                                                                        \
    W(uint8_t, 1, static_cast<uint8_t>((shr<C>(R(C, 2), dint_count(R(int32_t, 3))) & 1u) ^ pc[4])); \
    NEXT(4);                                                                             \
  L_ANDSHL_##TN: W(C, 1, static_cast<C>(R(C, 2) & shl<C>(R(C, 3), pc[4]))); NEXT(4);          \
  L_ANDSHR_##TN: W(C, 1, static_cast<C>(R(C, 2) & shr<C>(R(C, 3), pc[4]))); NEXT(4);          \
  L_ORSHL_##TN: W(C, 1, static_cast<C>(R(C, 2) | shl<C>(R(C, 3), pc[4]))); NEXT(4);           \
  L_ORSHR_##TN: W(C, 1, static_cast<C>(R(C, 2) | shr<C>(R(C, 3), pc[4]))); NEXT(4);           \
  L_XORSHL_##TN: W(C, 1, static_cast<C>(R(C, 2) ^ shl<C>(R(C, 3), pc[4]))); NEXT(4);          \
  L_XORSHR_##TN: W(C, 1, static_cast<C>(R(C, 2) ^ shr<C>(R(C, 3), pc[4]))); NEXT(4);          \
  L_CHK_##TN: {                                                                          \
    C v = R(C, 1), lo = R(C, 2), hi = R(C, 3);                                           \
    if ((v < lo || v > hi) && pc[4] == 1)                                                \
      return fail(TrapKind::IndexOutOfRange, pc,                                         \
                  fmt::format("index {} outside {}..{}", +v, +lo, +hi));                 \
    if (v < lo || v > hi)                                                                \
      return fail(TrapKind::RangeError, pc,                                              \
                  fmt::format("value {} outside subrange {}..{}", +v, +lo, +hi));        \
    NEXT(4);                                                                             \
  }                                                                                      \
  L_LOOPUP_##TN: {                                                                       \
    C v;                                                                                 \
    bool ovf = __builtin_add_overflow(R(C, 1), R(C, 2), &v);                             \
    W(C, 1, v);                                                                          \
    if (!ovf && v <= R(C, 3)) {                                                          \
      BACKJUMP();                                                                        \
      pc = code + pc[4];                                                                 \
      DISPATCH();                                                                        \
    }                                                                                    \
    NEXT(4);                                                                             \
  }                                                                                      \
  L_LOOPDN_##TN: {                                                                       \
    C v;                                                                                 \
    bool ovf = __builtin_add_overflow(R(C, 1), R(C, 2), &v);                             \
    W(C, 1, v);                                                                          \
    if (!ovf && v >= R(C, 3)) {                                                          \
      BACKJUMP();                                                                        \
      pc = code + pc[4];                                                                 \
      DISPATCH();                                                                        \
    }                                                                                    \
    NEXT(4);                                                                             \
  }
  PLCFI_INT_TYPES(INT_IMPL)
#undef INT_IMPL

L_ROUND_F32: W(float, 1, round_even(R(float, 2))); NEXT(2);
L_ROUND_F64: W(double, 1, round_even(R(double, 2))); NEXT(2);
L_TRUNC_F32: W(float, 1, std::trunc(R(float, 2))); NEXT(2);
L_TRUNC_F64: W(double, 1, std::trunc(R(double, 2))); NEXT(2);

// Element access into frame arrays, bounds-checked: LDX/STX (elementary elements),
// LDXS/STXS (a field of a structure element), each with a DINT index or, as the H
// variants, an INT index (no DINT copy of a loop counter per access).
#define ELEM_INDEX_AS(v, IT, k)                                                                 \
  int64_t v = static_cast<int64_t>(R(IT, k)) - static_cast<int32_t>(pc[k + 1]);                 \
  if (v < 0 || v >= static_cast<int64_t>(pc[k + 2]))                                            \
    return fail(TrapKind::IndexOutOfRange, pc,                                                  \
                app_->index_message(static_cast<uint32_t>(pc - code), R(IT, k), static_cast<int32_t>(pc[k + 1]), pc[k + 2]));
#define ELEM_INDEX(IT, k) ELEM_INDEX_AS(i, IT, k)
#define ELEM_IMPL(H, IT, N, T)                                                                 \
  L_LDX##H##N: { ELEM_INDEX(IT, 3) W(T, 1, ld<T>(base + pc[2] + i * N)); NEXT(5); }            \
  L_STX##H##N: { ELEM_INDEX(IT, 2) st<T>(base + pc[1] + i * N, R(T, 5)); NEXT(5); }            \
  L_LDXS##H##N: { ELEM_INDEX(IT, 3) W(T, 1, ld<T>(base + pc[2] + i * pc[6] + pc[7])); NEXT(7); } \
  L_STXS##H##N: { ELEM_INDEX(IT, 2) st<T>(base + pc[1] + i * pc[5] + pc[6], R(T, 7)); NEXT(7); }
  ELEM_IMPL(, int32_t, 1, uint8_t)
  ELEM_IMPL(, int32_t, 2, uint16_t)
  ELEM_IMPL(, int32_t, 4, uint32_t)
  ELEM_IMPL(, int32_t, 8, uint64_t)
  ELEM_IMPL(H, int16_t, 1, uint8_t)
  ELEM_IMPL(H, int16_t, 2, uint16_t)
  ELEM_IMPL(H, int16_t, 4, uint32_t)
  ELEM_IMPL(H, int16_t, 8, uint64_t)
#undef ELEM_IMPL
  // The same with a DINT index the compiler proved in range: no check.
#define ELEMN_IMPL(N, T)                                                                        \
  L_LDXN##N: W(T, 1, ld<T>(base + pc[2] + (int64_t{R(int32_t, 3)} - static_cast<int32_t>(pc[4])) * N)); NEXT(5); \
  L_STXN##N: st<T>(base + pc[1] + (int64_t{R(int32_t, 2)} - static_cast<int32_t>(pc[3])) * N, R(T, 5)); NEXT(5); \
  L_LDXSN##N: W(T, 1, ld<T>(base + pc[2] + (int64_t{R(int32_t, 3)} - static_cast<int32_t>(pc[4])) * pc[6] + pc[7])); NEXT(7); \
  L_STXSN##N: st<T>(base + pc[1] + (int64_t{R(int32_t, 2)} - static_cast<int32_t>(pc[3])) * pc[5] + pc[6], R(T, 7)); NEXT(7);
  ELEMN_IMPL(1, uint8_t)
  ELEMN_IMPL(2, uint16_t)
  ELEMN_IMPL(4, uint32_t)
  ELEMN_IMPL(8, uint64_t)
#undef ELEMN_IMPL

// Rank-2 frame arrays (LDXX/STXX): both indices checked, the first one first, as the
// ELEM chain they replace checks them.
#define ELEM_INDEX2(v, k) ELEM_INDEX_AS(v, int32_t, k)
#define ELEM2_IMPL(N, T)                                                                        \
  L_LDXX##N: {                                                                                  \
    ELEM_INDEX2(i0, 3) ELEM_INDEX2(i1, 7)                                                       \
    W(T, 1, ld<T>(base + pc[2] + i0 * pc[6] + i1 * pc[10] + pc[11]));                           \
    NEXT(11);                                                                                   \
  }                                                                                             \
  L_STXX##N: {                                                                                  \
    ELEM_INDEX2(i0, 2) ELEM_INDEX2(i1, 6)                                                       \
    st<T>(base + pc[1] + i0 * pc[5] + i1 * pc[9] + pc[10], R(T, 11));                           \
    NEXT(11);                                                                                   \
  }
  ELEM2_IMPL(1, uint8_t)
  ELEM2_IMPL(2, uint16_t)
  ELEM2_IMPL(4, uint32_t)
  ELEM2_IMPL(8, uint64_t)
#undef ELEM2_IMPL
  // LDXXN/STXXN: both indices proven in range by the compiler; lower bounds in the offset.
#define ELEM2N_IMPL(N, T)                                                                       \
  L_LDXXN##N: {                                                                                 \
    const int64_t at = int64_t{pc[2]} + int64_t{R(int32_t, 3)} * pc[6] + int64_t{R(int32_t, 7)} * pc[10] + \
                       static_cast<int32_t>(pc[11]);                                            \
    W(T, 1, ld<T>(base + at));                                                                  \
    NEXT(11);                                                                                   \
  }                                                                                             \
  L_STXXN##N: {                                                                                 \
    const int64_t at = int64_t{pc[1]} + int64_t{R(int32_t, 2)} * pc[5] + int64_t{R(int32_t, 6)} * pc[9] + \
                       static_cast<int32_t>(pc[10]);                                            \
    st<T>(base + at, R(T, 11));                                                                 \
    NEXT(11);                                                                                   \
  }
  ELEM2N_IMPL(1, uint8_t)
  ELEM2N_IMPL(2, uint16_t)
  ELEM2N_IMPL(4, uint32_t)
  ELEM2N_IMPL(8, uint64_t)
#undef ELEM2N_IMPL
  // An index linear in two variables (LDXL/STXL): x * m + y in DINT arithmetic, wrapping
  // as MUL_I32 and ADD_I32 do, then one bounds check.
#define ELEM_LINEAR(k)                                                                          \
  const int32_t lin = wadd<int32_t>(wmul<int32_t>(R(int32_t, k), R(int32_t, k + 1)), R(int32_t, k + 2)); \
  int64_t i = static_cast<int64_t>(lin) - static_cast<int32_t>(pc[k + 3]);                      \
  if (i < 0 || i >= static_cast<int64_t>(pc[k + 4]))                                            \
    return fail(TrapKind::IndexOutOfRange, pc,                                                  \
                fmt::format("index {} outside {}..{}", lin, static_cast<int32_t>(pc[k + 3]),     \
                            static_cast<int64_t>(static_cast<int32_t>(pc[k + 3])) + pc[k + 4] - 1));
#define ELEML_IMPL(N, T)                                                                        \
  L_LDXL##N: { ELEM_LINEAR(3) W(T, 1, ld<T>(base + pc[2] + i * N)); NEXT(7); }                  \
  L_STXL##N: { ELEM_LINEAR(2) st<T>(base + pc[1] + i * N, R(T, 7)); NEXT(7); }
  ELEML_IMPL(1, uint8_t)
  ELEML_IMPL(2, uint16_t)
  ELEML_IMPL(4, uint32_t)
  ELEML_IMPL(8, uint64_t)
#undef ELEML_IMPL
  // Whole elements of structure arrays, copied as blocks (move_block, as LDIN/STIN do).
L_LDXB: {
  ELEM_INDEX2(i, 3)
  move_element(base + pc[1], base + pc[2] + i * pc[6] + pc[7], pc[8]);
  NEXT(8);
}
L_STXB: {
  ELEM_INDEX2(i, 2)
  move_element(base + pc[1] + i * pc[5] + pc[6], base + pc[7], pc[8]);
  NEXT(8);
}
#undef ELEM_INDEX2
  // Rank-2 elements in a FOR loop: the offset of the row (the part the loop does not
  // change) from a slot ROWS set on the loop's entry, plus counter * stride. The compiler
  // proved both indices inside their dimensions, as for LDXXN.
#define ROW_IMPL(N, T)                                                                          \
  L_LDXR##N:                                                                                    \
    W(T, 1, ld<T>(base + (int64_t{R(int32_t, 2)} + int64_t{R(int32_t, 3)} * static_cast<int32_t>(pc[4])))); \
    NEXT(6);                                                                                    \
  L_STXR##N:                                                                                    \
    st<T>(base + (int64_t{R(int32_t, 1)} + int64_t{R(int32_t, 2)} * static_cast<int32_t>(pc[3])), R(T, 6)); \
    NEXT(6);
  ROW_IMPL(1, uint8_t)
  ROW_IMPL(2, uint16_t)
  ROW_IMPL(4, uint32_t)
  ROW_IMPL(8, uint64_t)
#undef ROW_IMPL
L_ROWS: {
  for (uint32_t e = 0, n = pc[2]; e < n; ++e)
    W(int32_t, 3 + 4 * e,
      static_cast<int32_t>(int64_t{static_cast<int32_t>(pc[4 + 4 * e])} + int64_t{R(int32_t, 5 + 4 * e)} * static_cast<int32_t>(pc[6 + 4 * e])));
  pc += 1 + pc[1];
  DISPATCH();
}

L_MADD_I32: W(int32_t, 1, wadd<int32_t>(wmul<int32_t>(R(int32_t, 2), R(int32_t, 3)), R(int32_t, 4))); NEXT(4);

// Float compare-and-jump, taken when the comparison fails (NaN included).
L_JNLT_F32: if (!(R(float, 2) < R(float, 3))) TAKE(1); FALL(3);
L_JNGE_F32: if (!(R(float, 2) >= R(float, 3))) TAKE(1); FALL(3);
L_JNLT_F64: if (!(R(double, 2) < R(double, 3))) TAKE(1); FALL(3);
L_JNGE_F64: if (!(R(double, 2) >= R(double, 3))) TAKE(1); FALL(3);

#define DIVK_IMPL(NAME, T, IS_MOD)                                                      \
  L_##NAME: {                                                                           \
    uint64_t m = static_cast<uint64_t>(pc[3]) | (static_cast<uint64_t>(pc[4]) << 32);   \
    W(T, 1, (divk<T, IS_MOD>(R(T, 2), m, static_cast<int32_t>(pc[5]))));                \
    NEXT(5);                                                                            \
  }
  DIVK_IMPL(DIVK_I16, int16_t, false)
  DIVK_IMPL(DIVK_I32, int32_t, false)
  DIVK_IMPL(MODK_I16, int16_t, true)
  DIVK_IMPL(MODK_I32, int32_t, true)
#undef DIVK_IMPL


// The first instruction: its effect (defining v, the value it stored) and its length.
#define HV_SIMPLE(T, e) T v = (e); W(T, 1, v);
#define HV_MOV1 HV_SIMPLE(uint8_t, R(uint8_t, 2))
#define HV_MOV2 HV_SIMPLE(uint16_t, R(uint16_t, 2))
#define HV_MOV4 HV_SIMPLE(uint32_t, R(uint32_t, 2))
#define HV_MOV8 HV_SIMPLE(uint64_t, R(uint64_t, 2))
#define HV_ADD_I32 HV_SIMPLE(int32_t, wadd<int32_t>(R(int32_t, 2), R(int32_t, 3)))
#define HV_SUB_I32 HV_SIMPLE(int32_t, wsub<int32_t>(R(int32_t, 2), R(int32_t, 3)))
#define HV_MUL_I32 HV_SIMPLE(int32_t, wmul<int32_t>(R(int32_t, 2), R(int32_t, 3)))
#define HV_MADD_I32 HV_SIMPLE(int32_t, wadd<int32_t>(wmul<int32_t>(R(int32_t, 2), R(int32_t, 3)), R(int32_t, 4)))
#define HV_ADD_F32 HV_SIMPLE(float, R(float, 2) + R(float, 3))
#define HV_SUB_F32 HV_SIMPLE(float, R(float, 2) - R(float, 3))
#define HV_MUL_F32 HV_SIMPLE(float, R(float, 2) * R(float, 3))
#define HV_EQ_I16 HV_SIMPLE(uint8_t, R(int16_t, 2) == R(int16_t, 3))
#define HV_BNOT HV_SIMPLE(uint8_t, static_cast<uint8_t>(R(uint8_t, 2) ^ 1u))
#define HV_BAND HV_SIMPLE(uint8_t, static_cast<uint8_t>(R(uint8_t, 2) & R(uint8_t, 3)))
#define HV_CVT_I16_I32 HV_SIMPLE(int32_t, R(int16_t, 2))
#define HV_DIVK(T, IS_MOD) \
  HV_SIMPLE(T, (divk<T, IS_MOD>(R(T, 2), static_cast<uint64_t>(pc[3]) | (static_cast<uint64_t>(pc[4]) << 32), static_cast<int32_t>(pc[5]))))
#define HV_MODK_I32 HV_DIVK(int32_t, true)
#define HV_DIVK_I32 HV_DIVK(int32_t, false)
#define HV_LDXH4 ELEM_INDEX(int16_t, 3) HV_SIMPLE(int32_t, ld<int32_t>(base + pc[2] + i * 4))
#define HV_COV taken[pc[1] >> 6] |= uint64_t(1) << (pc[1] & 63); [[maybe_unused]] int v = 0;
#define HV_JUMP_IF(c) if (c) TAKE(1); [[maybe_unused]] int v = 0;
#define HV_JMPF HV_JUMP_IF(!ld<uint8_t>(base + pc[2]))
#define HV_JGE_I32 HV_JUMP_IF(R(int32_t, 2) >= R(int32_t, 3))
#define HV_JNLT_F32 HV_JUMP_IF(!(R(float, 2) < R(float, 3)))
#define HL_MOV1 2
#define HL_MOV2 2
#define HL_MOV4 2
#define HL_MOV8 2
#define HL_ADD_I32 3
#define HL_SUB_I32 3
#define HL_MUL_I32 3
#define HL_MADD_I32 4
#define HL_ADD_F32 3
#define HL_SUB_F32 3
#define HL_MUL_F32 3
#define HL_EQ_I16 3
#define HL_BNOT 2
#define HL_BAND 3
#define HL_CVT_I16_I32 2
#define HL_MODK_I32 5
#define HL_DIVK_I32 5
#define HL_LDXH4 5
#define HL_COV 1
#define HL_JMPF 2
#define HL_JGE_I32 3
#define HL_JNLT_F32 3
// The second instruction with X (the value the first stored) as its operand b (_B) or c
// (_C): TV_ ends the handler with END (NEXT, or THEN_ for a third), MV_ defines OUT as the
// value it stored, for a third instruction to take in turn.
#define OPND_B(T, X) (static_cast<T>(X)), R(T, 3)
#define OPND_C(T, X) R(T, 2), (static_cast<T>(X))
#define TV_ARITH(T, f, K, END, X) W(T, 1, f<T>(OPND_##K(T, X))); END(3);
#define MV_ARITH(T, f, K, X, OUT) T OUT = f<T>(OPND_##K(T, X)); W(T, 1, OUT);
#define TV_ADD_I32(K, END, X) TV_ARITH(int32_t, wadd, K, END, X)
#define TV_SUB_I32(K, END, X) TV_ARITH(int32_t, wsub, K, END, X)
#define TV_MUL_I32(K, END, X) TV_ARITH(int32_t, wmul, K, END, X)
#define TV_MUL_F32(K, END, X) TV_ARITH(float, fmul, K, END, X)
#define TV_MADD_I32(K, END, X) W(int32_t, 1, wadd<int32_t>(wmul<int32_t>(OPND_##K(int32_t, X)), R(int32_t, 4))); END(4);
#define TV_ADD_F32(K, END, X) TV_ARITH(float, fadd, K, END, X)
#define TV_BAND(K, END, X) TV_ARITH(uint8_t, band, K, END, X)
#define MV_ADD_I32(K, X, OUT) MV_ARITH(int32_t, wadd, K, X, OUT)
#define MV_MUL_I32(K, X, OUT) MV_ARITH(int32_t, wmul, K, X, OUT)
#define MV_MUL_F32(K, X, OUT) MV_ARITH(float, fmul, K, X, OUT)
#define MV_ADD_F32(K, X, OUT) MV_ARITH(float, fadd, K, X, OUT)
// A jump ends the handler: its fall-through marks the arm it enters, as FALL does (END unused).
#define TV_JGE_I32(K, END, X) if (jge<int32_t>(OPND_##K(int32_t, X))) TAKE(1); FALL(3);
#define TV_JNLT_F32(K, END, X) if (jnlt(OPND_##K(float, X))) TAKE(1); FALL(3);
#define DIVK_OF(T, IS_MOD, X) \
  (divk<T, IS_MOD>(static_cast<T>(X), static_cast<uint64_t>(pc[3]) | (static_cast<uint64_t>(pc[4]) << 32), static_cast<int32_t>(pc[5])))
#define TV_MODK_I32(K, END, X) W(int32_t, 1, DIVK_OF(int32_t, true, X)); END(5);
#define TV_DIVK_I32(K, END, X) W(int32_t, 1, DIVK_OF(int32_t, false, X)); END(5);
#define MV_DIVK_I32(K, X, OUT) int32_t OUT = DIVK_OF(int32_t, false, X); W(int32_t, 1, OUT);

// Triples: a pair and the instruction after it, run by its own handler.
#define FUSED_P(H, T) L_P_##H##_##T: { HV_##H (void)v; pc += 1 + HL_##H; goto L_##T; }
#define FUSED_F(H, T, K) L_F_##H##_##T##_##K: { HV_##H pc += 1 + HL_##H; TV_##T(K, NEXT, v) }
#define FUSED_P3(H, T, U) \
  L_P3_##H##_##T##_##U: { { HV_##H (void)v; pc += 1 + HL_##H; } { HV_##T (void)v; pc += 1 + HL_##T; } goto L_##U; }
#define FUSED_FF3(H, T, K, U, K2)                                               \
  L_FF3_##H##_##T##_##K##_##U##_##K2: {                                         \
    HV_##H pc += 1 + HL_##H;                                                    \
    MV_##T(K, v, w) pc += 1 + HL_##T;                                           \
    TV_##U(K2, NEXT, w)                                                         \
  }
  PLCFI_FUSED(FUSED_P, FUSED_F, FUSED_P3, FUSED_FF3)
  // Rules 20 and 22 (PLCFI_ELEM_USES): the element load as its instruction does it (a
  // refused index traps at the load), then the next instruction's own handler.
#define EU_LOAD_LDX(N, T) ELEM_INDEX(int32_t, 3) W(T, 1, ld<T>(base + pc[2] + i * N)); pc += 6;
#define EU_LOAD_LDXN(N, T) W(T, 1, ld<T>(base + pc[2] + (int64_t{R(int32_t, 3)} - static_cast<int32_t>(pc[4])) * N)); pc += 6;
#define EU_LOAD_LDXS(N, T) ELEM_INDEX(int32_t, 3) W(T, 1, ld<T>(base + pc[2] + i * pc[6] + pc[7])); pc += 8;
#define EU_LOAD_LDXSN(N, T)                                                                                \
  W(T, 1, ld<T>(base + pc[2] + (int64_t{R(int32_t, 3)} - static_cast<int32_t>(pc[4])) * pc[6] + pc[7])); \
  pc += 8;
#define EU_LOAD_LDXL(N, T) ELEM_LINEAR(3) W(T, 1, ld<T>(base + pc[2] + i * N)); pc += 8;
#define EU_LOAD_LDXR(N, T) \
  W(T, 1, ld<T>(base + (int64_t{R(int32_t, 2)} + int64_t{R(int32_t, 3)} * static_cast<int32_t>(pc[4])))); pc += 7;
#define EU_T1 uint8_t
#define EU_T2 uint16_t
#define EU_T4 uint32_t
#define FUSED_EU(L, N, J) L_EU_##L##N##_##J: { EU_LOAD_##L(N, EU_T##N) goto L_##J; }
  PLCFI_ELEM_USES(FUSED_EU)
#undef FUSED_EU
#undef EU_LOAD_LDX
#undef EU_LOAD_LDXN
#undef EU_LOAD_LDXS
#undef EU_LOAD_LDXSN
#undef EU_LOAD_LDXL
#undef EU_LOAD_LDXR
#undef EU_T1
#undef EU_T2
#undef EU_T4
  // Rule 21: items[j] := items[j - 1], a structure (or FB instance) element assigned from
  // another: the LDXB into a temporary as it does it, then the STXB's store, with its own
  // index check, from the source element itself. The temporary holds the same bytes, but
  // reading back a block just stored in overlapping pieces (12 bytes as two 8-byte moves)
  // stalls the load until the stores are done, in every pass of an insertion sort.
#define ELEMENT_COPY(TEMPORARY)                                                          \
  ELEM_INDEX_AS(i, int32_t, 3)                                                           \
  const uint8_t* const from = base + pc[2] + i * pc[6] + pc[7];                          \
  const uint32_t size = pc[8];                                                           \
  if ((TEMPORARY) || pc[9 + 8] != size) move_element(base + pc[1], from, size);         \
  pc += 9;                                                                               \
  if (pc[8] != size) goto L_STXB; /* not the block the LDXB loaded: the plain STXB */   \
  ELEM_INDEX_AS(j, int32_t, 2)                                                           \
  move_element(base + pc[1] + j * pc[5] + pc[6], from, size);                            \
  NEXT(8);
L_EB_LDXB_STXB: { ELEMENT_COPY(true) }
  // Rule 31: the pair whose temporary nothing reads back (FusedRule::dead_head): one copy,
  // from element to element (move_element copies whole, so the two may be one element).
  // The plain STXB, where it runs instead, reads the temporary: it is written then.
L_EB_LDXB_STXB_DIRECT: { ELEMENT_COPY(false) }
#undef ELEMENT_COPY
  // Rule 30: a CASE on a selector narrower than DINT: the conversion's store as it does
  // it, and the table jump on the value converted, not on the value reloaded from where
  // the conversion stored it (a store-to-load wait on the way to the next pc).
#define CASE_ON(N, T)                                                                 \
  L_CJ_##N: {                                                                         \
    const int32_t v = static_cast<int32_t>(ld<T>(base + pc[2]));                      \
    st<int32_t>(base + pc[1], v);                                                     \
    pc += 3;                                                                          \
    const int64_t i = int64_t{v} - static_cast<int32_t>(pc[2]);                       \
    pc = i >= 0 && i < static_cast<int64_t>(pc[3]) ? code + pc[5 + i] : code + pc[4]; \
    COVER(pc);                                                                        \
    DISPATCH();                                                                       \
  }
  CASE_ON(I16, int16_t)
  CASE_ON(U16, uint16_t)
  CASE_ON(I8, int8_t)
  CASE_ON(U8, uint8_t)
#undef CASE_ON
  // A reduction loop as a whole (find_reductions, run_reduction).
L_REDUCE: {
  const auto head = static_cast<uint32_t>(pc - code);
  const auto r = std::lower_bound(reductions_.begin(), reductions_.end(), head,
                                  [](const Reduction& x, uint32_t h) { return x.head < h; });
  const ReductionExit x = run_reduction(*r, base, budget);
  pc = code + x.pc;
  if (x.how == ReductionExit::Done) DISPATCH();
  if (x.how == ReductionExit::Plain) goto* static_cast<const void*>(handlers + kOffsets[app_->code[x.pc]]);
  return fail(TrapKind::Watchdog, pc, watchdog_message(budget_limit_));
}
#undef FUSED_FF3
#undef FUSED_P
#undef FUSED_F
#undef FUSED_P3
#undef ELEM_INDEX
#undef ELEM_INDEX_AS
#undef ELEM_LINEAR

#undef LABEL_OFFSET
#undef PLCFI_FUSED
#undef PLCFI_ELEM_USES
#undef PLCFI_ELEM_USES_OF
#undef PLCFI_ELEM_JUMP
#undef PLCFI_ELEM_TEST
#undef DISPATCH
#undef NEXT
#undef R
#undef W
#undef PTR
#undef BACKJUMP
#undef TAKE
#undef COVER
#undef FALL
}
#pragma GCC diagnostic pop

// ----------------------------------------------------------------- assertions

namespace {
std::string format_value(ValueKind k, const uint8_t* p) {
  switch (k) {
    case ValueKind::Bool: return *p ? "TRUE" : "FALSE";
    case ValueKind::I8: return std::to_string(ld<int8_t>(p));
    case ValueKind::I16: return std::to_string(ld<int16_t>(p));
    case ValueKind::I32: return std::to_string(ld<int32_t>(p));
    case ValueKind::I64: case ValueKind::Enum: return std::to_string(ld<int64_t>(p));
    case ValueKind::U8: return std::to_string(ld<uint8_t>(p));
    case ValueKind::U16: return std::to_string(ld<uint16_t>(p));
    case ValueKind::U32: case ValueKind::Ref: return std::to_string(ld<uint32_t>(p));
    case ValueKind::U64: return std::to_string(ld<uint64_t>(p));
    case ValueKind::F32: return fmt::format("{}", ld<float>(p));
    case ValueKind::F64: return fmt::format("{}", ld<double>(p));
    case ValueKind::Time: {
      int64_t ns = ld<int64_t>(p);
      if (ns % 1'000'000 == 0) return fmt::format("T#{}ms", ns / 1'000'000);
      return fmt::format("T#{}ns", ns);
    }
    case ValueKind::UTime: {  // above INT64_MAX no TIME holds it: LTIME#
      uint64_t ns = ld<uint64_t>(p);
      const char* prefix = ns > static_cast<uint64_t>(INT64_MAX) ? "LTIME#" : "T#";
      if (ns % 1'000'000 == 0) return fmt::format("{}{}ms", prefix, ns / 1'000'000);
      return fmt::format("{}{}ns", prefix, ns);
    }
    case ValueKind::Date: return date_literal(ld<int64_t>(p));
    case ValueKind::Tod: return tod_literal(ld<int64_t>(p));
    case ValueKind::Dt: return dt_literal(ld<int64_t>(p));
    case ValueKind::String: return "'" + std::string(reinterpret_cast<const char*>(p)) + "'";
    case ValueKind::WString: return "'" + utf16_to_utf8(load_wstring(p, SIZE_MAX)) + "'";  // shown as UTF-8
  }
  return "?";
}

template <class T>
int cmp3(const uint8_t* a, const uint8_t* b) {
  T x = ld<T>(a), y = ld<T>(b);
  return x < y ? -1 : (y < x ? 1 : 0);
}

int compare(ValueKind k, const uint8_t* a, const uint8_t* b) {
  switch (k) {
    case ValueKind::Bool: case ValueKind::U8: return cmp3<uint8_t>(a, b);
    case ValueKind::I8: return cmp3<int8_t>(a, b);
    case ValueKind::I16: return cmp3<int16_t>(a, b);
    case ValueKind::I32: return cmp3<int32_t>(a, b);
    case ValueKind::I64: case ValueKind::Time: case ValueKind::Date: case ValueKind::Tod:
    case ValueKind::Dt: case ValueKind::Enum: return cmp3<int64_t>(a, b);
    case ValueKind::U16: return cmp3<uint16_t>(a, b);
    case ValueKind::U32: case ValueKind::Ref: return cmp3<uint32_t>(a, b);
    case ValueKind::U64: case ValueKind::UTime: return cmp3<uint64_t>(a, b);
    case ValueKind::F32: return cmp3<float>(a, b);
    case ValueKind::F64: return cmp3<double>(a, b);
    case ValueKind::String: {
      int c = std::strcmp(reinterpret_cast<const char*>(a), reinterpret_cast<const char*>(b));
      return c < 0 ? -1 : (c > 0 ? 1 : 0);
    }
    case ValueKind::WString: return wscmp(a, b);
  }
  return 0;
}
}  // namespace

namespace {

bool arrays_fit(const Machine& m, const ArrayDiffShape& s, uint32_t addr_e, uint32_t addr_a) {
  auto fits = [&](uint32_t addr, uint32_t count, uint32_t size) {
    return addr != 0 && static_cast<uint64_t>(addr) + static_cast<uint64_t>(count) * size <= m.mem_size();
  };
  return fits(addr_e, s.count_e, s.elem_size) && fits(addr_a, s.count_a, s.elem_size_a);
}

// The index of the first element that differs (REALs: by more than delta), or -1.
int64_t first_difference(const Machine& m, const ArrayDiffShape& s, uint32_t addr_e, uint32_t addr_a, double delta) {
  const auto kind = static_cast<ValueKind>(s.kind);
  for (uint32_t i = 0; i < s.count_e; ++i) {
    const uint8_t* x = m.mem() + addr_e + static_cast<size_t>(i) * s.elem_size;
    const uint8_t* y = m.mem() + addr_a + static_cast<size_t>(i) * s.elem_size_a;
    bool same;
    if (kind == ValueKind::F32) same = std::fabs(static_cast<double>(ld<float>(x)) - ld<float>(y)) <= delta;
    else if (kind == ValueKind::F64) same = std::fabs(ld<double>(x) - ld<double>(y)) <= delta;
    else same = compare(kind, x, y) == 0;
    if (!same) return i;
  }
  return -1;
}

// An element as TcUnit's assertion messages show it: bit strings in hex, REALs with a
// decimal point (-23.0).
std::string tcunit_element(ValueKind kind, uint32_t hex_digits, const uint8_t* p) {
  if (hex_digits) {
    uint64_t v = 0;
    std::memcpy(&v, p, std::min<uint32_t>(hex_digits / 2, 8));
    return fmt::format("0x{:0{}X}", v, hex_digits);
  }
  std::string s = format_value(kind, p);
  if ((kind == ValueKind::F32 || kind == ValueKind::F64) && s.find_first_of(".eni") == std::string::npos) s += ".0";
  return s;
}

// TcUnit's record of an array comparison (tcunit_abi::kSep between the parts).
std::string tcunit_array_record(Machine& m, const ArrayDiffShape& s, uint32_t addr_e, uint32_t addr_a, double delta) {
  const auto kind = static_cast<ValueKind>(s.kind);
  const char sep = '\x1f';
  auto bounds = [&](const int32_t* lo, const uint32_t* ext) {
    std::string b, x;
    for (uint32_t k = 0; k < s.ndims; ++k) {
      b += fmt::format("{}{}..{}", k ? "," : "", lo[k], static_cast<int64_t>(lo[k]) + ext[k] - 1);
      x += fmt::format("{}{}", k ? "x" : "", ext[k]);
    }
    return fmt::format("[{}] ({})", b, x);
  };
  std::string size_e, size_a;
  if (s.ndims == 1) {
    size_e = fmt::format("SIZE = {}", s.extent[0]);
    size_a = fmt::format("SIZE = {}", s.extent_a[0]);
  } else {
    size_e = "SIZE = " + bounds(s.lo, s.extent);
    size_a = "SIZE = " + bounds(s.lo_a, s.extent_a);
  }
  const std::string key = size_e + "|" + size_a;
  bool same_shape = true;
  for (uint32_t k = 0; k < s.ndims; ++k) same_shape = same_shape && s.extent[k] == s.extent_a[k];
  if (!same_shape) return std::string("S") + sep + size_e + sep + size_a + sep + key;
  if (!arrays_fit(m, s, addr_e, addr_a))
    return std::string("S") + sep + "an array outside the memory" + sep + "" + sep + key;  // not reached
  const int64_t at = first_difference(m, s, addr_e, addr_a, delta);
  if (at >= 0) {
    const auto i = static_cast<uint32_t>(at);
    const uint8_t* x = m.mem() + addr_e + static_cast<size_t>(i) * s.elem_size;
    const uint8_t* y = m.mem() + addr_a + static_cast<size_t>(i) * s.elem_size_a;
    std::string ie, ia;
    uint32_t rest = i;
    for (uint32_t k = s.ndims; k-- > 0;) {
      const uint32_t ext = s.extent[k] ? s.extent[k] : 1;
      const std::string sep_k = ie.empty() ? "" : ",";
      ie = fmt::format("{}{}{}", static_cast<int64_t>(s.lo[k]) + rest % ext, sep_k, ie);
      ia = fmt::format("{}{}{}", static_cast<int64_t>(s.lo_a[k]) + rest % ext, sep_k, ia);
      rest /= ext;
    }
    return std::string("C") + sep + fmt::format("ARRAY[{}] = {}", ie, tcunit_element(kind, s.hex_digits, x)) + sep +
           fmt::format("ARRAY[{}] = {}", ia, tcunit_element(kind, s.hex_digits, y)) + sep + key;
  }
  return std::string("=") + sep + size_e + sep + size_a + sep + key;
}

}  // namespace

void array_difference(Machine& m, uint32_t cap, uint8_t* out, uint8_t* blk, uint8_t* shape_bytes, uint8_t*) {
  ArrayDiffShape s;
  std::memcpy(&s, shape_bytes, sizeof s);
  const uint32_t addr_e = ld<uint32_t>(blk), addr_a = ld<uint32_t>(blk + 4);
  const double delta = ld<double>(blk + 8);
  const auto kind = static_cast<ValueKind>(s.kind);
  std::string msg;
  if (s.style == 1) {
    msg = tcunit_array_record(m, s, addr_e, addr_a, delta);
  } else if (s.count_e != s.count_a) {
    msg = fmt::format("EXP: an array of {} elements, ACT: {} elements", s.count_e, s.count_a);
  } else if (!arrays_fit(m, s, addr_e, addr_a)) {
    msg = "an array outside the memory";  // the compiler passes whole arrays: not reached
  } else if (const int64_t at = first_difference(m, s, addr_e, addr_a, delta); at >= 0) {
    const auto i = static_cast<uint32_t>(at);
    const uint8_t* x = m.mem() + addr_e + static_cast<size_t>(i) * s.elem_size;
    const uint8_t* y = m.mem() + addr_a + static_cast<size_t>(i) * s.elem_size_a;
    // The element's index in the expected array, one number per dimension (row-major).
    std::string index;
    uint32_t rest = i;
    for (uint32_t k = s.ndims; k-- > 0;) {
      const uint32_t ext = s.extent[k] ? s.extent[k] : 1;
      index = fmt::format("{}{}", static_cast<int64_t>(s.lo[k]) + rest % ext, index.empty() ? "" : "," + index);
      rest /= ext;
    }
    msg = fmt::format("EXP: {}, ACT: {} at [{}]", format_value(kind, x), format_value(kind, y), index);
  }
  const size_t n = std::min<size_t>(msg.size(), cap);
  std::memcpy(out, msg.data(), n);
  out[n] = 0;
}

bool Machine::do_assert(const uint32_t* pc, uint8_t* base) {
  auto kind = static_cast<AssertKind>(pc[1] >> 8);
  auto vk = static_cast<ValueKind>(pc[1] & 0xffu);
  const uint8_t* a = base + pc[2];
  const uint8_t* b = base + pc[3];
  bool ok = true;
  std::string msg;
  switch (kind) {
    case AssertKind::True:
    case AssertKind::False: {
      bool v = *a != 0;
      ok = kind == AssertKind::True ? v : !v;
      if (!ok) msg = fmt::format("expected {}, actual {}", kind == AssertKind::True ? "TRUE" : "FALSE", v ? "TRUE" : "FALSE");
      break;
    }
    case AssertKind::Near: {
      double x = vk == ValueKind::F32 ? ld<float>(a) : ld<double>(a);
      double y = vk == ValueKind::F32 ? ld<float>(b) : ld<double>(b);
      double tol = ld<double>(base + pc[4]);
      ok = std::fabs(x - y) <= tol;
      // ASSERT_NEAR(actual, expected, tol), like ASSERT_EQ(actual, expected).
      if (!ok) msg = fmt::format("expected {} +/- {}, actual {}", y, tol, x);
      break;
    }
    case AssertKind::Called:
    case AssertKind::CallCount: {
      uint32_t inst = ld<uint32_t>(a);
      if (inst == 0 || inst + 8 > mem_.size()) return fail(TrapKind::NullReference, pc, "not an FB instance");
      uint32_t count = ld<uint32_t>(mem_.data() + inst + 4);
      if (kind == AssertKind::Called) {
        ok = count > 0;
        if (!ok) msg = "expected the mocked instance to be called, it was not";
      } else {
        int64_t want = ld<int64_t>(b);
        ok = static_cast<int64_t>(count) == want;
        if (!ok) msg = fmt::format("expected {} calls, actual {}", want, count);
      }
      break;
    }
    default: {
      int c = compare(vk, a, b);
      const char* rel = "";
      switch (kind) {
        case AssertKind::Eq: ok = c == 0; rel = "="; break;
        case AssertKind::Neq: ok = c != 0; rel = "<>"; break;
        case AssertKind::Gt: ok = c > 0; rel = ">"; break;
        case AssertKind::Lt: ok = c < 0; rel = "<"; break;
        case AssertKind::Ge: ok = c >= 0; rel = ">="; break;
        case AssertKind::Le: ok = c <= 0; rel = "<="; break;
        default: break;
      }
      if (!ok) {
        // ASSERT_EQ(actual, expected): the test-file format puts the value under test
        // first (ASSERT_EQ(uut.count, 3)).
        if (kind == AssertKind::Eq)
          msg = fmt::format("expected {}, actual {}", format_value(vk, b), format_value(vk, a));
        else
          msg = fmt::format("expected {} {} {}", format_value(vk, a), rel, format_value(vk, b));
      }
      break;
    }
  }
  if (ok) return true;
  // A trailing message string, when given, is in slot e (0 = none).
  if (pc[5] != 0) msg += fmt::format(" ({})", reinterpret_cast<const char*>(base + pc[5]));
  assert_message_ = msg;
  return fail(TrapKind::AssertFailed, pc, msg);
}

}  // namespace plcfi::st

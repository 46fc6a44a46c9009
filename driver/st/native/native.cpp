// The native tier: bytecode -> C++ -> shared object (see native.hpp).
#include "native.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "vm/cpp_functions.hpp"
#include "vm/vm.hpp"

extern char** environ;

namespace plcfi::st {

namespace embedded {
extern const char* const kNativeAbiHpp;
extern const char* const kOpsHpp;
}  // namespace embedded

namespace {

namespace fs = std::filesystem;

const char* ctype(std::string_view tn) {
  if (tn == "I8") return "int8_t";
  if (tn == "I16") return "int16_t";
  if (tn == "I32") return "int32_t";
  if (tn == "I64") return "int64_t";
  if (tn == "U8") return "uint8_t";
  if (tn == "U16") return "uint16_t";
  if (tn == "U32") return "uint32_t";
  if (tn == "U64") return "uint64_t";
  if (tn == "F32") return "float";
  if (tn == "F64") return "double";
  return nullptr;
}

// FNV-1a, 64 bits: cache keys and function names (not a security boundary: the cache is
// the user's own folder).
uint64_t fnv1a(const std::string& s) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char ch : s) {
    h ^= ch;
    h *= 1099511628211ull;
  }
  return h;
}

bool is_int(std::string_view tn) { return tn[0] == 'I' || tn[0] == 'U'; }

// Code entries called directly (CALL/CALLA/CALLP/CALLS targets).
bool call_target(const uint32_t* w, uint32_t* target) {
  switch (static_cast<Op>(w[0])) {
    case Op::CALL:
    case Op::CALLA:
    case Op::CALLP:
    case Op::CALLS: *target = w[2]; return true;
    default: return false;
  }
}

// Jump targets inside the function (labels).
void jump_targets(const uint32_t* w, std::vector<uint32_t>* out) {
  auto op = static_cast<Op>(w[0]);
  switch (op) {
    case Op::JMP:
    case Op::JMPB: out->push_back(w[1]); return;
    case Op::JTAB:
      out->push_back(w[4]);
      for (uint32_t i = 0; i < w[3]; ++i) out->push_back(w[5 + i]);
      return;
    default: break;
  }
  if (is_conditional_jump(op)) out->push_back(w[1]);
  std::string_view n = op_info(op).name;
  if (n.rfind("LOOPUP_", 0) == 0 || n.rfind("LOOPDN_", 0) == 0) out->push_back(w[4]);
}

class Translator {
 public:
  Translator(const Application& app, size_t chunk_instructions)
      : app_(app), code_(app.code), chunk_instructions_(std::max<size_t>(chunk_instructions, 1)) {}

  // Translates every reachable entry. With split_bytes > 0 and more generated code than
  // that, the functions go to several units (see NativeProgram); else to one.
  NativeProgram run(size_t split_bytes) {
    NativeProgram prog;
    collect();
    size_t first_total = 0;
    for (uint32_t start : starts_) {
      uint32_t end = next_start(start);
      std::string f;
      if (function(start, end, &f)) {
        first_total += f.size();
        prog.entries.push_back(start);
        native_.insert(start);
      } else {
        prog.skipped.push_back(start);
      }
    }
    // Calls to entries left to the interpreter go through the host; the functions were
    // generated assuming all callees native, so regenerate with the final set.
    pass_ = 1;  // callees now known: the untranslated ones are called through the host
    summarize();
    // Split or not is decided before the final texts: a function's coverage words are
    // aligned with the bitset's in one unit (no shifts on the way out), relative to its
    // first branch in a split program (its text then does not depend on what lies before).
    prog.split = split_bytes > 0 && first_total > split_bytes;
    split_ = prog.split;
    struct Generated {
      uint32_t entry;
      std::string text;
      std::set<std::string> calls;
    };
    std::vector<Generated> gen;
    size_t total = 0;
    for (uint32_t e : prog.entries) {
      called_.clear();
      std::string f;
      function(e, next_start(e), &f);
      total += f.size();
      gen.push_back({e, std::move(f), called_});
    }
    // The relocations: each function's entry and first branch id, the only places its
    // text would otherwise name where it lies in the application's code.
    auto reloc = [&](uint32_t e) { return fmt::format("{{{}u, {}u}}", e, branch_base_.at(e)); };
    if (!prog.split) {
      std::ostringstream out;
      out << prelude();
      for (uint32_t e : prog.entries) out << "static int " << names_.at(e) << "(Ctx* c, uint8_t* base);\n";
      for (uint32_t e : prog.entries) out << "static const uint32_t R_" << names_.at(e) << "[2] = " << reloc(e) << ";\n";
      for (const Generated& g : gen) out << g.text;
      out << exports(prog.entries);
      prog.units.push_back({"all", out.str()});
      return prog;
    }
    // Units: every function of a POU (its body, methods, FB_init/FB_exit) in the unit its
    // name hashes to, so an edit to one POU's body changes one unit's text. 2 to 64 units
    // (a power of two) of about kUnitBytes each.
    size_t units = 2;
    while (units < 64 && total / units > kUnitBytes) units *= 2;
    std::vector<std::vector<const Generated*>> members(units);
    for (const Generated& g : gen) members[fnv1a(owners_.at(g.entry)) % units].push_back(&g);
    for (size_t u = 0; u < units; ++u) {
      if (members[u].empty()) continue;
      std::sort(members[u].begin(), members[u].end(),
                [&](const Generated* a, const Generated* b) { return names_.at(a->entry) < names_.at(b->entry); });
      std::set<std::string> declared;
      std::ostringstream out;
      out << prelude() << "#pragma GCC visibility push(hidden)\n";
      for (const Generated* g : members[u]) {
        out << "extern const uint32_t R_" << names_.at(g->entry) << "[2];\n";
        declared.insert(names_.at(g->entry));
      }
      for (const Generated* g : members[u]) declared.insert(g->calls.begin(), g->calls.end());
      for (const std::string& n : declared) out << "int " << n << "(Ctx* c, uint8_t* base);\n";
      for (const Generated* g : members[u]) out << g->text;
      out << "#pragma GCC visibility pop\n";
      prog.units.push_back({fmt::format("unit{:02}", u), out.str()});
    }
    // The index: the relocations and the entry table, the only text that changes when
    // code moves. Small, compiled every time something changed.
    std::ostringstream out;
    out << prelude() << "#pragma GCC visibility push(hidden)\n";
    for (uint32_t e : prog.entries) out << "int " << names_.at(e) << "(Ctx* c, uint8_t* base);\n";
    for (uint32_t e : prog.entries) out << "extern const uint32_t R_" << names_.at(e) << "[2] = " << reloc(e) << ";\n";
    out << "#pragma GCC visibility pop\n" << exports(prog.entries);
    prog.units.push_back({"index", out.str()});
    return prog;
  }

  // The generated code's own definitions, the same in every unit of a program.
  std::string prelude() const {
    std::string p =
        "// Generated by plcfi: the native tier of an application (do not edit).\n"
        "#include <cstdint>\n#include <cstdlib>\n#include <cstring>\n#include \"plcfi_native_abi.hpp\"\n#include \"plcfi_ops.hpp\"\n"
        "using namespace plcfi::st::ops;\nusing namespace plcfi::st::native_abi;\n"
        // Loads and stores of any alignment, through types that may alias anything (as
        // ops.hpp's ld/st with memcpy).
        "#define PLCFI_UA(T) typedef T ua_##T __attribute__((aligned(1), may_alias));\n"
        "PLCFI_UA(int8_t) PLCFI_UA(int16_t) PLCFI_UA(int32_t) PLCFI_UA(int64_t) PLCFI_UA(uint8_t) PLCFI_UA(uint16_t)\n"
        "PLCFI_UA(uint32_t) PLCFI_UA(uint64_t) PLCFI_UA(float) PLCFI_UA(double)\n"
        "#define LD(T, p) (*(const ua_##T*)(p))\n#define ST(T, p, v) ((void)(*(ua_##T*)(p) = (T)(v)))\n"
        "static constexpr int kMore = 3;  // a piece of a cut function: go on at *at\n"
        "#define TRAP(kind, pcv, a, b, cc) do { FLUSH(); BUDGET_OUT(); return c->trap(c, kind, pcv, (int64_t)(a), "
        "(int64_t)(b), (int64_t)(cc)); } while (0)\n"
        // A general call (depth checked by the caller): the method stack top and the depth
        // around it. One copy per unit instead of the same lines at every call.
        "static __attribute__((noinline)) int gcall(Ctx* c, Fn f, uint8_t* b) {\n"
        "  uint32_t mt = c->mtop; ++c->depth; int r = f(c, b); --c->depth; c->mtop = mt; return r;\n}\n";
    // A function's coverage word k reaches the bitset at its first branch id + 64 k. In
    // one unit that is a constant multiple of 64 and the shifts fold away; in a split
    // program one out-of-line copy keeps every way out of a function short to compile.
    p += split_ ? "static __attribute__((noinline)) void cov_or(uint64_t* t, uint32_t bit, uint64_t v) {\n"
                : "static inline void cov_or(uint64_t* t, uint32_t bit, uint64_t v) {\n";
    p += "  uint32_t w = bit >> 6, s = bit & 63; t[w] |= v << s; if (s && (v >> (64 - s))) t[w + 1] |= v >> (64 - s);\n}\n";
    return p;
  }

  // A split program's units hold about this much generated text each.
  static constexpr size_t kUnitBytes = 512 * 1024;

  std::string exports(const std::vector<uint32_t>& entries) const {
    std::ostringstream out;
    out << "extern \"C\" const uint32_t plcfi_native_abi = " << native_abi::kAbiVersion << ";\n";
    out << "extern \"C\" const uint32_t plcfi_native_count = " << entries.size() << ";\n";
    out << "extern \"C\" const Entry plcfi_native_entries[] = {";
    for (uint32_t e : entries) out << "{" << e << "u, " << names_.at(e) << "}, ";
    if (entries.empty()) out << "{0u, nullptr}";
    out << "};\n";
    return out.str();
  }

 private:
  // The end of the function at s: the next entry of any POU (reachable or not).
  uint32_t next_start(uint32_t s) const {
    auto it = std::upper_bound(bounds_.begin(), bounds_.end(), s);
    return it == bounds_.end() ? static_cast<uint32_t>(code_.size()) : *it;
  }

  // Every entry reachable from the application's roots: programs, observers, tests, and
  // (for dynamic dispatch) every vtable entry; the closure over direct calls.
  void collect() {
    std::vector<uint32_t> work;
    for (const auto& p : app_.programs) work.push_back(p.pou->entry);
    for (const auto& p : app_.observers) work.push_back(p.pou->entry);
    for (const auto& t : app_.tests) {
      work.push_back(t.setup_entry);
      work.push_back(t.body_entry);
      work.push_back(t.teardown_entry);
      if (t.has_init) work.push_back(t.init_entry);
      if (t.has_exit) work.push_back(t.exit_entry);
    }
    for (uint32_t e : app_.vtable)
      if (e) work.push_back(e);
    if (app_.has_init) work.push_back(app_.init_entry);
    if (app_.has_exit) work.push_back(app_.exit_entry);
    std::set<uint32_t> all_entries;  // every entry, to bound functions
    for (const auto& p : app_.pous)
      if (p->compiled) all_entries.insert(p->entry);
    for (uint32_t e : work) all_entries.insert(e);
    // Direct call targets anywhere in the code are entries too.
    for (uint32_t pc = 0; pc < code_.size(); pc += op_length(&code_[pc])) {
      uint32_t t;
      if (call_target(&code_[pc], &t)) all_entries.insert(t);
    }
    bounds_.assign(all_entries.begin(), all_entries.end());
    std::set<uint32_t> seen;
    while (!work.empty()) {
      uint32_t e = work.back();
      work.pop_back();
      if (e >= code_.size() || !seen.insert(e).second) continue;
      auto it = std::upper_bound(bounds_.begin(), bounds_.end(), e);
      uint32_t end = it == bounds_.end() ? static_cast<uint32_t>(code_.size()) : *it;
      for (uint32_t pc = e; pc < end; pc += op_length(&code_[pc])) {
        uint32_t t;
        if (call_target(&code_[pc], &t)) work.push_back(t);
      }
      // Falling off the end continues in the next entry's code.
      if (end < code_.size()) work.push_back(end);
    }
    starts_.assign(seen.begin(), seen.end());
    name_entries();
  }

  // Function names that do not depend on where code lies: F + a hash of what the entry
  // is (a POU's body, a method, FB_init, a test's part...). An edit to one POU leaves
  // the other functions' names, and so their callers' texts, unchanged. An entry nothing
  // names (code a function falls into) is named by its position.
  void name_entries() {
    std::map<uint32_t, std::pair<std::string, std::string>> what;  // entry -> (identity, owner)
    auto put = [&](uint32_t e, const std::string& id, const std::string& owner) { what.emplace(e, std::make_pair(id, owner)); };
    std::function<std::string(const PouInfo*)> path = [&](const PouInfo* p) -> std::string {
      std::string n = p->owner ? path(p->owner) + "." + p->name : p->name;
      return p->is_setter ? n + "#set" : n;
    };
    std::function<const PouInfo*(const PouInfo*)> top = [&](const PouInfo* p) { return p->owner ? top(p->owner) : p; };
    std::function<void(const PouInfo*)> pou = [&](const PouInfo* p) {
      std::string id = path(p), owner = "pou:" + top(p)->name;
      if (p->compiled) put(p->entry, "pou:" + id, owner);
      if (p->has_init) put(p->init_entry, "init:" + id, owner);
      if (p->has_exit) put(p->exit_entry, "exit:" + id, owner);
      for (const auto& m : p->methods) pou(m.get());
    };
    for (const auto& p : app_.pous) pou(p.get());
    for (const auto& t : app_.tests) {
      std::string owner = "test:" + t.name;
      put(t.setup_entry, owner + "#setup", owner);
      put(t.body_entry, owner + "#body", owner);
      put(t.teardown_entry, owner + "#teardown", owner);
      if (t.has_init) put(t.init_entry, owner + "#init", owner);
      if (t.has_exit) put(t.exit_entry, owner + "#exit", owner);
    }
    if (app_.has_init) put(app_.init_entry, "app#init", "app");
    if (app_.has_exit) put(app_.exit_entry, "app#exit", "app");
    std::set<std::string> used;
    for (uint32_t e : starts_) {
      auto it = what.find(e);
      std::string id = it != what.end() ? it->second.first : fmt::format("at:{}", e);
      std::string name = fmt::format("F{:016x}", fnv1a(id));
      if (!used.insert(name).second) name = fmt::format("F{:016x}_{}", fnv1a(id), e);  // the same identity twice
      used.insert(name);
      names_[e] = name;
      owners_[e] = it != what.end() ? it->second.second : id;
    }
  }

  // The name of the function of a native entry (see name_entries), noted as called.
  const std::string& fn_name(uint32_t target) {
    const std::string& n = names_.at(target);
    called_.insert(n);
    return n;
  }
  bool is_native(uint32_t target) const {
    return native_.count(target) || (pass_ == 0 && std::binary_search(starts_.begin(), starts_.end(), target));
  }
  std::string callee(uint32_t target, const std::string& base_expr) {
    if (is_native(target)) return fmt::format("{}(c, {})", fn_name(target), base_expr);
    return fmt::format("c->call_entry(c, {}u, {})", target, base_expr);
  }

  // What a function and everything it calls can do: a call into a `simple` one (no
  // recursion, no dynamic dispatch, every callee native) needs none of the bookkeeping a
  // general call does, once the call depth is known to fit (checked at the call).
  struct Summary {
    bool simple = true;
    bool loops = false;    // backward jumps (the watchdog budget), here or below
    bool fails = false;    // can end in a trap or a halt, here or below
    bool methods = false;  // moves the method stack top (ENTER), here or below
    uint32_t height = 0;   // the longest chain of calls below
    std::vector<uint32_t> calls;  // direct callees
    uint32_t next = 0;     // the entry the function falls into at its end (0: none)
  };

  // Instructions that never end a function early (no trap, no halt). Calls are judged by
  // their callees' summaries; everything not named here counts as possibly failing.
  static bool never_fails(Op op) {
    switch (op) {
      case Op::NOP: case Op::RET: case Op::JMP: case Op::JMPF: case Op::JMPT: case Op::JTAB: case Op::COV:
      case Op::FBENTER: case Op::FNMOCK: case Op::FRAME: case Op::CALL: case Op::CALLA: case Op::CALLS:
      case Op::MOV1: case Op::MOV2: case Op::MOV4: case Op::MOV8: case Op::SEL1: case Op::SEL2: case Op::SEL4: case Op::SEL8: case Op::MOVN:
      case Op::LDG1: case Op::LDG2: case Op::LDG4: case Op::LDG8: case Op::LDGN:
      case Op::STG1: case Op::STG2: case Op::STG4: case Op::STG8: case Op::STGN:
      case Op::LDBIT: case Op::STBIT: case Op::ADDR: case Op::ADDRK: case Op::INITBLK: case Op::NOW: case Op::ADVTIME:
      case Op::NATIVE: case Op::SCPY: case Op::SCMP: case Op::WSCPY: case Op::WSCMP:
      case Op::GETBIT1: case Op::GETBIT2: case Op::GETBIT4: case Op::GETBIT8:
      case Op::SETBIT1: case Op::SETBIT2: case Op::SETBIT4: case Op::SETBIT8:
      case Op::BAND: case Op::BOR: case Op::BXOR: case Op::BNOT: case Op::RISE: case Op::FALL:
      case Op::STEADY_HIGH: case Op::STEADY_LOW: case Op::TOBOOL8: case Op::TOBOOL16: case Op::TOBOOL32: case Op::TOBOOL64:
      case Op::DIVK_I16: case Op::DIVK_I32: case Op::MODK_I16: case Op::MODK_I32:
      case Op::ROWS: case Op::LDXR1: case Op::LDXR2: case Op::LDXR4: case Op::LDXR8:
      case Op::STXR1: case Op::STXR2: case Op::STXR4: case Op::STXR8:
        return true;
      default: break;
    }
    std::string_view n = op_info(op).name;
    const TypedFamily* f = typed_family(n);
    if (!f) return false;
    if (f->traps == TypedFamily::kIntegers) return n.substr(n.find('_') + 1)[0] == 'F';  // DIV on REAL/LREAL
    return f->traps == TypedFamily::kNever;
  }

  // The typed instruction families (NAME_TYPE) that work on frame registers only: they
  // write nothing but their destination (through W). Some can trap.
  struct TypedFamily {
    const char* name;
    enum { kNever, kIntegers, kAlways } traps;
  };
  static const TypedFamily* typed_family(std::string_view op_name) {
    static const TypedFamily kFamilies[] = {
        {"ADD", TypedFamily::kNever},    {"SUB", TypedFamily::kNever},    {"MUL", TypedFamily::kNever},
        {"MADD", TypedFamily::kNever},
        {"DIV", TypedFamily::kIntegers}, {"NEG", TypedFamily::kNever},    {"EQ", TypedFamily::kNever},
        {"NE", TypedFamily::kNever},     {"LT", TypedFamily::kNever},     {"LE", TypedFamily::kNever},
        {"GT", TypedFamily::kNever},     {"GE", TypedFamily::kNever},     {"JLT", TypedFamily::kNever},
        {"JGE", TypedFamily::kNever},    {"JEQ", TypedFamily::kNever},    {"JNE", TypedFamily::kNever},
        {"JNLT", TypedFamily::kNever},   {"JNGE", TypedFamily::kNever},   {"MIN", TypedFamily::kNever},
        {"MAX", TypedFamily::kNever},    {"ABS", TypedFamily::kNever},    {"CVT", TypedFamily::kNever},
        {"MOD", TypedFamily::kAlways},   {"MODZ", TypedFamily::kNever},   {"AND", TypedFamily::kNever},
        {"OR", TypedFamily::kNever},     {"XOR", TypedFamily::kNever},    {"NOT", TypedFamily::kNever},
        {"SHL", TypedFamily::kNever},    {"SHR", TypedFamily::kNever},    {"ROL", TypedFamily::kNever},
        {"ROR", TypedFamily::kNever},    {"CHK", TypedFamily::kAlways},   {"LOOPUP", TypedFamily::kAlways},
        {"LOOPDN", TypedFamily::kAlways}, {"ROUND", TypedFamily::kNever}, {"TRUNC", TypedFamily::kNever},
        {"JTZ", TypedFamily::kNever},    {"JTNZ", TypedFamily::kNever},   {"SHLD", TypedFamily::kNever},
        {"SHRD", TypedFamily::kNever},   {"ROLD", TypedFamily::kNever},   {"RORD", TypedFamily::kNever},
        {"GETBITD", TypedFamily::kNever},
        {"ANDSHL", TypedFamily::kNever}, {"ANDSHR", TypedFamily::kNever}, {"ORSHL", TypedFamily::kNever},
        {"ORSHR", TypedFamily::kNever},  {"XORSHL", TypedFamily::kNever}, {"XORSHR", TypedFamily::kNever},
    };
    size_t us = op_name.find('_');
    if (us == std::string_view::npos) return nullptr;
    for (const TypedFamily& f : kFamilies)
      if (op_name.substr(0, us) == f.name) return &f;
    return nullptr;
  }

  // A jump that counts against the watchdog: JMPB, a counted loop's step, or a conditional
  // jump to an earlier instruction (WHILE and REPEAT test at the bottom).
  bool back_edge(uint32_t pc) const {
    auto op = static_cast<Op>(code_[pc]);
    std::string_view n = op_info(op).name;
    if (op == Op::JMPB || n.rfind("LOOPUP_", 0) == 0 || n.rfind("LOOPDN_", 0) == 0) return true;
    return is_conditional_jump(op) && code_[pc + 1] <= pc;
  }

  void summarize() {
    for (uint32_t e : native_) {
      Summary& sm = sum_[e];
      uint32_t end = next_start(e);
      Op last = Op::NOP;
      for (uint32_t pc = e; pc < end; pc += op_length(&code_[pc])) {
        auto op = static_cast<Op>(code_[pc]);
        last = op;
        uint32_t t = 0;
        if (op == Op::CALL || op == Op::CALLA || op == Op::CALLS) {
          call_target(&code_[pc], &t);
          if (native_.count(t)) sm.calls.push_back(t);
          else sm.simple = false;
        } else if (op == Op::CALLV || op == Op::CALLP) {
          sm.simple = false;
        }
        if (back_edge(pc)) sm.loops = sm.fails = true;
        if (op == Op::ENTER) sm.methods = true;
        if (!never_fails(op) || (op == Op::NATIVE && native_traps(code_[pc + 1] & 0xffffu))) sm.fails = true;
      }
      bool falls = !(last == Op::RET || last == Op::HALT || last == Op::JMP || last == Op::JMPB || last == Op::JTAB ||
                     last == Op::TRAP);
      if (falls && end < code_.size()) {
        if (native_.count(end)) sm.next = end;
        else sm.simple = false;
      }
    }
    std::map<uint32_t, int> state;  // 1: being resolved, 2: done
    std::function<void(uint32_t)> resolve = [&](uint32_t e) {
      int& st = state[e];
      if (st != 0) return;
      st = 1;
      Summary& sm = sum_[e];
      auto take = [&](uint32_t callee, uint32_t depth) {
        resolve(callee);
        const Summary& o = sum_[callee];
        if (state[callee] == 1 || !o.simple) sm.simple = false;  // recursion, or below
        sm.loops |= o.loops;
        sm.fails |= o.fails;
        sm.methods |= o.methods;
        sm.height = std::max(sm.height, o.height + depth);
      };
      for (uint32_t callee : sm.calls) take(callee, 1);
      if (sm.next) take(sm.next, 0);
      state[e] = 2;
    };
    for (uint32_t e : native_) resolve(e);
  }

  // A direct call (CALL, CALLA, CALLS) to `target`: to a simple function, when the
  // depth of its deepest call fits, a plain C++ call; otherwise the general call.
  std::string direct_call(uint32_t pc, uint32_t target, const std::string& base_expr) {
    std::string general = is_native(target) ? native_call_block(pc, fn_name(target), base_expr)
                                            : call_block(pc, callee(target, base_expr));
    auto it = sum_.find(target);
    // A split program's calls all take the general path: half the code at every call to
    // compile, for a few instructions more per call at run time.
    if (pass_ == 0 || split_ || it == sum_.end() || !it->second.simple) return general;
    const Summary& sm = it->second;
    std::string call = fmt::format("{}(c, {})", fn_name(target), base_expr), fast;
    if (sm.methods) fast += "uint32_t mt = c->mtop; ";
    if (sm.loops) fast += "BUDGET_OUT(); ";
    fast += sm.fails ? fmt::format("int r = {}; ", call) : call + "; ";
    if (sm.methods) fast += "c->mtop = mt; ";
    if (sm.loops) fast += "BUDGET_IN(); ";
    if (sm.fails) fast += "if (r) { FLUSH(); return r; } ";
    return fmt::format("if (__builtin_expect(c->depth + {}u >= kMaxDepth, 0)) {{ {} }} else {{ {}}}", sm.height, general, fast);
  }

  std::string call_block(uint32_t pc, const std::string& call) const {
    return fmt::format(
        "if (c->depth >= kMaxDepth) TRAP(6, {0}, 0, 0, 0);\n"
        "    {{ uint32_t mt = c->mtop; ++c->depth; BUDGET_OUT(); int r = {1}; --c->depth; c->mtop = mt; "
        "BUDGET_IN(); if (r) {{ FLUSH(); return r; }} }}\n",
        P(pc), call);
  }
  // The same for a native callee, through the prelude's gcall.
  std::string native_call_block(uint32_t pc, const std::string& fn, const std::string& base_expr) const {
    return fmt::format("if (c->depth >= kMaxDepth) TRAP(6, {}, 0, 0, 0);\n"
                       "    {{ BUDGET_OUT(); int r = gcall(c, {}, {}); BUDGET_IN(); if (r) {{ FLUSH(); return r; }} }}\n",
                       P(pc), fn, base_expr);
  }
  // An instruction's pc and a label, relative to the function's entry (PC: see function).
  std::string P(uint32_t pc) const { return fmt::format("PC({}u)", pc - start_); }
  std::string label(uint32_t pc) const { return fmt::format("L{}", pc - start_); }
  // A jump: a goto, or out of a piece of a cut function to the piece the target is in.
  std::string go(uint32_t target) const {
    if (chunk_ == SIZE_MAX || static_cast<size_t>(std::upper_bound(cuts_.begin(), cuts_.end(), target) - cuts_.begin()) - 1 == chunk_)
      return fmt::format("goto {};", label(target));
    return fmt::format("{{ *at = {}u; FLUSH(); BUDGET_OUT(); return kMore; }}", target - start_);
  }

  // One function: code from `start` up to `end`. False when it has an instruction the
  // translator does not handle or jumps outside itself.
  bool function(uint32_t start, uint32_t end, std::string* out) {
    // The POU whose body holds this code: its constant pool is folded into the code.
    pou_ = nullptr;
    for (const auto& p : app_.pous)
      if (p->compiled && p->code_begin <= start && start < p->code_end) pou_ = p.get();
    std::vector<uint32_t> targets;
    for (uint32_t pc = start; pc < end; pc += op_length(&code_[pc])) {
      if (code_[pc] >= static_cast<uint32_t>(Op::Count_)) return false;
      jump_targets(&code_[pc], &targets);
    }
    for (uint32_t t : targets)
      if (t < start || t >= end) return false;
    std::set<uint32_t> labels(targets.begin(), targets.end());
    // Coverage bits gather in locals (registers) and reach the machine's bitset on every
    // way out of the function: a store into the bitset in a loop would make the compiler
    // reload every variable after it.
    // Branch ids are counted from the function's first (BR), pcs from its entry (PC): a
    // function's text does not change when code before it grows. In one unit the base is
    // the bitset word of the first branch, so the words line up and need no shifting.
    start_ = start;
    uint32_t first_branch = UINT32_MAX;
    for (uint32_t pc = start; pc < end; pc += op_length(&code_[pc]))
      if (static_cast<Op>(code_[pc]) == Op::COV) first_branch = std::min(first_branch, code_[pc + 1]);
    branch_base_[start] = first_branch == UINT32_MAX ? 0 : split_ ? first_branch : first_branch & ~63u;
    std::set<uint32_t> cov_words;
    for (uint32_t pc = start; pc < end; pc += op_length(&code_[pc]))
      if (static_cast<Op>(code_[pc]) == Op::COV) cov_words.insert((code_[pc + 1] - branch_base_[start]) >> 6);
    std::string flush;
    for (uint32_t wd : cov_words) flush += fmt::format("cov_or(taken, BR({}u), cov{}); ", wd * 64, wd);
    // The slot analysis does not depend on the pass (which callees are native changes
    // the calls' text, not what the instructions read and write): the final pass reuses
    // the first's, which is most of a large program's translation time.
    if (auto it = analysis_.find(start); pass_ == 1 && it != analysis_.end()) {
      Analysis& a = it->second;
      keys_ = std::move(a.keys);
      key_index_ = std::move(a.key_index);
      valid_in_ = std::move(a.valid_in);
      index_of_ = std::move(a.index_of);
      preload_ = std::move(a.preload);
      safe_ = std::move(a.safe);
      dead_ = std::move(a.dead);
      analysis_.erase(it);
    } else if (!cache_slots(start, end)) {
      return false;
    }
    // The watchdog budget lives in a local only in a function with loops of its own;
    // elsewhere c->budget is always current and needs no copying around calls.
    bool own_loops = false;
    for (uint32_t pc = start; pc < end; pc += op_length(&code_[pc])) own_loops = own_loops || back_edge(pc);
    // A very long function (a large PROGRAM body) is cut into pieces of at most
    // chunk_instructions_ instructions, so the C++ compiler, whose time grows faster
    // than a function's length, sees several functions of moderate size. The pieces
    // keep no variables in locals (memory is exact at every instruction, so nothing is
    // lost at a cut) and pass control through a loop in the function itself.
    cuts_.clear();
    if (index_of_.size() > chunk_instructions_) {
      keys_.clear();
      key_index_.clear();
      std::fill(preload_.begin(), preload_.end(), 0);
      size_t n = 0;
      for (uint32_t pc = start; pc < end; pc += op_length(&code_[pc]))
        if (n++ % chunk_instructions_ == 0) cuts_.push_back(pc);
    }
    std::ostringstream o;
    o << "#undef FLUSH\n#define FLUSH() do { " << flush << "} while (0)\n";
    const std::string& name = names_.at(start);
    o << "#undef PC\n#define PC(x) (R_" << name << "[0] + (x))\n#undef BR\n#define BR(x) (R_" << name << "[1] + (x))\n";
    o << "#undef BUDGET_OUT\n#undef BUDGET_IN\n";
    if (own_loops || !cuts_.empty()) o << "#define BUDGET_OUT() (c->budget = budget)\n#define BUDGET_IN() (budget = c->budget)\n";
    else o << "#define BUDGET_OUT() ((void)0)\n#define BUDGET_IN() ((void)0)\n";
    auto prologue = [&](bool budget) {
      o << "  uint8_t* const mem = c->mem; const uint64_t msize = c->msize; uint64_t* const taken = c->taken;"
        << (budget ? " int64_t budget = c->budget;" : "") << "\n  (void)mem; (void)msize; (void)taken;\n";
      for (uint32_t wd : cov_words) o << "  uint64_t cov" << wd << " = 0;\n";
    };
    auto body = [&](uint32_t from, uint32_t to) {
      uint32_t prev = UINT32_MAX;
      for (uint32_t pc = from; pc < to; prev = pc, pc += op_length(&code_[pc])) {
        if (labels.count(pc)) o << " " << label(pc) << ":\n";
        // An STXB right after the LDXB of its block, no jump between (block_copy).
        block_load_ = prev != UINT32_MAX && !labels.count(pc) && static_cast<Op>(code_[prev]) == Op::LDXB ? prev : UINT32_MAX;
        std::string s;
        valid_ = &valid_in_[index_of_.at(pc)];
        dead_now_ = &dead_[index_of_.at(pc)];
        if (!instruction(pc, &s)) return false;
        o << "  { " << s << " }\n";
      }
      valid_ = nullptr;
      dead_now_ = nullptr;
      block_load_ = UINT32_MAX;
      return true;
    };
    // Off the end: the interpreter would go on into the next entry's code.
    auto off_the_end = [&] {
      if (end < code_.size())
        o << "  FLUSH(); BUDGET_OUT(); return " << callee(end, "base") << ";\n";
      else
        o << "  FLUSH(); BUDGET_OUT(); return kOk;\n";
    };
    if (cuts_.empty()) {
      o << (split_ ? "" : "static ") << "int " << name << "(Ctx* c, uint8_t* base) {\n";
      prologue(own_loops);
      for (size_t k = 0; k < keys_.size(); ++k) {
        o << "  " << keys_[k].ctype << " " << key_name(static_cast<int>(k));
        if (test_bit(preload_, static_cast<int>(k))) o << " = ld<" << keys_[k].ctype << ">(base + " << keys_[k].off << "u)";
        o << ";\n";
      }
      if (!body(start, end)) return false;
      off_the_end();
    } else {
      // Piece k runs from *at (its first instruction or one of its labels) to a jump out
      // of it or its end, sets *at to where control goes on and returns kMore.
      for (size_t k = 0; k < cuts_.size(); ++k) {
        chunk_ = k;
        const uint32_t from = cuts_[k], to = k + 1 < cuts_.size() ? cuts_[k + 1] : end;
        o << "static int " << name << "_" << k << "(Ctx* c, uint8_t* base, uint32_t* at) {\n";
        prologue(true);
        o << "  switch (*at) { default: break;";
        for (uint32_t l : labels)
          if (l > from && l < to) o << " case " << l - start << "u: goto " << label(l) << ";";
        o << " }\n";
        if (!body(from, to)) return false;
        if (k + 1 < cuts_.size()) o << "  *at = " << to - start << "u; FLUSH(); BUDGET_OUT(); return kMore;\n";
        else off_the_end();
        o << "}\n";
      }
      chunk_ = SIZE_MAX;
      o << (split_ ? "" : "static ") << "int " << name << "(Ctx* c, uint8_t* base) {\n  uint32_t at = 0;\n  for (;;) {\n    int r = ";
      for (size_t k = 0; k + 1 < cuts_.size(); ++k)
        o << "at < " << cuts_[k + 1] - start << "u ? " << name << "_" << k << "(c, base, &at) : ";
      o << name << "_" << cuts_.size() - 1 << "(c, base, &at);\n    if (r != kMore) return r;\n  }\n";
    }
    o << "}\n";
    *out = memory_macros(o.str());
    if (pass_ == 0)
      analysis_[start] = Analysis{std::move(keys_), std::move(key_index_), std::move(valid_in_), std::move(index_of_),
                                  std::move(preload_), std::move(safe_), std::move(dead_)};
    return true;
  }

  // ld<T>(p) and st<T>(p, v) as the prelude's LD(T, p) and ST(T, p, v): the same loads
  // and stores, without a template call per access for the C++ compiler to parse,
  // instantiate and inline (a tenth of a large program's compile time).
  static std::string memory_macros(const std::string& in) {
    std::string out;
    out.reserve(in.size());
    size_t i = 0;
    while (i < in.size()) {
      size_t k = in.find("<", i);
      if (k == std::string::npos) break;
      bool word = k >= 2 && (in.compare(k - 2, 2, "ld") == 0 || in.compare(k - 2, 2, "st") == 0) &&
                  (k == 2 || !(std::isalnum(static_cast<unsigned char>(in[k - 3])) || in[k - 3] == '_'));
      size_t close = word ? in.find(">(", k) : std::string::npos;
      if (close == std::string::npos || close - k > 10) {
        out.append(in, i, k + 1 - i);
        i = k + 1;
        continue;
      }
      out.append(in, i, k - 2 - i);
      out += in[k - 2] == 'l' ? "LD(" : "ST(";
      out.append(in, k + 1, close - k - 1);
      out += ", ";
      i = close + 2;
    }
    out.append(in, i, std::string::npos);
    return out;
  }

  // A block copy between frame bytes that cannot overlap is a memcpy, which the C++
  // compiler open-codes for a small constant size (memmove stays a library call).
  static const char* copy_fn(uint64_t a, uint64_t b, uint64_t n) { return a + n <= b || b + n <= a ? "memcpy" : "memmove"; }
  // The same for LDIN/STIN through a pointer proven to stay in a frame array: the frame
  // bytes [at, at + n) outside that array cannot overlap the element.
  const char* proven_copy_fn(uint32_t pc, uint64_t at, uint64_t n) const {
    auto it = safe_.find(pc);
    if (!valid_ || it == safe_.end()) return "memmove";
    return at + n <= it->second.lo || it->second.hi <= at ? "memcpy" : "memmove";
  }

  // An element copied to another through a temporary block, `a[j] := a[j - 1]` (LDXB T;
  // STXB from T, nothing between): the STXB reads the source element itself, which the
  // LDXB checked and which T cannot overlap, instead of T just stored (a load that waits
  // for those stores). T is still written; the copy goes through a local buffer, so any
  // overlap of the two elements is harmless. The source element's address, or nothing.
  std::optional<std::string> block_copy(uint32_t pc) const {
    if (block_load_ == UINT32_MAX) return std::nullopt;
    const uint32_t* l = &code_[block_load_];
    const uint32_t* w = &code_[pc];
    const uint64_t t = l[1], n = l[8], arr = l[2], arr_n = uint64_t{l[5]} * l[6];
    if (w[7] != t || w[8] != n) return std::nullopt;
    const bool apart = (t + n <= l[3] || uint64_t{l[3]} + 4 <= t) && (t + n <= arr || arr + arr_n <= t);
    if (!apart) return std::nullopt;
    // The index as the LDXB read it: from its local when that holds it (only T was
    // written since), else from memory.
    std::string idx = fmt::format("ld<int32_t>(base + {}u)", l[3]);
    const int key = valid_ ? find_key(l[3], "int32_t") : -1;
    if (key >= 0 && test_bit(*valid_, key)) idx = fmt::format("((int32_t){})", key_name(key));
    return fmt::format("base + {}u + ((int64_t){} - (int64_t){}) * {}u + {}u", l[2], idx, static_cast<int32_t>(l[4]), l[6], l[7]);
  }

  bool instruction(uint32_t pc, std::string* out) {
    const uint32_t* w = &code_[pc];
    auto op = static_cast<Op>(w[0]);
    auto K = [&](int i) { return fmt::format("{}u", w[i]); };
    auto S = [&](int i) { return fmt::format("{}", static_cast<int32_t>(w[i])); };
    auto R = [&](const char* t, int i) {
      std::string k;
      if (literal(t, w[i], &k)) return k;
      if (reads_) reads_->push_back({w[i], t});
      if (valid_) {
        int key = find_key(w[i], t);
        if (key >= 0 && test_bit(*valid_, key)) return fmt::format("(({}){})", t, key_name(key));
      }
      return fmt::format("ld<{}>(base + {}u)", t, w[i]);
    };
    auto W = [&](const char* t, int i, const std::string& v) {
      if (collect_) collect_->push_back({w[i], t});
      int key = valid_ ? find_key(w[i], t) : -1;
      if (key >= 0 && dead_now_ && test_bit(*dead_now_, key))  // a temporary nobody reads from memory
        return fmt::format("{0} = ({1})({2})({3});", key_name(key), keys_[key].ctype, t, v);
      if (key >= 0) return fmt::format("{0} w_ = {1}; {2} = ({3})w_; st<{0}>(base + {4}u, w_);", t, v, key_name(key), keys_[key].ctype, w[i]);
      return fmt::format("st<{}>(base + {}u, {});", t, w[i], v);
    };
    auto G = [&](int i) { return fmt::format("mem + {}u", w[i]); };
    auto jump = [&](int i) { return go(w[i]); };
    auto backjump = [&]() { return fmt::format("if (--budget < 0) TRAP(5, {}, 0, 0, 0); ", P(pc)); };
    // A conditional jump back is a loop's back edge: it counts against the watchdog.
    auto cjump = [&](int i) { return w[i] <= pc ? "{ " + backjump() + go(w[i]) + " }" : go(w[i]); };
    // The address in slot i plus disp, checked for null and bounds of n bytes.
    // Through a pointer proven to stay inside a frame array (see `provenance`), neither
    // check can fail and both are left out.
    const bool proven = valid_ && safe_.count(pc);
    auto ptr = [&](const char* dst, int i, const std::string& disp, const std::string& n) {
      if (proven) return fmt::format("uint64_t {0} = (uint64_t){1} + ({2}); ", dst, R("uint32_t", i), disp);
      return fmt::format(
          "uint32_t {0}_r = {1}; if ({0}_r == 0) TRAP(4, {2}, 0, 0, 0); "
          "uint64_t {0} = (uint64_t){0}_r + ({3}); if ({0} + ({4}) > msize) TRAP(9, {2}, {0}, 0, 0); ",
          dst, R("uint32_t", i), P(pc), disp, n);
    };
    std::string& s = *out;
    switch (op) {
      case Op::NOP: return true;
      case Op::HALT: s = "FLUSH(); BUDGET_OUT(); return kHalt;"; return true;
      case Op::RET: s = "FLUSH(); BUDGET_OUT(); return kOk;"; return true;
      case Op::JMP: s = jump(1); return true;
      case Op::JMPB: s = backjump() + jump(1); return true;
      case Op::JMPF: s = fmt::format("if (!{}) {}", R("uint8_t", 2), cjump(1)); return true;
      case Op::JMPT: s = fmt::format("if ({}) {}", R("uint8_t", 2), cjump(1)); return true;
      case Op::CALL: s = direct_call(pc, w[2], fmt::format("base + {}u", w[1])); return true;
      case Op::CALLA: s = direct_call(pc, w[2], G(1)); return true;
      case Op::CALLP:
        s = fmt::format("if (c->depth >= kMaxDepth) TRAP(6, {}, 0, 0, 0); ", P(pc)) + ptr("a", 1, "0", "8") +
            call_block(pc, callee(w[2], "mem + a"));
        return true;
      case Op::FRAME: s = W("uint32_t", 1, "c->mtop"); return true;
      case Op::ENTER:
        s = fmt::format("uint64_t top = (uint64_t)(base - mem) + {}u; if (top > c->mend) TRAP(6, {}, 1, 0, 0); "
                        "c->mtop = (uint32_t)top;",
                        w[1], P(pc));
        return true;
      case Op::CALLS: s = direct_call(pc, w[2], fmt::format("mem + {}", R("uint32_t", 1))); return true;
      case Op::CALLV:
        s = fmt::format("if (c->depth >= kMaxDepth) TRAP(6, {}, 0, 0, 0); ", P(pc)) + ptr("inst", 2, "0", "8") +
            fmt::format("uint32_t type = ld<uint16_t>(mem + inst); uint32_t entry = type < {1}u ? c->vtable[{0}u * {1}u + type] : 0; "
                        "if (entry == 0) TRAP(8, {2}, 0, 0, 0); uint8_t* frame = mem + {3}; "
                        "st<uint32_t>(frame + 8, (uint32_t)inst);\n    ",
                        w[3], app_.n_types, P(pc), R("uint32_t", 1)) +
            call_block(pc, "c->call_entry(c, entry, frame)");
        return true;
      case Op::JTAB: {
        s = fmt::format("int64_t i = (int64_t){} - (int64_t){}; switch (i) {{ ", R("int32_t", 1), S(2));
        for (uint32_t i = 0; i < w[3]; ++i) s += fmt::format("case {}: {} ", i, go(w[5 + i]));
        s += fmt::format("default: {} }}", go(w[4]));
        return true;
      }
      case Op::ROWS:
        s.clear();
        for (uint32_t e = 0; e < w[2]; ++e) {
          const int at = 3 + 4 * static_cast<int>(e);
          s += "{ " + W("int32_t", at, fmt::format("(int32_t)((int64_t){} + (int64_t){} * {})", S(at + 1), R("int32_t", at + 2), S(at + 3))) +
               " } ";
        }
        return true;
      case Op::LDXR1: case Op::LDXR2: case Op::LDXR4: case Op::LDXR8: {
        const char* t = op == Op::LDXR1 ? "uint8_t" : op == Op::LDXR2 ? "uint16_t" : op == Op::LDXR4 ? "uint32_t" : "uint64_t";
        // The compiler proved the element inside the array; the C++ compiler is told so.
        s = fmt::format("int64_t at = (int64_t){} + (int64_t){} * {}; if (at < {}ll || at > {}ll) __builtin_unreachable(); ",
                        R("int32_t", 2), R("int32_t", 3), S(4), w[5], int64_t{w[5]} + w[6] - ctype_size(t));
        s += W(t, 1, fmt::format("ld<{}>(base + at)", t));
        return true;
      }
      case Op::STXR1: case Op::STXR2: case Op::STXR4: case Op::STXR8: {
        const char* t = op == Op::STXR1 ? "uint8_t" : op == Op::STXR2 ? "uint16_t" : op == Op::STXR4 ? "uint32_t" : "uint64_t";
        s = fmt::format("int64_t at = (int64_t){} + (int64_t){} * {}; if (at < {}ll || at > {}ll) __builtin_unreachable(); ",
                        R("int32_t", 1), R("int32_t", 2), S(3), w[4], int64_t{w[4]} + w[5] - ctype_size(t));
        s += fmt::format("st<{}>(base + at, {});", t, R(t, 6));
        return true;
      }
      case Op::COV: {
        uint32_t b = w[1] - branch_base_.at(start_);
        s = fmt::format("cov{} |= (uint64_t)1 << {};", b >> 6, b & 63);
        return true;
      }
      case Op::FBENTER:
        s = "st<uint32_t>(base + 4, ld<uint32_t>(base + 4) + 1); if (base[2]) { FLUSH(); BUDGET_OUT(); return kOk; }";
        return true;
      case Op::FNMOCK:
        s = fmt::format("if (mem[{0}u]) {{ std::memcpy(base + {1}u, mem + {0}u + 8, {2}u); FLUSH(); BUDGET_OUT(); return kOk; }}",
                        w[1], w[2], w[3]);
        return true;
      case Op::TRAP: s = fmt::format("TRAP({}u, {}, 0, 0, 0);", w[1], P(pc)); return true;
      case Op::MOV1: s = W("uint8_t", 1, R("uint8_t", 2)); return true;
      case Op::MOV2: s = W("uint16_t", 1, R("uint16_t", 2)); return true;
      case Op::MOV4: s = W("uint32_t", 1, R("uint32_t", 2)); return true;
      case Op::MOV8: s = W("uint64_t", 1, R("uint64_t", 2)); return true;
      case Op::SEL1: case Op::SEL2: case Op::SEL4: case Op::SEL8: {
        const char* t = op == Op::SEL1 ? "uint8_t" : op == Op::SEL2 ? "uint16_t" : op == Op::SEL4 ? "uint32_t" : "uint64_t";
        s = W(t, 1, fmt::format("({} != 0 ? {} : {})", R("uint8_t", 2), R(t, 3), R(t, 4)));
        return true;
      }
      case Op::MOVN: s = fmt::format("std::{}(base + {}, base + {}, {});", copy_fn(w[1], w[2], w[3]), K(1), K(2), K(3)); return true;
      case Op::LDG1: s = W("uint8_t", 1, fmt::format("ld<uint8_t>({})", G(2))); return true;
      case Op::LDG2: s = W("uint16_t", 1, fmt::format("ld<uint16_t>({})", G(2))); return true;
      case Op::LDG4: s = W("uint32_t", 1, fmt::format("ld<uint32_t>({})", G(2))); return true;
      case Op::LDG8: s = W("uint64_t", 1, fmt::format("ld<uint64_t>({})", G(2))); return true;
      case Op::LDGN: s = fmt::format("std::memmove(base + {}, mem + {}, {});", K(1), K(2), K(3)); return true;
      case Op::STG1: s = fmt::format("st<uint8_t>({}, {});", G(1), R("uint8_t", 2)); return true;
      case Op::STG2: s = fmt::format("st<uint16_t>({}, {});", G(1), R("uint16_t", 2)); return true;
      case Op::STG4: s = fmt::format("st<uint32_t>({}, {});", G(1), R("uint32_t", 2)); return true;
      case Op::STG8: s = fmt::format("st<uint64_t>({}, {});", G(1), R("uint64_t", 2)); return true;
      case Op::STGN: s = fmt::format("std::memmove(mem + {}, base + {}, {});", K(1), K(2), K(3)); return true;
      case Op::LDI1: s = ptr("p", 2, K(3), "1") + W("uint8_t", 1, "ld<uint8_t>(mem + p)"); return true;
      case Op::LDI2: s = ptr("p", 2, K(3), "2") + W("uint16_t", 1, "ld<uint16_t>(mem + p)"); return true;
      case Op::LDI4: s = ptr("p", 2, K(3), "4") + W("uint32_t", 1, "ld<uint32_t>(mem + p)"); return true;
      case Op::LDI8: s = ptr("p", 2, K(3), "8") + W("uint64_t", 1, "ld<uint64_t>(mem + p)"); return true;
      case Op::LDIN:
        s = ptr("p", 2, K(3), K(4)) + fmt::format("std::{}(base + {}, mem + p, {});", proven_copy_fn(pc, w[1], w[4]), K(1), K(4));
        return true;
      case Op::STI1: s = ptr("p", 1, K(2), "1") + fmt::format("st<uint8_t>(mem + p, {});", R("uint8_t", 3)); return true;
      case Op::STI2: s = ptr("p", 1, K(2), "2") + fmt::format("st<uint16_t>(mem + p, {});", R("uint16_t", 3)); return true;
      case Op::STI4: s = ptr("p", 1, K(2), "4") + fmt::format("st<uint32_t>(mem + p, {});", R("uint32_t", 3)); return true;
      case Op::STI8: s = ptr("p", 1, K(2), "8") + fmt::format("st<uint64_t>(mem + p, {});", R("uint64_t", 3)); return true;
      case Op::STIN:
        s = ptr("p", 1, K(2), K(4)) + fmt::format("std::{}(mem + p, base + {}, {});", proven_copy_fn(pc, w[3], w[4]), K(3), K(4));
        return true;
      case Op::LDBIT: s = W("uint8_t", 1, fmt::format("(uint8_t)((mem[{}] >> {}) & 1u)", K(2), K(3))); return true;
      case Op::STBIT:
        s = fmt::format("uint8_t m = (uint8_t)(1u << {1}); mem[{0}] = (uint8_t)({2} ? (mem[{0}] | m) : (mem[{0}] & ~m));", K(1),
                        K(2), R("uint8_t", 3));
        return true;
      case Op::ADDR: s = W("uint32_t", 1, fmt::format("(uint32_t)(base - mem + {})", K(2))); return true;
      case Op::ADDRI: s = ptr("p", 2, K(3), "0") + W("uint32_t", 1, "(uint32_t)p"); return true;
      case Op::ADDRK: s = W("uint32_t", 1, K(2)); return true;
      case Op::ELEM:
        s = fmt::format("int64_t i = (int64_t){0} - (int64_t){1}; if (i < 0 || i >= (int64_t){2}) TRAP(2, {3}, {0}, 0, 0); ",
                        R("int32_t", 3), S(4), K(5), P(pc)) +
            ptr("p", 2, fmt::format("(uint64_t)i * {}", K(6)), "0") + W("uint32_t", 1, "(uint32_t)p");
        return true;
      case Op::INITBLK: s = fmt::format("std::memcpy(base + {}, mem + {}, {});", K(1), K(2), K(3)); return true;
      case Op::NOW: s = W("int64_t", 1, "*c->now"); return true;
      case Op::ADVTIME: s = fmt::format("*c->now += {};", R("int64_t", 1)); return true;
      case Op::SETMOCK: s = ptr("p", 1, "0", "8") + "mem[p + 2] = 1;"; return true;
      case Op::NATIVE:
        if (math_inline(w, &s) || string_inline(w, &s, nullptr)) return true;
        s = fmt::format("c->native_fn(c, {}, {}, base + {}, base + {}, base + {}, base + {})", P(pc), K(1), K(2), K(3), K(4), K(5));
        // The memory functions check their addresses and may trap; the rest never do.
        s = native_traps(w[1] & 0xffffu) ? fmt::format("if ({}) {{ FLUSH(); BUDGET_OUT(); return kTrap; }}", s) : s + ";";
        return true;
      case Op::ASSERT: s = fmt::format("BUDGET_OUT(); if (c->assert_fn(c, {}, base)) {{ FLUSH(); return kTrap; }}", P(pc)); return true;
      case Op::SCPY:
        s = fmt::format("const char* src = (const char*)(base + {1}); size_t n = strnlen(src, {2}); "
                        "std::memmove(base + {0}, src, n); base[{0} + n] = 0;",
                        K(1), K(2), K(3));
        return true;
      case Op::SCMP:
      case Op::WSCMP: {
        const char* rel[] = {"== 0", "!= 0", "< 0", "<= 0", "> 0", ">= 0"};
        std::string cmp = op == Op::SCMP ? fmt::format("std::strcmp((const char*)(base + {}), (const char*)(base + {}))", K(2), K(3))
                                         : fmt::format("wscmp(base + {}, base + {})", K(2), K(3));
        s = W("uint8_t", 1, fmt::format("(uint8_t)({} {})", cmp, rel[std::min<uint32_t>(w[4], 5)]));
        return true;
      }
      case Op::WSCPY: s = fmt::format("wscpy(base + {}, base + {}, {});", K(1), K(2), K(3)); return true;
      case Op::GETBIT1: s = W("uint8_t", 1, fmt::format("(uint8_t)(({} >> {}) & 1u)", R("uint8_t", 2), K(3))); return true;
      case Op::GETBIT2: s = W("uint8_t", 1, fmt::format("(uint8_t)(({} >> {}) & 1u)", R("uint16_t", 2), K(3))); return true;
      case Op::GETBIT4: s = W("uint8_t", 1, fmt::format("(uint8_t)(({} >> {}) & 1u)", R("uint32_t", 2), K(3))); return true;
      case Op::GETBIT8: s = W("uint8_t", 1, fmt::format("(uint8_t)(({} >> {}) & 1u)", R("uint64_t", 2), K(3))); return true;
      case Op::SETBIT1:
      case Op::SETBIT2:
      case Op::SETBIT4:
      case Op::SETBIT8: {
        const char* t = op == Op::SETBIT1 ? "uint8_t" : op == Op::SETBIT2 ? "uint16_t" : op == Op::SETBIT4 ? "uint32_t" : "uint64_t";
        s = fmt::format("{0} m = ({0})(({0})1 << {1}); {0} v = {2}; ", t, K(2), R(t, 1)) +
            W(t, 1, fmt::format("({})({} ? (v | m) : (v & ({})~m))", t, R("uint8_t", 3), t));
        return true;
      }
      case Op::BAND: s = W("uint8_t", 1, fmt::format("(uint8_t)({} & {})", R("uint8_t", 2), R("uint8_t", 3))); return true;
      case Op::BOR: s = W("uint8_t", 1, fmt::format("(uint8_t)({} | {})", R("uint8_t", 2), R("uint8_t", 3))); return true;
      case Op::BXOR: s = W("uint8_t", 1, fmt::format("(uint8_t)({} ^ {})", R("uint8_t", 2), R("uint8_t", 3))); return true;
      case Op::BNOT: s = W("uint8_t", 1, fmt::format("(uint8_t)({} ^ 1u)", R("uint8_t", 2))); return true;
      case Op::RISE:
        s = W("uint8_t", 1, fmt::format("(uint8_t)({} & ({} ^ 1u) & {})", R("uint8_t", 2), R("uint8_t", 3), R("uint8_t", 4)));
        return true;
      case Op::FALL:
        s = W("uint8_t", 1, fmt::format("(uint8_t)(({} ^ 1u) & {} & {})", R("uint8_t", 2), R("uint8_t", 3), R("uint8_t", 4)));
        return true;
      case Op::STEADY_HIGH:
        s = W("uint8_t", 1, fmt::format("(uint8_t)({} & {} & {})", R("uint8_t", 2), R("uint8_t", 3), R("uint8_t", 4)));
        return true;
      case Op::STEADY_LOW:
        s = W("uint8_t", 1,
              fmt::format("(uint8_t)(({} ^ 1u) & ({} ^ 1u) & {})", R("uint8_t", 2), R("uint8_t", 3), R("uint8_t", 4)));
        return true;
      case Op::TOBOOL8: s = W("uint8_t", 1, fmt::format("(uint8_t)({} != 0)", R("uint8_t", 2))); return true;
      case Op::TOBOOL16: s = W("uint8_t", 1, fmt::format("(uint8_t)({} != 0)", R("uint16_t", 2))); return true;
      case Op::TOBOOL32: s = W("uint8_t", 1, fmt::format("(uint8_t)({} != 0)", R("uint32_t", 2))); return true;
      case Op::TOBOOL64: s = W("uint8_t", 1, fmt::format("(uint8_t)({} != 0)", R("uint64_t", 2))); return true;
      case Op::DIVK_I16:
      case Op::DIVK_I32:
      case Op::MODK_I16:
      case Op::MODK_I32: {
        const char* t = op == Op::DIVK_I16 || op == Op::MODK_I16 ? "int16_t" : "int32_t";
        bool mod = op == Op::MODK_I16 || op == Op::MODK_I32;
        // |K| >= 2: C's truncating division by the literal is the instruction's result
        // (no overflow), and the C++ compiler picks the best multiply-shift sequence.
        s = W(t, 1, fmt::format("({})((int32_t){} {} (int32_t){})", t, R(t, 2), mod ? "%" : "/", S(5)));
        return true;
      }
      case Op::JNLT_F32:
      case Op::JNGE_F32:
      case Op::JNLT_F64:
      case Op::JNGE_F64: {
        const char* t = op == Op::JNLT_F32 || op == Op::JNGE_F32 ? "float" : "double";
        const char* rel = op == Op::JNLT_F32 || op == Op::JNLT_F64 ? "<" : ">=";
        s = fmt::format("if (!({} {} {})) {}", R(t, 2), rel, R(t, 3), cjump(1));
        return true;
      }
      default: break;
    }
    std::string_view name = op_info(op).name;
    // Rank-2 frame arrays: two indices, checked in order (TRAP's b says which failed).
    if (name.rfind("LDXX", 0) == 0 || name.rfind("STXX", 0) == 0) {
      int n = name.back() - '0';
      const char* t = n == 1 ? "uint8_t" : n == 2 ? "uint16_t" : n == 4 ? "uint32_t" : "uint64_t";
      bool load = name[0] == 'L';
      int at = load ? 3 : 2;
      if (name[4] == 'N') {
        // Indices the compiler proved in range: no check, but the C++ compiler is told the
        // range; the lower bounds are in the offset.
        s.clear();
        for (int d = 0; d < 2; ++d) {
          int idx = at + 4 * d;
          s += fmt::format("int64_t i{0} = {1}; if (i{0} < (int64_t){2} || i{0} - (int64_t){2} >= (int64_t){3}) __builtin_unreachable(); ",
                           d, R("int32_t", idx), S(idx + 1), K(idx + 2));
        }
        std::string addr = fmt::format("base + ((int64_t){} + i0 * {} + i1 * {} + (int64_t)({}))", K(at - 1), K(at + 3), K(at + 7),
                                       S(at + 8));
        s += load ? W(t, 1, fmt::format("ld<{}>({})", t, addr)) : fmt::format("st<{}>({}, {});", t, addr, R(t, 11));
        return true;
      }
      s.clear();
      for (int d = 0; d < 2; ++d) {
        int idx = at + 4 * d;
        s += fmt::format("int64_t i{4} = (int64_t){0} - (int64_t){1}; if (i{4} < 0 || i{4} >= (int64_t){2}) TRAP(2, {3}, {0}, {4}, 0); ",
                         R("int32_t", idx), S(idx + 1), K(idx + 2), P(pc), d);
      }
      std::string addr = fmt::format("base + {} + i0 * {} + i1 * {} + {}", K(at - 1), K(at + 3), K(at + 7), K(at + 8));
      if (load) s += W(t, 1, fmt::format("ld<{}>({})", t, addr));
      else s += fmt::format("st<{}>({}, {});", t, addr, R(t, 11));
      return true;
    }
    // An index linear in two variables, wrapping as MUL_I32 and ADD_I32 do, checked once.
    if (name.rfind("LDXL", 0) == 0 || name.rfind("STXL", 0) == 0) {
      int n = name.back() - '0';
      const char* t = n == 1 ? "uint8_t" : n == 2 ? "uint16_t" : n == 4 ? "uint32_t" : "uint64_t";
      bool load = name[0] == 'L';
      int at = load ? 3 : 2;
      s = fmt::format("int32_t l = wadd<int32_t>(wmul<int32_t>({}, {}), {}); ", R("int32_t", at), R("int32_t", at + 1),
                      R("int32_t", at + 2));
      s += fmt::format("int64_t i = (int64_t)l - (int64_t){0}; if (i < 0 || i >= (int64_t){1}) TRAP(2, {2}, l, 0, 0); ", S(at + 3),
                       K(at + 4), P(pc));
      std::string addr = fmt::format("base + {} + i * {}", K(at - 1), n);
      if (load) s += W(t, 1, fmt::format("ld<{}>({})", t, addr));
      else s += fmt::format("st<{}>({}, {});", t, addr, R(t, 7));
      return true;
    }
    // Whole structure elements as blocks; a copy that cannot overlap is a memcpy.
    if (op == Op::LDXB || op == Op::STXB) {
      bool load = op == Op::LDXB;
      int at = load ? 3 : 2;
      uint64_t arr = w[at - 1], arr_n = uint64_t{w[at + 2]} * w[at + 3], blk = load ? w[1] : w[7], n = w[8];
      const char* fn = blk + n <= arr || arr + arr_n <= blk ? "memcpy" : "memmove";
      s = fmt::format("int64_t i = (int64_t){0} - (int64_t){1}; if (i < 0 || i >= (int64_t){2}) TRAP(2, {3}, {0}, 0, 0); ",
                      R("int32_t", at), S(at + 1), K(at + 2), P(pc));
      std::string elem = fmt::format("base + {} + i * {} + {}", K(at - 1), K(at + 3), K(at + 4));
      if (load) s += fmt::format("std::{}(base + {}, {}, {});", fn, K(1), elem, K(8));
      else if (auto from = block_copy(pc)) s += fmt::format("uint8_t b_[{0}]; std::memcpy(b_, {1}, {0}); std::memcpy({2}, b_, {0});", K(8), *from, elem);
      else s += fmt::format("std::{}({}, base + {}, {});", fn, elem, K(7), K(8));
      return true;
    }
    // Element access into frame arrays (bounds-checked); an H variant takes an INT index.
    if (name.rfind("LDX", 0) == 0 || name.rfind("STX", 0) == 0) {
      bool structs = name[3] == 'S';
      const char* index = name.find('H') != std::string_view::npos ? "int16_t" : "int32_t";
      int n = name.back() - '0';
      const char* t = n == 1 ? "uint8_t" : n == 2 ? "uint16_t" : n == 4 ? "uint32_t" : "uint64_t";
      bool load = name[0] == 'L';
      int idx = load ? 3 : 2, lo = idx + 1, cnt = idx + 2;
      // An N variant's index is proven in range: the C++ compiler is told so, nothing checked.
      const bool unchecked = name[name.size() - 2] == 'N';
      s = fmt::format("int64_t i = (int64_t){0} - (int64_t){1}; if (i < 0 || i >= (int64_t){2}) {3}; ", R(index, idx), S(lo),
                      K(cnt), unchecked ? "__builtin_unreachable()" : fmt::format("TRAP(2, {}, {}, 0, 0)", P(pc), R(index, idx)));
      std::string addr = structs ? fmt::format("base + {} + i * {} + {}", K(load ? 2 : 1), K(load ? 6 : 5), K(load ? 7 : 6))
                                 : fmt::format("base + {} + i * {}", K(load ? 2 : 1), n);
      if (load) s += W(t, 1, fmt::format("ld<{}>({})", t, addr));
      else s += fmt::format("st<{}>({}, {});", t, addr, R(t, structs ? 7 : 5));
      return true;
    }
    size_t us = name.find('_');
    if (us == std::string_view::npos) return false;
    std::string_view fam = name.substr(0, us), tn = name.substr(us + 1);
    if (fam == "CVT") {
      size_t us2 = tn.find('_');
      const char* from = ctype(tn.substr(0, us2));
      const char* to = ctype(tn.substr(us2 + 1));
      if (!from || !to) return false;
      s = W(to, 1, fmt::format("(cvt<{}>({}))", to, R(from, 2)));
      return true;
    }
    const char* C = ctype(tn);
    if (!C) return false;
    auto bin = [&](const char* f) { s = W(C, 1, fmt::format("({}<{}>({}, {}))", f, C, R(C, 2), R(C, 3))); };
    auto cmp = [&](const char* rel) { s = W("uint8_t", 1, fmt::format("(uint8_t)({} {} {})", R(C, 2), rel, R(C, 3))); };
    auto cj = [&](const char* rel) { s = fmt::format("if ({} {} {}) {}", R(C, 2), rel, R(C, 3), cjump(1)); };
    if (fam == "ADD") bin("wadd");
    else if (fam == "SUB") bin("wsub");
    else if (fam == "MUL") bin("wmul");
    else if (fam == "MADD") s = W(C, 1, fmt::format("(wadd<{0}>(wmul<{0}>({1}, {2}), {3}))", C, R(C, 2), R(C, 3), R(C, 4)));
    else if (fam == "DIV") {
      if (is_int(tn))
        s = fmt::format("{0} d = {1}; if (d == ({0})0) TRAP(1, {2}, 0, 0, 0); ", C, R(C, 3), P(pc)) +
            W(C, 1, fmt::format("(wdiv<{}>({}, d))", C, R(C, 2)));
      else
        s = W(C, 1, fmt::format("({})({} / {})", C, R(C, 2), R(C, 3)));
    } else if (fam == "NEG") s = W(C, 1, fmt::format("(wneg<{}>({}))", C, R(C, 2)));
    else if (fam == "EQ") cmp("==");
    else if (fam == "NE") cmp("!=");
    else if (fam == "LT") cmp("<");
    else if (fam == "LE") cmp("<=");
    else if (fam == "GT") cmp(">");
    else if (fam == "GE") cmp(">=");
    else if (fam == "JLT") cj("<");
    else if (fam == "JGE") cj(">=");
    else if (fam == "JEQ") cj("==");
    else if (fam == "JNE") cj("!=");
    else if (fam == "JTZ") s = fmt::format("if (({}) ({} & {}) == 0) {}", C, R(C, 2), R(C, 3), cjump(1));
    else if (fam == "JTNZ") s = fmt::format("if (({}) ({} & {}) != 0) {}", C, R(C, 2), R(C, 3), cjump(1));
    else if (fam == "MIN") s = fmt::format("{0} x = {1}, y = {2}; ", C, R(C, 2), R(C, 3)) + W(C, 1, "(y < x ? y : x)");
    else if (fam == "MAX") s = fmt::format("{0} x = {1}, y = {2}; ", C, R(C, 2), R(C, 3)) + W(C, 1, "(x < y ? y : x)");
    else if (fam == "ABS") s = W(C, 1, fmt::format("(wabs<{}>({}))", C, R(C, 2)));
    else if (fam == "MOD")
      s = fmt::format("{0} d = {1}; if (d == ({0})0) TRAP(1, {2}, 1, 0, 0); ", C, R(C, 3), P(pc)) +
          W(C, 1, fmt::format("(wmod<{}>({}, d))", C, R(C, 2)));
    else if (fam == "MODZ")
      s = fmt::format("{0} d = {1}; ", C, R(C, 3)) + W(C, 1, fmt::format("(d == ({0})0 ? ({0})0 : wmod<{0}>({1}, d))", C, R(C, 2)));
    else if (fam == "AND") s = W(C, 1, fmt::format("({})({} & {})", C, R(C, 2), R(C, 3)));
    else if (fam == "OR") s = W(C, 1, fmt::format("({})({} | {})", C, R(C, 2), R(C, 3)));
    else if (fam == "XOR") s = W(C, 1, fmt::format("({})({} ^ {})", C, R(C, 2), R(C, 3)));
    else if (fam == "NOT") s = W(C, 1, fmt::format("({})(~{})", C, R(C, 2)));
    else if (fam == "SHL" || fam == "SHR" || fam == "ROL" || fam == "ROR") {
      std::string f(fam);
      std::transform(f.begin(), f.end(), f.begin(), [](char ch) { return static_cast<char>(ch - 'A' + 'a'); });
      s = W(C, 1, fmt::format("({}<{}>({}, {}))", f, C, R(C, 2), R("uint64_t", 3)));
    } else if (fam == "SHLD" || fam == "SHRD" || fam == "ROLD" || fam == "RORD") {
      std::string f(fam.substr(0, 3));
      std::transform(f.begin(), f.end(), f.begin(), [](char ch) { return static_cast<char>(ch - 'A' + 'a'); });
      s = W(C, 1, fmt::format("({}<{}>({}, dint_count({})))", f, C, R(C, 2), R("int32_t", 3)));
    } else if (fam == "GETBITD") {
      s = W("uint8_t", 1, fmt::format("((uint8_t)((shr<{}>({}, dint_count({})) & 1u) ^ {}))", C, R(C, 2), R("int32_t", 3), K(4)));
    } else if (fam == "ANDSHL" || fam == "ANDSHR" || fam == "ORSHL" || fam == "ORSHR" || fam == "XORSHL" || fam == "XORSHR") {
      // A bitwise operation on a shifted operand: the count is an immediate below the width.
      const bool shl = fam.substr(fam.size() - 3) == "SHL";
      const char* bit = fam[0] == 'A' ? "&" : fam[0] == 'O' ? "|" : "^";
      s = W(C, 1, fmt::format("({0})({1} {2} {3}<{0}>({4}, {5}))", C, R(C, 2), bit, shl ? "shl" : "shr", R(C, 3), K(4)));
    } else if (fam == "CHK")
      s = fmt::format("{0} v = {1}, lo = {2}, hi = {3}; if (v < lo || v > hi) TRAP({4}, {5}, v, lo, hi);", C, R(C, 1),
                      R(C, 2), R(C, 3), w[4] == 1 ? 2 : 3, P(pc));
    else if (fam == "LOOPUP" || fam == "LOOPDN")
      s = fmt::format("{0} v; bool ovf = __builtin_add_overflow({1}, {2}, &v); {3} if (!ovf && v {4} {5}) {{ {6}{7} }}", C,
                      R(C, 1), R(C, 2), W(C, 1, "v"), fam == "LOOPUP" ? "<=" : ">=", R(C, 3), backjump(), jump(4));
    else if (fam == "ROUND") s = W(C, 1, fmt::format("round_even({})", R(C, 2)));
    else if (fam == "TRUNC") s = W(C, 1, fmt::format("trunc_real({})", R(C, 2)));
    else return false;
    return true;
  }

  // ---- frame slots cached in C++ locals (write-through)
  //
  // Every store into the frame stays a store, so memory is exact at every instruction
  // (traps, calls, coverage and probes see what the interpreter would). What changes is
  // the reads: a slot this function wrote, through a path on which nothing else can have
  // written it since, is read from the local that holds the value it stored. A loop that
  // updates a variable then runs on registers instead of a chain of stores and the loads
  // that wait for them. "Nothing else" is decided per instruction: a write of the same
  // bytes under another type, a block or element write overlapping it, and anything that
  // may write memory the translator does not see (calls, pointers, absolute addresses,
  // host functions) invalidates the locals it may touch.
  struct SlotKey {
    uint32_t off;
    std::string ctype;
  };
  static uint32_t ctype_size(std::string_view t) {
    if (t == "int8_t" || t == "uint8_t") return 1;
    if (t == "int16_t" || t == "uint16_t") return 2;
    if (t == "int32_t" || t == "uint32_t" || t == "float") return 4;
    return 8;
  }
  static bool test_bit(const std::vector<uint64_t>& b, int k) { return (b[static_cast<size_t>(k) >> 6] >> (k & 63)) & 1u; }
  // Integers of one size share a local (the unsigned type; a read converts, as the
  // load from memory would); REAL and LREAL have their own.
  static std::string key_type(std::string_view t) {
    if (t == "float" || t == "double") return std::string(t);
    switch (ctype_size(t)) {
      case 1: return "uint8_t";
      case 2: return "uint16_t";
      case 4: return "uint32_t";
      default: return "uint64_t";
    }
  }
  int find_key(uint32_t off, std::string_view t) const {
    auto it = key_index_.find({off, key_type(t)});
    return it == key_index_.end() ? -1 : it->second;
  }

  // Frame bytes [from, to) an instruction writes other than through W (-1: anything,
  // memory it cannot name; 0 with from == to: nothing).
  struct Clobber {
    bool all = false;
    uint32_t from = 0, to = 0;
  };
  Clobber clobbers(uint32_t pc) const {
    const uint32_t* w = &code_[pc];
    auto op = static_cast<Op>(w[0]);
    auto range = [](uint64_t a, uint64_t n) { return Clobber{false, static_cast<uint32_t>(a), static_cast<uint32_t>(std::min<uint64_t>(a + n, UINT32_MAX))}; };
    switch (op) {
      // Writes only through W, or none at all.
      case Op::NOP: case Op::HALT: case Op::RET: case Op::JMP: case Op::JMPB: case Op::JMPF: case Op::JMPT: case Op::JTAB:
      case Op::COV: case Op::FNMOCK: case Op::TRAP: case Op::FRAME: case Op::ENTER:
      case Op::MOV1: case Op::MOV2: case Op::MOV4: case Op::MOV8: case Op::SEL1: case Op::SEL2: case Op::SEL4: case Op::SEL8:
      case Op::LDG1: case Op::LDG2: case Op::LDG4: case Op::LDG8:
      case Op::LDI1: case Op::LDI2: case Op::LDI4: case Op::LDI8:
      case Op::LDBIT: case Op::ADDR: case Op::ADDRI: case Op::ADDRK: case Op::ELEM: case Op::NOW: case Op::ADVTIME:
      case Op::SCMP: case Op::WSCMP: case Op::GETBIT1: case Op::GETBIT2: case Op::GETBIT4: case Op::GETBIT8:
      case Op::SETBIT1: case Op::SETBIT2: case Op::SETBIT4: case Op::SETBIT8:
      case Op::BAND: case Op::BOR: case Op::BXOR: case Op::BNOT: case Op::RISE: case Op::FALL:
      case Op::STEADY_HIGH: case Op::STEADY_LOW: case Op::TOBOOL8: case Op::TOBOOL16: case Op::TOBOOL32: case Op::TOBOOL64:
      case Op::DIVK_I16: case Op::DIVK_I32: case Op::MODK_I16: case Op::MODK_I32:
      case Op::ROWS: case Op::LDXR1: case Op::LDXR2: case Op::LDXR4: case Op::LDXR8:
        return {};
      // Elements through a row offset, inside the array the instruction names.
      case Op::STXR1: case Op::STXR2: case Op::STXR4: case Op::STXR8: return range(w[4], w[5]);
      // Block writes into the frame.
      case Op::MOVN: case Op::LDGN: case Op::INITBLK: return range(w[1], w[3]);
      case Op::LDIN: return range(w[1], w[4]);
      case Op::SCPY: return range(w[1], uint64_t{w[3]} + 1);
      case Op::WSCPY: return range(w[1], 2 * (uint64_t{w[3]} + 1));
      case Op::FBENTER: return range(4, 4);
      case Op::NATIVE: {
        std::string ignored;
        uint32_t bytes = 0;
        if (math_inline(w, &ignored)) return range(w[2], 8);
        if (string_inline(w, &ignored, &bytes)) return range(w[2], bytes);
        return {true};
      }
      default: break;
    }
    if (op == Op::STI1 || op == Op::STI2 || op == Op::STI4 || op == Op::STI8 || op == Op::STIN) {
      auto it = safe_.find(pc);
      if (it != safe_.end()) return range(it->second.lo, uint64_t{it->second.hi} - it->second.lo);
      return {true};
    }
    std::string_view n = op_info(op).name;
    // Element writes stay inside their (bounds-checked) array.
    if (op == Op::LDXB) return range(w[1], w[8]);
    if (op == Op::STXB) return range(w[1], uint64_t{w[4]} * w[5]);
    if (n.rfind("STXX", 0) == 0) return range(w[1], uint64_t{w[4]} * w[5]);
    if (n.rfind("LDXX", 0) == 0) return {};
    if (n.rfind("STXL", 0) == 0) return range(w[1], uint64_t{w[6]} * static_cast<uint64_t>(n.back() - '0'));
    if (n.rfind("LDXL", 0) == 0) return {};
    if (n.rfind("STXS", 0) == 0) return range(w[1], uint64_t{w[4]} * w[5]);
    if (n.rfind("STX", 0) == 0) return range(w[1], uint64_t{w[4]} * static_cast<uint64_t>(n.back() - '0'));
    if (n.rfind("LDX", 0) == 0) return {};
    if (typed_family(n)) return {};
    return {true};  // calls, pointers, absolute stores, host functions, anything new
  }

  // The analysis for one function: which slots get locals, and for each instruction the
  // locals that hold their slot's value when it starts (a forward "must" dataflow:
  // valid on every path in).
  bool cache_slots(uint32_t start, uint32_t end) {
    keys_.clear();
    key_index_.clear();
    valid_in_.clear();
    index_of_.clear();
    std::vector<uint32_t> pcs;
    for (uint32_t pc = start; pc < end; pc += op_length(&code_[pc])) {
      index_of_[pc] = pcs.size();
      pcs.push_back(pc);
    }
    // The W writes of each instruction (translating it in collect mode).
    std::vector<std::vector<SlotKey>> writes(pcs.size()), reads(pcs.size());
    for (size_t i = 0; i < pcs.size(); ++i) {
      collect_ = &writes[i];
      reads_ = &reads[i];
      std::string ignored;
      bool ok = instruction(pcs[i], &ignored);
      collect_ = nullptr;
      reads_ = nullptr;
      if (!ok) return false;
      for (SlotKey& k : writes[i]) {
        k.ctype = key_type(k.ctype);
        if (key_index_.emplace(std::make_pair(k.off, k.ctype), static_cast<int>(keys_.size())).second) keys_.push_back(k);
      }
    }
    provenance(pcs, writes);
    const size_t nk = keys_.size(), words = (nk + 63) / 64;
    preload_.assign(words, 0);
    auto kill_range = [&](std::vector<uint64_t>& b, uint64_t from, uint64_t to, int except) {
      for (size_t k = 0; k < nk; ++k) {
        uint64_t a = keys_[k].off, e = a + ctype_size(keys_[k].ctype);
        if (static_cast<int>(k) != except && a < to && from < e) b[k >> 6] &= ~(uint64_t{1} << (k & 63));
      }
    };
    // Transfer function per instruction.
    auto transfer = [&](size_t i, std::vector<uint64_t> b) {
      Clobber cl = clobbers(pcs[i]);
      if (cl.all) std::fill(b.begin(), b.end(), 0);
      else if (cl.from < cl.to) kill_range(b, cl.from, cl.to, -1);
      for (const SlotKey& k : writes[i]) {
        int key = key_index_.at({k.off, k.ctype});
        kill_range(b, k.off, uint64_t{k.off} + ctype_size(k.ctype), key);
        b[static_cast<size_t>(key) >> 6] |= uint64_t{1} << (key & 63);
      }
      return b;
    };
    // Successors: the next instruction unless control never falls through, and targets.
    std::vector<std::vector<size_t>> succ(pcs.size());
    for (size_t i = 0; i < pcs.size(); ++i) {
      auto op = static_cast<Op>(code_[pcs[i]]);
      bool falls = !(op == Op::JMP || op == Op::JMPB || op == Op::RET || op == Op::HALT || op == Op::TRAP || op == Op::JTAB);
      if (falls && i + 1 < pcs.size()) succ[i].push_back(i + 1);
      std::vector<uint32_t> t;
      jump_targets(&code_[pcs[i]], &t);
      for (uint32_t x : t) {
        auto at = index_of_.find(x);
        if (at == index_of_.end()) return false;  // not an instruction start: left to the interpreter
        succ[i].push_back(at->second);
      }
    }
    auto solve = [&] {
      valid_in_.assign(pcs.size(), std::vector<uint64_t>(words, ~uint64_t{0}));
      if (!pcs.empty()) valid_in_[0] = preload_;
      std::vector<bool> reached(pcs.size(), false);
      if (!pcs.empty()) reached[0] = true;
      for (bool changed = true; changed;) {
        changed = false;
        for (size_t i = 0; i < pcs.size(); ++i) {
          if (!reached[i]) continue;
          std::vector<uint64_t> out = transfer(i, valid_in_[i]);
          for (size_t j : succ[i]) {
            std::vector<uint64_t> meet(words);
            for (size_t x = 0; x < words; ++x) meet[x] = reached[j] ? (valid_in_[j][x] & out[x]) : out[x];
            if (!reached[j] || meet != valid_in_[j]) {
              valid_in_[j] = std::move(meet);
              reached[j] = true;
              changed = true;
            }
          }
        }
      }
    };
    solve();
    // A slot the function writes but also reads where no write reaches on every path (a
    // loop's first pass, a variable updated from its previous scan's value) is loaded
    // once on entry instead: then it is valid there too, until something clobbers it.
    bool more = false;
    for (size_t i = 0; i < pcs.size(); ++i)
      for (const SlotKey& r : reads[i]) {
        int key = find_key(r.off, r.ctype);
        if (key >= 0 && !test_bit(valid_in_[i], key) && !test_bit(preload_, key)) {
          preload_[static_cast<size_t>(key) >> 6] |= uint64_t{1} << (key & 63);
          more = true;
        }
      }
    if (more) solve();
    dead_stores(pcs, end, writes, reads);
    return true;
  }
  static std::string key_name(int k) { return fmt::format("r{}", k); }

  // ---- stores of temporaries nobody reads back
  //
  // Write-through keeps memory exact for whoever reads it. A compiler temporary (the
  // frame's last part: [variables][hidden][constants][temporaries]) is read by this
  // function only, and mostly from the local its store also set: such a store is dead
  // when no path from it reaches a read of those bytes from memory before the next
  // store of the same slot. Backward liveness decides it, with every read from memory
  // counted: an R the locals do not serve, a block or string read of the frame, and
  // anything that may read the frame unseen (calls, host functions) or the next entry
  // this code falls into, which read every slot. A trap ends the scan: a temporary is
  // not looked at after it, and the next call starts by writing it again (a slot that
  // is loaded on entry keeps its stores). Taking a temporary's address keeps them all.
  static uint32_t align8(uint64_t v) { return static_cast<uint32_t>((v + 7) & ~uint64_t{7}); }
  // Frame bytes [from, to) an instruction reads other than through R (all: anything).
  Clobber frame_reads(uint32_t pc) const {
    const uint32_t* w = &code_[pc];
    auto op = static_cast<Op>(w[0]);
    auto range = [](uint64_t a, uint64_t n) { return Clobber{false, static_cast<uint32_t>(a), static_cast<uint32_t>(std::min<uint64_t>(a + n, UINT32_MAX))}; };
    switch (op) {
      case Op::NOP: case Op::HALT: case Op::RET: case Op::JMP: case Op::JMPB: case Op::JMPF: case Op::JMPT: case Op::JTAB:
      case Op::COV: case Op::TRAP: case Op::FRAME: case Op::ENTER:
      case Op::MOV1: case Op::MOV2: case Op::MOV4: case Op::MOV8: case Op::SEL1: case Op::SEL2: case Op::SEL4: case Op::SEL8:
      case Op::LDG1: case Op::LDG2: case Op::LDG4: case Op::LDG8: case Op::STG1: case Op::STG2: case Op::STG4: case Op::STG8:
      case Op::LDI1: case Op::LDI2: case Op::LDI4: case Op::LDI8: case Op::STI1: case Op::STI2: case Op::STI4: case Op::STI8:
      case Op::LDBIT: case Op::STBIT: case Op::ADDR: case Op::ADDRI: case Op::ADDRK: case Op::ELEM: case Op::NOW: case Op::ADVTIME:
      case Op::GETBIT1: case Op::GETBIT2: case Op::GETBIT4: case Op::GETBIT8:
      case Op::SETBIT1: case Op::SETBIT2: case Op::SETBIT4: case Op::SETBIT8:
      case Op::BAND: case Op::BOR: case Op::BXOR: case Op::BNOT: case Op::RISE: case Op::FALL:
      case Op::STEADY_HIGH: case Op::STEADY_LOW: case Op::TOBOOL8: case Op::TOBOOL16: case Op::TOBOOL32: case Op::TOBOOL64:
      case Op::DIVK_I16: case Op::DIVK_I32: case Op::MODK_I16: case Op::MODK_I32: case Op::INITBLK: case Op::LDGN: case Op::LDIN:
      case Op::ROWS: case Op::STXR1: case Op::STXR2: case Op::STXR4: case Op::STXR8:
        return {};
      case Op::LDXR1: case Op::LDXR2: case Op::LDXR4: case Op::LDXR8: return range(w[5], w[6]);
      case Op::FBENTER: return range(2, 6);
      case Op::FNMOCK: return range(w[2], w[3]);
      case Op::MOVN: case Op::STGN: return range(w[2], w[3]);
      case Op::STIN: return range(w[3], w[4]);
      case Op::SCPY: return range(w[2], uint64_t{w[3]} + 1);
      case Op::WSCPY: return range(w[2], 2 * (uint64_t{w[3]} + 1));
      case Op::NATIVE: {
        std::string ignored;
        if (math_inline(w, &ignored)) return range(std::min(w[3], w[4]), uint64_t{std::max(w[3], w[4])} - std::min(w[3], w[4]) + 8);
        return {true};
      }
      default: break;
    }
    std::string_view n = op_info(op).name;
    if (op == Op::LDXB) return range(w[2], uint64_t{w[5]} * w[6]);
    if (op == Op::STXB) return range(w[7], w[8]);
    if (n.rfind("LDXX", 0) == 0) return range(w[2], uint64_t{w[5]} * w[6]);
    if (n.rfind("STXX", 0) == 0) return {};
    if (n.rfind("LDXL", 0) == 0) return range(w[2], uint64_t{w[7]} * static_cast<uint64_t>(n.back() - '0'));
    if (n.rfind("STXL", 0) == 0) return {};
    if (n.rfind("LDXS", 0) == 0) return range(w[2], uint64_t{w[5]} * w[6]);
    if (n.rfind("LDX", 0) == 0) return range(w[2], uint64_t{w[5]} * static_cast<uint64_t>(n.back() - '0'));
    if (n.rfind("STX", 0) == 0) return {};
    if (typed_family(n)) return {};
    return {true};  // calls, string comparisons, host functions, assertions, anything new
  }
  void dead_stores(const std::vector<uint32_t>& pcs, uint32_t end, const std::vector<std::vector<SlotKey>>& writes,
                   const std::vector<std::vector<SlotKey>>& reads) {
    const size_t n = pcs.size(), nk = keys_.size(), words = (nk + 63) / 64;
    dead_.assign(n, std::vector<uint64_t>(words, 0));
    if (!pou_ || n == 0) return;
    const uint64_t tfrom = align8(uint64_t{pou_->const_from} + pou_->consts.size()), tto = pou_->frame_size;
    std::vector<bool> temp(nk, false);
    bool any = false;
    for (size_t k = 0; k < nk; ++k) {
      temp[k] = keys_[k].off >= tfrom && keys_[k].off + ctype_size(keys_[k].ctype) <= tto && !test_bit(preload_, static_cast<int>(k));
      any = any || temp[k];
    }
    for (uint32_t pc : pcs)
      if (static_cast<Op>(code_[pc]) == Op::ADDR && code_[pc + 2] >= tfrom && code_[pc + 2] < tto) return;
    if (!any) return;
    auto mark = [&](std::vector<uint64_t>& b, uint64_t from, uint64_t to) {
      for (size_t k = 0; k < nk; ++k)
        if (keys_[k].off < to && from < keys_[k].off + ctype_size(keys_[k].ctype)) b[k >> 6] |= uint64_t{1} << (k & 63);
    };
    const std::vector<uint64_t> all(words, ~uint64_t{0});
    std::vector<std::vector<uint64_t>> gen(n, std::vector<uint64_t>(words, 0)), kill = gen, succ_all = gen;
    std::vector<std::vector<size_t>> succ(n);
    for (size_t i = 0; i < n; ++i) {
      for (const SlotKey& r : reads[i]) {
        int key = find_key(r.off, r.ctype);
        if (key < 0 || !test_bit(valid_in_[i], key)) mark(gen[i], r.off, uint64_t{r.off} + ctype_size(r.ctype));
      }
      Clobber rd = frame_reads(pcs[i]);
      if (rd.all) gen[i] = all;
      else if (rd.from < rd.to) mark(gen[i], rd.from, rd.to);
      for (const SlotKey& k : writes[i]) {
        int key = key_index_.at({k.off, k.ctype});
        kill[i][static_cast<size_t>(key) >> 6] |= uint64_t{1} << (key & 63);
      }
      auto op = static_cast<Op>(code_[pcs[i]]);
      bool falls = !(op == Op::JMP || op == Op::JMPB || op == Op::RET || op == Op::HALT || op == Op::TRAP || op == Op::JTAB);
      if (falls && i + 1 < n) succ[i].push_back(i + 1);
      if (falls && i + 1 == n && end < code_.size()) succ_all[i] = all;  // on into the next entry's code
      std::vector<uint32_t> t;
      jump_targets(&code_[pcs[i]], &t);
      for (uint32_t x : t) succ[i].push_back(index_of_.at(x));
    }
    std::vector<std::vector<uint64_t>> in(n, std::vector<uint64_t>(words, 0)), out = in;
    for (bool changed = true; changed;) {
      changed = false;
      for (size_t i = n; i-- > 0;) {
        std::vector<uint64_t> o = succ_all[i];
        for (size_t j : succ[i])
          for (size_t x = 0; x < words; ++x) o[x] |= in[j][x];
        std::vector<uint64_t> v(words);
        for (size_t x = 0; x < words; ++x) v[x] = gen[i][x] | (o[x] & ~kill[i][x]);
        if (v != in[i] || o != out[i]) {
          in[i] = std::move(v);
          out[i] = std::move(o);
          changed = true;
        }
      }
    }
    for (size_t i = 0; i < n; ++i)
      for (const SlotKey& k : writes[i]) {
        int key = key_index_.at({k.off, k.ctype});
        if (temp[static_cast<size_t>(key)] && !test_bit(out[i], key) && !test_bit(gen[i], key))
          dead_[i][static_cast<size_t>(key) >> 6] |= uint64_t{1} << (key & 63);
      }
  }

  // ---- frame arrays reached through ADDR and ELEM
  //
  // A multi-dimensional or struct-element access into an array of the frame is ADDR
  // (the array's frame address), one ELEM per index (bounds-checked), then LDI/STI at a
  // field offset. When the pointer an instruction uses was made that way in the same
  // straight-line stretch of code (no label between, nothing overwrote the slot since),
  // the address lies inside the array by construction: ELEM's index check bounds it,
  // each further ELEM or offset is checked here to fit in the element it narrows, and
  // the array lies inside the frame. Such an access needs no null or memory-bounds
  // check, and a store through it clobbers only the array's bytes, so locals holding
  // other variables stay valid across it (the interpreter checks the same accesses and
  // can never fail them either).
  struct Prov {
    uint32_t lo = 0, hi = 0;  // the array's frame bytes [lo, hi)
    uint32_t elem = 0;        // bytes from the pointer that lie inside one element
    bool whole = false;       // ADDR of a variable: its extent comes from the first ELEM
  };
  void provenance(const std::vector<uint32_t>& pcs, const std::vector<std::vector<SlotKey>>& writes) {
    safe_.clear();
    std::set<uint32_t> labels;
    for (uint32_t pc : pcs) {
      std::vector<uint32_t> t;
      jump_targets(&code_[pc], &t);
      labels.insert(t.begin(), t.end());
    }
    std::map<uint32_t, Prov> at;  // pointer slot -> what it points into
    auto forget = [&](uint64_t from, uint64_t to) {
      for (auto it = at.begin(); it != at.end();)
        it = it->first < to && from < uint64_t{it->first} + 4 ? at.erase(it) : std::next(it);
    };
    for (size_t i = 0; i < pcs.size(); ++i) {
      const uint32_t pc = pcs[i];
      const uint32_t* w = &code_[pc];
      auto op = static_cast<Op>(w[0]);
      if (labels.count(pc)) at.clear();
      // The access this instruction makes: pointer slot, offset, bytes.
      int slot = -1;
      uint64_t off = 0, n = 0;
      switch (op) {
        case Op::ELEM: slot = 2; break;
        case Op::ADDRI: slot = 2, off = w[3]; break;
        case Op::LDI1: case Op::LDI2: case Op::LDI4: case Op::LDI8:
          slot = 2, off = w[3], n = op == Op::LDI1 ? 1 : op == Op::LDI2 ? 2 : op == Op::LDI4 ? 4 : 8;
          break;
        case Op::LDIN: slot = 2, off = w[3], n = w[4]; break;
        case Op::STI1: case Op::STI2: case Op::STI4: case Op::STI8:
          slot = 1, off = w[2], n = op == Op::STI1 ? 1 : op == Op::STI2 ? 2 : op == Op::STI4 ? 4 : 8;
          break;
        case Op::STIN: slot = 1, off = w[2], n = w[4]; break;
        default: break;
      }
      bool made = false;
      Prov result;
      if (slot >= 0) {
        auto it = at.find(w[slot]);
        if (it != at.end()) {
          const Prov p = it->second;
          if (op == Op::ELEM) {
            uint64_t extent = uint64_t{w[5]} * w[6];
            if (p.whole && p.lo + extent <= UINT32_MAX) {
              result = {p.lo, static_cast<uint32_t>(p.lo + extent), w[6], false};
              made = true;
            } else if (!p.whole && extent <= p.elem) {
              result = {p.lo, p.hi, w[6], false};
              made = true;
            }
          } else if (!p.whole && off + n <= p.elem) {
            if (op == Op::ADDRI) result = {p.lo, p.hi, static_cast<uint32_t>(p.elem - off), false}, made = true;
          }
          if (made || (!p.whole && op != Op::ELEM && off + n <= p.elem)) safe_[pc] = p;
        }
      } else if (op == Op::ADDR) {
        result = {w[2], 0, 0, true};
        made = true;
      }
      for (const SlotKey& k : writes[i]) forget(k.off, uint64_t{k.off} + ctype_size(k.ctype));
      Clobber cl = clobbers(pc);
      if (cl.all) at.clear();
      else if (cl.from < cl.to) forget(cl.from, cl.to);
      if (made) at[w[1]] = result;
    }
  }

  // The standard functions on numbers (NATIVE with a math id) as direct libm calls the
  // C++ compiler sees, with the host's arithmetic (cpp_functions.cpp): REAL computed in double
  // and rounded once.
  static bool math_inline(const uint32_t* w, std::string* out) {
    static const char* const kFn[] = {"sqrt", "log", "log10", "exp", "sin", "cos", "tan", "asin", "acos", "atan", "pow"};
    static_assert(static_cast<uint32_t>(Native::SQRT_F32) == 0 && static_cast<uint32_t>(Native::SIN_F64) == 9 &&
                  static_cast<uint32_t>(Native::EXPT_F64) == 21, "kFn follows PLCFI_NATIVE_MATH, F32 then F64");
    uint32_t id = w[1] & 0xffffu;
    if (id >= 2 * (sizeof kFn / sizeof kFn[0])) return false;
    const char* fn = kFn[id / 2];
    bool f32 = id % 2 == 0;
    bool two = std::string_view(fn) == "pow";
    std::string x = f32 ? fmt::format("(double)ld<float>(base + {}u)", w[3]) : fmt::format("ld<double>(base + {}u)", w[3]);
    std::string y = f32 ? fmt::format("(double)ld<float>(base + {}u)", w[4]) : fmt::format("ld<double>(base + {}u)", w[4]);
    std::string v = two ? fmt::format("__builtin_{}({}, {})", fn, x, y) : fmt::format("__builtin_{}({})", fn, x);
    *out = f32 ? fmt::format("st<float>(base + {}u, (float){});", w[2], v) : fmt::format("st<double>(base + {}u, {});", w[2], v);
    return true;
  }

  // The STRING functions that work in place (ops.hpp) and the integer conversions to and
  // from text as direct calls the C++ compiler sees, instead of the host's dispatch.
  // *bytes: how much of the result slot they write.
  static bool string_inline(const uint32_t* w, std::string* out, uint32_t* bytes) {
    const uint32_t cap = w[1] >> 16;
    auto at = [&](int i) { return fmt::format("base + {}u", w[i]); };
    auto i64 = [&](int i) { return fmt::format("ld<int64_t>(base + {}u)", w[i]); };
    uint32_t n = cap + 1;
    switch (static_cast<Native>(w[1] & 0xffffu)) {
      case Native::S_LEN: *out = fmt::format("str_len({}, {});", at(2), at(3)), n = 2; break;
      case Native::S_LEFT: *out = fmt::format("str_left({}, {}u, {}, {});", at(2), cap, at(3), i64(4)); break;
      case Native::S_RIGHT: *out = fmt::format("str_right({}, {}u, {}, {});", at(2), cap, at(3), i64(4)); break;
      case Native::S_MID: *out = fmt::format("str_mid({}, {}u, {}, {}, {});", at(2), cap, at(3), i64(4), i64(5)); break;
      case Native::S_CONCAT: *out = fmt::format("str_concat({}, {}u, {}, {});", at(2), cap, at(3), at(4)); break;
      case Native::S_FIND: *out = fmt::format("str_find({}, {}, {});", at(2), at(3), at(4)), n = 2; break;
      case Native::I64_TO_S: *out = fmt::format("str_of_i64({}, {}u, {});", at(2), cap, i64(3)); break;
      case Native::S_TO_I64:
        *out = fmt::format("st<int64_t>({}, (int64_t)std::strtoll((const char*)({}), nullptr, 10));", at(2), at(3)), n = 8;
        break;
      default: return false;
    }
    if (bytes) *bytes = n;
    return true;
  }

  // A read of a constant-pool slot as a literal of type t.
  bool literal(std::string_view t, uint32_t off, std::string* out) const {
    if (!pou_ || off < pou_->const_from) return false;
    size_t size = t == "int8_t" || t == "uint8_t" ? 1 : t == "int16_t" || t == "uint16_t" ? 2
                : t == "int32_t" || t == "uint32_t" || t == "float" ? 4 : 8;
    size_t at = off - pou_->const_from;
    if (at + size > pou_->consts.size()) return false;
    uint64_t bits = 0;
    std::memcpy(&bits, pou_->consts.data() + at, size);
    // A finite REAL/LREAL as a hexadecimal literal (exact, and nothing for the C++
    // compiler to call); infinities and NaNs by their bits.
    if (t == "float" || t == "double") {
      double v;
      if (t == "float") {
        float f;
        uint32_t b32 = static_cast<uint32_t>(bits);
        std::memcpy(&f, &b32, 4);
        v = f;
      } else {
        std::memcpy(&v, &bits, 8);
      }
      if (!std::isfinite(v)) *out = t == "float" ? fmt::format("f32_bits({}u)", static_cast<uint32_t>(bits)) : fmt::format("f64_bits({}ull)", bits);
      else *out = fmt::format("({:a}{})", v, t == "float" ? "f" : "");
    }
    else if (t[0] == 'u') *out = fmt::format("(({}){}ull)", t, bits);
    else {
      int64_t v = size == 1 ? static_cast<int8_t>(bits) : size == 2 ? static_cast<int16_t>(bits)
                : size == 4 ? static_cast<int32_t>(bits) : static_cast<int64_t>(bits);
      *out = v == INT64_MIN ? fmt::format("(({})INT64_MIN)", t) : fmt::format("(({}){}ll)", t, v);
    }
    return true;
  }

  const Application& app_;
  const PouInfo* pou_ = nullptr;
  const std::vector<uint32_t>& code_;
  std::vector<uint32_t> bounds_;   // every entry (function boundaries)
  std::vector<uint32_t> starts_;   // reachable entries
  std::set<uint32_t> native_;
  std::map<uint32_t, Summary> sum_;
  // The function being translated: its cached slots and, per instruction, those valid.
  std::vector<SlotKey> keys_;
  std::map<std::pair<uint32_t, std::string>, int> key_index_;
  std::vector<std::vector<uint64_t>> valid_in_;
  std::map<uint32_t, size_t> index_of_;
  const std::vector<uint64_t>* valid_ = nullptr;  // during emission
  std::vector<SlotKey>* collect_ = nullptr;       // during analysis: W's slots
  std::vector<SlotKey>* reads_ = nullptr;         // during analysis: R's slots
  std::vector<uint64_t> preload_;                 // slots loaded on entry
  std::map<uint32_t, Prov> safe_;                 // pc -> the frame array its pointer operand points into
  std::vector<std::vector<uint64_t>> dead_;       // per instruction: the keys whose store W leaves out
  const std::vector<uint64_t>* dead_now_ = nullptr;  // during emission
  uint32_t block_load_ = UINT32_MAX;  // during emission: the LDXB right before this instruction
  int pass_ = 0;
  // The first pass's slot analysis of each function, for the final pass.
  struct Analysis {
    std::vector<SlotKey> keys;
    std::map<std::pair<uint32_t, std::string>, int> key_index;
    std::vector<std::vector<uint64_t>> valid_in;
    std::map<uint32_t, size_t> index_of;
    std::vector<uint64_t> preload;
    std::map<uint32_t, Prov> safe;
    std::vector<std::vector<uint64_t>> dead;
  };
  std::map<uint32_t, Analysis> analysis_;
  bool split_ = false;                            // the final texts are for several units
  size_t chunk_instructions_ = SIZE_MAX;          // a longer function is cut into pieces this long
  std::vector<uint32_t> cuts_;                    // the current function's pieces' first pcs (none: not cut)
  size_t chunk_ = SIZE_MAX;                       // the piece being written
  uint32_t start_ = 0;                            // the entry of the function being translated
  std::map<uint32_t, std::string> names_;         // entry -> function name (name_entries)
  std::map<uint32_t, std::string> owners_;        // entry -> the POU (or test) it belongs to
  std::map<uint32_t, uint32_t> branch_base_;      // entry -> the branch id BR(0) stands for
  std::set<std::string> called_;                  // the functions the current one calls
};


std::string cache_dir(const NativeOptions& o) {
  if (!o.cache_dir.empty()) return o.cache_dir;
  if (const char* d = std::getenv("PLCFI_NATIVE_CACHE"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return std::string(d) + "/plcfi/native";
  if (const char* d = std::getenv("HOME"); d && *d) return std::string(d) + "/.cache/plcfi/native";
  return "/tmp/plcfi-native-" + std::to_string(::getuid());
}

// Runs argv, stderr to err_file; returns the exit status (-1: could not start).
int spawn(const std::vector<std::string>& argv, const std::string& err_file) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 2, err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  int rc = posix_spawnp(&pid, args[0], &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}


struct Job {
  std::vector<std::string> argv;
  std::string err_file;
};

// Runs the jobs, `parallel` at a time, until all are done or one fails (no new job starts
// then). Returns the index of the first failed job (its status in *status) or -1. With
// `progress`, once two seconds have passed, a line on stderr counts the jobs finished.
int run_jobs(const std::vector<Job>& jobs, unsigned parallel, bool progress, const char* what, int* status) {
  std::mutex mu;
  std::condition_variable cv;
  size_t next = 0, done = 0;
  int failed = -1;
  auto worker = [&] {
    for (;;) {
      size_t k;
      {
        std::lock_guard<std::mutex> lock(mu);
        if (failed >= 0 || next == jobs.size()) return;
        k = next++;
      }
      int rc = spawn(jobs[k].argv, jobs[k].err_file);
      std::lock_guard<std::mutex> lock(mu);
      ++done;
      if (rc != 0 && failed < 0) {
        failed = static_cast<int>(k);
        *status = rc;
      }
      cv.notify_all();
    }
  };
  std::vector<std::thread> threads;
  for (unsigned t = 0; t < std::max(1u, std::min<unsigned>(parallel, static_cast<unsigned>(jobs.size()))); ++t)
    threads.emplace_back(worker);
  const auto t0 = std::chrono::steady_clock::now();
  bool shown = false;
  {
    std::unique_lock<std::mutex> lock(mu);
    while (done < jobs.size() && !(failed >= 0 && done == next)) {
      cv.wait_for(lock, std::chrono::milliseconds(250));
      double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (progress && s >= 2.0) {
        std::string line = jobs.size() > 1 ? fmt::format("native tier: compiling {}, {} of {} done ({:.0f} s)", what, done, jobs.size(), s)
                                           : fmt::format("native tier: compiling {} ({:.0f} s)", what, s);
        std::fputs(("\r" + line + "\033[K").c_str(), stderr);
        shown = true;
      }
    }
  }
  for (auto& t : threads) t.join();
  if (shown) std::fputs("\r\033[K", stderr);
  return failed;
}

// How many compilers run at once: the options', else $PLCFI_JOBS, else one per core.
// 0 with *err set: $PLCFI_JOBS is not a count.
unsigned compile_jobs(const NativeOptions& o, std::string* err) {
  if (o.jobs) return o.jobs;
  if (const char* j = std::getenv("PLCFI_JOBS"); j && *j) {
    char* end = nullptr;
    errno = 0;
    long n = std::strtol(j, &end, 10);
    if (errno != 0 || *end != 0 || n < 1 || n > 256) {
      *err = fmt::format("native tier: PLCFI_JOBS is '{}': give the number of compilers to run at once, from 1 to 256", j);
      return 0;
    }
    return static_cast<unsigned>(n);
  }
  return std::max(1u, std::thread::hardware_concurrency());
}

// The first lines of a compiler's error output, indented.
std::string first_lines(const std::string& file) {
  std::ifstream ef(file);
  std::string first, line;
  for (int i = 0; i < 8 && std::getline(ef, line); ++i) first += "\n  " + line;
  return first;
}

}  // namespace

std::vector<std::pair<uint64_t, uint64_t>> scratch_ranges(const Application& app) {
  std::vector<std::pair<uint64_t, uint64_t>> out;
  std::map<const Type*, bool> holds;  // a type with an FB instance inside (memo)
  std::function<bool(const Type*)> has_pou = [&](const Type* t) -> bool {
    if (!t) return false;
    if (t->kind == TypeKind::Pou) return true;
    auto it = holds.find(t);
    if (it != holds.end()) return it->second;
    holds[t] = false;
    bool r = false;
    if (t->kind == TypeKind::Array) r = has_pou(t->elem);
    if (t->kind == TypeKind::Struct)
      for (const Field& f : t->fields) r = r || has_pou(f.type);
    holds[t] = r;
    return r;
  };
  std::function<void(const Type*, uint64_t)> walk_type;
  auto walk_pou = [&](const PouInfo* p, uint64_t at) {
    for (const PouInfo* q = p; q; q = q->base) {
      if (!q->compiled) continue;
      uint64_t from = (uint64_t{q->const_from} + q->consts.size() + 7) & ~uint64_t{7};
      if (from < q->frame_size) out.emplace_back(at + from, at + q->frame_size);
      for (const auto& v : q->vars)
        if (v->where == Where::Frame && has_pou(v->type)) walk_type(v->type, at + v->offset);
    }
  };
  walk_type = [&](const Type* t, uint64_t at) {
    if (!has_pou(t)) return;
    if (t->kind == TypeKind::Pou && t->pou) walk_pou(t->pou, at);
    else if (t->kind == TypeKind::Array && t->elem && t->elem->size)
      for (uint64_t k = 0; k < t->size / t->elem->size; ++k) walk_type(t->elem, at + k * t->elem->size);
    else if (t->kind == TypeKind::Struct)
      for (const Field& f : t->fields) walk_type(f.type, at + f.offset);
  };
  for (const auto& p : app.programs) walk_pou(p.pou, p.addr);
  for (const auto& p : app.observers) walk_pou(p.pou, p.addr);
  for (const auto& g : app.globals)
    if (g.sym && g.sym->where == Where::Abs) walk_type(g.sym->type, g.sym->offset);
  if (app.mstack_size) out.emplace_back(app.mstack_addr, uint64_t{app.mstack_addr} + app.mstack_size);
  std::sort(out.begin(), out.end());
  return out;
}

uint64_t first_difference(const std::vector<std::pair<uint64_t, uint64_t>>& scratch, const uint8_t* a, const uint8_t* b, uint64_t n) {
  uint64_t at = 0;
  auto compare = [&](uint64_t to) {
    to = std::min(to, n);
    if (at < to && std::memcmp(a + at, b + at, to - at) != 0)
      for (uint64_t i = at; i < to; ++i)
        if (a[i] != b[i]) return i;
    return n;
  };
  for (auto [from, to] : scratch) {
    if (from > at) {
      uint64_t d = compare(from);
      if (d != n) return d;
    }
    at = std::max(at, to);
  }
  return compare(n);
}

NativeProgram native_program(const Application& app, size_t split_bytes, size_t chunk_instructions) {
  Translator t(app, chunk_instructions);
  return t.run(split_bytes);
}

std::string native_source(const Application& app, std::vector<uint32_t>* entries, std::vector<uint32_t>* skipped) {
  NativeProgram p = native_program(app, 0, NativeOptions{}.chunk_instructions);
  *entries = p.entries;
  *skipped = p.skipped;
  return p.units.at(0).text;
}

NativeCode::~NativeCode() {
  if (handle_) dlclose(handle_);
}

std::unique_ptr<NativeCode> NativeCode::build(const Application& app, const NativeOptions& o, std::string* err) {
  const unsigned n_jobs = compile_jobs(o, err);
  if (n_jobs == 0) return nullptr;
  NativeProgram prog = native_program(app, o.split_bytes, o.chunk_instructions);
  std::string compiler = !o.compiler.empty() ? o.compiler : (std::getenv("PLCFI_CXX") ? std::getenv("PLCFI_CXX") : "c++");
  std::string optimize = prog.split ? o.optimize_split : o.optimize;
  if (const char* v = std::getenv("PLCFI_NATIVE_OPT"); v && *v) optimize = v;  // e.g. -O2 for a long run of a large program
  const std::vector<std::string> flags = {"-std=c++20", optimize, "-fPIC", "-w", "-fno-strict-aliasing", "-ffp-contract=off"};
  std::string common = compiler;
  for (const auto& f : flags) common += " " + f;
  common += embedded::kNativeAbiHpp;
  common += embedded::kOpsHpp;
  std::string dir = cache_dir(o);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    *err = "native tier: cannot create the cache folder " + dir + ": " + ec.message();
    return nullptr;
  }
  // Cache keys: a unit's object by its text, the library by its objects. One unit is
  // compiled straight into the library.
  std::vector<std::string> objects;
  std::string lib_key = common + (prog.split ? " split" : " -shared");
  for (const NativeUnit& u : prog.units) {
    objects.push_back(fmt::format("{}/{:016x}.o", dir, fnv1a(common + u.text)));
    lib_key += prog.split ? objects.back() : u.text;
  }
  std::string stem = fmt::format("{}/{:016x}", dir, fnv1a(lib_key));
  std::unique_ptr<NativeCode> nc(new NativeCode());
  nc->library_ = stem + ".so";
  nc->units_ = prog.units.size();
  auto t0 = std::chrono::steady_clock::now();
  if (!fs::exists(nc->library_)) {
    // A private work folder: concurrent builds of the same program do not collide; the
    // finished objects and library are renamed into place atomically.
    std::string work = fmt::format("{}.{}.tmp", stem, ::getpid());
    fs::create_directories(work, ec);
    std::ofstream(work + "/plcfi_native_abi.hpp") << embedded::kNativeAbiHpp;
    std::ofstream(work + "/plcfi_ops.hpp") << embedded::kOpsHpp;
    std::vector<Job> jobs;
    std::vector<size_t> unit_of;  // job -> unit
    for (size_t k = 0; k < prog.units.size(); ++k) {
      if (prog.split && fs::exists(objects[k])) continue;
      std::string src = fmt::format("{}/{}.cpp", work, prog.units[k].name);
      std::ofstream(src) << prog.units[k].text;
      Job j;
      j.argv = {compiler};
      j.argv.insert(j.argv.end(), flags.begin(), flags.end());
      if (prog.split) j.argv.insert(j.argv.end(), {"-c", "-I", work, "-o", work + "/" + prog.units[k].name + ".o", src});
      else j.argv.insert(j.argv.end(), {"-shared", "-I", work, "-o", work + "/native.so", src});
      j.err_file = fmt::format("{}/{}.errors.txt", work, prog.units[k].name);
      jobs.push_back(std::move(j));
      unit_of.push_back(k);
    }
    // The largest first: the last to finish is then a small one.
    std::vector<size_t> order(jobs.size());
    for (size_t j = 0; j < order.size(); ++j) order[j] = j;
    std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) {
      return prog.units[unit_of[x]].text.size() > prog.units[unit_of[y]].text.size();
    });
    std::vector<Job> sorted_jobs;
    std::vector<size_t> sorted_units;
    for (size_t j : order) {
      sorted_jobs.push_back(std::move(jobs[j]));
      sorted_units.push_back(unit_of[j]);
    }
    jobs = std::move(sorted_jobs);
    unit_of = std::move(sorted_units);
    nc->units_compiled_ = jobs.size();
    int rc = 0;
    int failed = run_jobs(jobs, n_jobs, o.progress, prog.split ? "units" : "the program", &rc);
    if (failed >= 0) {
      *err = rc < 0 ? fmt::format("native tier: cannot run the C++ compiler '{}' (set PLCFI_CXX, or install g++)", compiler)
                    : fmt::format("native tier: '{}' failed on the generated code (exit {}), kept in {}{}", compiler, rc,
                                  work, first_lines(jobs[failed].err_file));
      return nullptr;
    }
    if (prog.split) {
      for (size_t j = 0; j < jobs.size(); ++j) {
        fs::rename(fmt::format("{}/{}.o", work, prog.units[unit_of[j]].name), objects[unit_of[j]], ec);
        if (ec) {
          *err = "native tier: " + objects[unit_of[j]] + ": " + ec.message();
          return nullptr;
        }
      }
      Job link;
      link.argv = {compiler, "-shared", "-o", work + "/native.so"};
      link.argv.insert(link.argv.end(), objects.begin(), objects.end());
      link.err_file = work + "/link.errors.txt";
      if (run_jobs({link}, 1, false, "", &rc) >= 0) {
        *err = fmt::format("native tier: '{}' could not link the units (exit {}), kept in {}{}", compiler, rc, work,
                           first_lines(link.err_file));
        return nullptr;
      }
    }
    fs::rename(work + "/native.so", nc->library_, ec);
    if (ec) {
      *err = "native tier: " + nc->library_ + ": " + ec.message();
      return nullptr;
    }
    fs::remove_all(work, ec);
  } else {
    nc->from_cache_ = true;
  }
  nc->compile_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  nc->handle_ = dlopen(nc->library_.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!nc->handle_) {
    *err = std::string("native tier: ") + dlerror();
    return nullptr;
  }
  auto* abi = static_cast<const uint32_t*>(dlsym(nc->handle_, "plcfi_native_abi"));
  auto* count = static_cast<const uint32_t*>(dlsym(nc->handle_, "plcfi_native_count"));
  auto* table = static_cast<const native_abi::Entry*>(dlsym(nc->handle_, "plcfi_native_entries"));
  if (!abi || !count || !table || *abi != native_abi::kAbiVersion) {
    *err = "native tier: " + nc->library_ + " is not a plcfi native library of this version";
    return nullptr;
  }
  nc->by_entry_.assign(app.code.size(), nullptr);
  for (uint32_t i = 0; i < *count; ++i)
    if (table[i].pc < app.code.size()) nc->by_entry_[table[i].pc] = table[i].fn;
  nc->functions_ = *count;
  nc->skipped_ = prog.skipped.size();
  return nc;
}

}  // namespace plcfi::st

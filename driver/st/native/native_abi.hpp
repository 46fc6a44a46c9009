// The interface between plcfi and the code of its native tier: the bytecode of an
// application translated to C++, compiled by the system's C++ compiler into a shared
// object and loaded. Included by the host and, verbatim, by the generated source, so it
// depends on the standard library only. Every generated function has the signature Fn:
// it runs one code entry with a frame base, like the interpreter from that entry until
// the matching RET, and returns kOk, kTrap (the host recorded the trap) or kHalt.
#pragma once

#include <cstdint>

namespace plcfi::st::native_abi {

constexpr int kOk = 0, kTrap = 1, kHalt = 2;
constexpr uint32_t kMaxDepth = 256;  // as the interpreter's call stack
constexpr uint32_t kAbiVersion = 2;  // 2: native_fn takes the pc and can trap

struct Ctx {
  uint8_t* mem;
  uint64_t msize;
  uint64_t* taken;          // branch coverage bits
  int64_t* now;             // the machine's scan clock
  const uint32_t* vtable;   // [selector * n_types + type] -> entry
  int64_t budget;           // backward jumps left in this call (watchdog)
  uint32_t depth;           // calls in progress
  uint32_t mtop, mend;      // method stack
  void* host;
  // Host services. trap() records the trap of the instruction at pc (a, b, c: the
  // values its message names) and returns kTrap.
  int (*trap)(Ctx* c, uint32_t kind, uint32_t pc, int64_t a, int64_t b, int64_t cc);
  // Runs any entry (native or interpreted) as a call from the current frame.
  int (*call_entry)(Ctx* c, uint32_t entry, uint8_t* base);
  // The NATIVE instruction at pc (standard functions on strings etc.; kTrap when the
  // function found a runtime error, recorded by the host: MEMCPY outside the memory) and
  // ASSERT.
  int (*native_fn)(Ctx* c, uint32_t pc, uint32_t id, uint8_t* a, uint8_t* b, uint8_t* cc, uint8_t* d);
  int (*assert_fn)(Ctx* c, uint32_t pc, uint8_t* base);
};

using Fn = int (*)(Ctx* c, uint8_t* base);

struct Entry {
  uint32_t pc;
  Fn fn;
};

}  // namespace plcfi::st::native_abi

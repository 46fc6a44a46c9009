// A compiled single-file application and a machine running its first program: the
// fixture of the VM unit tests.
#pragma once

#include <gtest/gtest.h>

#include <initializer_list>
#include <memory>
#include <string>

#include "engine.hpp"

namespace plcfi::st::vmtest {

// How often `what` occurs in `text` (instructions in a listing).
inline size_t occurrences(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

struct VmRun {
  std::unique_ptr<Build> b;
  std::unique_ptr<Machine> m;

  explicit VmRun(const std::string& src, CompileOptions opt = {}, const std::string& file = "vm.st") {
    b = build_sources({{file, src}}, opt);
    if (!b->ok()) {
      ADD_FAILURE() << b->diags.render_all();
      return;
    }
    m = std::make_unique<Machine>(*b->app);
  }
  bool ok() const { return m != nullptr; }
  bool scan() {
    const auto& p = b->app->programs.at(0);
    return m->call(p.pou->entry, p.addr);
  }
  VarHandle h(const std::string& path) const {
    std::string err;
    auto r = resolve(*b->app, path, &err);
    if (!r) ADD_FAILURE() << err;
    return r.value_or(VarHandle{});
  }
  int64_t get(const std::string& path) const { return read_int(*m, h(path)); }
  double real(const std::string& path) const { return read_real(*m, h(path)); }
  void set(const std::string& path, int64_t v) { write_int(*m, h(path), v); }
  std::string disasm() const { return disassemble(*b->app, b.get()); }
  // Branch arms taken so far.
  uint32_t taken_count() const {
    uint32_t n = 0;
    for (uint64_t w : m->taken()) n += static_cast<uint32_t>(__builtin_popcountll(w));
    return n;
  }
};

// src compiled with and without a rule (`with`, `without`) runs `scans` scans with the
// same integer values of `vars` after each.
inline void same_scan_by_scan(const std::string& src, const CompileOptions& with, const CompileOptions& without,
                              int scans, std::initializer_list<const char*> vars) {
  VmRun on(src, with, "rule.st");
  VmRun off(src, without, "rule.st");
  ASSERT_TRUE(on.ok() && off.ok());
  for (int s = 0; s < scans; ++s) {
    ASSERT_TRUE(on.scan()) << on.m->trap().message;
    ASSERT_TRUE(off.scan()) << off.m->trap().message;
    SCOPED_TRACE("scan " + std::to_string(s));
    for (const char* v : vars) ASSERT_EQ(on.get(v), off.get(v)) << v;
  }
}

// A loop that never ends, compiled with and without a rule (`with`, `without`): both stop
// on the watchdog after `budget` passes, leaving `counter` (counted once a pass) at `want`.
inline void traps_after_as_many_passes(const std::string& src, const CompileOptions& with,
                                       const CompileOptions& without, int64_t budget, const std::string& counter,
                                       int64_t want) {
  for (const CompileOptions* o : {&with, &without}) {
    VmRun p(src, *o, "forever.st");
    ASSERT_TRUE(p.ok());
    p.m->set_budget(budget);
    EXPECT_FALSE(p.scan());
    EXPECT_NE(p.m->trap().message.find("endless loop"), std::string::npos) << p.m->trap().message;
    EXPECT_EQ(p.get(counter), want) << (o == &with ? "with the rule" : "without");
  }
}

}  // namespace plcfi::st::vmtest

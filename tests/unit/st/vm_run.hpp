// A compiled single-file application and a machine running its first program: the
// fixture of the VM unit tests.
#pragma once

#include <gtest/gtest.h>

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

}  // namespace plcfi::st::vmtest

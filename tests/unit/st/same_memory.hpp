// The interpreter's and the native tier's memory compared byte by byte, the compiler
// temporaries aside (native.hpp, scratch_ranges): the native tier leaves out stores of
// temporaries nobody reads back, so those bytes may hold an older value.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "engine.hpp"
#include "native/native.hpp"
#include "vm/vm.hpp"

namespace plcfi::st {

inline ::testing::AssertionResult same_memory(const Application& app, const Machine& a, const Machine& n) {
  uint64_t i = first_difference(scratch_ranges(app), a.mem(), n.mem(), a.mem_size());
  if (i == a.mem_size()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "memory differs at address " << i << ": " << int{a.mem()[i]} << " (interpreter) vs "
                                       << int{n.mem()[i]} << " (native)";
}

// One source (compiled as `file`) run in both tiers, scan by scan: the same result, trap,
// memory and coverage after every scan. budget 0: the machines' default watchdog.
// `inputs`, when given, writes the same inputs into both machines before each scan.
inline void same_in_both_tiers(const std::string& file, const std::string& src, int scans, uint64_t budget = 0,
                               const std::function<void(Machine&, int)>& inputs = nullptr,
                               const CompileOptions& options = {}) {
  auto b = build_sources({{file, src}}, options);
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  std::string err;
  auto native = NativeCode::build(*b->app, NativeOptions{}, &err);
  ASSERT_TRUE(native) << err;
  EXPECT_EQ(native->interpreted(), 0u);
  Machine a(*b->app), n(*b->app);
  n.set_native(native.get());
  if (budget != 0) {
    a.set_budget(budget);
    n.set_budget(budget);
  }
  const auto& inst = b->app->programs.at(0);
  for (int s = 0; s < scans; ++s) {
    if (inputs) {
      inputs(a, s);
      inputs(n, s);
    }
    a.clear_taken();
    n.clear_taken();
    bool ra = a.call(inst.pou->entry, inst.addr);
    bool rn = n.call(inst.pou->entry, inst.addr);
    ASSERT_EQ(ra, rn) << "scan " << s;
    EXPECT_EQ(describe_trap(*b->app, a.trap()), describe_trap(*b->app, n.trap())) << "scan " << s;
    ASSERT_TRUE(same_memory(*b->app, a, n)) << "memory differs after scan " << s;
    ASSERT_EQ(a.taken(), n.taken()) << "coverage differs after scan " << s;
  }
}

}  // namespace plcfi::st

// A scan hook that samples trace writers (VCD, CSV) at the end of every scan, after the
// outputs went out: what `sim --vcd` and the logs of `script --log` record.
#pragma once

#include <vector>

#include "report/trace.hpp"
#include "runtime/runtime.hpp"

namespace plcfi::cli {

class TraceHook final : public rt::ScanHooks {
 public:
  explicit TraceHook(std::vector<report::TraceWriter*> w) : writers_(std::move(w)) {}
  void end_of_scan(rt::Runtime& r) override {
    for (auto* w : writers_) w->sample(r.now(), r.machine());
  }

 private:
  std::vector<report::TraceWriter*> writers_;
};

}  // namespace plcfi::cli

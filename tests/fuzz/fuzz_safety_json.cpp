// Fuzz target: an earlier run's safety.json as `campaign --baseline` reads it
// (parse_safety_json), compared with itself and with an empty report.
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "report/safety.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  report::SafetyReport r;
  std::string err;
  if (report::parse_safety_json(std::string(fuzz::as_text(data, size)), "safety.json", &r, &err)) {
    (void)report::compare_safety(r, r);
    (void)report::compare_safety(report::SafetyReport{}, r);
    (void)report::safety_json(r);
  }
  return 0;
}

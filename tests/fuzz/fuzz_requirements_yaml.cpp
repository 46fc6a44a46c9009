// Fuzz target: the EDTL requirements reader (load_requirements); requirements it accepts
// are compiled and checked on the hand dryer's recorded trace, as `plcfi edtl check` does.
#include <cstdint>
#include <string>

#include "fuzz_support.hpp"
#include "monitor/edtl.hpp"
#include "report/edtl.hpp"

namespace {

std::string g_trace;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  plcfi::fuzz::copy_into_temp("st_programs/handdryer/trace_ok.csv", "trace.csv");
  g_trace = plcfi::fuzz::temp_dir() + "/trace.csv";
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  std::string path = fuzz::write_temp("requirements.yaml", fuzz::as_text(data, size));
  monitor::RequirementsFile reqs;
  std::string err;
  if (!monitor::load_requirements(path, &reqs, &err)) return 0;
  monitor::TraceCheck result;
  if (monitor::check_trace(reqs, g_trace, 0, &result, &err)) (void)report::edtl_verdicts_text(result.verdicts);
  return 0;
}

// Fuzz target: the CPTest+ script reader (parse_script) and the binding of what it reads
// to a compiled program (the bead dispenser's): names, types, values, devices.
#include <cstdint>
#include <memory>
#include <string>

#include "engine.hpp"
#include "fuzz_support.hpp"
#include "script/bind.hpp"
#include "script/cpt.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  static std::unique_ptr<st::Build> build = [] {
    st::CompileOptions opt;
    opt.warnings = false;
    return st::build_files({std::string(PLCFI_SOURCE_DIR) + "/st_programs/bead_dispenser/bead_dispenser.st"}, opt);
  }();
  if (!build->ok()) __builtin_trap();  // the repository's program must compile
  script::Script s;
  std::string err;
  if (!script::parse_script("fuzz.cpt", std::string(fuzz::as_text(data, size)), &s, &err)) return 0;
  script::BoundScript b;
  (void)script::bind_script(*build->app, s, {"plant"}, &b, &err);
  return 0;
}

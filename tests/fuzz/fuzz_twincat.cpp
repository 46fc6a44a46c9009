// Fuzz target: the TwinCAT 3 importer on one object file (.TcPOU-style XML: POU, Itf, DUT,
// GVL or Task), then the ST front end on the units it assembles. A project (.plcproj) names
// other files, which the fuzzer cannot create; its reader is the same XML walk.
#include <cstdint>
#include <string>

#include "engine.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  const std::string path = fuzz::write_temp("fuzz.TcPOU", fuzz::as_text(data, size));
  st::CompileOptions opt;
  opt.warnings = true;
  auto b = st::build_files({path}, opt);
  (void)b->diags.render_all();
  return 0;
}

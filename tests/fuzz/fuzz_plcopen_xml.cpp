// Fuzz target: the PLCopen XML importer (st/import/plcopen.cpp) on one file, and the front
// end on the ST it generates (through st::build_files, as the CLI reads a .xml); every
// diagnostic is rendered, so each line origin is resolved against the XML text.
#include <cstdint>
#include <string>

#include "engine.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  const std::string path = fuzz::write_temp("fuzz.xml", fuzz::as_text(data, size));
  st::CompileOptions opt;
  opt.warnings = true;
  auto b = st::build_files({path}, opt);
  (void)b->diags.render_all();
  return 0;
}

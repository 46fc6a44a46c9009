// Fuzz target: the TwinCAT 3 importer on one object file (.TcPOU-style XML: POU, Itf, DUT,
// GVL or Task), then the ST parser on the units it assembles, with every diagnostic
// rendered through the line origins back into the XML; units that parse are compiled too
// (the whole build, as plcfi check does it: only then, since compiling the standard
// library with each input halves the speed). A project (.plcproj) names other files, which
// the fuzzer cannot create; its reader is the same XML walk.
#include <cstdint>
#include <string>
#include <vector>

#include "engine.hpp"
#include "fuzz_support.hpp"
#include "import/import.hpp"
#include "syntax/parser.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  const std::string path = fuzz::write_temp("fuzz.TcPOU", fuzz::as_text(data, size));
  st::SourceManager sm;
  st::DiagEngine diags(sm);
  std::vector<uint32_t> units;
  st::import_twincat(path, sm, diags, &units);
  for (uint32_t u : units) (void)st::parse_unit(sm, u, diags);
  (void)diags.render_all();
  if (units.empty() || diags.has_errors()) return 0;
  st::CompileOptions opt;
  opt.warnings = true;
  auto b = st::build_files({path}, opt);
  (void)b->diags.render_all();
  return 0;
}

// Fuzz target: the TwinCAT 3 importer on one object file (.TcPOU-style XML: POU, Itf, DUT,
// GVL or Task), then the ST parser on the units it assembles, with every diagnostic
// rendered through the line origins back into the XML; units that parse are compiled too
// (the whole build, as plcfi check does it: only then, since compiling the standard
// library with each input halves the speed). An input whose root looks like <Project> is
// read as a project (.plcproj): the files it names do not exist (missing-file errors), its
// library parameters are checked and turned into TcUnit's parameter list.
#include <cstdint>
#include <string>
#include <vector>

#include "engine.hpp"
#include "fuzz_support.hpp"
#include "import/import.hpp"
#include "syntax/parser.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  const std::string text(fuzz::as_text(data, size));
  const bool project = text.find("<Project") != std::string::npos;
  const std::string path = fuzz::write_temp(project ? "fuzz.plcproj" : "fuzz.TcPOU", text);
  st::SourceManager sm;
  st::DiagEngine diags(sm);
  std::vector<uint32_t> units;
  std::vector<st::LibraryParam> params;
  st::import_twincat(path, sm, diags, &units, &params);
  std::vector<std::pair<std::string, std::string>> values;
  for (const auto& p : params)
    if (st::tcunit_param_error(p.key, p.value).empty()) values.emplace_back(p.key, p.value);
  (void)st::tcunit_params_source(values);
  for (uint32_t u : units) (void)st::parse_unit(sm, u, diags);
  (void)diags.render_all();
  if (units.empty() || diags.has_errors()) return 0;
  st::CompileOptions opt;
  opt.warnings = true;
  auto b = st::build_files({path}, opt);
  (void)b->diags.render_all();
  return 0;
}

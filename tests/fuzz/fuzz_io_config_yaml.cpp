// Fuzz target: the io: section reader (load_io_config) against the stamping program's
// image, then the Modbus backend's request blocks built from what it accepted.
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>

#include "engine.hpp"
#include "fuzz_support.hpp"
#include "io/io_config.hpp"
#ifdef PLCFI_HAVE_MODBUS
#include "io/modbus/modbus_backend.hpp"
#endif

namespace {

std::unique_ptr<plcfi::st::Build> g_build;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  plcfi::st::CompileOptions opt;
  opt.warnings = false;
  g_build = plcfi::st::build_files({std::string(PLCFI_SOURCE_DIR) + "/st_programs/stamping/stamping.st"}, opt);
  if (!g_build->ok()) std::abort();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  std::string path = fuzz::write_temp("io.yaml", fuzz::as_text(data, size));
  io::IoConfig cfg;
  std::string err;
  if (!io::load_io_config(path, *g_build->app, &cfg, &err)) return 0;
#ifdef PLCFI_HAVE_MODBUS
  // create() only plans the requests; nothing connects before the first read().
  (void)io::ModbusBackend::create(cfg, 10'000'000, &err);
#endif
  return 0;
}

// Fuzz target: the manifest of a program FMU (resources/plcfi/program.txt), which the FMU
// binary reads at fmi2Instantiate from an archive anyone may have edited. A manifest that
// reads must write back to text that reads to the same manifest.
#include <cstdint>
#include <string>

#include "fmu/program_fmu.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  fmu::Manifest m;
  std::string err;
  if (!fmu::read_manifest(std::string(fuzz::as_text(data, size)), &m, &err)) {
    if (err.rfind("line ", 0) != 0) __builtin_trap();  // every error names its line
    return 0;
  }
  const std::string text = fmu::write_manifest(m);
  fmu::Manifest again;
  if (!fmu::read_manifest(text, &again, &err) || fmu::write_manifest(again) != text) __builtin_trap();
  return 0;
}

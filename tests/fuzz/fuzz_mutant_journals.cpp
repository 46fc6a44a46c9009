// Fuzz target: plcfi merge on plcfi mutate shard journals (merge_mutant_journals). The
// input holds up to three files separated by NUL bytes.
#include <cstdint>
#include <string>
#include <vector>

#include "campaign/mutate.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  const auto files = fuzz::write_temp_files(fuzz::as_text(data, size), "mutants", 3);
  std::string err;
  (void)campaign::merge_mutant_journals(files, fuzz::write_temp("merged.jsonl", ""), &err);
  return 0;
}

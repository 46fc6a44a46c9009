// Fuzz target: plcfi merge on campaign shard files (merge_shards). The input holds up to
// three files separated by NUL bytes; the merged journal goes to a temporary file.
#include <cstdint>
#include <string>
#include <vector>

#include "campaign/parallel.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  const auto files = fuzz::write_temp_files(fuzz::as_text(data, size), "shard", 3);
  campaign::MergeResult out;
  std::string err;
  (void)campaign::merge_shards(files, fuzz::write_temp("merged.jsonl", ""), &out, &err);
  return 0;
}

// Fuzz target: plcfi merge on campaign shard files (merge_shards). The input holds up to
// three files separated by NUL bytes; the merged journal goes to a temporary file.
#include <cstdint>
#include <string>
#include <vector>

#include "campaign/parallel.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  std::string_view text = fuzz::as_text(data, size);
  std::vector<std::string> files;
  for (size_t begin = 0; files.size() < 3;) {
    size_t end = text.find('\0', begin);
    std::string_view part = text.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin);
    files.push_back(fuzz::write_temp("shard" + std::to_string(files.size()) + ".jsonl", part));
    if (end == std::string_view::npos) break;
    begin = end + 1;
  }
  campaign::MergeResult out;
  std::string err;
  (void)campaign::merge_shards(files, fuzz::write_temp("merged.jsonl", ""), &out, &err);
  return 0;
}

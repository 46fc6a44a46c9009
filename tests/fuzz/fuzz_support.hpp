// Helpers of the fuzz targets: handing the fuzzer's bytes to readers that take a path.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace plcfi::fuzz {

// One private directory per process (parallel fuzzing jobs must not share files),
// removed when the process exits normally.
inline const std::string& temp_dir() {
  // Never destroyed: the exit handler below still needs the name.
  static const std::string* dir = [] {
    std::string tmpl = (std::filesystem::temp_directory_path() / "plcfi-fuzz-XXXXXX").string();
    if (!mkdtemp(tmpl.data())) {
      std::perror("plcfi fuzz: mkdtemp");
      std::abort();
    }
    return new std::string(tmpl);
  }();
  static const bool cleanup = std::atexit([] {
    std::error_code ec;
    std::filesystem::remove_all(*dir, ec);
  }) == 0;
  (void)cleanup;
  return *dir;
}

// Writes `data` to temp_dir()/name (replacing it) and returns the path.
inline std::string write_temp(const std::string& name, std::string_view data) {
  std::string path = temp_dir() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  if (!out) {
    std::perror("plcfi fuzz: write");
    std::abort();
  }
  return path;
}

inline std::string_view as_text(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Up to `max` files from one input, separated by NUL bytes, written as
// temp_dir()/<stem><i>.jsonl; their paths (targets that read several files at once).
inline std::vector<std::string> write_temp_files(std::string_view text, const std::string& stem, size_t max) {
  std::vector<std::string> files;
  for (size_t begin = 0; files.size() < max;) {
    size_t end = text.find('\0', begin);
    std::string_view part = text.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin);
    files.push_back(write_temp(stem + std::to_string(files.size()) + ".jsonl", part));
    if (end == std::string_view::npos) break;
    begin = end + 1;
  }
  return files;
}

// Copies a repository file into temp_dir() (a reader follows references relative to the file).
inline void copy_into_temp(const std::string& repo_path, const std::string& name) {
  std::filesystem::copy_file(std::string(PLCFI_SOURCE_DIR) + "/" + repo_path, temp_dir() + "/" + name,
                             std::filesystem::copy_options::overwrite_existing);
}

}  // namespace plcfi::fuzz

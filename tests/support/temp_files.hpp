// Temporary files of a test program: remembered when made, removed when the program ends
// (ctest runs many test programs; none may leave files behind in /tmp).
#pragma once

#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace plcfi::testing_support {

inline std::string remember_temp(std::string path) {
  struct TempFiles {
    std::vector<std::string> paths;
    ~TempFiles() {
      std::error_code ec;
      for (const auto& p : paths) std::filesystem::remove(p, ec);
    }
  };
  static TempFiles files;
  files.paths.push_back(path);
  return path;
}

}  // namespace plcfi::testing_support

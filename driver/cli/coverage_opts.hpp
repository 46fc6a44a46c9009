// --lcov FILE and --cobertura FILE of `plcfi test`, `plcfi sim` and `plcfi campaign`: the
// options, the check of the paths before a run, and the writing after it.
#pragma once

#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <boost/program_options.hpp>

#include "report/coverage_export.hpp"

namespace plcfi::cli {

inline void add_coverage_export_options(boost::program_options::options_description& desc) {
  desc.add_options()
      ("lcov", boost::program_options::value<std::string>(), "write branch coverage (scans per arm) as an lcov tracefile (genhtml --branch-coverage renders it)")
      ("cobertura", boost::program_options::value<std::string>(), "write branch coverage as Cobertura XML (SOURCE_DATE_EPOCH fixes its timestamp)");
}

inline bool coverage_export_wanted(const boost::program_options::variables_map& vm) {
  return vm.count("lcov") || vm.count("cobertura");
}

// Before the run: each output's folder exists and the path is no folder, so a long run does
// not end in an unwritable file. False with a message on stderr (exit status 2).
inline bool check_coverage_paths(const boost::program_options::variables_map& vm, const char* cmd) {
  for (const char* opt : {"lcov", "cobertura"}) {
    if (!vm.count(opt)) continue;
    const std::string path = vm[opt].as<std::string>();
    std::error_code ec;
    std::filesystem::path dir = std::filesystem::path(path).parent_path();
    if (path.empty() || std::filesystem::is_directory(path, ec)) {
      std::cerr << cmd << ": --" << opt << " " << path << ": is a folder, not a file\n";
      return false;
    }
    if (!dir.empty() && !std::filesystem::is_directory(dir, ec)) {
      std::cerr << cmd << ": --" << opt << " " << path << ": cannot write: folder " << dir.string() << " does not exist\n";
      return false;
    }
  }
  return true;
}

// After the run: writes the files asked for. False with a message on stderr (exit status 2).
inline bool write_coverage_exports(const boost::program_options::variables_map& vm, const st::Application& app,
                                   const std::vector<uint64_t>& hits, const std::vector<uint32_t>& files,
                                   const std::string& test_name, const char* cmd) {
  const auto cov = report::coverage_by_file(app, hits, files);
  std::string err;
  if (vm.count("lcov") && !report::write_coverage_file(vm["lcov"].as<std::string>(), report::lcov_tracefile(cov, test_name), &err)) {
    std::cerr << cmd << ": --lcov " << err << "\n";
    return false;
  }
  if (vm.count("cobertura") &&
      !report::write_coverage_file(vm["cobertura"].as<std::string>(), report::cobertura_xml(cov, report::coverage_timestamp_ms()), &err)) {
    std::cerr << cmd << ": --cobertura " << err << "\n";
    return false;
  }
  return true;
}

}  // namespace plcfi::cli

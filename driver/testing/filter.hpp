// --filter GLOB of every test front end: which tests run (or are listed).
#pragma once

#include <string>
#include <vector>

namespace plcfi::testing {

class Filter {
 public:
  Filter() = default;
  explicit Filter(std::vector<std::string> globs) : globs_(std::move(globs)) {}

  bool empty() const { return globs_.empty(); }
  // A test is selected when there is no glob, or one glob (shell pattern: * ? [...])
  // matches its suite's name, its own name, or "SUITE/TEST".
  bool selects(const std::string& suite, const std::string& test) const;
  // A glob names this suite: it matches the suite's name, or its SUITE part does.
  bool names_suite(const std::string& suite) const;

 private:
  std::vector<std::string> globs_;
};

}  // namespace plcfi::testing

#include "filter.hpp"

#include <fnmatch.h>

namespace plcfi::testing {

namespace {
bool glob(const std::string& pattern, const std::string& s) { return fnmatch(pattern.c_str(), s.c_str(), 0) == 0; }
}  // namespace

bool Filter::selects(const std::string& suite, const std::string& test) const {
  if (globs_.empty()) return true;
  const std::string full = suite + "/" + test;
  for (const auto& g : globs_)
    if (glob(g, suite) || glob(g, test) || glob(g, full)) return true;
  return false;
}

bool Filter::names_suite(const std::string& suite) const {
  if (globs_.empty()) return true;
  for (const auto& g : globs_) {
    const auto slash = g.rfind('/');
    if (glob(g, suite) || (slash != std::string::npos && glob(g.substr(0, slash), suite))) return true;
  }
  return false;
}

}  // namespace plcfi::testing

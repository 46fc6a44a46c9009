// Robustness: mutated versions of the conformance sources go through the whole pipeline
// (parse, check, compile, run with a small budget) without crashing or hanging.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "engine.hpp"
#include "testing/test_files.hpp"

namespace plcfi::st {
namespace {

std::vector<std::pair<std::string, std::string>> corpus() {
  std::vector<std::pair<std::string, std::string>> out;
  std::filesystem::path dir = std::filesystem::path(PLCFI_NEGATIVE_DIR).parent_path() / "st";
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() != ".st") continue;
    std::ifstream in(e.path());
    std::stringstream ss;
    ss << in.rdbuf();
    out.emplace_back(e.path().filename().string(), ss.str());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string mutate(const std::string& src, std::mt19937& rng) {
  std::string s = src;
  if (s.empty()) return s;
  std::uniform_int_distribution<size_t> pos(0, s.size() - 1);
  switch (rng() % 5) {
    case 0: s.resize(pos(rng)); break;                                      // truncation
    case 1: s[pos(rng)] = static_cast<char>(rng() % 128); break;            // byte flip
    case 2: { size_t p = pos(rng); s.erase(p, std::min<size_t>(s.size() - p, 1 + rng() % 12)); break; }
    case 3: { size_t p = pos(rng); s.insert(p, s.substr(pos(rng) % s.size(), 1 + rng() % 20)); break; }
    default: {  // swap two lines
      std::vector<std::string> lines;
      std::stringstream ss(s);
      for (std::string l; std::getline(ss, l);) lines.push_back(l);
      if (lines.size() > 1) std::swap(lines[rng() % lines.size()], lines[rng() % lines.size()]);
      s.clear();
      for (const auto& l : lines) s += l + "\n";
    }
  }
  return s;
}

TEST(PipelineFuzz, MutatedSourcesNeverCrash) {
  auto files = corpus();
  ASSERT_GT(files.size(), 20u);
  // PLCFI_FUZZ_ROUNDS / PLCFI_FUZZ_SEED let a developer run a longer campaign locally.
  const char* rounds_env = std::getenv("PLCFI_FUZZ_ROUNDS");
  const char* seed_env = std::getenv("PLCFI_FUZZ_SEED");
  int rounds = rounds_env ? std::atoi(rounds_env) : 600;
  std::mt19937 rng(seed_env ? static_cast<unsigned>(std::atoi(seed_env)) : 20261122u);
  size_t compiled = 0, rejected = 0;
  // Pairs (source, test file) as the conformance suite runs them, one mutated at a time.
  for (int round = 0; round < rounds; ++round) {
    const auto& [name, text] = files[rng() % files.size()];
    std::string mutated = mutate(text, rng);
    CompileOptions opt;
    opt.test_mode = true;
    auto b = build_sources({{name, mutated}}, opt);
    if (!b->ok()) {
      ++rejected;
      EXPECT_TRUE(b->diags.has_errors()) << name << ": rejected without a diagnostic";
      // Every diagnostic points into the text it was given (a line that exists).
      const size_t lines = static_cast<size_t>(std::count(mutated.begin(), mutated.end(), '\n')) + 1;
      for (const auto& d : b->diags.all())
        EXPECT_LE(d.loc.line, lines) << name << ": " << d.code << " at line " << d.loc.line << " of " << lines;
      continue;
    }
    ++compiled;
    Machine m(*b->app);
    testing::TestRunOptions ro;
    ro.budget = 20000;
    testing::run_tests(*b->app, m, ro);  // traps are fine; crashes and hangs are not
  }
  // Both outcomes occur: mutations that break nothing (in comments, swapped independent
  // lines) and ones that break the program; all-rejected would mean a broken corpus.
  EXPECT_GT(rejected, 0u);
  EXPECT_GT(compiled, 0u);
}

}  // namespace
}  // namespace plcfi::st

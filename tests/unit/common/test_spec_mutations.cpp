// Generated bad spec files: the shipped TSD, fault classes, requirements and plant
// parameters with random edits. Each loader must either accept the text or answer with one
// message that starts with the file's name, never crash, throw or hang.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <unistd.h>

#include "campaign/spec.hpp"
#include "monitor/edtl.hpp"
#include "plant_model/stamping/stamping_params.hpp"

namespace plcfi::common {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Random insertions, deletions and replacements with the characters YAML cares about.
std::string mutate(std::string t, std::mt19937& rng) {
  static const std::string kChars = ":-[]{},\"'&*!|>#%@ \n\t0123456789.abcxyzTRUEms";
  const int edits = 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < edits; ++e) {
    const size_t at = t.empty() ? 0 : rng() % t.size();
    const char c = kChars[rng() % kChars.size()];
    switch (rng() % 3) {
      case 0: t.insert(t.begin() + static_cast<std::ptrdiff_t>(at), c); break;
      case 1: if (!t.empty()) t.erase(at, 1 + rng() % 3); break;
      default: if (!t.empty()) t[at] = c; break;
    }
  }
  return t;
}

template <class Load>
void check_loader(const fs::path& original, const std::string& name, Load&& load) {
  const std::string text = slurp(original);
  ASSERT_FALSE(text.empty()) << original;
  const fs::path path = fs::temp_directory_path() / ("plcfi_mut_" + std::to_string(::getpid()) + "_" + name);
  std::mt19937 rng(static_cast<unsigned>(std::hash<std::string>{}(name)));
  int rejected = 0;
  for (int iter = 0; iter < 300; ++iter) {
    const std::string bad = mutate(text, rng);
    std::ofstream(path, std::ios::binary) << bad;
    std::string err;
    bool ok = false;
    EXPECT_NO_THROW(ok = load(path.string(), &err)) << bad;
    if (!ok) {
      ++rejected;
      // "PATH:LINE:COL: message" (or "PATH: ..." for a file error); no "YAML: ..." fallback.
      ASSERT_EQ(err.rfind(path.string() + ":", 0), 0u) << err << "\n--- text:\n" << bad;
      ASSERT_EQ(err.find('\n'), std::string::npos) << err;
    }
  }
  EXPECT_GT(rejected, 20) << name;  // the edits must reach the checks
  fs::remove(path);
}

const fs::path kRoot = PLCFI_SOURCE_DIR;

TEST(SpecMutations, Tsd) {
  check_loader(kRoot / "faults/campaigns/stamping/tsd.yaml", "tsd.yaml", [](const std::string& p, std::string* err) {
    campaign::Tsd t;
    return campaign::load_tsd(p, &t, err);
  });
}

TEST(SpecMutations, FaultClasses) {
  check_loader(kRoot / "faults/campaigns/stamping/fault_classes.yaml", "classes.yaml",
               [](const std::string& p, std::string* err) {
                 campaign::FaultClasses c;
                 return campaign::load_fault_classes(p, &c, err);
               });
}

TEST(SpecMutations, FmeaCsv) {
  check_loader(kRoot / "faults/campaigns/stamping/fmea.csv", "fmea.csv", [](const std::string& p, std::string* err) {
    campaign::Fmea f;
    return campaign::load_fmea(p, &f, err);
  });
}

TEST(SpecMutations, Requirements) {
  check_loader(kRoot / "st_programs/handdryer/requirements.yaml", "reqs.yaml", [](const std::string& p, std::string* err) {
    monitor::RequirementsFile r;
    return monitor::load_requirements(p, &r, err);
  });
}

TEST(SpecMutations, PlantParameters) {
  // The shipped file is all comments: edit a filled-in variant instead.
  const fs::path filled = fs::temp_directory_path() / ("plcfi_mut_filled_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(filled) << "variation: 0.02\nslider:\n  travel: 0.3\nstamp:\n  travel: 0.2\n  min_pressure: 5700\n"
                           "supply:\n  mode: schedule\n  schedule: [1, 5, 9]\nnext:\n  ready: true\n  busy: [{from: 1, to: 2}]\n"
                           "operator:\n  mode: manual\n  jog: [{button: stamp, from: 1, to: 2}]\n";
  check_loader(filled, "plant.yaml", [](const std::string& p, std::string* err) {
    plant::StampingParams params;
    return plant::load_stamping_params(p, &params, err);
  });
  fs::remove(filled);
}

}  // namespace
}  // namespace plcfi::common

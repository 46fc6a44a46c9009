// Plant factory over the three kinds of plant.
#include "io/sim/plant_factory.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "common/yaml.hpp"
#include "io/sim/st_plant.hpp"
#include "plant_model/fmu/fmu_plant.hpp"
#include "plant_model/plant_file.hpp"

namespace plcfi::io {

namespace {

// A built-in plant whose signals a plant file binds to other image addresses.
class MappedPlant final : public plant::Plant {
 public:
  MappedPlant(std::unique_ptr<plant::Plant> inner, std::vector<plant::SignalInfo> signals, std::string origin)
      : inner_(std::move(inner)), signals_(std::move(signals)), origin_(std::move(origin)) {}
  const std::string& name() const override { return inner_->name(); }
  const std::vector<plant::SignalInfo>& signals() const override { return signals_; }
  void reset(uint64_t seed) override { inner_->reset(seed); }
  void step(double dt, const double* a, double* s) override { inner_->step(dt, a, s); }
  void sense(double* s) const override { inner_->sense(s); }
  std::vector<std::pair<std::string, double>> stats() const override { return inner_->stats(); }
  std::string origin() const override { return origin_; }

 private:
  std::unique_ptr<plant::Plant> inner_;
  std::vector<plant::SignalInfo> signals_;
  std::string origin_;
};

std::unique_ptr<plant::Plant> open_builtin(const plant::PlantFile& pf) {
  std::string err;
  auto inner = plant::make_builtin_plant(pf.builtin, pf.config, &err);
  if (!inner) throw common::InputError(pf.where + ": " + err);
  std::string origin = pf.path + " (built-in plant " + pf.builtin + ")";
  if (pf.step_ns > 0)
    throw common::InputError(pf.step_where + ": step: a built-in plant steps with every scan; leave step out");
  std::vector<plant::SignalInfo> sigs = inner->signals();
  for (const auto& m : pf.map) {
    auto it = std::find_if(sigs.begin(), sigs.end(), [&](const auto& s) { return s.name == m.plant; });
    if (it == sigs.end()) {
      std::string names;
      for (const auto& s : sigs) names += (names.empty() ? "" : ", ") + s.name;
      throw common::InputError(fmt::format("{}: the plant {} has no signal '{}' (its signals: {})", m.plant_where,
                                           pf.builtin, m.plant, names));
    }
    if ((it->dir == plant::Direction::FromPlant) != m.input)
      throw common::InputError(fmt::format("{}: '{}' is {} of {}: it belongs in {}", m.where, m.plant,
                                           m.input ? "an actuator" : "a sensor", pf.builtin, m.input ? "%Q" : "%I"));
    const bool bit = it->kind == plant::SignalKind::Bool;
    plant::check_binding(m, bit ? plant::ValueKind::Bool : plant::ValueKind::Integer,
                         bit ? "a BOOL signal" : "an analog signal in image units");
    it->address = m.image;
    it->where = m.where;
  }
  return std::make_unique<MappedPlant>(std::move(inner), std::move(sigs), origin);
}

}  // namespace

std::unique_ptr<plant::Plant> open_plant(const std::string& name_or_file, const std::string& config_path,
                                         std::string* err) {
  if (!plant::is_plant_file(name_or_file)) {
    const bool fmu = name_or_file.ends_with(".fmu");
    if (fmu || name_or_file.ends_with(".st")) {
      *err = fmt::format("{}: an {} plant is named by a plant file (YAML: {}: {}, its step and the map onto the image; "
                         "see docs/pages/formats/plant-files.md)",
                         name_or_file, fmu ? "FMU" : "ST", fmu ? "fmu" : "st", name_or_file);
      return nullptr;
    }
    return plant::make_builtin_plant(name_or_file, config_path, err);
  }
  try {
    if (!config_path.empty())
      throw common::InputError(fmt::format("{}: a plant file names its own parameters (config: or parameters:); "
                                           "--plant-config {} is for a built-in plant named directly",
                                           name_or_file, config_path));
    plant::PlantFile pf = plant::read_plant_file(name_or_file);
    switch (pf.kind) {
      case plant::PlantFile::Kind::Builtin: return open_builtin(pf);
      case plant::PlantFile::Kind::Fmu: return plant::fmu::FmuPlant::create(pf);
      case plant::PlantFile::Kind::St: return StPlant::create(pf);
    }
  } catch (const common::InputError& e) {
    *err = e.what();
  } catch (const plant::fmu::FmuError& e) {
    *err = e.what();
  } catch (const PlantProgramError& e) {
    *err = e.what();
  }
  return nullptr;
}

}  // namespace plcfi::io

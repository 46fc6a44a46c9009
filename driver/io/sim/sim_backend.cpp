// Plant-model backend.
#include "sim_backend.hpp"

#include <algorithm>
#include <cmath>

namespace plcfi::io {

std::unique_ptr<SimBackend> SimBackend::create(const st::Application& app, std::unique_ptr<plant::Plant> plant,
                                               std::string* err) {
  std::unique_ptr<SimBackend> b(new SimBackend());
  b->name_ = "sim:" + plant->name();
  const auto& sigs = plant->signals();
  b->values_.assign(sigs.size(), 0.0);
  for (size_t i = 0; i < sigs.size(); ++i) {
    const auto& s = sigs[i];
    rt::ImageRef ref;
    std::string e;
    // A binding from a plant file is reported at its line there.
    const std::string at = s.where.empty() ? "plant " + plant->name() + ", signal " + s.name : s.where + ": " + s.name;
    if (!rt::parse_image_ref(app, s.address, &ref, &e)) {
      *err = at + ": " + e;
      return nullptr;
    }
    char want = s.dir == plant::Direction::FromPlant ? 'I' : 'Q';
    if (ref.area != want) {
      *err = at + ": a " +
             (want == 'I' ? std::string("sensor belongs in %I") : std::string("actuator belongs in %Q")) + ", not " + s.address;
      return nullptr;
    }
    if ((s.kind == plant::SignalKind::Bool) != ref.is_bit) {
      *err = at + ": " +
             (ref.is_bit ? "an analog signal needs a word address, not " : "a BOOL signal needs a bit address, not ") + s.address;
      return nullptr;
    }
    uint32_t end = ref.offset + ref.size;
    if (want == 'I') {
      b->in_extent_ = std::max(b->in_extent_, end);
      b->sensors_.push_back(i);
    } else {
      b->out_extent_ = std::max(b->out_extent_, end);
      b->actuators_.push_back(i);
    }
    b->refs_.push_back(ref);
  }
  b->plant_ = std::move(plant);
  b->reset(0);
  return b;
}

namespace {
// A sensor value to the integer the image holds: most are whole already (switches 0/1,
// counts), which needs no call into libm's rounding (a seventh of a native-tier
// simulation's time went there).
int64_t to_image(double v) {
  if (v > -1e15 && v < 1e15) {
    auto i = static_cast<int64_t>(v);
    if (static_cast<double>(i) == v) return i;
  }
  return static_cast<int64_t>(std::lround(v));
}
}  // namespace

bool SimBackend::read(uint8_t* inputs, int64_t) {
  for (size_t i : sensors_) refs_[i].set(inputs, to_image(values_[i]));
  return true;
}

bool SimBackend::write(const uint8_t* outputs, int64_t, int64_t dt_ns) {
  for (size_t i : actuators_) values_[i] = static_cast<double>(refs_[i].get(outputs));
  plant_->step(static_cast<double>(dt_ns) * 1e-9, values_.data(), values_.data());
  return true;
}

void SimBackend::reset(uint64_t seed) {
  plant_->reset(seed);
  std::fill(values_.begin(), values_.end(), 0.0);
  plant_->sense(values_.data());
}

}  // namespace plcfi::io

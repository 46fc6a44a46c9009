// The offline backend: a plant model behind the I/O image, advanced in virtual time by
// one base tick per scan.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "plant_model/plant.hpp"
#include "runtime/backend.hpp"
#include "runtime/image.hpp"

namespace plcfi::io {

class SimBackend final : public rt::IoBackend {
 public:
  // Binds every plant signal to its default image address. Returns null and fills err
  // when an address does not fit the application (e.g. a BOOL signal on a word address).
  static std::unique_ptr<SimBackend> create(const st::Application& app, std::unique_ptr<plant::Plant> plant,
                                            std::string* err);

  const std::string& name() const override { return name_; }
  uint32_t input_extent() const override { return in_extent_; }
  uint32_t output_extent() const override { return out_extent_; }
  bool read(uint8_t* inputs, int64_t now_ns) override;
  bool write(const uint8_t* outputs, int64_t now_ns, int64_t dt_ns) override;
  void reset(uint64_t seed) override;
  const std::string& last_error() const override { return error_; }

  plant::Plant& plant() { return *plant_; }
  // Signal values as last exchanged (index = plant signal index).
  const std::vector<double>& signal_values() const { return values_; }

 private:
  SimBackend() = default;
  std::unique_ptr<plant::Plant> plant_;
  std::vector<rt::ImageRef> refs_;  // per signal
  std::vector<double> values_;      // actuators from the last write, sensors from the last step
  std::vector<size_t> sensors_, actuators_;
  uint32_t in_extent_ = 0, out_extent_ = 0;
  std::string name_, error_;
};

}  // namespace plcfi::io

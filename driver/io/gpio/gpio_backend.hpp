// GPIO backend (libgpiod 1.6, the kernel's GPIO character device): lines of GPIO chips
// exchanged with image bits in the scan. Per chip, all input lines are held by one bulk
// request and all output lines by another (lines whose flags differ -- bias, drive,
// active-low -- need a request of their own, as the kernel sets flags per request);
// only the bulk get/set calls are used on them (libgpiod 1.6 applies single-line calls
// on a bulk request to its first line). The consumer name is "plcfi".
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/io_config.hpp"
#include "runtime/backend.hpp"

struct gpiod_chip;  // libgpiod's opaque chip

namespace plcfi::io {

class GpioBackend final : public rt::IoBackend {
 public:
  // Opens the chips, resolves line names, requests the lines (outputs start in the safe
  // state). Errors name the device, the chip and the line: "board (gpiochip0) line 12:
  // no such line (the chip has 8)".
  static std::unique_ptr<GpioBackend> open(const IoConfig& cfg, std::string* err);
  ~GpioBackend() override;

  const std::string& name() const override { return name_; }
  uint32_t input_extent() const override { return in_extent_; }
  uint32_t output_extent() const override { return out_extent_; }
  bool read(uint8_t* inputs, int64_t now_ns) override;
  bool write(const uint8_t* outputs, int64_t now_ns, int64_t dt_ns) override;
  void reset(uint64_t) override {}
  const std::string& last_error() const override { return error_; }

  uint64_t failures() const { return failures_; }
  // One line per request: "board (gpiochip0 'plcfi-sim'): inputs 0,1,2,3 -> %IX0.0.., pull-up".
  std::vector<std::string> describe() const;
  // Releases every line and closes the chips (the driver writes the safe state before).
  void close();

 private:
  struct Request;
  GpioBackend() = default;

  std::vector<gpiod_chip*> chips_;
  std::vector<std::unique_ptr<Request>> requests_;
  uint32_t in_extent_ = 0, out_extent_ = 0;
  uint64_t failures_ = 0;
  std::string name_ = "gpio", error_;
};

}  // namespace plcfi::io

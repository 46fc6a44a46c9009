// A broken link between the controller and one device, as a fault: for a while every
// request to the device is lost. Inputs stay frozen at the last good value, outputs are
// not delivered (the device keeps acting on the last ones it got), the device's status
// bit reads FALSE and each lost exchange is counted (failed_exchanges), exactly what a
// pulled cable does to a remote I/O module. Wraps any backend: offline the device is
// the plant model, which keeps running through the fault.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "runtime/backend.hpp"
#include "runtime/image.hpp"

namespace plcfi::io {

class LinkFaultBackend final : public rt::IoBackend {
 public:
  // `device`: the name scripts use (offline: "plant"); `status`: an optional %IX bit that
  // is TRUE while the link works.
  LinkFaultBackend(rt::IoBackend* inner, std::string device, std::optional<rt::ImageRef> status = std::nullopt);

  const std::string& name() const override { return inner_->name(); }
  uint32_t input_extent() const override;
  uint32_t output_extent() const override { return inner_->output_extent(); }
  bool read(uint8_t* inputs, int64_t now_ns) override;
  bool write(const uint8_t* outputs, int64_t now_ns, int64_t dt_ns) override;
  // The fault is withdrawn for the safe state: it reaches the device.
  bool write_final(const uint8_t* outputs, int64_t now_ns) override { return inner_->write_final(outputs, now_ns); }
  // A restart ends any fault in progress (a new test run starts with a working link).
  void reset(uint64_t seed) override;
  const std::string& last_error() const override { return error_; }
  uint64_t failed_exchanges() const override { return lost_ + inner_->failed_exchanges(); }

  std::vector<std::string> link_devices() const override;
  // Its own device here, any other one in the wrapped backend.
  bool break_link(const std::string& device, int64_t from_ns, int64_t duration_ns) override;
  const std::string& device() const { return device_; }
  bool down(int64_t now_ns) const { return now_ns >= from_ns_ && now_ns < to_ns_; }
  uint64_t lost() const { return lost_; }

 private:
  rt::IoBackend* inner_;
  std::string device_, error_;
  std::optional<rt::ImageRef> status_;
  int64_t from_ns_ = 0, to_ns_ = 0;
  uint64_t lost_ = 0;
  std::vector<uint8_t> last_in_, last_out_;
};

}  // namespace plcfi::io

// The link-fault wrapper of a backend.
#include "io/link_fault.hpp"

#include <algorithm>
#include <cstring>

#include <fmt/format.h>

namespace plcfi::io {

LinkFaultBackend::LinkFaultBackend(rt::IoBackend* inner, std::string device, std::optional<rt::ImageRef> status)
    : inner_(inner), device_(std::move(device)), status_(std::move(status)) {
  last_in_.assign(input_extent(), 0);
  last_out_.assign(inner_->output_extent(), 0);
}

uint32_t LinkFaultBackend::input_extent() const {
  uint32_t e = inner_->input_extent();
  if (status_) e = std::max<uint32_t>(e, status_->offset + 1);
  return e;
}

std::vector<std::string> LinkFaultBackend::link_devices() const {
  std::vector<std::string> d{device_};
  for (auto& n : inner_->link_devices()) d.push_back(std::move(n));
  return d;
}

bool LinkFaultBackend::break_link(const std::string& device, int64_t from_ns, int64_t duration_ns) {
  if (device != device_) return inner_->break_link(device, from_ns, duration_ns);
  from_ns_ = from_ns;
  to_ns_ = from_ns + duration_ns;
  return true;
}

bool LinkFaultBackend::read(uint8_t* inputs, int64_t now_ns) {
  const uint32_t n = input_extent();
  if (down(now_ns)) {
    // The request is lost: the image keeps the last good inputs, the status bit drops.
    ++lost_;
    std::memcpy(inputs, last_in_.data(), n);
    if (status_) status_->set(inputs, 0);
    error_ = fmt::format("{}: link broken (fault injected), request lost", device_);
    return false;
  }
  bool ok = inner_->read(inputs, now_ns);
  if (status_) status_->set(inputs, ok ? 1 : 0);
  std::memcpy(last_in_.data(), inputs, n);
  if (!ok) error_ = inner_->last_error();
  return ok;
}

bool LinkFaultBackend::write(const uint8_t* outputs, int64_t now_ns, int64_t dt_ns) {
  const uint32_t n = inner_->output_extent();
  if (down(now_ns)) {
    // Not delivered: the device goes on with the outputs it last received (a plant model
    // keeps stepping its physics under them).
    ++lost_;
    inner_->write(last_out_.data(), now_ns, dt_ns);
    error_ = fmt::format("{}: link broken (fault injected), outputs not delivered", device_);
    return false;
  }
  std::memcpy(last_out_.data(), outputs, n);
  bool ok = inner_->write(outputs, now_ns, dt_ns);
  if (!ok) error_ = inner_->last_error();
  return ok;
}

void LinkFaultBackend::reset(uint64_t seed) {
  from_ns_ = to_ns_ = 0;
  std::fill(last_in_.begin(), last_in_.end(), 0);
  std::fill(last_out_.begin(), last_out_.end(), 0);
  inner_->reset(seed);
}

}  // namespace plcfi::io

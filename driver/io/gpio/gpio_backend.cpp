// GPIO backend on libgpiod 1.6 (v1 character-device ABI).
#include "gpio_backend.hpp"

#include <gpiod.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>
#include <tuple>

#include <fmt/format.h>

namespace plcfi::io {

struct GpioBackend::Request {
  std::string label;  // "board (gpiochip0)"
  bool output = false;
  int flags = 0;
  gpiod_line_bulk bulk{};
  std::vector<unsigned> offsets;
  std::vector<uint32_t> byte;   // image byte of each line
  std::vector<uint8_t> mask;    // and its bit
  std::vector<int> invert;      // 1: active-low (inverted here, so it shares the request)
  std::vector<int> values, last;
  bool requested = false, written = false;
  std::string where;            // the first mapping's FILE:LINE:COL
};

namespace {

std::string present_chips() {
  std::string list;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator("/dev", ec)) {
    std::string n = e.path().filename().string();
    if (n.rfind("gpiochip", 0) == 0) list += (list.empty() ? "" : ", ") + n;
  }
  return list.empty() ? "this machine has no /dev/gpiochip*" : "chips here: " + list;
}

// The kernel's flags of a line's request. Active-low is not among them: plcfi inverts
// those lines itself, so lines that differ only in it share one bulk request.
int request_flags(const GpioPoint& p) {
  int f = 0;
  switch (p.bias) {
    case GpioBias::AsIs: break;
    case GpioBias::Disabled: f |= GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE; break;
    case GpioBias::PullUp: f |= GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP; break;
    case GpioBias::PullDown: f |= GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN; break;
  }
  switch (p.drive) {
    case GpioDrive::PushPull: break;
    case GpioDrive::OpenDrain: f |= GPIOD_LINE_REQUEST_FLAG_OPEN_DRAIN; break;
    case GpioDrive::OpenSource: f |= GPIOD_LINE_REQUEST_FLAG_OPEN_SOURCE; break;
  }
  return f;
}

std::string flag_text(int f) {
  std::string t;
  auto add = [&](const char* s) { t += std::string(t.empty() ? "" : ", ") + s; };
  if (f & GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE) add("bias disabled");
  if (f & GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP) add("pull-up");
  if (f & GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN) add("pull-down");
  if (f & GPIOD_LINE_REQUEST_FLAG_OPEN_DRAIN) add("open-drain");
  if (f & GPIOD_LINE_REQUEST_FLAG_OPEN_SOURCE) add("open-source");
  return t;
}

}  // namespace

std::unique_ptr<GpioBackend> GpioBackend::open(const IoConfig& cfg, std::string* err) {
  std::unique_ptr<GpioBackend> b(new GpioBackend());
  std::vector<std::string> labels;
  for (const auto& d : cfg.gpio_devices) {
    gpiod_chip* chip = gpiod_chip_open_lookup(d.chip.c_str());
    if (!chip) {
      *err = fmt::format("{}: device '{}': cannot open GPIO chip '{}': {} ({})", d.where, d.name, d.chip,
                         std::strerror(errno), present_chips());
      return nullptr;
    }
    b->chips_.push_back(chip);
    labels.push_back(fmt::format("{} ({} '{}')", d.name, gpiod_chip_name(chip), gpiod_chip_label(chip)));
  }
  // Group the lines: one request per (chip, direction, flags); normally two per chip.
  std::map<std::tuple<size_t, bool, int>, size_t> group;
  std::map<std::pair<size_t, unsigned>, std::string> taken;  // line -> its mapping
  for (const auto& p : cfg.gpio_points) {
    gpiod_chip* chip = b->chips_[p.device];
    const std::string& label = labels[p.device];
    bool output = p.image.area == 'Q';
    int flags = request_flags(p);
    auto key = std::make_tuple(p.device, output, flags);
    auto [it, fresh] = group.emplace(key, b->requests_.size());
    if (fresh) {
      auto r = std::make_unique<Request>();
      r->label = label;
      r->output = output;
      r->flags = flags;
      r->where = p.where;
      gpiod_line_bulk_init(&r->bulk);
      b->requests_.push_back(std::move(r));
    }
    Request& r = *b->requests_[it->second];
    uint32_t bit = p.image.offset * 8u + p.image.bit;
    for (const auto& l : p.lines) {
      gpiod_line* line = nullptr;
      if (l.offset >= 0) {
        unsigned n = gpiod_chip_num_lines(chip);
        if (static_cast<unsigned>(l.offset) >= n) {
          *err = fmt::format("{}: {}: line {} does not exist (the chip has {} lines, 0..{})", p.where, label, l.offset, n, n - 1);
          return nullptr;
        }
        line = gpiod_chip_get_line(chip, static_cast<unsigned>(l.offset));
      } else {
        line = gpiod_chip_find_line(chip, l.name.c_str());
        if (!line) {
          *err = fmt::format("{}: {}: no line named '{}'", p.where, label, l.name);
          return nullptr;
        }
      }
      if (!line) {
        *err = fmt::format("{}: {}: line {}: {}", p.where, label, l.offset, std::strerror(errno));
        return nullptr;
      }
      unsigned off = gpiod_line_offset(line);
      auto [t, first] = taken.emplace(std::make_pair(p.device, off), p.where);
      if (!first) {
        *err = fmt::format("{}: {}: line {}{} is already mapped at {}", p.where, label, off,
                           l.name.empty() ? "" : " ('" + l.name + "')", t->second);
        return nullptr;
      }
      if (r.offsets.size() == GPIOD_LINE_BULK_MAX_LINES) {
        *err = fmt::format("{}: {}: more than {} {} lines with the same flags (one bulk request)", p.where, label,
                           GPIOD_LINE_BULK_MAX_LINES, output ? "output" : "input");
        return nullptr;
      }
      gpiod_line_bulk_add(&r.bulk, line);
      r.offsets.push_back(off);
      r.byte.push_back(bit / 8);
      r.mask.push_back(static_cast<uint8_t>(1u << (bit % 8)));
      r.invert.push_back(p.active_low ? 1 : 0);
      uint32_t end = bit / 8 + 1;
      (output ? b->out_extent_ : b->in_extent_) = std::max(output ? b->out_extent_ : b->in_extent_, end);
      ++bit;
    }
  }
  for (auto& rp : b->requests_) {
    Request& r = *rp;
    r.values.assign(r.offsets.size(), 0);
    r.last.assign(r.offsets.size(), -1);
    if (r.output) {
      // Outputs come up in the safe state (all off unless io: safe_state says otherwise).
      for (size_t i = 0; i < r.offsets.size(); ++i) {
        int logical = 0;
        for (const auto& [ref, v] : cfg.safe_state)
          if (ref.is_bit && ref.offset == r.byte[i] && (1u << ref.bit) == r.mask[i]) logical = v != 0;
        r.values[i] = logical ^ r.invert[i];
      }
    }
    gpiod_line_request_config rc{};
    rc.consumer = "plcfi";
    rc.request_type = r.output ? GPIOD_LINE_REQUEST_DIRECTION_OUTPUT : GPIOD_LINE_REQUEST_DIRECTION_INPUT;
    rc.flags = r.flags;
    if (gpiod_line_request_bulk(&r.bulk, &rc, r.output ? r.values.data() : nullptr) != 0) {
      int e = errno;
      std::string busy;
      for (unsigned i = 0; i < r.bulk.num_lines; ++i) {
        gpiod_line* line = r.bulk.lines[i];
        gpiod_line_update(line);
        if (gpiod_line_is_used(line)) {
          const char* who = gpiod_line_consumer(line);
          busy += fmt::format("{}line {} is used by '{}'", busy.empty() ? "" : "; ", gpiod_line_offset(line), who ? who : "?");
        }
      }
      *err = fmt::format("{}: {}: cannot request {} lines {}: {}{}", r.where, r.label, r.output ? "output" : "input",
                         fmt::join(r.offsets, ","), std::strerror(e), busy.empty() ? "" : " (" + busy + ")");
      return nullptr;
    }
    r.requested = true;
    if (r.output) r.last = r.values;
  }
  return b;
}

GpioBackend::~GpioBackend() { close(); }

void GpioBackend::close() {
  for (auto& r : requests_)
    if (r->requested) {
      gpiod_line_release_bulk(&r->bulk);
      r->requested = false;
    }
  for (auto* c : chips_) gpiod_chip_close(c);
  chips_.clear();
}

bool GpioBackend::read(uint8_t* inputs, int64_t) {
  bool ok = true;
  for (auto& rp : requests_) {
    Request& r = *rp;
    if (r.output || !r.requested) continue;
    if (gpiod_line_get_value_bulk(&r.bulk, r.values.data()) != 0) {
      ++failures_;
      error_ = fmt::format("{}: read lines {}: {}", r.label, fmt::join(r.offsets, ","), std::strerror(errno));
      ok = false;  // the image keeps the last good inputs
      continue;
    }
    for (size_t i = 0; i < r.values.size(); ++i) {
      if (r.values[i] ^ r.invert[i]) inputs[r.byte[i]] |= r.mask[i];
      else inputs[r.byte[i]] &= static_cast<uint8_t>(~r.mask[i]);
    }
  }
  return ok;
}

bool GpioBackend::write(const uint8_t* outputs, int64_t, int64_t) {
  bool ok = true;
  for (auto& rp : requests_) {
    Request& r = *rp;
    if (!r.output || !r.requested) continue;
    bool changed = false;
    for (size_t i = 0; i < r.values.size(); ++i) {
      r.values[i] = ((outputs[r.byte[i]] & r.mask[i]) ? 1 : 0) ^ r.invert[i];
      changed = changed || r.values[i] != r.last[i];
    }
    if (!changed) continue;  // the kernel holds the lines' values
    if (gpiod_line_set_value_bulk(&r.bulk, r.values.data()) != 0) {
      ++failures_;
      error_ = fmt::format("{}: write lines {}: {}", r.label, fmt::join(r.offsets, ","), std::strerror(errno));
      r.last.assign(r.last.size(), -1);  // retried in full next cycle
      ok = false;
      continue;
    }
    r.last = r.values;
  }
  return ok;
}

std::vector<std::string> GpioBackend::describe() const {
  std::vector<std::string> out;
  for (const auto& r : requests_) {
    std::string f = flag_text(r->flags);
    std::vector<unsigned> low;
    for (size_t i = 0; i < r->offsets.size(); ++i)
      if (r->invert[i]) low.push_back(r->offsets[i]);
    if (!low.empty()) f += fmt::format("{}active-low {}", f.empty() ? "" : ", ", fmt::join(low, ","));
    out.push_back(fmt::format("{}: {} lines {} (one bulk request{})", r->label, r->output ? "output" : "input",
                              fmt::join(r->offsets, ","), f.empty() ? "" : ", " + f));
  }
  return out;
}

}  // namespace plcfi::io

// The I/O image seen from the runtime: addresses in the %I and %Q areas, and overlays,
// the one place where faults act. Inputs exist twice (as the backend delivered them,
// as the program sees them) and so do outputs (as the program wrote them, as the plant
// receives them); an overlay rewrites the copy between the two layers.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "vm/program.hpp"

namespace plcfi::rt {

// A location in one image area, relative to the area's start.
struct ImageRef {
  char area = 'I';        // 'I' or 'Q' (overlays act on these two)
  uint32_t offset = 0;    // byte offset in the area
  uint8_t size = 1;       // bytes: 1, 2, 4 or 8 (a bit address has size 1)
  bool is_bit = false;
  uint8_t bit = 0;
  const st::Type* type = nullptr;  // BOOL, WORD, INT, ... (what the address holds)
  std::string text;       // "%IX0.4"

  // Reads/writes the value at this location in an area buffer (little-endian, as the VM).
  int64_t get(const uint8_t* area_base) const;
  void set(uint8_t* area_base, int64_t v) const;
};

// Called for every mapped signal in every scan: inline.
inline int64_t ImageRef::get(const uint8_t* base) const {
  const uint8_t* p = base + offset;
  if (is_bit) return (*p >> bit) & 1u;
  switch (size) {
    case 1: return type && type->is_signed() ? static_cast<int8_t>(*p) : *p;
    case 2: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return type && type->is_signed() ? static_cast<int16_t>(v) : v;
    }
    case 4: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return type && type->is_signed() ? static_cast<int32_t>(v) : v;
    }
    default: {
      int64_t v;
      std::memcpy(&v, p, 8);
      return v;
    }
  }
}

inline void ImageRef::set(uint8_t* base, int64_t v) const {
  uint8_t* p = base + offset;
  if (is_bit) {
    auto m = static_cast<uint8_t>(1u << bit);
    *p = static_cast<uint8_t>(v ? (*p | m) : (*p & ~m));
    return;
  }
  switch (size) {
    case 1: *p = static_cast<uint8_t>(v); break;
    case 2: {
      auto x = static_cast<uint16_t>(v);
      std::memcpy(p, &x, 2);
      break;
    }
    case 4: {
      auto x = static_cast<uint32_t>(v);
      std::memcpy(p, &x, 4);
      break;
    }
    default: std::memcpy(p, &v, 8); break;
  }
}

// Parses "%IX0.4", "%QW2", ... (or any path resolving into the %I/%Q areas) against an
// application's image layout. Fails with a message naming the address.
bool parse_image_ref(const st::Application& app, const std::string& text, ImageRef* ref, std::string* err);

// A rule of an overlay. dst already holds a copy of src (the unmodified layer); a rule
// rewrites the bytes it owns. Called once per scan; must not allocate.
class OverlayRule {
 public:
  virtual ~OverlayRule() = default;
  virtual void apply(uint8_t* dst, const uint8_t* src, int64_t now_ns) = 0;
  virtual std::string describe() const = 0;
  // One past the last byte of the area the rule touches (the runtime copies that far).
  virtual uint32_t extent() const = 0;
  // A copy with the rule's state as it is now (a delay line's samples, a noise
  // generator's position): saved runtime states hold copies.
  virtual std::unique_ptr<OverlayRule> clone() const = 0;
};

// Forces a location to a fixed value (the classic force table of soft PLCs).
class ForceRule final : public OverlayRule {
 public:
  ForceRule(ImageRef ref, int64_t value) : ref_(std::move(ref)), value_(value) {}
  void apply(uint8_t* dst, const uint8_t*, int64_t) override { ref_.set(dst, value_); }
  std::string describe() const override;
  uint32_t extent() const override { return ref_.offset + ref_.size; }
  std::unique_ptr<OverlayRule> clone() const override { return std::make_unique<ForceRule>(*this); }

 private:
  ImageRef ref_;
  int64_t value_;
};

class Overlay {
 public:
  // Copies n bytes from src to dst, then applies every rule in insertion order.
  void apply(uint8_t* dst, const uint8_t* src, size_t n, int64_t now_ns) const;
  void add(std::unique_ptr<OverlayRule> rule) {
    extent_ = std::max(extent_, rule->extent());
    rules_.push_back(std::move(rule));
  }
  void clear() {
    rules_.clear();
    extent_ = 0;
  }
  uint32_t extent() const { return extent_; }
  bool empty() const { return rules_.empty(); }
  // A copy of every rule with its state (clone()).
  Overlay copy() const {
    Overlay o;
    for (const auto& r : rules_) o.add(r->clone());
    return o;
  }
  const std::vector<std::unique_ptr<OverlayRule>>& rules() const { return rules_; }

 private:
  std::vector<std::unique_ptr<OverlayRule>> rules_;
  uint32_t extent_ = 0;
};

}  // namespace plcfi::rt

// Fault models: parsing of their spec text and their overlay rules.
#include "fault_model.hpp"

#include <cctype>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <fmt/format.h>

#include "runtime/schedule.hpp"

namespace plcfi::faults {

namespace {

struct KindInfo {
  Kind kind;
  const char* name;
  bool actuator;
};

constexpr KindInfo kKinds[] = {
    {Kind::StuckAt, "stuck_at", false},    {Kind::StuckCurrent, "stuck", false},  {Kind::Frozen, "frozen", false},
    {Kind::Offset, "offset", false},       {Kind::Gain, "gain", false},           {Kind::Drift, "drift", false},
    {Kind::Noise, "noise", false},         {Kind::Delay, "delay", false},         {Kind::Intermittent, "intermittent", false},
    {Kind::Inverted, "inverted", false},   {Kind::OpenWire, "open_wire", false},  {Kind::NoEffect, "no_effect", true},
    {Kind::StuckOn, "stuck_on", true},     {Kind::StuckOff, "stuck_off", true},   {Kind::Delayed, "delayed", true},
};

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

struct Arg {
  std::string text;  // trimmed
  uint32_t col = 0;  // where it starts in the spec text
};

bool number(const Arg& a, double* v) {
  try {
    size_t used = 0;
    *v = std::stod(a.text, &used);
    return used == a.text.size() && std::isfinite(*v);
  } catch (const std::exception&) {
    return false;
  }
}

std::string fmt_num(double v) { return fmt::format("{:g}", v); }

std::string fmt_dur(int64_t ns) {
  if (ns % 1'000'000'000 == 0) return fmt::format("{}s", ns / 1'000'000'000);
  if (ns % 1'000'000 == 0) return fmt::format("{}ms", ns / 1'000'000);
  if (ns % 1'000 == 0) return fmt::format("{}us", ns / 1'000);
  return fmt::format("{}ns", ns);
}

}  // namespace

bool is_actuator_fault(Kind k) {
  for (const auto& i : kKinds)
    if (i.kind == k) return i.actuator;
  return false;
}

std::string kind_name(Kind k) {
  for (const auto& i : kKinds)
    if (i.kind == k) return i.name;
  return "?";
}

bool parse_fault(const std::string& text, FaultSpec* out, std::string* err, uint32_t* err_col) {
  auto fail = [&](uint32_t col, std::string msg) {
    *err = std::move(msg);
    *err_col = col;
    return false;
  };
  size_t i = 0;
  while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  size_t name_at = i;
  while (i < text.size() && (std::isalnum(static_cast<unsigned char>(text[i])) || text[i] == '_')) ++i;
  std::string name = lower(text.substr(name_at, i - name_at));
  const uint32_t ncol = static_cast<uint32_t>(name_at);
  if (name.empty()) return fail(ncol, "expected a fault model (e.g. stuck, stuck_at(1), offset(100), no_effect)");
  const KindInfo* info = nullptr;
  for (const auto& k : kKinds)
    if (name == k.name) info = &k;
  if (!info) {
    std::string all;
    for (const auto& k : kKinds) all += (all.empty() ? "" : ", ") + std::string(k.name);
    return fail(ncol, "unknown fault model '" + text.substr(name_at, i - name_at) + "' (known: " + all + ")");
  }
  // Arguments.
  std::vector<Arg> args;
  while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  if (i < text.size()) {
    if (text[i] != '(') return fail(static_cast<uint32_t>(i), "expected '(' or the end after '" + name + "'");
    size_t close = text.find(')', i);
    if (close == std::string::npos) return fail(static_cast<uint32_t>(text.size()), "missing ')'");
    for (size_t j = close + 1; j < text.size(); ++j)
      if (!std::isspace(static_cast<unsigned char>(text[j])))
        return fail(static_cast<uint32_t>(j), "unexpected text after ')'");
    size_t start = i + 1;
    while (true) {
      size_t comma = text.find(',', start);
      size_t end = comma == std::string::npos || comma > close ? close : comma;
      size_t b = start, e = end;
      while (b < e && std::isspace(static_cast<unsigned char>(text[b]))) ++b;
      while (e > b && std::isspace(static_cast<unsigned char>(text[e - 1]))) --e;
      if (b == e) return fail(static_cast<uint32_t>(b), "empty argument");
      args.push_back(Arg{text.substr(b, e - b), static_cast<uint32_t>(b)});
      if (end == close) break;
      start = end + 1;
    }
  }
  auto want = [&](size_t lo, size_t hi, const char* usage) {
    if (args.size() < lo || args.size() > hi)
      return fail(args.empty() ? static_cast<uint32_t>(i) : args.front().col,
                  fmt::format("{} takes {}: {}", name, lo == hi && lo == 0 ? "no arguments" : "arguments", usage));
    return true;
  };
  auto num = [&](const Arg& a, double* v, const char* what) {
    if (!number(a, v)) return fail(a.col, fmt::format("{}: '{}' is not a number ({})", name, a.text, what));
    return true;
  };
  auto dur = [&](const Arg& a, int64_t* ns, const char* what) {
    std::string e;
    if (!rt::parse_duration(a.text, ns, &e)) return fail(a.col, fmt::format("{}: {} ({})", name, e, what));
    if (*ns <= 0) return fail(a.col, fmt::format("{}: {} must be positive", name, what));
    return true;
  };
  FaultSpec f;
  f.kind = info->kind;
  switch (f.kind) {
    case Kind::StuckAt: {
      if (!want(1, 1, "stuck_at(value), e.g. stuck_at(TRUE), stuck_at(0), stuck_at(6000)")) return false;
      std::string up = lower(args[0].text);
      if (up == "true") f.value = 1;
      else if (up == "false") f.value = 0;
      else if (!num(args[0], &f.value, "the value the sensor reads")) return false;
      f.text = "stuck_at(" + (up == "true" || up == "false" ? up : fmt_num(f.value)) + ")";
      break;
    }
    case Kind::Offset:
    case Kind::Gain:
    case Kind::Noise: {
      const char* usage = f.kind == Kind::Offset ? "offset(d), e.g. offset(150)"
                          : f.kind == Kind::Gain ? "gain(k), e.g. gain(1.2)"
                                                 : "noise(sigma), e.g. noise(50)";
      if (!want(1, 1, usage) || !num(args[0], &f.value, usage)) return false;
      if (f.kind == Kind::Noise && f.value <= 0) return fail(args[0].col, "noise: sigma must be positive");
      f.text = name + "(" + fmt_num(f.value) + ")";
      break;
    }
    case Kind::Drift: {
      if (!want(1, 1, "drift(rate/s), e.g. drift(100/s)")) return false;
      const Arg& a = args[0];
      size_t slash = a.text.find('/');
      if (slash == std::string::npos) return fail(a.col, "drift: give the rate per time unit, e.g. drift(100/s)");
      std::string unit = lower(a.text.substr(slash + 1));
      while (!unit.empty() && std::isspace(static_cast<unsigned char>(unit.front()))) unit.erase(unit.begin());
      double per = unit == "s" ? 1 : unit == "min" ? 60 : unit == "ms" ? 1e-3 : unit == "h" ? 3600 : 0;
      if (per == 0) return fail(static_cast<uint32_t>(a.col + slash + 1), "drift: unit '" + unit + "' is not s, ms, min or h");
      std::string n = a.text.substr(0, slash);
      while (!n.empty() && std::isspace(static_cast<unsigned char>(n.back()))) n.pop_back();
      if (!num(Arg{n, a.col}, &f.value, "the rate")) return false;
      f.value /= per;
      f.text = "drift(" + fmt_num(f.value) + "/s)";
      break;
    }
    case Kind::Delay:
    case Kind::Delayed:
      if (!want(1, 1, f.kind == Kind::Delay ? "delay(t), e.g. delay(200ms)" : "delayed(t), e.g. delayed(300ms)") ||
          !dur(args[0], &f.duration_ns, "the delay"))
        return false;
      f.text = name + "(" + fmt_dur(f.duration_ns) + ")";
      break;
    case Kind::Intermittent: {
      if (!want(2, 3, "intermittent(period, duty) or intermittent(random, p, interval)")) return false;
      if (lower(args[0].text) == "random") {
        if (args.size() != 3) return fail(args[0].col, "intermittent(random, p, interval): three arguments");
        f.random = true;
        if (!num(args[1], &f.value, "the probability")) return false;
        if (f.value < 0 || f.value > 1) return fail(args[1].col, "intermittent: the probability must be in 0..1");
        if (!dur(args[2], &f.duration_ns, "the interval")) return false;
        f.text = fmt::format("intermittent(random, {}, {})", fmt_num(f.value), fmt_dur(f.duration_ns));
      } else {
        if (args.size() != 2) return fail(args[0].col, "intermittent(period, duty): two arguments");
        if (!dur(args[0], &f.duration_ns, "the period") || !num(args[1], &f.value, "the duty cycle")) return false;
        if (f.value < 0 || f.value > 1) return fail(args[1].col, "intermittent: the duty cycle must be in 0..1");
        f.text = fmt::format("intermittent({}, {})", fmt_dur(f.duration_ns), fmt_num(f.value));
      }
      break;
    }
    case Kind::OpenWire:
      if (!want(0, 1, "open_wire or open_wire(value)")) return false;
      if (!args.empty()) {
        if (!num(args[0], &f.value, "the value an open input reads")) return false;
        f.has_value = true;
        f.text = "open_wire(" + fmt_num(f.value) + ")";
      } else {
        f.text = "open_wire";
      }
      break;
    default:
      if (!want(0, 0, name.c_str())) return false;
      f.text = name;
      break;
  }
  *out = f;
  return true;
}

namespace {

bool is_bool(const rt::ImageRef& r) { return r.is_bit || (r.type && r.type->kind == st::TypeKind::Bool); }
bool is_integer(const rt::ImageRef& r) { return !is_bool(r) && r.type && (r.type->is_integer() || r.type->is_bitstring()); }
bool is_real(const rt::ImageRef& r) { return !r.is_bit && r.type && r.type->is_real() && (r.size == 4 || r.size == 8); }

// A REAL/LREAL location's value from the bits ImageRef::get returns (the low 4 or 8 bytes).
double real_from_bits(const rt::ImageRef& r, int64_t bits) {
  if (r.size == 4) {
    auto b = static_cast<uint32_t>(bits);
    float f;
    std::memcpy(&f, &b, 4);
    return f;
  }
  double d;
  std::memcpy(&d, &bits, 8);
  return d;
}

// The value at a location as a number: integers as themselves, REAL/LREAL as reals.
double value_at(const rt::ImageRef& r, int64_t raw) { return is_real(r) ? real_from_bits(r, raw) : static_cast<double>(raw); }

// Base of all fault rules: one location, a value transform, clamping to the location's type.
class FaultRule : public rt::OverlayRule {
 public:
  FaultRule(const InjectionContext& ctx, std::string desc)
      : ref_(ctx.ref), baseline_(value_at(ctx.ref, ctx.baseline)), inject_ns_(ctx.inject_ns), desc_(std::move(desc)),
        real_(is_real(ctx.ref)) {
    if (is_bool(ref_)) {
      lo_ = 0;
      hi_ = 1;
    } else if (ref_.type && ref_.type->is_signed()) {
      lo_ = -std::ldexp(1.0, 8 * ref_.size - 1);
      hi_ = std::ldexp(1.0, 8 * ref_.size - 1) - 1;
    } else {
      lo_ = 0;
      hi_ = std::ldexp(1.0, 8 * ref_.size) - 1;
    }
  }
  void apply(uint8_t* dst, const uint8_t* src, int64_t now_ns) override {
    if (real_) {  // analog values as REAL/LREAL: no rounding, no clamping (beyond the float range)
      double v = transform(real_from_bits(ref_, ref_.get(src)), now_ns);
      if (ref_.size == 4) {
        auto f = static_cast<float>(v);
        std::memcpy(dst + ref_.offset, &f, 4);
      } else {
        std::memcpy(dst + ref_.offset, &v, 8);
      }
      return;
    }
    double v = transform(static_cast<double>(ref_.get(src)), now_ns);
    v = std::round(v);
    if (v < lo_) v = lo_;
    if (v > hi_) v = hi_;
    // An 8-byte unsigned range does not fit int64 exactly; the largest value is a fair answer.
    ref_.set(dst, v >= 9.2e18 ? INT64_MAX : static_cast<int64_t>(v));
  }
  std::string describe() const override { return desc_; }
  uint32_t extent() const override { return ref_.offset + ref_.size; }

 protected:
  virtual double transform(double v, int64_t now_ns) = 0;
  rt::ImageRef ref_;
  double baseline_;  // the value at the injection
  int64_t inject_ns_;
  std::string desc_;
  bool real_;
  double lo_ = 0, hi_ = 0;
};

class ConstantRule final : public FaultRule {
 public:
  std::unique_ptr<rt::OverlayRule> clone() const override { return std::make_unique<ConstantRule>(*this); }
  ConstantRule(const InjectionContext& c, std::string d, double v) : FaultRule(c, std::move(d)), v_(v) {}
  double transform(double, int64_t) override { return v_; }

 private:
  double v_;
};

class AffineRule final : public FaultRule {  // v * gain + offset + rate * t
 public:
  std::unique_ptr<rt::OverlayRule> clone() const override { return std::make_unique<AffineRule>(*this); }
  AffineRule(const InjectionContext& c, std::string d, double gain, double offset, double rate_per_s)
      : FaultRule(c, std::move(d)), gain_(gain), offset_(offset), rate_(rate_per_s) {}
  double transform(double v, int64_t now) override {
    return v * gain_ + offset_ + rate_ * static_cast<double>(now - inject_ns_) * 1e-9;
  }

 private:
  double gain_, offset_, rate_;
};

class InvertRule final : public FaultRule {
 public:
  std::unique_ptr<rt::OverlayRule> clone() const override { return std::make_unique<InvertRule>(*this); }
  using FaultRule::FaultRule;
  double transform(double v, int64_t) override { return v != 0 ? 0 : 1; }
};

// Gaussian noise: Box-Muller over a 64-bit Mersenne Twister, so the sequence depends only
// on the seed (not on a library's distribution code).
class NoiseRule final : public FaultRule {
 public:
  std::unique_ptr<rt::OverlayRule> clone() const override { return std::make_unique<NoiseRule>(*this); }
  NoiseRule(const InjectionContext& c, std::string d, double sigma) : FaultRule(c, std::move(d)), sigma_(sigma), rng_(c.seed) {}
  double transform(double v, int64_t) override {
    double u1 = static_cast<double>((rng_() >> 11) + 1) * 0x1.0p-53;  // (0, 1]
    double u2 = static_cast<double>(rng_() >> 11) * 0x1.0p-53;        // [0, 1)
    return v + sigma_ * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  double sigma_;
  std::mt19937_64 rng_;
};

// Transport delay: the value of `delay` ago; before the first such sample, the baseline.
// The ring holds delay / tick samples (+ margin), allocated here and never grown.
class DelayRule final : public FaultRule {
 public:
  std::unique_ptr<rt::OverlayRule> clone() const override { return std::make_unique<DelayRule>(*this); }
  DelayRule(const InjectionContext& c, std::string d, int64_t delay_ns) : FaultRule(c, std::move(d)), delay_(delay_ns) {
    int64_t tick = c.tick_ns > 0 ? c.tick_ns : 1'000'000;
    ring_.resize(static_cast<size_t>(delay_ns / tick) + 4);
    current_ = baseline_;
  }
  double transform(double v, int64_t now) override {
    if (count_ == ring_.size()) pop();  // ticks shorter than planned: drop the oldest
    ring_[(head_ + count_) % ring_.size()] = {now, v};
    ++count_;
    while (count_ > 0 && ring_[head_].first <= now - delay_) pop();
    return current_;
  }

 private:
  void pop() {
    current_ = ring_[head_].second;
    head_ = (head_ + 1) % ring_.size();
    --count_;
  }
  int64_t delay_;
  std::vector<std::pair<int64_t, double>> ring_;
  size_t head_ = 0, count_ = 0;
  double current_ = 0;
};

// The sensor drops to its pre-fault value part of the time.
class IntermittentRule final : public FaultRule {
 public:
  std::unique_ptr<rt::OverlayRule> clone() const override { return std::make_unique<IntermittentRule>(*this); }
  IntermittentRule(const InjectionContext& c, std::string d, const FaultSpec& f)
      : FaultRule(c, std::move(d)), random_(f.random), p_(f.value), span_(f.duration_ns), rng_(c.seed) {}
  double transform(double v, int64_t now) override {
    int64_t t = now - inject_ns_;
    if (t < 0) t = 0;
    bool active;
    if (random_) {
      int64_t k = t / span_;
      while (k > interval_) {  // one draw per interval, also for intervals without a scan
        ++interval_;
        active_ = static_cast<double>(rng_() >> 11) * 0x1.0p-53 < p_;
      }
      active = active_;
    } else {
      active = static_cast<double>(t % span_) < p_ * static_cast<double>(span_);
    }
    return active ? baseline_ : v;
  }

 private:
  bool random_;
  double p_;
  int64_t span_;
  std::mt19937_64 rng_;
  int64_t interval_ = -1;
  bool active_ = false;
};

}  // namespace

std::unique_ptr<rt::OverlayRule> make_rule(const FaultSpec& f, const InjectionContext& ctx, std::string* err) {
  const rt::ImageRef& r = ctx.ref;
  const std::string at = r.text.empty() ? "the location" : r.text;
  const bool actuator = is_actuator_fault(f.kind);
  if (actuator && r.area != 'Q') {
    *err = fmt::format("fault '{}' is an actuator fault; {} is not an output (%Q)", f.text, at);
    return nullptr;
  }
  if (!actuator && r.area != 'I') {
    *err = fmt::format("fault '{}' is a sensor fault; {} is not an input (%I)", f.text, at);
    return nullptr;
  }
  const bool b = is_bool(r);
  if (!b && !is_integer(r) && !is_real(r)) {
    *err = fmt::format("fault '{}': {} holds no BOOL, integer or REAL value", f.text, at);
    return nullptr;
  }
  switch (f.kind) {
    case Kind::Offset:
    case Kind::Gain:
    case Kind::Drift:
    case Kind::Noise:
      if (b) {
        *err = fmt::format("fault '{}' needs an analog signal; {} is BOOL", f.text, at);
        return nullptr;
      }
      break;
    case Kind::Inverted:
    case Kind::StuckOn:
      if (!b) {
        *err = fmt::format("fault '{}' needs a BOOL signal; {} is {}", f.text, at, r.type ? r.type->name : "analog");
        return nullptr;
      }
      break;
    case Kind::StuckAt:
      if (b && f.value != 0 && f.value != 1) {
        *err = fmt::format("fault '{}': {} is BOOL (stuck_at(TRUE) or stuck_at(FALSE))", f.text, at);
        return nullptr;
      }
      break;
    default:
      break;
  }
  const double baseline = value_at(ctx.ref, ctx.baseline);
  const std::string base = b ? (ctx.baseline ? "TRUE" : "FALSE") : is_real(ctx.ref) ? fmt_num(baseline) : std::to_string(ctx.baseline);
  switch (f.kind) {
    case Kind::StuckAt:
      return std::make_unique<ConstantRule>(ctx, fmt::format("{}: stuck at {}", at, b ? (f.value ? "TRUE" : "FALSE") : fmt_num(f.value)),
                                            f.value);
    case Kind::StuckCurrent:
    case Kind::Frozen:
      return std::make_unique<ConstantRule>(
          ctx, fmt::format("{}: {} at {} (its value at the injection)", at, f.kind == Kind::Frozen ? "frozen" : "stuck", base),
          baseline);
    case Kind::Offset:
      return std::make_unique<AffineRule>(ctx, fmt::format("{}: offset {}", at, fmt_num(f.value)), 1.0, f.value, 0.0);
    case Kind::Gain:
      return std::make_unique<AffineRule>(ctx, fmt::format("{}: gain {}", at, fmt_num(f.value)), f.value, 0.0, 0.0);
    case Kind::Drift:
      return std::make_unique<AffineRule>(ctx, fmt::format("{}: drift {}/s", at, fmt_num(f.value)), 1.0, 0.0, f.value);
    case Kind::Noise:
      return std::make_unique<NoiseRule>(ctx, fmt::format("{}: gaussian noise, sigma {}", at, fmt_num(f.value)), f.value);
    case Kind::Delay:
      return std::make_unique<DelayRule>(ctx, fmt::format("{}: transport delay {}", at, fmt_dur(f.duration_ns)), f.duration_ns);
    case Kind::Intermittent:
      return std::make_unique<IntermittentRule>(
          ctx, fmt::format("{}: intermittent, drops to {} ({})", at, base, f.text), f);
    case Kind::Inverted:
      return std::make_unique<InvertRule>(ctx, at + ": inverted");
    case Kind::OpenWire:
      return std::make_unique<ConstantRule>(ctx, fmt::format("{}: open wire, reads {}", at, b ? "FALSE" : fmt_num(f.value)),
                                            b ? 0.0 : f.value);
    case Kind::NoEffect:
      return std::make_unique<ConstantRule>(ctx, fmt::format("{}: no effect, the plant keeps receiving {}", at, base), baseline);
    case Kind::StuckOn:
      return std::make_unique<ConstantRule>(ctx, at + ": stuck on (TRUE)", 1.0);
    case Kind::StuckOff:
      return std::make_unique<ConstantRule>(ctx, at + ": stuck off", 0.0);
    case Kind::Delayed:
      return std::make_unique<DelayRule>(ctx, fmt::format("{}: commands delayed by {}", at, fmt_dur(f.duration_ns)), f.duration_ns);
  }
  *err = "unknown fault kind";
  return nullptr;
}

}  // namespace plcfi::faults

// FMU plant: the map checked against modelDescription.xml, values converted between the
// FMU's types and the image's (BOOL bits, 16-bit words, Real through a linear scale).
#include "plant_model/fmu/fmu_plant.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "common/duration.hpp"
#include "common/yaml.hpp"

namespace plcfi::plant::fmu {

namespace {

[[noreturn]] void fail_at(const std::string& where, const std::string& message) {
  throw common::InputError(where + ": " + message);
}

double clamp_word(double v) { return std::clamp(v, -32768.0, 32767.0); }

// The FMU's variables of one causality, for "expected one of" in a message.
std::string names_of(const ModelDescription& md, Causality c) {
  std::string out;
  for (const auto& v : md.variables)
    if (v.causality == c) out += (out.empty() ? "" : ", ") + v.name;
  return out.empty() ? "none" : out;
}

}  // namespace

std::unique_ptr<FmuPlant> FmuPlant::create(const PlantFile& pf) {
  std::unique_ptr<FmuPlant> p(new FmuPlant());
  try {
    p->archive_ = FmuArchive::open(pf.fmu);
  } catch (const common::InputError& e) {
    // Where the plant file names the FMU, then what is wrong with it.
    throw common::InputError(pf.fmu_where + ": fmu: " + e.what());
  }
  const ModelDescription& md = p->archive_->description();
  p->name_ = md.model_name;
  p->origin_ = fmt::format("{} (FMU {}, FMI {} co-simulation)", pf.path, pf.fmu, md.fmi_version);

  if (pf.step_ns > 0) {
    p->step_ns_ = pf.step_ns;
  } else if (md.default_step) {
    p->step_ns_ = std::max<int64_t>(1, std::llround(*md.default_step * 1e9));
  } else {
    fail_at(pf.where, fmt::format("missing key 'step' in the plant file: the FMU {} gives no DefaultExperiment "
                                  "stepSize, so the plant step must be set (e.g. step: 1ms)",
                                  pf.fmu));
  }
  p->stop_ns_ = pf.stop_time_ns;
  if (md.default_step && pf.step_ns > 0) {
    const int64_t suggested = std::max<int64_t>(1, std::llround(*md.default_step * 1e9));
    if (suggested != pf.step_ns)
      p->notes_.push_back(fmt::format("the FMU's DefaultExperiment suggests a step of {}; the plant file steps it every {}",
                                      common::format_duration(suggested), common::format_duration(pf.step_ns)));
  }
  if (md.default_stop && pf.stop_time_ns > 0 && static_cast<double>(pf.stop_time_ns) * 1e-9 > *md.default_stop)
    p->notes_.push_back(fmt::format("stop_time {} is later than the FMU's DefaultExperiment stopTime {} s",
                                    common::format_duration(pf.stop_time_ns), *md.default_stop));

  const std::string fmu_md = pf.fmu + "/modelDescription.xml";
  for (const MapEntry& m : pf.map) {
    const ScalarVariable* v = md.find(m.plant);
    if (!v)
      fail_at(m.plant_where, fmt::format("the FMU has no variable '{}' (its {}s: {})", m.plant,
                                         m.input ? "output" : "input",
                                         names_of(md, m.input ? Causality::Output : Causality::Input)));
    const Causality want = m.input ? Causality::Output : Causality::Input;
    if (v->causality != want)
      fail_at(m.plant_where, fmt::format("'{}' is {} {} of the FMU ({}:{}:{}); {} takes an {} ({})", m.plant,
                                         v->causality == Causality::Input || v->causality == Causality::Output ||
                                                 v->causality == Causality::Independent
                                             ? "an"
                                             : "a",
                                         causality_name(v->causality), fmu_md, v->line, v->col, m.image,
                                         causality_name(want),
                                         m.input ? "what the plant tells the PLC" : "what the PLC commands"));
    if (v->type == VarType::String || v->type == VarType::Enumeration)
      fail_at(m.plant_where, fmt::format("'{}' is a {} variable ({}:{}:{}): the map takes Real, Integer and Boolean",
                                         m.plant, type_name(v->type), fmu_md, v->line, v->col));
    check_binding(m,
                  v->type == VarType::Boolean   ? ValueKind::Bool
                  : v->type == VarType::Integer ? ValueKind::Integer
                                                : ValueKind::Real,
                  fmt::format("{} ({}:{}:{})", type_name(v->type), fmu_md, v->line, v->col));

    SignalInfo s;
    s.name = m.plant;
    s.dir = m.input ? Direction::FromPlant : Direction::ToPlant;
    s.kind = m.bit ? SignalKind::Bool : SignalKind::Analog;
    s.address = m.image;
    s.description = v->description;
    s.where = m.where;
    const size_t index = p->signals_.size();
    p->signals_.push_back(std::move(s));
    p->bind_.push_back({v->type, m.scale});
    Group& g = v->type == VarType::Real      ? (m.input ? p->out_real_ : p->in_real_)
               : v->type == VarType::Integer ? (m.input ? p->out_int_ : p->in_int_)
                                             : (m.input ? p->out_bool_ : p->in_bool_);
    g.vr.push_back(v->value_reference);
    g.signal.push_back(index);
  }

  for (const Parameter& par : pf.parameters) {
    const ScalarVariable* v = md.find(par.name);
    if (!v) fail_at(par.where, fmt::format("the FMU has no variable '{}' (its parameters: {})", par.name, names_of(md, Causality::Parameter)));
    if (v->causality != Causality::Parameter && v->causality != Causality::Input)
      fail_at(par.where, fmt::format("'{}' is an {} of the FMU ({}:{}:{}): only parameters and inputs take a start value",
                                     par.name, causality_name(v->causality), fmu_md, v->line, v->col));
    if (v->variability == Variability::Constant)
      fail_at(par.where, fmt::format("'{}' is a constant of the FMU ({}:{}:{})", par.name, fmu_md, v->line, v->col));
    const std::string& t = par.value;
    switch (v->type) {
      case VarType::Real: {
        char* end = nullptr;
        double d = std::strtod(t.c_str(), &end);
        if (t.empty() || end != t.c_str() + t.size() || !std::isfinite(d))
          fail_at(par.where, fmt::format("'{}' is Real: expected a number, got '{}'", par.name, t));
        p->par_real_.vr.push_back(v->value_reference);
        p->par_real_v_.push_back(d);
        break;
      }
      case VarType::Integer: {
        int64_t x = 0;
        auto [q, ec] = std::from_chars(t.data(), t.data() + t.size(), x);
        if (t.empty() || ec != std::errc() || q != t.data() + t.size() || x < INT32_MIN || x > INT32_MAX)
          fail_at(par.where, fmt::format("'{}' is Integer: expected a 32-bit integer, got '{}'", par.name, t));
        p->par_int_.vr.push_back(v->value_reference);
        p->par_int_v_.push_back(static_cast<fmi2Integer>(x));
        break;
      }
      case VarType::Boolean: {
        std::string l = t;
        std::transform(l.begin(), l.end(), l.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        if (l != "true" && l != "false")
          fail_at(par.where, fmt::format("'{}' is Boolean: expected true or false, got '{}'", par.name, t));
        p->par_bool_.vr.push_back(v->value_reference);
        p->par_bool_v_.push_back(l == "true" ? fmi2True : fmi2False);
        break;
      }
      default:
        fail_at(par.where, fmt::format("'{}' is a {} variable: parameters take Real, Integer and Boolean", par.name,
                                       type_name(v->type)));
    }
  }

  for (const Parameter& s : pf.stats) {
    const ScalarVariable* v = md.find(s.name);
    if (!v) fail_at(s.where, fmt::format("stats: the FMU has no variable '{}'", s.name));
    if (v->type != VarType::Real && v->type != VarType::Integer && v->type != VarType::Boolean)
      fail_at(s.where, fmt::format("stats: '{}' is a {} variable; statistics are Real, Integer or Boolean", s.name,
                                   type_name(v->type)));
    p->stats_.push_back({s.name, v->type, v->value_reference});
  }

  if (!pf.seed_parameter.empty()) {
    const ScalarVariable* v = md.find(pf.seed_parameter);
    if (!v || v->type != VarType::Integer || v->causality != Causality::Parameter)
      fail_at(pf.seed_where, fmt::format("seed_parameter: the FMU has no Integer parameter '{}' (its parameters: {})",
                                         pf.seed_parameter, names_of(md, Causality::Parameter)));
    p->has_seed_ = true;
    p->seed_ref_ = v->value_reference;
  }

  const size_t most = std::max({p->in_real_.vr.size(), p->out_real_.vr.size(), size_t{1}});
  p->real_buf_.assign(most, 0.0);
  p->int_buf_.assign(std::max({p->in_int_.vr.size(), p->out_int_.vr.size(), size_t{1}}), 0);
  p->bool_buf_.assign(std::max({p->in_bool_.vr.size(), p->out_bool_.vr.size(), size_t{1}}), 0);
  p->values_.assign(p->signals_.size(), 0.0);
  p->instance_ = std::make_unique<FmuInstance>(*p->archive_, std::filesystem::path(pf.fmu).stem().string());
  p->instance_->set_call_timeout(pf.call_timeout_ns);
  p->initialize();
  return p;
}

void FmuPlant::initialize() {
  instance_->initialize(static_cast<double>(stop_ns_) * 1e-9, [&] {
    instance_->set_real(par_real_.vr, par_real_v_);
    instance_->set_integer(par_int_.vr, par_int_v_);
    instance_->set_boolean(par_bool_.vr, par_bool_v_);
    if (has_seed_) instance_->set_integer({seed_ref_}, {seed_});
  });
  t_ns_ = pending_ns_ = 0;
  steps_ = 0;
  std::fill(values_.begin(), values_.end(), 0.0);
  exchange_outputs();
}

void FmuPlant::reset(uint64_t seed) {
  // The seed reaches an FMU only through the plant file's seed_parameter.
  seed_ = static_cast<fmi2Integer>(seed & 0x7fffffff);
  failed_ = true;
  instance_->reset();
  initialize();
  failed_ = false;
}

void FmuPlant::exchange_outputs() {
  if (!out_real_.vr.empty()) {
    instance_->get_real(out_real_.vr, &real_buf_);
    for (size_t k = 0; k < out_real_.vr.size(); ++k) {
      const size_t i = out_real_.signal[k];
      values_[i] = clamp_word(bind_[i].scale->to_image(real_buf_[k]));
    }
  }
  if (!out_int_.vr.empty()) {
    instance_->get_integer(out_int_.vr, &int_buf_);
    for (size_t k = 0; k < out_int_.vr.size(); ++k) values_[out_int_.signal[k]] = clamp_word(int_buf_[k]);
  }
  if (!out_bool_.vr.empty()) {
    instance_->get_boolean(out_bool_.vr, &bool_buf_);
    for (size_t k = 0; k < out_bool_.vr.size(); ++k) values_[out_bool_.signal[k]] = bool_buf_[k] != fmi2False ? 1.0 : 0.0;
  }
}

void FmuPlant::step(double dt, const double* actuators, double* sensors) {
  if (dt != last_dt_) {  // the scan's tick, nearly always the same
    last_dt_ = dt;
    last_dt_ns_ = std::llround(dt * 1e9);
  }
  pending_ns_ += last_dt_ns_;
  // After a failure the FMU is not called again (its error was thrown once; the safe
  // outputs written on the way out must not throw a second time).
  if (!failed_ && pending_ns_ >= step_ns_) {
    failed_ = true;  // until this exchange completes
    actuators_ = actuators;
    instance_->batch([](void* self) { static_cast<FmuPlant*>(self)->exchange(); }, this);
    failed_ = false;
  }
  sense(sensors);
}

void FmuPlant::exchange() {
  const double* actuators = actuators_;
  {
    // The PLC's outputs of this scan, held for the steps it covers.
    if (!in_real_.vr.empty()) {
      for (size_t k = 0; k < in_real_.vr.size(); ++k) {
        const size_t i = in_real_.signal[k];
        real_buf_[k] = bind_[i].scale->to_plant(actuators[i]);
      }
      instance_->set_real(in_real_.vr, real_buf_);
    }
    if (!in_int_.vr.empty()) {
      for (size_t k = 0; k < in_int_.vr.size(); ++k) int_buf_[k] = static_cast<fmi2Integer>(actuators[in_int_.signal[k]]);
      instance_->set_integer(in_int_.vr, int_buf_);
    }
    if (!in_bool_.vr.empty()) {
      for (size_t k = 0; k < in_bool_.vr.size(); ++k) bool_buf_[k] = actuators[in_bool_.signal[k]] != 0.0 ? fmi2True : fmi2False;
      instance_->set_boolean(in_bool_.vr, bool_buf_);
    }
    while (pending_ns_ >= step_ns_) {
      instance_->do_step(static_cast<double>(t_ns_) * 1e-9, static_cast<double>(step_ns_) * 1e-9);
      t_ns_ += step_ns_;
      pending_ns_ -= step_ns_;
      ++steps_;
    }
    exchange_outputs();
  }
}

void FmuPlant::sense(double* sensors) const {
  for (size_t i = 0; i < signals_.size(); ++i)
    if (signals_[i].dir == Direction::FromPlant) sensors[i] = values_[i];
}

std::vector<std::pair<std::string, double>> FmuPlant::stats() const {
  std::vector<std::pair<std::string, double>> out;
  if (!failed_) {
    try {
      for (const Stat& s : stats_) {
        double v = 0;
        if (s.type == VarType::Real) {
          std::vector<fmi2Real> r(1);
          instance_->get_real({s.vr}, &r);
          v = r[0];
        } else if (s.type == VarType::Integer) {
          std::vector<fmi2Integer> r(1);
          instance_->get_integer({s.vr}, &r);
          v = r[0];
        } else {
          std::vector<fmi2Boolean> r(1);
          instance_->get_boolean({s.vr}, &r);
          v = r[0] != fmi2False ? 1 : 0;
        }
        out.emplace_back(s.name, v);
      }
    } catch (const FmuError&) {
      out.clear();  // a summary is no place to fail; the run reported its own errors
    }
  }
  out.emplace_back("fmu_steps", static_cast<double>(steps_));
  out.emplace_back("fmu_time_s", static_cast<double>(t_ns_) / 1e9);
  return out;
}

}  // namespace plcfi::plant::fmu

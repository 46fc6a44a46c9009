// ST plant: compile, bind the map to typed variable handles, scan at the plant step.
#include "io/sim/st_plant.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "common/yaml.hpp"

namespace plcfi::io {

namespace {

[[noreturn]] void fail_at(const std::string& where, const std::string& message) {
  throw common::InputError(where + ": " + message);
}

bool is_integer(st::TypeKind k) {
  switch (k) {
    case st::TypeKind::SInt: case st::TypeKind::Int: case st::TypeKind::DInt: case st::TypeKind::LInt:
    case st::TypeKind::USInt: case st::TypeKind::UInt: case st::TypeKind::UDInt: case st::TypeKind::ULInt:
    case st::TypeKind::Byte: case st::TypeKind::Word: case st::TypeKind::DWord: case st::TypeKind::LWord:
      return true;
    default:
      return false;
  }
}

}  // namespace

std::unique_ptr<StPlant> StPlant::create(const plant::PlantFile& pf) {
  std::unique_ptr<StPlant> p(new StPlant());
  if (pf.step_ns <= 0)
    fail_at(pf.where, "missing key 'step' in the plant file: an ST plant is scanned at its own step (e.g. step: 1ms)");
  p->step_ns_ = pf.step_ns;

  st::CompileOptions opt;
  opt.warnings = false;
  p->build_ = st::build_files(pf.st, opt);
  std::string errors;
  for (const auto& e : p->build_->io_errors) errors += e + "\n";
  errors += p->build_->diags.render_all();
  if (!p->build_->ok()) {
    while (!errors.empty() && errors.back() == '\n') errors.pop_back();
    throw common::InputError(fmt::format("{}\n{}: the ST plant does not compile", errors, pf.where));
  }
  const st::Application& app = *p->build_->app;
  rt::Schedule sched;
  std::string err;
  if (!sched.single_program(app, pf.program, pf.step_ns, &err)) fail_at(pf.where, "the ST plant: " + err);
  const size_t prog = sched.tasks().front().programs.front();
  p->name_ = app.programs[prog].name;
  std::string files;
  for (const auto& f : pf.st) files += (files.empty() ? "" : ", ") + f;
  p->origin_ = fmt::format("{} (ST plant {}: {})", pf.path, p->name_, files);
  p->runtime_ = std::make_unique<rt::Runtime>(app, sched, nullptr);

  // A name without a dot is looked up in the plant program first, then globally.
  auto lookup = [&](const std::string& name, const std::string& where) {
    std::string e1, e2;
    if (name.find('.') == std::string::npos)
      if (auto h = st::resolve(app, p->name_ + "." + name, &e1)) return *h;
    if (auto h = st::resolve(app, name, &e2)) return *h;
    fail_at(where, fmt::format("the ST plant has no variable '{}' ({})", name, e2));
  };

  for (const plant::MapEntry& m : pf.map) {
    Binding b;
    b.var = lookup(m.plant, m.plant_where);
    const st::TypeKind k = b.var.type->kind;
    if (k == st::TypeKind::Bool) b.kind = Kind::Bool;
    else if (is_integer(k)) b.kind = Kind::Int;
    else if (k == st::TypeKind::Real || k == st::TypeKind::LReal) b.kind = Kind::Real;
    else fail_at(m.plant_where, fmt::format("'{}' is of type {}: the map takes BOOL, integers, REAL and LREAL", m.plant, b.var.type->name));
    check_binding(m,
                  b.kind == Kind::Bool  ? plant::ValueKind::Bool
                  : b.kind == Kind::Int ? plant::ValueKind::Integer
                                        : plant::ValueKind::Real,
                  b.var.type->name);
    b.scale = m.scale;
    plant::SignalInfo s;
    s.name = m.plant;
    s.dir = m.input ? plant::Direction::FromPlant : plant::Direction::ToPlant;
    s.kind = m.bit ? plant::SignalKind::Bool : plant::SignalKind::Analog;
    s.address = m.image;
    s.where = m.where;
    p->signals_.push_back(std::move(s));
    p->bind_.push_back(std::move(b));
  }
  for (const plant::Parameter& par : pf.parameters) {
    Preset pr{lookup(par.name, par.where), par.value, par.where};
    p->presets_.push_back(std::move(pr));
  }
  for (const plant::Parameter& s : pf.stats) p->stats_.push_back(lookup(s.name, s.where));
  p->values_.assign(p->signals_.size(), 0.0);
  p->reset(0);
  return p;
}

void StPlant::reset(uint64_t seed) {
  runtime_->cold_restart(seed);
  failed_ = false;
  if (runtime_->stopped()) throw PlantProgramError(fmt::format("the ST plant {}: {}", name_, runtime_->stop_reason()));
  for (const Preset& pr : presets_) {
    std::string err;
    if (!st::write_text(runtime_->machine(), pr.var, pr.text, &err))
      throw common::InputError(fmt::format("{}: parameter '{}': {}", pr.where, pr.var.path, err));
  }
  pending_ns_ = 0;
  scans_ = 0;
  read_sensors();
}

void StPlant::read_sensors() {
  const st::Machine& m = runtime_->machine();
  for (size_t i = 0; i < bind_.size(); ++i) {
    if (signals_[i].dir != plant::Direction::FromPlant) continue;
    const Binding& b = bind_[i];
    switch (b.kind) {
      case Kind::Bool: values_[i] = st::read_bool(m, b.var) ? 1.0 : 0.0; break;
      case Kind::Int: values_[i] = std::clamp(static_cast<double>(st::read_int(m, b.var)), -32768.0, 32767.0); break;
      case Kind::Real: values_[i] = std::clamp(b.scale->to_image(st::read_real(m, b.var)), -32768.0, 32767.0); break;
    }
  }
}

void StPlant::step(double dt, const double* actuators, double* sensors) {
  pending_ns_ += std::llround(dt * 1e9);
  // A plant program that trapped is reported once; it is not scanned again.
  if (!failed_ && pending_ns_ >= step_ns_) {
    st::Machine& m = runtime_->machine();
    for (size_t i = 0; i < bind_.size(); ++i) {
      if (signals_[i].dir != plant::Direction::ToPlant) continue;
      const Binding& b = bind_[i];
      switch (b.kind) {
        case Kind::Bool: st::write_bool(m, b.var, actuators[i] != 0.0); break;
        case Kind::Int: st::write_int(m, b.var, std::llround(actuators[i])); break;
        case Kind::Real: st::write_real(m, b.var, b.scale->to_plant(actuators[i])); break;
      }
    }
    while (pending_ns_ >= step_ns_) {
      if (runtime_->scan() == rt::ScanStatus::Trapped) {
        failed_ = true;
        throw PlantProgramError(fmt::format("the ST plant {} stopped: {}", name_, runtime_->stop_reason()));
      }
      pending_ns_ -= step_ns_;
      ++scans_;
    }
    read_sensors();
  }
  sense(sensors);
}

void StPlant::sense(double* sensors) const {
  for (size_t i = 0; i < signals_.size(); ++i)
    if (signals_[i].dir == plant::Direction::FromPlant) sensors[i] = values_[i];
}

std::vector<std::pair<std::string, double>> StPlant::stats() const {
  std::vector<std::pair<std::string, double>> out;
  for (const auto& h : stats_) {
    const std::string& path = h.path;
    const size_t dot = path.rfind('.');
    out.emplace_back(dot == std::string::npos ? path : path.substr(dot + 1), st::read_real(runtime_->machine(), h));
  }
  out.emplace_back("plant_scans", static_cast<double>(scans_));
  return out;
}

}  // namespace plcfi::io

// The PLC program as an FMI 2.0 co-simulation FMU: the binary `plcfi export-fmu` packs.
// It is the engine itself (front end, VM, scan cycle, fault models) in a shared object:
// fmi2Instantiate compiles the sources the archive holds (resources/plcfi/), and each
// fmi2DoStep runs the scans of the program's tasks that fall into the step, at the
// program's own base tick, as `plcfi sim` does: inputs as the master set them, through the
// input overlay, the tasks, the output overlay; outputs are what reaches the plant.
// Fault parameters put a fault model of plcfi's on a port from a given time on, as a
// campaign injects it. Value references: see program_fmu.hpp. The FMU state can be saved
// and restored (canGetAndSetFMUstate).
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "common/file.hpp"
#include "engine.hpp"
#include "faults/fault_model.hpp"
#include "fmu/program_fmu.hpp"
#include "plant_model/fmu/fmi2.h"
#include "runtime/runtime.hpp"

namespace {

using namespace plcfi;

enum class State { Instantiated, Initialization, Stepping, Terminated, Error };

// The I/O image as the master exchanges it: inputs as last set, outputs as last delivered.
class HostBackend final : public rt::IoBackend {
 public:
  HostBackend(uint32_t in_size, uint32_t out_size) : in(in_size, 0), out(out_size, 0) {}
  const std::string& name() const override { return name_; }
  uint32_t input_extent() const override { return static_cast<uint32_t>(in.size()); }
  uint32_t output_extent() const override { return static_cast<uint32_t>(out.size()); }
  bool read(uint8_t* inputs, int64_t) override {
    std::memcpy(inputs, in.data(), in.size());
    return true;
  }
  bool write(const uint8_t* outputs, int64_t, int64_t) override {
    std::memcpy(out.data(), outputs, out.size());
    return true;
  }
  void reset(uint64_t) override { std::fill(out.begin(), out.end(), 0); }  // the master's inputs stay
  const std::string& last_error() const override { return error_; }

  std::vector<uint8_t> in, out;

 private:
  std::string name_ = "fmi2 master", error_;
};

struct PortFault {
  std::string text;  // the String parameter, "" for none
  double at_s = 0;   // the Real parameter
  faults::FaultSpec spec;
  bool armed = false, injected = false;
};

struct Instance;
void log(const Instance* in, fmi2Status status, const char* fmt, ...) __attribute__((format(printf, 3, 4)));

// Injects each armed fault at the first scan at or after its time, as the campaign
// driver does: the baseline is the raw input or the command last delivered.
class FaultHook final : public rt::ScanHooks {
 public:
  explicit FaultHook(Instance* in) : in_(in) {}
  void before_scan(rt::Runtime& r) override;

 private:
  Instance* in_;
};

struct Instance {
  std::string name;
  fmi2CallbackFunctions cb{};
  bool logging = false;
  fmu::Manifest manifest;
  std::unique_ptr<st::Build> build;
  std::vector<rt::ImageRef> refs;  // per port
  std::unique_ptr<HostBackend> backend;
  std::unique_ptr<rt::Runtime> runtime;
  FaultHook hook{this};
  std::vector<PortFault> faults;  // per port
  fmi2Integer seed = 1;
  State state = State::Instantiated;
  int64_t time_ns = 0;  // the next communication point
  bool trap_logged = false;
};

void log(const Instance* in, fmi2Status status, const char* fmt, ...) {
  if (!in || !in->cb.logger) return;
  char text[2048];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(text, sizeof text, fmt, ap);
  va_end(ap);
  in->cb.logger(in->cb.componentEnvironment, in->name.c_str(), status,
                status >= fmi2Error ? "logStatusError" : status == fmi2Warning ? "logStatusWarning" : "logAll", "%s",
                text);
}

void FaultHook::before_scan(rt::Runtime& r) {
  for (size_t i = 0; i < in_->faults.size(); ++i) {
    PortFault& f = in_->faults[i];
    if (!f.armed || f.injected || static_cast<double>(r.now()) < f.at_s * 1e9 - 0.5) continue;
    const rt::ImageRef& ref = in_->refs[i];
    faults::InjectionContext ctx;
    ctx.ref = ref;
    ctx.baseline = ref.area == 'I' ? ref.get(r.raw_inputs()) : ref.get(r.delivered_outputs());
    ctx.inject_ns = r.now();
    ctx.tick_ns = r.schedule().tick_ns();
    ctx.seed = static_cast<uint64_t>(in_->seed);
    std::string err;
    auto rule = faults::make_rule(f.spec, ctx, &err);
    f.injected = true;
    if (!rule) {  // checked at fmi2ExitInitializationMode already
      log(in_, fmi2Error, "fault.%s: %s", in_->manifest.ports[i].path.c_str(), err.c_str());
      continue;
    }
    if (ref.area == 'I') {
      r.input_overlay().add(std::move(rule));
      r.reapply_input_overlay();
    } else {
      r.output_overlay().add(std::move(rule));
    }
    if (in_->logging)
      log(in_, fmi2OK, "t = %.6f s: fault '%s' on %s (%s)", static_cast<double>(r.now()) * 1e-9, f.spec.text.c_str(),
          in_->manifest.ports[i].path.c_str(), in_->manifest.ports[i].address.c_str());
  }
}

Instance* as(fmi2Component c) { return static_cast<Instance*>(c); }

fmi2Status error(Instance* in, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
fmi2Status error(Instance* in, const char* fmt, ...) {
  char text[2048];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(text, sizeof text, fmt, ap);
  va_end(ap);
  log(in, fmi2Error, "%s", text);
  return fmi2Error;
}

// No exception may cross the C interface: a throw becomes fmi2Fatal with its message.
template <class F>
fmi2Status guarded(fmi2Component c, const char* function, F&& f) {
  Instance* in = as(c);
  if (!in) return fmi2Error;
  try {
    return f(in);
  } catch (const std::exception& e) {
    log(in, fmi2Fatal, "%s: %s", function, e.what());
  } catch (...) {
    log(in, fmi2Fatal, "%s: an unknown exception", function);
  }
  in->state = State::Error;
  return fmi2Fatal;
}

// A function of a capability the description does not claim.
fmi2Status unsupported(fmi2Component c, const char* function, const char* why) {
  log(as(c), fmi2Error, "%s: not supported (%s)", function, why);
  return fmi2Error;
}

bool before_init(const Instance* in) { return in->state == State::Instantiated || in->state == State::Initialization; }

// "file:///a/b%20c/resources" -> "/a/b c/resources"; false for other schemes.
bool uri_to_path(const std::string& uri, std::string* path) {
  std::string p;
  if (uri.rfind("file://", 0) == 0) {
    p = uri.substr(7);
    if (!p.empty() && p[0] != '/') {  // file://host/path: only the local host
      const size_t slash = p.find('/');
      if (slash == std::string::npos || p.substr(0, slash) != "localhost") return false;
      p = p.substr(slash);
    }
  } else if (uri.rfind("file:", 0) == 0) {
    p = uri.substr(5);
  } else {
    return false;
  }
  std::string out;
  for (size_t i = 0; i < p.size(); ++i) {
    if (p[i] == '%' && i + 2 < p.size() && std::isxdigit(static_cast<unsigned char>(p[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(p[i + 2]))) {
      out += static_cast<char>(std::stoi(p.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += p[i];
    }
  }
  while (out.size() > 1 && out.back() == '/') out.pop_back();
  *path = out;
  return !out.empty();
}

// Compiles the archive's sources and checks that they give the manifest's ports.
bool load(Instance* in, const std::string& resources, const char* guid) {
  const std::string dir = resources + "/plcfi";
  std::string text, err;
  if (!common::read_file(dir + "/program.txt", 1 << 20, &text, &err)) {
    log(in, fmi2Error, "%s", err.c_str());
    return false;
  }
  if (!fmu::read_manifest(text, &in->manifest, &err)) {
    log(in, fmi2Error, "%s/program.txt: %s", dir.c_str(), err.c_str());
    return false;
  }
  const fmu::Manifest& m = in->manifest;
  if (!guid || m.guid != guid) {
    log(in, fmi2Error, "wrong GUID %s (the archive's resources are for %s)", guid ? guid : "(null)", m.guid.c_str());
    return false;
  }
  st::CompileOptions opt;
  opt.dialect = m.dialect;
  opt.strict = m.strict;
  opt.warnings = false;
  for (const auto& f : m.libraries) opt.library_files.push_back(dir + "/" + f);
  std::vector<std::string> sources;
  for (const auto& f : m.sources) sources.push_back(dir + "/" + f);
  in->build = st::build_files(sources, opt);
  if (!in->build->ok()) {
    std::string msg;
    for (const auto& e : in->build->io_errors) msg += e + "\n";
    msg += in->build->diags.render_all();
    log(in, fmi2Error, "the program in the FMU's resources does not compile:\n%s", msg.c_str());
    return false;
  }
  const st::Application& app = *in->build->app;
  rt::Schedule sched;
  if (!fmu::make_schedule(app, m, &sched, &err)) {
    log(in, fmi2Error, "%s", err.c_str());
    return false;
  }
  std::vector<fmu::Port> ports;
  if (!fmu::list_ports(app, &ports, &err)) {
    log(in, fmi2Error, "%s", err.c_str());
    return false;
  }
  bool same = sched.tick_ns() == m.tick_ns && ports.size() == m.ports.size();
  for (size_t i = 0; same && i < ports.size(); ++i)
    same = ports[i].path == m.ports[i].path && ports[i].input == m.ports[i].input && ports[i].fmi == m.ports[i].fmi;
  if (!same) {
    log(in, fmi2Error, "the program in the FMU's resources no longer matches its model description (ports or cycle)");
    return false;
  }
  uint32_t in_extent = 0, out_extent = 0;
  for (const auto& p : m.ports) {
    rt::ImageRef ref;
    if (!rt::parse_image_ref(app, p.path, &ref, &err)) {
      log(in, fmi2Error, "%s", err.c_str());
      return false;
    }
    (ref.area == 'I' ? in_extent : out_extent) =
        std::max(ref.area == 'I' ? in_extent : out_extent, ref.offset + ref.size);
    in->refs.push_back(std::move(ref));
  }
  in->backend = std::make_unique<HostBackend>(in_extent, out_extent);
  in->runtime = std::make_unique<rt::Runtime>(app, std::move(sched), in->backend.get());
  in->runtime->add_hooks(&in->hook);
  in->faults.assign(m.ports.size(), PortFault{});
  in->runtime->cold_restart(static_cast<uint64_t>(in->seed));
  return true;
}

// Back to the state after fmi2Instantiate: inputs and parameters to their start values.
void reset(Instance* in) {
  std::fill(in->backend->in.begin(), in->backend->in.end(), 0);
  in->faults.assign(in->manifest.ports.size(), PortFault{});
  in->seed = 1;
  in->runtime->input_overlay().clear();
  in->runtime->output_overlay().clear();
  in->runtime->cold_restart(1);
  in->time_ns = 0;
  in->trap_logged = false;
  in->state = State::Instantiated;
}

// The port of a value reference, if it has this FMI type (and is an input when `set`).
const fmu::Port* port_of(Instance* in, fmi2ValueReference vr, fmu::FmiType t, bool set) {
  if (vr >= in->manifest.ports.size()) return nullptr;
  const fmu::Port& p = in->manifest.ports[vr];
  if (p.fmi != t || (set && !p.input)) return nullptr;
  return &p;
}

const uint8_t* area_of(const Instance* in, const rt::ImageRef& ref) {
  return ref.area == 'I' ? in->backend->in.data() : in->runtime->delivered_outputs();
}

double get_real(const Instance* in, const rt::ImageRef& ref) {
  const uint8_t* p = area_of(in, ref) + ref.offset;
  if (ref.type->kind == st::TypeKind::Real) {
    float f;
    std::memcpy(&f, p, 4);
    return f;
  }
  if (ref.type->kind == st::TypeKind::LReal) {
    double d;
    std::memcpy(&d, p, 8);
    return d;
  }
  return static_cast<double>(ref.get(area_of(in, ref)));  // UDINT, DWORD
}

// The range of values an integer port's type holds.
void int_range(const st::Type* t, int64_t* lo, int64_t* hi) {
  if (t->ranged) {
    *lo = t->lo;
    *hi = t->hi;
    return;
  }
  const uint32_t w = t->bit_width();
  if (t->is_signed()) {
    *lo = -(int64_t{1} << (w - 1));
    *hi = (int64_t{1} << (w - 1)) - 1;
  } else {
    *lo = 0;
    *hi = (int64_t{1} << w) - 1;
  }
}

}  // namespace

extern "C" {

FMI2_EXPORT const char* fmi2GetVersion(void) { return "2.0"; }
FMI2_EXPORT const char* fmi2GetTypesPlatform(void) { return "default"; }

FMI2_EXPORT fmi2Component fmi2Instantiate(fmi2String instance_name, fmi2Type type, fmi2String guid,
                                          fmi2String resource_location, const fmi2CallbackFunctions* functions,
                                          fmi2Boolean, fmi2Boolean logging_on) {
  auto* in = new (std::nothrow) Instance();
  if (!in) return nullptr;
  if (functions) in->cb = *functions;
  in->name = instance_name ? instance_name : "";
  in->logging = logging_on != fmi2False;
  bool ok = false;
  try {
    std::string dir;
    if (type != fmi2CoSimulation)
      log(in, fmi2Error, "this FMU supports co-simulation only");
    else if (!resource_location || !uri_to_path(resource_location, &dir))
      log(in, fmi2Error, "fmuResourceLocation '%s' is not a file: URI", resource_location ? resource_location : "(null)");
    else
      ok = load(in, dir, guid);
  } catch (const std::exception& e) {
    log(in, fmi2Fatal, "fmi2Instantiate: %s", e.what());
  }
  if (!ok) {
    delete in;
    return nullptr;
  }
  return in;
}

FMI2_EXPORT void fmi2FreeInstance(fmi2Component c) { delete as(c); }

FMI2_EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t, const fmi2String[]) {
  if (!c) return fmi2Error;
  as(c)->logging = on != fmi2False;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean, fmi2Real, fmi2Real start, fmi2Boolean,
                                           fmi2Real) {
  return guarded(c, "fmi2SetupExperiment", [&](Instance* in) {
    if (in->state != State::Instantiated) return error(in, "fmi2SetupExperiment: only after fmi2Instantiate or fmi2Reset");
    if (start != 0.0) return error(in, "the PLC program starts at time 0, not %g", start);
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
  return guarded(c, "fmi2EnterInitializationMode", [&](Instance* in) {
    if (in->state != State::Instantiated) return error(in, "fmi2EnterInitializationMode: not after fmi2Instantiate");
    in->state = State::Initialization;
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
  return guarded(c, "fmi2ExitInitializationMode", [&](Instance* in) {
    if (in->state != State::Initialization) return error(in, "fmi2ExitInitializationMode: not in initialization mode");
    // The fault parameters are known now: each must be a fault model that fits its port.
    for (size_t i = 0; i < in->faults.size(); ++i) {
      PortFault& f = in->faults[i];
      const fmu::Port& p = in->manifest.ports[i];
      f.armed = f.injected = false;
      if (f.text.empty()) continue;
      std::string err;
      uint32_t col = 0;
      if (!faults::parse_fault(f.text, &f.spec, &err, &col))
        return error(in, "fault.%s = '%s': column %u: %s", p.path.c_str(), f.text.c_str(), col + 1, err.c_str());
      if (!(f.at_s >= 0.0) || !std::isfinite(f.at_s))
        return error(in, "fault_at.%s = %g: the injection time must be 0 or later (s)", p.path.c_str(), f.at_s);
      faults::InjectionContext ctx;
      ctx.ref = in->refs[i];
      ctx.tick_ns = in->runtime->schedule().tick_ns();
      if (!faults::make_rule(f.spec, ctx, &err)) return error(in, "fault.%s: %s", p.path.c_str(), err.c_str());
      f.armed = true;
    }
    in->runtime->input_overlay().clear();
    in->runtime->output_overlay().clear();
    in->runtime->cold_restart(static_cast<uint64_t>(in->seed));
    in->time_ns = 0;
    in->trap_logged = false;
    in->state = State::Stepping;
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2Terminate(fmi2Component c) {
  if (!c) return fmi2Error;
  as(c)->state = State::Terminated;
  return fmi2OK;
}

FMI2_EXPORT fmi2Status fmi2Reset(fmi2Component c) {
  return guarded(c, "fmi2Reset", [&](Instance* in) {
    reset(in);
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
  return guarded(c, "fmi2GetReal", [&](Instance* in) {
    for (size_t k = 0; k < n; ++k) {
      if (vr[k] >= fmu::kFaultAtRef && vr[k] - fmu::kFaultAtRef < in->faults.size()) {
        value[k] = in->faults[vr[k] - fmu::kFaultAtRef].at_s;
        continue;
      }
      if (!port_of(in, vr[k], fmu::FmiType::Real, false)) return error(in, "fmi2GetReal: no Real variable %u", vr[k]);
      value[k] = get_real(in, in->refs[vr[k]]);
    }
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
  return guarded(c, "fmi2SetReal", [&](Instance* in) {
    for (size_t k = 0; k < n; ++k) {
      if (vr[k] >= fmu::kFaultAtRef && vr[k] - fmu::kFaultAtRef < in->faults.size()) {
        if (!before_init(in))
          return error(in, "fault_at.%s is a fixed parameter: set it before fmi2ExitInitializationMode",
                       in->manifest.ports[vr[k] - fmu::kFaultAtRef].path.c_str());
        in->faults[vr[k] - fmu::kFaultAtRef].at_s = value[k];
        continue;
      }
      const fmu::Port* p = port_of(in, vr[k], fmu::FmiType::Real, true);
      if (!p) return error(in, "fmi2SetReal: no Real input %u", vr[k]);
      const rt::ImageRef& ref = in->refs[vr[k]];
      uint8_t* at = in->backend->in.data() + ref.offset;
      const double v = value[k];
      if (ref.type->kind == st::TypeKind::Real) {
        if (std::isfinite(v) && std::fabs(v) > std::numeric_limits<float>::max())
          return error(in, "%s: %g is beyond the range of REAL", p->path.c_str(), v);
        const auto f = static_cast<float>(v);
        std::memcpy(at, &f, 4);
      } else if (ref.type->kind == st::TypeKind::LReal) {
        std::memcpy(at, &v, 8);
      } else {  // UDINT, DWORD: whole numbers 0 .. 2^32 - 1
        if (!(v >= 0.0 && v <= 4294967295.0) || v != std::floor(v))
          return error(in, "%s: %g is not a value of %s (a whole number 0..4294967295)", p->path.c_str(), v,
                       p->type.c_str());
        ref.set(in->backend->in.data(), static_cast<int64_t>(v));
      }
    }
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
  return guarded(c, "fmi2GetInteger", [&](Instance* in) {
    for (size_t k = 0; k < n; ++k) {
      if (vr[k] == fmu::kSeedRef) {
        value[k] = in->seed;
        continue;
      }
      if (!port_of(in, vr[k], fmu::FmiType::Integer, false))
        return error(in, "fmi2GetInteger: no Integer variable %u", vr[k]);
      const rt::ImageRef& ref = in->refs[vr[k]];
      value[k] = static_cast<fmi2Integer>(ref.get(area_of(in, ref)));
    }
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                      const fmi2Integer value[]) {
  return guarded(c, "fmi2SetInteger", [&](Instance* in) {
    for (size_t k = 0; k < n; ++k) {
      if (vr[k] == fmu::kSeedRef) {
        if (!before_init(in)) return error(in, "seed is a fixed parameter: set it before fmi2ExitInitializationMode");
        in->seed = value[k];
        continue;
      }
      const fmu::Port* p = port_of(in, vr[k], fmu::FmiType::Integer, true);
      if (!p) return error(in, "fmi2SetInteger: no Integer input %u", vr[k]);
      const rt::ImageRef& ref = in->refs[vr[k]];
      int64_t lo = 0, hi = 0;
      int_range(ref.type, &lo, &hi);
      if (value[k] < lo || value[k] > hi)
        return error(in, "%s: %d is not a value of %s (%lld..%lld)", p->path.c_str(), value[k], p->type.c_str(),
                     static_cast<long long>(lo), static_cast<long long>(hi));
      ref.set(in->backend->in.data(), value[k]);
    }
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
  return guarded(c, "fmi2GetBoolean", [&](Instance* in) {
    for (size_t k = 0; k < n; ++k) {
      if (!port_of(in, vr[k], fmu::FmiType::Boolean, false))
        return error(in, "fmi2GetBoolean: no Boolean variable %u", vr[k]);
      const rt::ImageRef& ref = in->refs[vr[k]];
      value[k] = ref.get(area_of(in, ref)) != 0 ? fmi2True : fmi2False;
    }
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                      const fmi2Boolean value[]) {
  return guarded(c, "fmi2SetBoolean", [&](Instance* in) {
    for (size_t k = 0; k < n; ++k) {
      if (!port_of(in, vr[k], fmu::FmiType::Boolean, true)) return error(in, "fmi2SetBoolean: no Boolean input %u", vr[k]);
      in->refs[vr[k]].set(in->backend->in.data(), value[k] != fmi2False ? 1 : 0);
    }
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
  return guarded(c, "fmi2GetString", [&](Instance* in) {
    for (size_t k = 0; k < n; ++k) {
      if (vr[k] < fmu::kFaultRef || vr[k] - fmu::kFaultRef >= in->faults.size())
        return error(in, "fmi2GetString: no String variable %u", vr[k]);
      value[k] = in->faults[vr[k] - fmu::kFaultRef].text.c_str();
    }
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                     const fmi2String value[]) {
  return guarded(c, "fmi2SetString", [&](Instance* in) {
    for (size_t k = 0; k < n; ++k) {
      if (vr[k] < fmu::kFaultRef || vr[k] - fmu::kFaultRef >= in->faults.size())
        return error(in, "fmi2SetString: no String variable %u", vr[k]);
      const size_t i = vr[k] - fmu::kFaultRef;
      if (!before_init(in))
        return error(in, "fault.%s is a fixed parameter: set it before fmi2ExitInitializationMode",
                     in->manifest.ports[i].path.c_str());
      in->faults[i].text = value[k] ? value[k] : "";
    }
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean) {
  return guarded(c, "fmi2DoStep", [&](Instance* in) {
    if (in->state != State::Stepping) return error(in, "fmi2DoStep: only after fmi2ExitInitializationMode");
    const double now = static_cast<double>(in->time_ns) * 1e-9;
    if (!(h > 0.0) || !std::isfinite(t + h) || std::fabs(t - now) > 1e-6)
      return error(in, "fmi2DoStep(t = %g s, h = %g s): the program is at t = %g s", t, h, now);
    const auto end = static_cast<int64_t>(std::llround((t + h) * 1e9));
    fmi2Status status = fmi2OK;
    rt::Runtime& r = *in->runtime;
    while (r.now() < end) {
      if (r.scan() == rt::ScanStatus::Trapped && !in->trap_logged) {
        // As a PLC does: the program stops, its outputs go to the safe state.
        log(in, fmi2Warning, "t = %.6f s: the program stopped: %s; its outputs are in the safe state from now on",
            static_cast<double>(r.now()) * 1e-9 - static_cast<double>(r.schedule().tick_ns()) * 1e-9,
            r.stop_reason().c_str());
        in->trap_logged = true;
        status = fmi2Warning;
      }
    }
    in->time_ns = end;
    return status;
  });
}

FMI2_EXPORT fmi2Status fmi2CancelStep(fmi2Component c) {
  log(as(c), fmi2Error, "fmi2CancelStep: not supported (fmi2DoStep always completes)");
  return fmi2Error;
}

FMI2_EXPORT fmi2Status fmi2GetStatus(fmi2Component, fmi2StatusKind, fmi2Status*) { return fmi2Discard; }
FMI2_EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, fmi2StatusKind kind, fmi2Real* value) {
  if (!c || kind != fmi2LastSuccessfulTime) return fmi2Discard;
  *value = static_cast<double>(as(c)->time_ns) * 1e-9;
  return fmi2OK;
}
FMI2_EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component, fmi2StatusKind, fmi2Integer*) { return fmi2Discard; }
FMI2_EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, fmi2StatusKind kind, fmi2Boolean* value) {
  if (!c || kind != fmi2Terminated) return fmi2Discard;
  *value = fmi2False;
  return fmi2OK;
}
FMI2_EXPORT fmi2Status fmi2GetStringStatus(fmi2Component, fmi2StatusKind, fmi2String*) { return fmi2Discard; }

// ---- FMU state: a copy of the scan's state (program memory, clock, image layers, the
// fault overlays with their rules' state) and of the instance's own, so a master can go
// back to an earlier communication point. Serialization and derivatives are not offered;
// the description says so and the functions refuse with a log message.

namespace {
struct SavedState {
  rt::Runtime::State runtime;
  std::vector<uint8_t> in, out;
  std::vector<PortFault> faults;
  fmi2Integer seed = 1;
  State state = State::Instantiated;
  int64_t time_ns = 0;
  bool trap_logged = false;
};
}  // namespace

FMI2_EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* state) {
  return guarded(c, "fmi2GetFMUstate", [&](Instance* in) {
    if (!state) return error(in, "fmi2GetFMUstate: no place for the state (NULL)");
    auto saved = std::make_unique<SavedState>(SavedState{in->runtime->save_state(), in->backend->in, in->backend->out,
                                                         in->faults, in->seed, in->state, in->time_ns, in->trap_logged});
    delete static_cast<SavedState*>(*state);  // an earlier state handed back to be overwritten
    *state = saved.release();
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
  return guarded(c, "fmi2SetFMUstate", [&](Instance* in) {
    if (!state) return error(in, "fmi2SetFMUstate: no state (NULL)");
    const auto* s = static_cast<const SavedState*>(state);
    in->runtime->restore_state(s->runtime);
    in->backend->in = s->in;
    in->backend->out = s->out;
    in->faults = s->faults;
    in->seed = s->seed;
    in->state = s->state;
    in->time_ns = s->time_ns;
    in->trap_logged = s->trap_logged;
    return fmi2OK;
  });
}

FMI2_EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* state) {
  if (!c || !state) return fmi2Error;
  delete static_cast<SavedState*>(*state);
  *state = nullptr;
  return fmi2OK;
}

#include "plant_model/fmu/export/fmi2_refusals.inc"

}  // extern "C"

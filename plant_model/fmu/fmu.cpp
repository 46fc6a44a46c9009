// FMU archive (libzip), binary (dlopen) and the checked FMI 2.0 call sequence, with a
// crash guard around every call into the FMU's code.
#include "plant_model/fmu/fmu.hpp"

#include <dlfcn.h>
#include <pthread.h>
#include <setjmp.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zip.h>

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <string_view>

#include <fmt/format.h>

#include "common/duration.hpp"
#include "common/yaml.hpp"

namespace plcfi::plant::fmu {

namespace fs = std::filesystem;

namespace {

// Limits of what an archive may unpack to: far above any real plant model, low enough that
// a zip bomb stops early.
constexpr size_t kMaxDescriptionBytes = 16u << 20;
constexpr uint64_t kMaxUnpackedBytes = 1ull << 30;
constexpr zip_int64_t kMaxEntries = 100'000;

[[noreturn]] void input_error(const std::string& message) { throw common::InputError(message); }

// ---- crash guard ----
// A process-wide handler for the signals a crashing FMU raises, installed once when the
// first FMU is instantiated. Inside a guarded call it jumps back to the call site; outside
// one it puts the previous handler back and returns, so the signal is raised again and
// handled as before (the default action, or a sanitizer's report).
constexpr int kCrashSignals[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT};
struct sigaction g_previous[NSIG];
thread_local sigjmp_buf* t_guard = nullptr;
thread_local volatile sig_atomic_t t_signal = 0;
// The instance whose call is running: what the FMU allocates through the callbacks is
// recorded there, so that a crashed instance (never called again, so never freed by the
// FMU) does not leak.
thread_local FmuInstance* t_current = nullptr;
std::mutex g_alloc_mutex;
std::unordered_map<void*, const FmuInstance*> g_allocations;  // live block -> the instance it was made in

// ---- hang watchdog ----
// A thread that looks every 50 ms at the guarded call in progress (one per process: plcfi
// drives its plant from one thread). A call that has not returned within its limit gets
// kWatchdogSignal, whose handler jumps out of it like out of a crash. Each arming of the
// guard has a generation: the handler acts only on the generation the watchdog fired at,
// so a signal that arrives just after the call returned (or in the next call) is ignored.
constexpr int kWatchdogSignal = SIGUSR2;
std::atomic<uint64_t> g_generation{0};   // of the current arming (odd: armed)
std::atomic<int64_t> g_armed_at{0};      // steady clock, ns
std::atomic<int64_t> g_limit_ns{0};
std::atomic<uint64_t> g_fired{0};        // the generation the watchdog signalled
pthread_t g_guarded_thread;

int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void watchdog_loop() {
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const uint64_t gen = g_generation.load(std::memory_order_acquire);
    if (!(gen & 1)) continue;  // no call in progress
    const int64_t at = g_armed_at.load(std::memory_order_acquire);
    const int64_t limit = g_limit_ns.load(std::memory_order_relaxed);
    if (g_generation.load(std::memory_order_acquire) != gen || limit <= 0 || steady_ns() - at < limit) continue;
    if (g_fired.exchange(gen) == gen) continue;  // signalled already
    pthread_kill(g_guarded_thread, kWatchdogSignal);
  }
}

void on_watchdog(int sig, siginfo_t*, void*) {
  sigjmp_buf* b = t_guard;
  if (!b || g_fired.load(std::memory_order_acquire) != g_generation.load(std::memory_order_acquire)) return;
  t_guard = nullptr;
  t_signal = sig;
  siglongjmp(*b, 1);
}

void on_crash(int sig, siginfo_t*, void*) {
  if (sigjmp_buf* b = t_guard) {
    t_guard = nullptr;
    t_signal = sig;
    siglongjmp(*b, 1);
  }
  sigaction(sig, &g_previous[sig], nullptr);
}

void install_crash_guard() {
  static std::once_flag once;
  std::call_once(once, [] {
    // A stack overflow inside the FMU needs a stack of its own to report.
    stack_t current{};
    if (sigaltstack(nullptr, &current) == 0 && (current.ss_flags & SS_DISABLE)) {
      static char alt[1 << 16];
      stack_t st{};
      st.ss_sp = alt;
      st.ss_size = sizeof alt;
      sigaltstack(&st, nullptr);
    }
    for (int sig : kCrashSignals) {
      struct sigaction sa {};
      sa.sa_sigaction = on_crash;
      sa.sa_flags = SA_SIGINFO | SA_NODEFER | SA_ONSTACK;
      sigemptyset(&sa.sa_mask);
      sigaction(sig, &sa, &g_previous[sig]);
    }
    struct sigaction wa {};
    wa.sa_sigaction = on_watchdog;
    wa.sa_flags = SA_SIGINFO | SA_NODEFER | SA_RESTART;
    sigemptyset(&wa.sa_mask);
    sigaction(kWatchdogSignal, &wa, nullptr);
    g_guarded_thread = pthread_self();
    std::thread(watchdog_loop).detach();
    std::atexit(FmuInstance::on_process_exit);
    std::at_quick_exit(FmuInstance::on_process_exit);
  });
}

const char* status_name(fmi2Status s) {
  switch (s) {
    case fmi2OK: return "fmi2OK";
    case fmi2Warning: return "fmi2Warning";
    case fmi2Discard: return "fmi2Discard";
    case fmi2Error: return "fmi2Error";
    case fmi2Fatal: return "fmi2Fatal";
    case fmi2Pending: return "fmi2Pending";
  }
  return "an unknown status";
}

// An entry name that stays inside the folder it is unpacked to.
bool safe_entry_name(std::string_view name) {
  if (name.empty() || name.front() == '/' || name.find('\\') != std::string_view::npos) return false;
  size_t start = 0;
  while (start <= name.size()) {
    size_t end = name.find('/', start);
    if (end == std::string_view::npos) end = name.size();
    if (name.substr(start, end - start) == "..") return false;
    start = end + 1;
  }
  return true;
}

std::string zip_message(zip_t* z) { return zip_error_strerror(zip_get_error(z)); }

// Percent-encodes a path for a file: URI (RFC 3986 unreserved characters and '/' stay).
std::string file_uri(const std::string& path) {
  std::string out = "file://";
  for (unsigned char c : path) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '.' || c == '_' || c == '~') out += static_cast<char>(c);
    else out += fmt::format("%{:02X}", c);
  }
  return out;
}

}  // namespace

// ---- FmuArchive ----

std::unique_ptr<FmuArchive> FmuArchive::open(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) input_error(fmt::format("{}: cannot open ({})", path, std::strerror(errno)));
  if (S_ISDIR(st.st_mode)) input_error(path + ": is a directory, not an .fmu archive");
  if (!S_ISREG(st.st_mode)) input_error(path + ": not a regular file (an .fmu archive is a zip file)");

  int zerr = 0;
  zip_t* z = zip_open(path.c_str(), ZIP_RDONLY, &zerr);
  if (!z) {
    zip_error_t e;
    zip_error_init_with_code(&e, zerr);
    std::string what = zip_error_strerror(&e);
    zip_error_fini(&e);
    input_error(fmt::format("{}: not an FMU (an FMU is a zip archive): {}", path, what));
  }
  std::unique_ptr<zip_t, void (*)(zip_t*)> zip(z, [](zip_t* p) { zip_discard(p); });

  std::unique_ptr<FmuArchive> a(new FmuArchive());
  a->path_ = path;
  const char* tmp = std::getenv("TMPDIR");
  std::string templ = std::string(tmp && *tmp ? tmp : "/tmp") + "/plcfi_fmu_XXXXXX";
  if (!mkdtemp(templ.data())) input_error(fmt::format("{}: cannot create a folder to unpack it in ({}): {}", path, templ, std::strerror(errno)));
  a->dir_ = templ;

  const zip_int64_t n = zip_get_num_entries(z, 0);
  if (n < 0 || n > kMaxEntries) input_error(fmt::format("{}: {} entries (at most {})", path, n, kMaxEntries));
  std::string description;
  bool has_description = false;
  uint64_t unpacked = 0;
  std::vector<std::string> binaries;  // "linux64/tank.so", ... for the message when ours is missing
  std::vector<char> buf(1 << 16);
  for (zip_int64_t i = 0; i < n; ++i) {
    const char* raw = zip_get_name(z, static_cast<zip_uint64_t>(i), ZIP_FL_ENC_GUESS);
    if (!raw) input_error(fmt::format("{}: entry {}: {}", path, i, zip_message(z)));
    std::string name = raw;
    while (name.rfind("./", 0) == 0) name.erase(0, 2);
    if (name.empty() || name.back() == '/') continue;  // a folder
    if (!safe_entry_name(name)) input_error(fmt::format("{}: entry '{}' points outside the archive", path, raw));
    const bool is_description = name == "modelDescription.xml";
    const bool is_binary = name.rfind("binaries/", 0) == 0;
    const bool is_resource = name.rfind("resources/", 0) == 0;
    if (is_binary) binaries.push_back(name.substr(9));
    if (!is_description && name.rfind("binaries/linux64/", 0) != 0 && !is_resource) continue;

    zip_file_t* f = zip_fopen_index(z, static_cast<zip_uint64_t>(i), 0);
    if (!f) input_error(fmt::format("{}: cannot read '{}': {}", path, name, zip_message(z)));
    std::unique_ptr<zip_file_t, int (*)(zip_file_t*)> file(f, zip_fclose);
    std::FILE* out = nullptr;
    if (!is_description) {
      fs::path target = fs::path(a->dir_) / name;
      std::error_code ec;
      fs::create_directories(target.parent_path(), ec);
      out = std::fopen(target.c_str(), "wb");
      if (!out) input_error(fmt::format("{}: cannot unpack '{}' to {}: {}", path, name, target.string(), std::strerror(errno)));
    }
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> closer(out, [](std::FILE* p) { return p ? std::fclose(p) : 0; });
    for (;;) {
      zip_int64_t got = zip_fread(f, buf.data(), buf.size());
      if (got < 0) input_error(fmt::format("{}: '{}' is damaged: {}", path, name, zip_error_strerror(zip_file_get_error(f))));
      if (got == 0) break;
      unpacked += static_cast<uint64_t>(got);
      if (unpacked > kMaxUnpackedBytes)
        input_error(fmt::format("{}: unpacks to more than {} MiB", path, kMaxUnpackedBytes >> 20));
      if (is_description) {
        if (description.size() + static_cast<size_t>(got) > kMaxDescriptionBytes)
          input_error(fmt::format("{}: modelDescription.xml is larger than {} MiB", path, kMaxDescriptionBytes >> 20));
        description.append(buf.data(), static_cast<size_t>(got));
      } else if (std::fwrite(buf.data(), 1, static_cast<size_t>(got), out) != static_cast<size_t>(got)) {
        input_error(fmt::format("{}: cannot unpack '{}': {}", path, name, std::strerror(errno)));
      }
    }
    if (is_description) has_description = true;
  }
  if (!has_description) input_error(path + ": no modelDescription.xml at the top of the archive (not an FMU?)");
  a->md_ = parse_model_description(description, path + "/modelDescription.xml");

  const std::string so = "binaries/linux64/" + a->md_.model_identifier + ".so";
  const fs::path lib = fs::path(a->dir_) / so;
  if (!fs::exists(lib)) {
    std::string have;
    for (const auto& b : binaries) have += (have.empty() ? "" : ", ") + b;
    input_error(fmt::format("{}: no binary for this platform: {} is missing ({})", path, so,
                            have.empty() ? "the archive has no binaries: a source-only FMU must be compiled first"
                                         : "the archive has " + have));
  }
  a->lib_ = dlopen(lib.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!a->lib_) {
    const char* e = dlerror();
    input_error(fmt::format("{}: cannot load {}: {}{}", path, so, e ? e : "unknown error",
                            " (unpacked to " + a->dir_ + "; a TMPDIR on a noexec file system cannot load libraries)"));
  }
  auto need = [&](auto** fn, const char* symbol, bool required) {
    dlerror();
    void* p = dlsym(a->lib_, symbol);
    if (!p && required)
      input_error(fmt::format("{}: {} does not define {}: not an FMI 2.0 co-simulation binary", path, so, symbol));
    *fn = reinterpret_cast<std::remove_pointer_t<decltype(fn)>>(p);
  };
  Api& f = a->api_;
  need(&f.get_version, "fmi2GetVersion", true);
  need(&f.instantiate, "fmi2Instantiate", true);
  need(&f.free_instance, "fmi2FreeInstance", true);
  need(&f.setup_experiment, "fmi2SetupExperiment", true);
  need(&f.enter_initialization_mode, "fmi2EnterInitializationMode", true);
  need(&f.exit_initialization_mode, "fmi2ExitInitializationMode", true);
  need(&f.terminate, "fmi2Terminate", true);
  need(&f.reset, "fmi2Reset", true);
  need(&f.get_real, "fmi2GetReal", true);
  need(&f.get_integer, "fmi2GetInteger", true);
  need(&f.get_boolean, "fmi2GetBoolean", true);
  need(&f.set_real, "fmi2SetReal", true);
  need(&f.set_integer, "fmi2SetInteger", true);
  need(&f.set_boolean, "fmi2SetBoolean", true);
  need(&f.do_step, "fmi2DoStep", true);
  need(&f.get_boolean_status, "fmi2GetBooleanStatus", false);
  need(&f.get_real_status, "fmi2GetRealStatus", false);
  const char* version = f.get_version();
  if (!version || std::string_view(version).rfind("2.", 0) != 0)
    input_error(fmt::format("{}: {}: fmi2GetVersion() says '{}', expected 2.0", path, so, version ? version : "(null)"));
  return a;
}

FmuArchive::~FmuArchive() {
  if (lib_) dlclose(lib_);
  if (!dir_.empty()) {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
}

std::string FmuArchive::resource_uri() const { return file_uri(dir_ + "/resources"); }

// ---- FmuInstance ----

FmuInstance::FmuInstance(const FmuArchive& fmu, const std::string& instance_name) : fmu_(fmu), name_(instance_name) {
  install_crash_guard();
  callbacks_.logger = &FmuInstance::logger;
  callbacks_.allocateMemory = &FmuInstance::allocate;
  callbacks_.freeMemory = &FmuInstance::release;
  callbacks_.stepFinished = nullptr;
  callbacks_.componentEnvironment = this;
  instantiate();
}

FmuInstance::~FmuInstance() {
  if (!c_ || dead_) {
    free_leftovers();
    return;
  }
  try {
    const auto& api = fmu_.api();
    if (initialized_) guarded("fmi2Terminate", [&] { return api.terminate(c_); });
    guarded("fmi2FreeInstance", [&] {
      api.free_instance(c_);
      return fmi2OK;
    });
  } catch (const FmuError&) {
    // A crash on the way out: the run's result stands; nothing more to call.
  }
  free_leftovers();
}

void FmuInstance::free_leftovers() {
  // What a freed instance still holds was lost by the FMU; what a crashed one holds can
  // never be freed by it.
  std::lock_guard<std::mutex> lock(g_alloc_mutex);
  for (auto it = g_allocations.begin(); it != g_allocations.end();) {
    if (it->second == this) {
      std::free(it->first);
      it = g_allocations.erase(it);
    } else {
      ++it;
    }
  }
}

void* FmuInstance::allocate(size_t count, size_t size) {
  void* p = std::calloc(count == 0 ? 1 : count, size == 0 ? 1 : size);
  if (p) {
    std::lock_guard<std::mutex> lock(g_alloc_mutex);
    g_allocations[p] = t_current;
  }
  return p;
}

void FmuInstance::release(void* p) {
  if (!p) return;
  {
    std::lock_guard<std::mutex> lock(g_alloc_mutex);
    g_allocations.erase(p);
  }
  std::free(p);
}

std::string FmuInstance::label() const { return "FMU " + fmu_.path(); }

void FmuInstance::logger(fmi2ComponentEnvironment env, fmi2String, fmi2Status status, fmi2String category,
                         fmi2String message, ...) {
  auto* self = static_cast<FmuInstance*>(env);
  if (!self || !message) return;
  char text[1024];
  va_list ap;
  va_start(ap, message);
  std::vsnprintf(text, sizeof text, message, ap);
  va_end(ap);
  // Warnings and worse are what a failure message quotes; chatter does not replace them.
  if (status >= fmi2Warning || self->last_message_.empty()) self->last_message_ = text;
  (void)category;
}

template <class F>
fmi2Status FmuInstance::guarded(std::string_view call, F&& f) {
  if (dead_) fail(call, "not called: the FMU crashed or failed fatally before");
  current_call_ = call;
  // Inside batch() the guard is armed already: the call only names itself.
  if (t_guard && t_current == this) return f();
  t_current = this;
  g_limit_ns.store(call_timeout_ns_, std::memory_order_relaxed);
  g_armed_at.store(steady_ns(), std::memory_order_release);
  g_generation.fetch_add(1, std::memory_order_acq_rel);  // odd: armed
  sigjmp_buf buf;
  // No signal mask saved (savemask 0): no system call per call. The handler runs with
  // SA_NODEFER, so nothing is left blocked when it jumps back here. After the jump only
  // members are read (nothing local that the call could have changed).
  if (sigsetjmp(buf, 0) != 0) crashed();
  t_guard = &buf;
  // Disarmed however f ends (a batch throws FmuError for a bad status): a crash later
  // must never jump into this frame once it is gone. (No object with a destructor lives
  // between here and the FMU's code: a jump back to sigsetjmp must skip none.)
  fmi2Status s = fmi2OK;
  try {
    s = f();
  } catch (...) {
    disarm();
    throw;
  }
  disarm();
  return s;
}

void FmuInstance::disarm() {
  t_guard = nullptr;
  t_current = nullptr;
  g_generation.fetch_add(1, std::memory_order_acq_rel);  // even: no call
}

void FmuInstance::batch(void (*fn)(void*), void* context) {
  guarded("fmi2 exchange", [&] {
    fn(context);
    return fmi2OK;
  });
}

void FmuInstance::crashed() {
  dead_ = true;
  disarm();
  const int sig = t_signal;
  if (sig == kWatchdogSignal)
    fail(current_call_, fmt::format("did not return within {} (the FMU hangs; call_timeout in the plant file sets the limit)",
                                    common::format_duration(call_timeout_ns_)));
  fail(current_call_, fmt::format("crashed inside the FMU ({}, signal {})", strsignal(sig), sig));
}

void FmuInstance::on_process_exit() {
  const FmuInstance* in = t_current;
  if (!t_guard || !in) return;  // an ordinary exit, not one from inside an FMU call
  std::string msg = fmt::format("plcfi: {}: {} ended the process (exit() inside the FMU); an FMU must return a status",
                                in->label(), in->current_call_);
  if (!in->last_message_.empty()) msg += fmt::format(" (the FMU logged: {})", in->last_message_);
  std::fflush(stdout);
  std::fprintf(stderr, "%s\n", msg.c_str());
  std::fflush(stderr);
  std::_Exit(2);
}

void FmuInstance::fail(std::string_view call, const std::string& what) {
  std::string msg = fmt::format("{}: {} {}", label(), call, what);
  if (!last_message_.empty()) msg += fmt::format(" (the FMU logged: {})", last_message_);
  throw FmuError(msg);
}

void FmuInstance::check(fmi2Status s, std::string_view call) {
  if (s == fmi2OK || s == fmi2Warning) return;
  if (s == fmi2Fatal) dead_ = true;
  fail(call, fmt::format("returned {}", status_name(s)));
}

void FmuInstance::instantiate() {
  const auto& api = fmu_.api();
  const auto& md = fmu_.description();
  const std::string uri = fmu_.resource_uri();
  fmi2Component c = nullptr;
  guarded("fmi2Instantiate", [&] {
    c = api.instantiate(name_.c_str(), fmi2CoSimulation, md.guid.c_str(), uri.c_str(), &callbacks_, fmi2False, fmi2False);
    return fmi2OK;
  });
  if (!c) fail("fmi2Instantiate", "returned no instance");
  c_ = c;
  initialized_ = false;
}

void FmuInstance::setup(double stop_time) {
  const auto& api = fmu_.api();
  const bool has_stop = stop_time > 0.0;
  fmi2Status s = guarded("fmi2SetupExperiment", [&] {
    return api.setup_experiment(c_, fmi2False, 0.0, 0.0, has_stop ? fmi2True : fmi2False, has_stop ? stop_time : 0.0);
  });
  if (s != fmi2OK && s != fmi2Warning && !has_stop) {
    if (s == fmi2Fatal) dead_ = true;
    fail("fmi2SetupExperiment", fmt::format("returned {} without a stop time; if the FMU needs one, set stop_time "
                                            "in the plant file",
                                            status_name(s)));
  }
  check(s, has_stop ? fmt::format("fmi2SetupExperiment(stop time {} s)", stop_time) : std::string("fmi2SetupExperiment"));
}

void FmuInstance::enter_exit_initialization() {
  const auto& api = fmu_.api();
  check(guarded("fmi2EnterInitializationMode", [&] { return api.enter_initialization_mode(c_); }),
        "fmi2EnterInitializationMode");
  check(guarded("fmi2ExitInitializationMode", [&] { return api.exit_initialization_mode(c_); }),
        "fmi2ExitInitializationMode");
  initialized_ = true;
}

void FmuInstance::reset() {
  const auto& api = fmu_.api();
  last_message_.clear();
  fmi2Status s = guarded("fmi2Reset", [&] { return api.reset(c_); });
  if (s == fmi2OK || s == fmi2Warning) {
    initialized_ = false;
    return;
  }
  // An FMU that cannot reset gets a fresh instance.
  if (s != fmi2Fatal) {
    if (initialized_) guarded("fmi2Terminate", [&] { return api.terminate(c_); });
    guarded("fmi2FreeInstance", [&] {
      api.free_instance(c_);
      return fmi2OK;
    });
  }
  c_ = nullptr;
  dead_ = false;
  instantiate();
}

void FmuInstance::set_real(const std::vector<fmi2ValueReference>& vr, const std::vector<fmi2Real>& v) {
  if (vr.empty()) return;
  check(guarded("fmi2SetReal", [&] { return fmu_.api().set_real(c_, vr.data(), vr.size(), v.data()); }), "fmi2SetReal");
}
void FmuInstance::set_integer(const std::vector<fmi2ValueReference>& vr, const std::vector<fmi2Integer>& v) {
  if (vr.empty()) return;
  check(guarded("fmi2SetInteger", [&] { return fmu_.api().set_integer(c_, vr.data(), vr.size(), v.data()); }),
        "fmi2SetInteger");
}
void FmuInstance::set_boolean(const std::vector<fmi2ValueReference>& vr, const std::vector<fmi2Boolean>& v) {
  if (vr.empty()) return;
  check(guarded("fmi2SetBoolean", [&] { return fmu_.api().set_boolean(c_, vr.data(), vr.size(), v.data()); }),
        "fmi2SetBoolean");
}
void FmuInstance::get_real(const std::vector<fmi2ValueReference>& vr, std::vector<fmi2Real>* v) {
  if (vr.empty()) return;
  check(guarded("fmi2GetReal", [&] { return fmu_.api().get_real(c_, vr.data(), vr.size(), v->data()); }), "fmi2GetReal");
}
void FmuInstance::get_integer(const std::vector<fmi2ValueReference>& vr, std::vector<fmi2Integer>* v) {
  if (vr.empty()) return;
  check(guarded("fmi2GetInteger", [&] { return fmu_.api().get_integer(c_, vr.data(), vr.size(), v->data()); }),
        "fmi2GetInteger");
}
void FmuInstance::get_boolean(const std::vector<fmi2ValueReference>& vr, std::vector<fmi2Boolean>* v) {
  if (vr.empty()) return;
  check(guarded("fmi2GetBoolean", [&] { return fmu_.api().get_boolean(c_, vr.data(), vr.size(), v->data()); }),
        "fmi2GetBoolean");
}

void FmuInstance::do_step(double t, double h) {
  const auto& api = fmu_.api();
  fmi2Status s = guarded("fmi2DoStep", [&] { return api.do_step(c_, t, h, fmi2True); });
  if (s == fmi2OK || s == fmi2Warning) return;
  const std::string call = fmt::format("fmi2DoStep(t = {:.6g} s, h = {:.6g} s)", t, h);
  if (s == fmi2Discard) {
    // The FMU could not complete the step: the end of its simulation, or a step it rejects.
    fmi2Boolean terminated = fmi2False;
    fmi2Real last = t;
    if (api.get_boolean_status)
      guarded("fmi2GetBooleanStatus", [&] { return api.get_boolean_status(c_, fmi2Terminated, &terminated); });
    if (api.get_real_status)
      guarded("fmi2GetRealStatus", [&] { return api.get_real_status(c_, fmi2LastSuccessfulTime, &last); });
    const auto& md = fmu_.description();
    if (terminated == fmi2True)
      fail(call, fmt::format("returned fmi2Discard: the FMU ended its simulation at t = {:.6g} s{}; this run needs "
                             "the plant for longer",
                             last, md.default_stop ? fmt::format(" (its DefaultExperiment stopTime is {:.6g} s)", *md.default_stop) : ""));
    fail(call, fmt::format("returned fmi2Discard: the FMU rejected the step (it reached t = {:.6g} s); a plant step "
                           "it accepts may be smaller: set step in the plant file",
                           last));
  }
  check(s, call);
}

}  // namespace plcfi::plant::fmu

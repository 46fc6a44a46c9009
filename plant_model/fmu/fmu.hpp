// An FMI 2.0 co-simulation FMU loaded from its .fmu archive: unpacked into a private
// temporary folder, its modelDescription.xml read, its linux64 binary opened, and one
// instance driven through the standard call sequence with every status checked.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "plant_model/fmu/fmi2.h"
#include "plant_model/fmu/model_description.hpp"

namespace plcfi::plant::fmu {

// A call into the FMU failed at run time (fmi2Error, fmi2Fatal, a crash, the end of its
// simulation): what() names the FMU, the call, the time and the FMU's last log message.
// The run cannot go on with a plant in an unknown state; the command reports it and
// exits with status 2.
class FmuError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The unpacked archive and the opened library. Not copyable; one per .fmu file.
class FmuArchive {
 public:
  // Unpacks `path` and opens its binary. Throws common::InputError with a precise message
  // ("PATH: ...", or "PATH/modelDescription.xml:LINE:COL: ...") when the archive, the
  // description or the binary is unusable.
  static std::unique_ptr<FmuArchive> open(const std::string& path);
  ~FmuArchive();
  FmuArchive(const FmuArchive&) = delete;
  FmuArchive& operator=(const FmuArchive&) = delete;

  const std::string& path() const { return path_; }
  const ModelDescription& description() const { return md_; }
  // "file:///tmp/.../resources/": the fmuResourceLocation of fmi2Instantiate.
  std::string resource_uri() const;

  // The FMU's functions (all required ones resolved at open()).
  struct Api {
    fmi2GetVersionTYPE* get_version = nullptr;
    fmi2InstantiateTYPE* instantiate = nullptr;
    fmi2FreeInstanceTYPE* free_instance = nullptr;
    fmi2SetupExperimentTYPE* setup_experiment = nullptr;
    fmi2EnterInitializationModeTYPE* enter_initialization_mode = nullptr;
    fmi2ExitInitializationModeTYPE* exit_initialization_mode = nullptr;
    fmi2TerminateTYPE* terminate = nullptr;
    fmi2ResetTYPE* reset = nullptr;
    fmi2GetRealTYPE* get_real = nullptr;
    fmi2GetIntegerTYPE* get_integer = nullptr;
    fmi2GetBooleanTYPE* get_boolean = nullptr;
    fmi2SetRealTYPE* set_real = nullptr;
    fmi2SetIntegerTYPE* set_integer = nullptr;
    fmi2SetBooleanTYPE* set_boolean = nullptr;
    fmi2DoStepTYPE* do_step = nullptr;
    fmi2GetBooleanStatusTYPE* get_boolean_status = nullptr;  // optional
    fmi2GetRealStatusTYPE* get_real_status = nullptr;        // optional
  };
  const Api& api() const { return api_; }

 private:
  FmuArchive() = default;
  std::string path_, dir_;
  ModelDescription md_;
  void* lib_ = nullptr;
  Api api_;
};

// One instance of an FMU. Every call checks its status: fmi2OK and fmi2Warning go on,
// anything else throws FmuError (fmi2Discard from DoStep is reported with the FMU's
// explanation: the end of its simulation, or a step it rejected). A crash inside the FMU
// (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT) during a call is caught and reported as an
// FmuError too; the instance is dead afterwards and is never called again. An FMU that
// ends the process (exit, quick_exit) during a call makes plcfi print the FMU and the call
// and exit with status 2, whatever status the FMU gave.
class FmuInstance {
 public:
  // fmi2Instantiate (co-simulation, not visible, logging off).
  FmuInstance(const FmuArchive& fmu, const std::string& instance_name);
  ~FmuInstance();
  FmuInstance(const FmuInstance&) = delete;
  FmuInstance& operator=(const FmuInstance&) = delete;

  // The set-up sequence up to the first step: SetupExperiment(start 0, stop if > 0),
  // then `set_parameters` (called between Instantiate/Reset and EnterInitializationMode),
  // EnterInitializationMode, ExitInitializationMode.
  template <class F>
  void initialize(double stop_time, F&& set_parameters) {
    setup(stop_time);
    set_parameters();
    enter_exit_initialization();
  }
  // fmi2Reset, back to the instantiated state (a second Instantiate if Reset fails).
  void reset();

  void set_real(const std::vector<fmi2ValueReference>& vr, const std::vector<fmi2Real>& v);
  void set_integer(const std::vector<fmi2ValueReference>& vr, const std::vector<fmi2Integer>& v);
  void set_boolean(const std::vector<fmi2ValueReference>& vr, const std::vector<fmi2Boolean>& v);
  void get_real(const std::vector<fmi2ValueReference>& vr, std::vector<fmi2Real>* v);
  void get_integer(const std::vector<fmi2ValueReference>& vr, std::vector<fmi2Integer>* v);
  void get_boolean(const std::vector<fmi2ValueReference>& vr, std::vector<fmi2Boolean>* v);
  // fmi2DoStep(t, h).
  void do_step(double t, double h);
  // Runs fn(context), a sequence of the calls above, under one arming of the crash guard
  // (the per-step exchange of a plant: sets, steps and gets at the cost of one).
  void batch(void (*fn)(void*), void* context);

  // How long one call (or one batch) may take before it counts as a hang and is broken
  // off as an FmuError (the instance is dead then). 0: no limit.
  void set_call_timeout(int64_t ns) { call_timeout_ns_ = ns; }

  // The last message the FMU logged (its logger callback), or "".
  const std::string& last_message() const { return last_message_; }
  // What messages name this FMU by: "FMU tank.fmu".
  std::string label() const;

  // Registered with atexit and at_quick_exit by the crash guard (not for callers): the
  // process ending inside a guarded call (the FMU called exit) is reported with the FMU
  // and the call, and plcfi exits with status 2 instead.
  static void on_process_exit();

 private:
  void setup(double stop_time);
  void enter_exit_initialization();
  void instantiate();
  // Checks a status; throws FmuError for fmi2Error/fmi2Fatal/fmi2Discard/fmi2Pending.
  void check(fmi2Status s, std::string_view call);
  // Runs f() with the crash guard armed; a crash becomes an FmuError naming `call` (a
  // string that outlives the call).
  template <class F>
  fmi2Status guarded(std::string_view call, F&& f);
  [[noreturn]] void crashed();
  static void disarm();
  [[noreturn]] void fail(std::string_view call, const std::string& what);

  static void* allocate(size_t count, size_t size);
  static void release(void* p);
  void free_leftovers();
  static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status, fmi2String category,
                     fmi2String message, ...);

  const FmuArchive& fmu_;
  std::string name_;
  fmi2CallbackFunctions callbacks_{};
  fmi2Component c_ = nullptr;
  bool dead_ = false;         // crashed or fatal: never called again
  bool initialized_ = false;  // past ExitInitializationMode: Terminate before Free
  std::string last_message_;
  std::string_view current_call_;
  int64_t call_timeout_ns_ = 10'000'000'000;
};

}  // namespace plcfi::plant::fmu

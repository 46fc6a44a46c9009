// The plcfi subcommands. Each takes the arguments after its name and returns the exit status.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "runtime/realtime.hpp"
#include "runtime/schedule.hpp"
#include "vm/program.hpp"
#include "native/native.hpp"
#include "vm/vm.hpp"

namespace plcfi::cli {

int cmd_check(const std::vector<std::string>& args);
int cmd_run(const std::vector<std::string>& args);
int cmd_test(const std::vector<std::string>& args);
int cmd_disasm(const std::vector<std::string>& args);
int cmd_sim(const std::vector<std::string>& args);
int cmd_edtl(const std::vector<std::string>& args);
int cmd_generate(const std::vector<std::string>& args);
int cmd_campaign(const std::vector<std::string>& args);
int cmd_mutate(const std::vector<std::string>& args);
int cmd_plant_server(const std::vector<std::string>& args);
int cmd_script(const std::vector<std::string>& args);
int cmd_history(const std::vector<std::string>& args);
int cmd_plant(const std::vector<std::string>& args);
int cmd_merge(const std::vector<std::string>& args);
int cmd_export_fmu(const std::vector<std::string>& args);

// The folder of the running plcfi executable (the FMU binaries are built beside it).
std::string exe_dir();

// --native: the application's native tier, built (or found in the cache) and reported
// on stderr as `who: native tier: ...`; nullptr after printing the error.
std::unique_ptr<st::NativeCode> load_native(const st::Application& app, const char* who);

// The platform set-up of the scan thread (rt::realtime_setup), its warnings on stderr
// prefixed by `who`.
void warn_realtime_setup(const rt::RealtimeOptions& o, const char* who);

// `plcfi run --io`: the program on real I/O, paced in real time.
struct RunIoOptions {
  uint64_t cycles = 0;      // 0: no limit
  int64_t duration_ns = 0;  // 0: no limit
  bool realtime = false;
  rt::RealtimeOptions rt;
  std::string junit;        // JUnit XML with the real-time figures as properties ("": none)
  const st::NativeCode* native = nullptr;
};
// setup() runs once after the cold restart (--set); report() at the end (--print).
int run_with_io(const st::Application& app, const rt::Schedule& sched, const std::string& io_path, const RunIoOptions& o,
                const std::function<bool(st::Machine&)>& setup, const std::function<void(st::Machine&, int)>& report);

}  // namespace plcfi::cli

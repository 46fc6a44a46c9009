// Fuzz target: the ST front end (lexer, parser, semantic checks, bytecode compiler) on one
// source; a program that compiles restarts (FB_init) and runs a few scans under a small VM
// budget (the watchdog). A source that holds the comment `(* dialect: codesys *)` is
// compiled as CODESYS ST (the seeds of CODESYS constructs carry it), any other as IEC;
// one of odd length without coverage marks.
#include <cstdint>
#include <string>

#include "engine.hpp"
#include "fuzz_support.hpp"
#include "runtime/schedule.hpp"

namespace {

constexpr uint64_t kScans = 4;
// Backward jumps per call: a loop without end traps (Watchdog) instead of hanging.
constexpr uint64_t kBudget = 20'000;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace plcfi;
  st::CompileOptions opt;
  opt.warnings = true;
  // Sources of odd length compile as `plcfi run` compiles without --coverage (IFs on
  // bits as selects, jumps without coverage marks); of even length with the marks.
  opt.coverage = size % 2 == 0;
  std::string text(fuzz::as_text(data, size));
  if (text.find("(* dialect: codesys *)") != std::string::npos) opt.dialect = st::Dialect::Codesys;
  auto b = st::build_sources({{"fuzz.st", std::move(text)}}, opt);
  (void)b->diags.render_all();
  if (!b->ok()) return 0;
  const st::Application& app = *b->app;
  rt::Schedule sched;
  std::string err;
  bool scheduled = app.has_configuration ? sched.from_configuration(app, &err)
                                         : sched.single_program(app, "", 10'000'000, &err);
  if (!scheduled) return 0;
  st::Machine m(app);
  m.set_budget(kBudget);
  bool trapped = !m.cold_restart();
  for (uint64_t n = 0; n < kScans && !trapped; ++n) {
    m.set_now(static_cast<int64_t>(n) * sched.tick_ns());
    m.clear_taken();
    sched.for_each_due(n, [&](const rt::ScheduledTask& t) {
      for (size_t pi : t.programs) {
        if (trapped) return;
        const auto& inst = app.programs[pi];
        if (!m.call(inst.pou->entry, inst.addr)) {
          (void)st::describe_trap(app, m.trap());
          trapped = true;
        }
      }
    });
    m.merge_coverage();
  }
  return 0;
}

// TcUnit runner: find the suite instances, scan, call the suites, apply TcUnit's rules.
#include "tcunit.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <map>
#include <set>

#include <fmt/format.h>

#include "codegen/compiler.hpp"
#include "engine.hpp"
#include "stdlib/tcunit_abi.hpp"
#include "common/duration.hpp"
#include "instances.hpp"
#include "scan.hpp"
#include "vm/memory.hpp"

namespace plcfi::testing {

namespace {

const st::PouInfo* suite_base(const st::Application& app) {
  for (const auto& p : app.pous)
    if (p->is_stdlib && p->kind == st::PouKind::FunctionBlock && st::iequals(p->name, "FB_TestSuite")) return p.get();
  return nullptr;
}

std::vector<Found> find_suites(const st::Application& app) {
  const st::PouInfo* base = suite_base(app);
  if (!base) return {};
  return find_instances(app, [&](const st::PouInfo* p) { return p != base && derives(p, base); });
}

const st::Symbol* global(const st::Application& app, const char* name, const char* scope = nullptr) {
  for (const auto& g : app.globals)
    if (g.sym && g.sym->where == st::Where::Abs && st::iequals(g.sym->name, name) && (!scope || st::iequals(g.scope, scope)))
      return g.sym;
  return nullptr;
}

// A GVL_Param_TcUnit value (an unsigned integer), or `fallback` when it is not declared.
uint32_t param(const st::Symbol* s, const st::Machine& m, uint32_t fallback) {
  if (!s || !s->type) return fallback;
  const uint8_t* p = m.mem() + s->offset;
  switch (s->type->size) {
    case 2: return st::load_as<uint16_t>(p);
    case 4: return st::load_as<uint32_t>(p);
    default: return fallback;
  }
}

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Offsets of FB_TestSuite's mailbox (stdlib/tcunit_abi.hpp) inside a suite instance.
struct Mailbox {
  const st::Field *ok = nullptr, *exp = nullptr, *act = nullptr, *msg = nullptr, *key = nullptr, *type = nullptr,
                  *name = nullptr, *loc = nullptr;
  bool valid() const { return ok && exp && act && msg && key && type && name && loc; }
};

Mailbox mailbox_of(const st::PouInfo* base) {
  namespace abi = st::tcunit_abi;
  const st::Type* t = base->type;
  Mailbox b;
  b.ok = t->field(abi::kOk);
  b.exp = t->field(abi::kExp);
  b.act = t->field(abi::kAct);
  b.msg = t->field(abi::kMsg);
  b.key = t->field(abi::kKey);
  b.type = t->field(abi::kType);
  b.name = t->field(abi::kName);
  b.loc = t->field(abi::kLoc);
  return b;
}

// One distinct assertion of a suite: how often it ran in the current and the last cycle,
// and the entries TcUnit keeps of it (one more each time a cycle runs it more often than
// the cycle before): its share of the test's number of assertions.
struct Seen {
  uint32_t last = 0, now = 0, entries = 0;
};

struct AssertTable {
  std::map<std::string, Seen> seen;
  uint32_t entries = 0;  // bounded by MaxNumberOfAssertsForEachTestSuite
  bool full_told = false;
};

// A registered test, while the suites run.
struct LiveTest {
  TcUnitTest result;
  uint64_t touched = UINT64_MAX;  // the cycle its TEST last ran in
  bool duplicate_told = false;
  uint32_t order = 0;             // TEST_ORDERED's position (1-based); 0: not ordered
  int64_t started_ns = -1;
  bool filtered = false;          // not selected by --filter: run, not reported
};

struct LiveSuite {
  Found at;
  std::vector<LiveTest> tests;
  uint32_t registered = 0;
  uint32_t ordered = 0, turn = 1;  // ordered tests registered; the one whose turn it is
  // Distinct assertions (scalar and array ones are kept apart, as TcUnit does), keyed by
  // test path, message and key; the cycle the counts are of.
  AssertTable asserts, array_asserts;
  uint64_t counted_cycle = UINT64_MAX;
  std::set<std::string> beyond;  // names of tests over MaxNumberOfTestsForEachTestSuite
  bool started = false, done = false, stopped = false;
  int64_t started_ns = -1;
  double seconds = 0;
  std::string trap;
  st::SourceLoc trap_loc;
  int current_at_trap = -1;
};

// TcUnit's line for a failed assertion, within the 253 characters of an ADS message: the
// message gives way first ("...TestMsg too long"), then the rest ("...TestName too long").
std::string failure_line(const std::string& path, const std::string& exp, const std::string& act, std::string msg) {
  constexpr size_t kMax = 253;
  static const std::string kNameTooLong = "...TestName too long", kMsgTooLong = "...TestMsg too long";
  std::string head = fmt::format("FAILED TEST '{}', EXP: {}, ACT: {}", path, exp, act);
  if (!msg.empty()) head += ", MSG: %s";  // the message is the format's argument
  if (head.size() > 255) head.resize(255);  // TcUnit's strings hold 255 characters
  if (msg.size() > 255) msg.resize(255);
  if (head.size() + msg.size() <= kMax) {
  } else if (head.size() <= kMax - kMsgTooLong.size()) {
    msg = msg.substr(0, kMax - kMsgTooLong.size() - head.size()) + kMsgTooLong;
  } else {
    head = head.substr(0, kMax - kNameTooLong.size()) + kNameTooLong;
    msg.clear();
  }
  if (const size_t at = head.find("%s"); at != std::string::npos) head.replace(at, 2, msg);
  return head;
}

bool all_finished(const LiveSuite& s) {
  if (s.tests.empty()) return s.started;  // TcUnit: a suite without tests, after its first call
  for (const auto& t : s.tests)
    if (!t.result.finished && !t.result.disabled && !t.filtered) return false;
  return true;
}

// The runner's side of TcUnit's library: TcUnit's global state (the test being called,
// whether its assertions are ignored) and every suite's tests and assertions.
class Runner : public st::LibraryHook, public ScanTest {
 public:
  Runner(const st::PouInfo* base, TcUnitReport* rep, const TcUnitOptions& opt)
      : box_(mailbox_of(base)), rep_(rep), opt_(opt) {}

  // After each scan: when RUN() was called in it, every suite not done (RUN_IN_SEQUENCE:
  // the first one not done) is called once. False when all are done or TcUnit stopped.
  bool after_scan(st::Machine& m, uint64_t n, int64_t now) override;

  bool valid() const { return box_.valid(); }
  std::vector<LiveSuite>& suites() { return suites_; }
  void set_cycle(uint64_t n, int64_t now_ns) {
    cycle_ = n;
    now_ns_ = now_ns;
  }
  void set_tick(int64_t tick) { tick_ = tick; }
  void set_params(const st::Symbol* max_suites, const st::Symbol* max_tests, const st::Symbol* max_asserts) {
    max_suites_sym_ = max_suites;
    max_tests_sym_ = max_tests;
    max_asserts_sym_ = max_asserts;
  }
  void set_limits(uint32_t max_tests, uint32_t max_asserts) {
    max_tests_ = max_tests;
    max_asserts_ = max_asserts;
  }
  // The suite about to be called (TcUnit's CurrentTestSuiteBeingCalled).
  void enter(LiveSuite* s) { current_suite_ = s; }
  bool aborted() const { return aborted_; }
  int current_test_index() const { return current_test_; }

  int32_t tcunit(st::Machine& m, int32_t event, uint32_t suite) override {
    namespace abi = st::tcunit_abi;
    LiveSuite* s = find(suite);
    if (!s) return 0;
    uint8_t* inst = m.mem() + suite;
    switch (event) {
      case abi::kActive: return active() ? 1 : 0;
      case abi::kTest: test(*s, text(inst, box_.name), false); return 1;
      case abi::kTestOrdered: return test(*s, text(inst, box_.name), true) ? 1 : 0;
      case abi::kFinished: {
        if (LiveTest* t = by_name(*s, current_name_)) finish(*s, *t);
        current_finished_ = true;
        return 1;
      }
      case abi::kFinishedNamed: {
        const std::string name = trim(text(inst, box_.name));
        LiveTest* t = by_name(*s, name);
        if (!t) {
          log("error", fmt::format("Failed to find test '{}'", name));
          aborted_ = true;  // TcUnit stops running the suites
          return 0;
        }
        finish(*s, *t);
        current_finished_ = true;
        return 1;
      }
      case abi::kIsFinished: {
        const LiveTest* t = by_name(*s, trim(text(inst, box_.name)));
        return t && t->result.finished ? 1 : 0;
      }
      case abi::kAssert:
      case abi::kAssertArray: assertion(*s, inst, event == abi::kAssertArray); return 0;
      default: return 0;
    }
  }

 private:
  LiveSuite* find(uint32_t addr) {
    if (current_suite_ && current_suite_->at.addr == addr) return current_suite_;
    for (auto& s : suites_)
      if (s.at.addr == addr) return &s;
    return nullptr;
  }

  static std::string text(const uint8_t* inst, const st::Field* f) {
    const char* p = reinterpret_cast<const char*>(inst + f->offset);
    return std::string(p, strnlen(p, f->type->size));
  }

  bool active() const { return !ignore_ && !current_finished_; }

  LiveTest* by_name(LiveSuite& s, const std::string& name) {
    for (auto& t : s.tests)
      if (t.result.name == name) return &t;
    return nullptr;
  }

  void log(const char* level, std::string line) {
    if (line.size() > 253 && line.rfind("FAILED TEST '", 0) != 0) line.resize(253);  // an ADS message's limit
    if (std::string_view(level) == "error" && line.rfind("FAILED TEST '", 0) != 0) ++rep_->own_errors;
    rep_->log.push_back(TcUnitLogLine{level, std::move(line)});
  }

  // TEST / TEST_ORDERED: TcUnit's AddTest, then the ordered test's turn.
  bool test(LiveSuite& s, const std::string& raw, bool ordered) {
    const std::string given = trim(raw);
    current_name_ = given;
    ignore_ = false;
    std::string name = given;
    const bool disabled = lower(name).rfind("disabled_", 0) == 0;
    if (disabled) name = name.substr(9);
    LiveTest* t = by_name(s, name);
    if (t) {
      if (t->touched == cycle_ && !t->filtered) {  // a second test of this name in this cycle
        ignore_ = true;
        if (!t->duplicate_told) {
          t->duplicate_told = true;
          log("error", fmt::format("Test with name '{}' already exists in test suite '{}'", name, s.at.path));
        }
      }
      t->touched = cycle_;
    } else if (s.tests.size() >= max_tests_) {
      s.beyond.insert(name);  // TcUnit keeps no more: counted, not run
      s.registered = static_cast<uint32_t>(s.tests.size() + s.beyond.size());
    } else {
      ++s.registered;
      {
        LiveTest n;
        n.result.name = name;
        n.result.disabled = disabled;
        n.filtered = opt_.filter && !opt_.filter->selects(s.at.path, name);
        n.touched = cycle_;
        if (ordered) n.order = ++s.ordered;
        s.tests.push_back(std::move(n));
        t = &s.tests.back();
      }
    }
    current_test_ = t ? static_cast<int>(t - s.tests.data()) : -1;
    const LiveTest* named = by_name(s, given);  // TcUnit looks the unstripped name up
    current_finished_ = named && named->result.finished;
    if (disabled || (t && t->filtered)) {  // not run: its assertions are ignored
      if (ordered && t && t->filtered && t->order == s.turn) ++s.turn;  // the next one's turn
      ignore_ = true;
      return false;
    }
    if (!ordered) {
      if (t && t->started_ns < 0) t->started_ns = now_ns_;
      return true;
    }
    if (ignore_ || !t || t->order != s.turn) {  // not this ordered test's turn
      ignore_ = true;
      return false;
    }
    if (current_finished_) {  // done: the next one's turn
      ++s.turn;
      ignore_ = true;
      return false;
    }
    if (t->started_ns < 0) t->started_ns = now_ns_;
    return true;
  }

  void finish(LiveSuite& s, LiveTest& t) {
    if (!t.result.finished) {
      t.result.finished = true;
      t.result.seconds = t.started_ns < 0 ? 0.0 : static_cast<double>(now_ns_ - t.started_ns) / 1e9;
    }
    const std::string path = s.at.path + "@" + t.result.name;
    uint32_t n = 0;
    for (const AssertTable* table : {&s.asserts, &s.array_asserts})
      for (const auto& [key, seen] : table->seen)
        if (key.compare(0, path.size() + 1, path + '\x1e') == 0) n += seen.entries;
    if (n > 0) t.result.asserts = n;
  }

  // An assertion: TcUnit reports it unless it already reported this occurrence.
  void assertion(LiveSuite& s, const uint8_t* inst, bool array) {
    namespace abi = st::tcunit_abi;
    if (!active()) return;
    std::string exp = text(inst, box_.exp), act = text(inst, box_.act), msg = text(inst, box_.msg);
    std::string key = text(inst, box_.key);
    bool ok = inst[box_.ok->offset] != 0;
    if (array) {  // ARRAY_DIFF's record: verdict, EXP, ACT, key
      std::vector<std::string> part;
      size_t from = 0;
      for (size_t at; (at = exp.find(abi::kSep, from)) != std::string::npos; from = at + 1) part.push_back(exp.substr(from, at - from));
      part.push_back(exp.substr(from));
      if (part.size() != 4) return;
      ok = part[0] == "=";
      if (part[0] == "S") msg += ", size of arrays not matching.";
      exp = part[1];
      act = part[2];
      key = part[3];
    }
    if (key.empty()) key = exp + '\x1f' + act;
    const std::string type = text(inst, box_.type);
    const std::string path = s.at.path + "@" + current_name_;
    // Counts are per cycle: a new cycle's first assertion of this suite turns the page.
    if (s.counted_cycle != cycle_) {
      for (AssertTable* table : {&s.asserts, &s.array_asserts})
        for (auto& [k, seen] : table->seen) {
          seen.last = seen.now;
          seen.now = 0;
        }
      s.counted_cycle = cycle_;
    }
    AssertTable& table = array ? s.array_asserts : s.asserts;
    const std::string id = path + '\x1e' + msg + '\x1e' + type + '\x1e' + key;
    auto it = table.seen.find(id);
    // A new occurrence: a new assertion, or one more of it in this cycle than in the last.
    const bool fresh = it == table.seen.end() || ++it->second.now > it->second.last;
    if (fresh && table.entries >= max_asserts_) {
      // TcUnit keeps no more: an assertion it does not keep is reported every time.
      if (!table.full_told) {
        table.full_told = true;
        log("error", fmt::format("{}. Max number of assertions exceeded. Check parameter MaxNumberOfAssertsForEachTestSuite.",
                                 s.at.path));
      }
    } else if (fresh) {
      ++table.entries;
      if (it == table.seen.end()) it = table.seen.emplace(id, Seen{0, 1, 0}).first;
      ++it->second.entries;
    }
    const bool reported_before = !fresh;
    if (reported_before || ok) return;
    const std::string line = failure_line(path, exp, act, msg);
    log("error", line);
    st::SourceLoc where;
    if (const int64_t at = st::load_as<int64_t>(inst + box_.loc->offset); at != 0) where = st::unpack_location(at);
    if (LiveTest* t = by_name(s, current_name_)) {  // TcUnit's SetTestFailed
      t->result.failed = true;
      if (t->result.message.empty()) t->result.message = text(inst, box_.msg);
      if (t->result.type.empty()) t->result.type = type;
      t->result.failures.push_back(TcUnitFailure{line, where});
    }  // else: before any TEST (or of a test not kept): TcUnit's log has it, no test fails
  }

  Mailbox box_;
  TcUnitReport* rep_;
  const TcUnitOptions& opt_;
  const st::Symbol *run_ = nullptr, *mode_ = nullptr, *pause_ = nullptr;
  int64_t first_run_ns_ = -1, next_start_ns_ = 0, tick_ = 0;
  const st::Symbol *max_suites_sym_ = nullptr, *max_tests_sym_ = nullptr, *max_asserts_sym_ = nullptr;

  // --test-timeout: a test not finished that long after its first TEST call fails and is
  // finished (its later assertions are ignored), so the suite goes on.
  void time_out_tests(LiveSuite& s, int64_t now) {
    if (opt_.test_timeout_ns <= 0) return;
    for (auto& t : s.tests) {
      if (t.result.finished || t.result.disabled || t.filtered || t.started_ns < 0) continue;
      if (now - t.started_ns < opt_.test_timeout_ns) continue;
      t.result.finished = true;
      t.result.failed = true;
      t.result.seconds = static_cast<double>(now - t.started_ns) / 1e9;
      t.result.problem = fmt::format("not finished within the per-test time-out ({}): TEST_FINISHED() was not called",
                                     common::format_duration(opt_.test_timeout_ns));
    }
  }

 public:
  void set_globals(const st::Symbol* run, const st::Symbol* mode, const st::Symbol* pause) {
    run_ = run;
    mode_ = mode;
    pause_ = pause;
  }
  int64_t first_run_ns() const { return first_run_ns_; }

 private:
  std::vector<LiveSuite> suites_;
  LiveSuite* current_suite_ = nullptr;
  std::string current_name_;
  int current_test_ = -1;
  bool ignore_ = false, current_finished_ = false, aborted_ = false;
  uint64_t cycle_ = 0;
  int64_t now_ns_ = 0;
  uint32_t max_tests_ = 100, max_asserts_ = 1000;
};

bool Runner::after_scan(st::Machine& m, uint64_t n, int64_t now) {
  if (n == 0) {  // GVL_Param_TcUnit's constants, initialised by the restart
    rep_->max_tests = param(max_tests_sym_, m, 100);
    rep_->max_asserts = param(max_asserts_sym_, m, 1000);
    set_limits(rep_->max_tests, rep_->max_asserts);
    const uint32_t max_suites = param(max_suites_sym_, m, 1000);
    if (suites_.size() > max_suites) {  // TcUnit would write past its table: plcfi runs the first ones
      log("error", fmt::format("{} test suites are more than GVL_Param_TcUnit.MaxNumberOfTestSuites ({}): the ones "
                               "after {} do not run",
                               suites_.size(), max_suites, suites_[max_suites - 1].at.path));
      suites_.resize(max_suites);
    }
  }
  for (auto& e : m.log()) rep_->log.push_back(TcUnitLogLine{e.level, e.text});  // the program's ADSLOGSTR
  m.log().clear();
  uint8_t* mem = m.mem();
  if (st::load_as<int32_t>(mem + run_->offset) == 0) return true;  // RUN() not called in this scan
  rep_->run_called = true;
  if (first_run_ns_ < 0) first_run_ns_ = now;
  st::store_as<int32_t>(mem + run_->offset, 0);
  const bool in_sequence = st::load_as<int16_t>(mem + mode_->offset) == 2;
  set_cycle(n + 1, now);
  for (auto& s : suites_) {
    if (s.done) continue;
    if (in_sequence && now < next_start_ns_) break;  // TimeBetweenTestSuitesExecution
    if (!s.started) s.started_ns = now;
    s.started = true;
    enter(&s);
    if (!m.call(s.at.type->entry, s.at.addr)) {
      s.stopped = true;
      s.done = true;
      s.trap = st::describe_trap_kind(m.trap());
      s.trap_loc = m.trap().loc;
      s.current_at_trap = current_test_;
    } else {
      time_out_tests(s, now);
      s.done = all_finished(s);
    }
    for (auto& e : m.log()) rep_->log.push_back(TcUnitLogLine{e.level, e.text});  // TCUNIT_ADSLOGSTR, in order
    m.log().clear();
    if (s.done) {
      s.seconds = static_cast<double>(now - s.started_ns) / 1e9;
      if (in_sequence && pause_) next_start_ns_ = now + tick_ + st::load_as<int64_t>(m.mem() + pause_->offset);
    }
    if (aborted_) return false;
    if (in_sequence && !s.done) break;  // the next suite starts when this one is done
  }
  for (const auto& s : suites_)
    if (!s.done) return true;
  return false;
}

}  // namespace

bool has_tcunit_suites(const st::Application& app) { return !find_suites(app).empty(); }

std::vector<std::pair<std::string, const st::PouInfo*>> tcunit_suite_instances(const st::Application& app) {
  std::vector<std::pair<std::string, const st::PouInfo*>> out;
  for (const auto& f : find_suites(app)) out.emplace_back(f.path, f.type);
  return out;
}

TcUnitReport run_tcunit(const st::Application& app, const rt::Schedule& schedule, st::Machine& m, const TcUnitOptions& opt) {
  TcUnitReport rep;
  const st::PouInfo* base = suite_base(app);
  const st::Symbol* run = global(app, "_TcUnitRun");
  const st::Symbol* mode = global(app, "_TcUnitMode");
  const st::Symbol* pause = global(app, "_TcUnitPause");
  if (!base || !run || !mode) return rep;
  Runner runner(base, &rep, opt);
  if (!runner.valid()) return rep;
  runner.set_globals(run, mode, pause);
  for (auto& f : find_suites(app)) {
    LiveSuite s;
    s.at = f;
    runner.suites().push_back(std::move(s));
  }
  auto& live = runner.suites();

  m.set_hook(&runner);
  struct Unhook {
    st::Machine& m;
    ~Unhook() { m.set_hook(nullptr); }
  } unhook{m};
  runner.set_params(global(app, "MaxNumberOfTestSuites", "GVL_Param_TcUnit"),
                    global(app, "MaxNumberOfTestsForEachTestSuite", "GVL_Param_TcUnit"),
                    global(app, "MaxNumberOfAssertsForEachTestSuite", "GVL_Param_TcUnit"));
  runner.set_tick(schedule.tick_ns());
  const ScanRun scans = run_scans(app, schedule, m, runner, opt.timeout_ns, opt.budget);
  rep.program_trap = scans.program_trap;
  rep.cycles = scans.cycles;
  rep.virtual_ns = scans.virtual_ns;
  rep.timed_out = scans.timed_out;
  rep.aborted = runner.aborted();
  rep.seconds = runner.first_run_ns() < 0 ? 0.0 : static_cast<double>(rep.virtual_ns - runner.first_run_ns()) / 1e9;

  for (auto& s : live) {
    TcUnitSuite out;
    out.path = s.at.path;
    out.type = s.at.type;
    out.started = s.started;
    out.registered = s.registered;
    out.seconds = s.seconds;
    for (size_t i = 0; i < s.tests.size(); ++i) {
      if (s.tests[i].filtered) {
        ++out.filtered;
        continue;
      }
      TcUnitTest t = std::move(s.tests[i].result);
      if (t.disabled) {
        t.failed = false;
      } else if (s.stopped && s.current_at_trap == static_cast<int>(i)) {
        t.failed = true;
        t.problem = s.trap;
        t.problem_at = s.trap_loc;
      } else if (!t.finished) {
        t.failed = true;
        t.problem = s.stopped ? "not finished: the suite stopped at a runtime error in another test"
                    : !rep.program_trap.empty() ? "not finished: a runtime error in the program stopped the run"
                    : rep.aborted ? "not finished: TcUnit stopped (TEST_FINISHED_NAMED of a test that does not exist)"
                                  : fmt::format("not finished within the time-out ({}): TEST_FINISHED() was not called",
                                                common::format_duration(opt.timeout_ns));
      }
      out.tests.push_back(std::move(t));
    }
    if (s.tests.empty() && s.stopped) {
      TcUnitTest t;
      t.name = "(before any TEST)";
      t.failed = true;
      t.problem = s.trap;
      t.problem_at = s.trap_loc;
      out.tests.push_back(std::move(t));
    }
    rep.suites.push_back(std::move(out));
  }
  return rep;
}

}  // namespace plcfi::testing

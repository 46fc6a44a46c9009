// The passive driver: scan hooks, runs and restarts, verdicts, the results journal.
#include "driver.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <fcntl.h>
#include <unistd.h>

#include <fmt/format.h>

#include "common/file.hpp"
#include "common/hash.hpp"
#include "explore.hpp"
#include "io/sim/plant_factory.hpp"
#include "io/sim/sim_backend.hpp"
#include "journal.hpp"
#include "plant_model/plant.hpp"
#include "report/trace.hpp"
#include "runtime/clock.hpp"
#include "runtime/runtime.hpp"

namespace plcfi::campaign {

std::string campaign_fingerprint(const CampaignBuild& cb) {
  common::Fnv64 h;
  auto mix = [&](const std::string& s) { h.add(s); };
  mix(cb.spec.name);
  mix(std::to_string(cb.spec.seed));
  mix(std::to_string(cb.spec.max_paths));
  mix(cb.spec.restart == RestartKind::Cold ? "cold" : "warm");
  mix(cb.spec.plant + "|" + cb.spec.plant_config);
  for (const auto& p : cb.spec.programs) {
    // The programs compiled already, so they read; should one vanish since, its error
    // text stands in (a different fingerprint, never a crash).
    std::string text, read_err;
    if (!common::read_file(p, common::kMaxSourceBytes, &text, &read_err)) text = read_err;
    mix(text);  // another program under test is another campaign
  }
  if (cb.spec.explore.enabled && !cb.spec.requirements.empty()) {  // explored cases check them
    std::string text, read_err;
    if (!common::read_file(cb.spec.requirements, common::kMaxSpecBytes, &text, &read_err)) text = read_err;
    mix(text);
  }
  for (const auto& c : cb.cases) {
    mix(c.id);
    mix(c.precondition);
    mix(c.fault.text);
    mix(c.target->bind);
    mix(std::to_string(c.deadline_ns));
  }
  return h.hex();
}

std::vector<std::string> distinguishing_branches(const CampaignBuild& cb, const std::vector<Execution>& all,
                                                 const Execution& e) {
  std::vector<const Execution*> same;
  for (const auto& x : all)
    if (x.case_index == e.case_index) same.push_back(&x);
  if (same.size() < 2) return {};
  // Branch ids every path of the case took are common ground; the rest tells them apart.
  std::set<uint32_t> common(e.branches.begin(), e.branches.end());
  for (const auto* x : same) {
    std::set<uint32_t> keep;
    for (uint32_t b : x->branches)
      if (common.count(b)) keep.insert(b);
    common = std::move(keep);
  }
  std::vector<std::string> out;
  const st::Application& app = *cb.build->app;
  for (uint32_t b : e.branches) {
    if (common.count(b) || b >= app.branches.size()) continue;
    const auto& bp = app.branches[b];
    std::string file = bp.loc.file < app.file_paths.size() ? app.file_paths[bp.loc.file] : "?";
    out.push_back(fmt::format("{}:{} {} ({})", std::filesystem::path(file).filename().string(), bp.loc.line, bp.kind, bp.pou));
  }
  return out;
}

namespace {

// The scan hooks of one campaign: preconditions before the scan, monitors after it.
class PassiveDriver final : public rt::ScanHooks {
 public:
  PassiveDriver(CampaignBuild& cb, const DriverOptions& opt) : cb_(cb), opt_(opt) {
    const st::Application& app = *cb.build->app;
    size_t n = cb.cases.size();
    prev_.assign(n, 0);
    paths_.assign(n, 0);
    user_branch_.assign(app.branches.size(), false);
    std::set<uint32_t> files(cb.program_files.begin(), cb.program_files.end());
    for (size_t b = 0; b < app.branches.size(); ++b) user_branch_[b] = files.count(app.branches[b].loc.file) > 0;
  }

  // Marks (case, path) tested (a resumed journal).
  void mark_tested(const Execution& e) {
    tested_.insert({e.case_index, e.path_hash});
    paths_[e.case_index] = std::max(paths_[e.case_index], e.path);
  }

  bool all_done() const {
    for (int p : paths_)
      if (p < cb_.spec.max_paths) return false;
    return true;
  }
  size_t cases_tested() const {
    size_t k = 0;
    for (int p : paths_) k += p > 0;
    return k;
  }

  void begin_run(uint64_t run) {
    run_ = run;
    std::fill(prev_.begin(), prev_.end(), 0);
    active_ = SIZE_MAX;
    done_ = false;
    injected_ = false;
    claimed_ = false;
  }
  bool claimed() const { return claimed_; }
  bool done() const { return done_; }
  const std::string& error() const { return error_; }
  bool injected() const { return injected_; }
  bool active() const { return active_ != SIZE_MAX; }
  Execution& result() { return exec_; }

  void before_scan(rt::Runtime& r) override {
    if (active_ != SIZE_MAX || done_ || r.stopped()) return;
    st::Machine& m = r.machine();
    if (!m.call(cb_.preconditions_entry, cb_.preconditions_addr)) return;  // a trap: no case can start
    const uint8_t* pre = m.mem() + cb_.preconditions.addr;
    const size_t n = prev_.size();
    bool probed = false;
    for (size_t i = 0; i < n; ++i) {
      uint8_t now = pre[i];
      bool rose = now && !prev_[i];
      prev_[i] = now;
      if (!rose || active_ != SIZE_MAX || claimed_ || paths_[i] >= cb_.spec.max_paths) continue;
      if (!probed) {
        path_of_scan(r);
        probed = true;
      }
      if (tested_.count({i, hash_})) continue;
      if (opt_.share_n > 1 && run_ % static_cast<uint64_t>(opt_.share_n) != static_cast<uint64_t>(opt_.share_k))
        claim(r, i);
      else
        inject(r, i);
    }
  }

  void after_scan(rt::Runtime& r) override {
    if (active_ == SIZE_MAX) return;
    if (opt_.window_branches) {  // before the monitors run on the same machine
      const auto& taken = r.machine().taken();
      auto& w = *opt_.window_branches;
      if (w.size() < taken.size()) w.resize(taken.size(), 0);
      for (size_t k = 0; k < taken.size(); ++k) w[k] |= taken[k];
    }
    const TestCase& tc = cb_.cases[active_];
    int64_t t = r.now();
    monitors_->step(r.machine(), state_++, t);
    if (trace_) trace_->sample(t, r.machine());
    if (phase_ != Phase::Test) {
      recovery_after_scan(r, tc, t);
      return;
    }
    auto v = monitors_->verdicts();
    if (tc.explored) {
      explore_after_scan(r, tc, v, t);
      return;
    }
    size_t n_class = tc.reqs - tc.forbidden;
    bool all_met = true;
    for (size_t k = 0; k < v.size(); ++k) {
      if (v[k].triggers && start_time_[k] < 0) start_time_[k] = t;
      if (k < n_class) {
        if (v[k].holds && react_time_[k] < 0) react_time_[k] = t;
        all_met = all_met && v[k].holds > 0;
      }
    }
    for (size_t k = 0; k < v.size(); ++k) {
      if (!v[k].violated()) continue;
      const auto& x = v[k].violations.front();
      const auto& spec = cb_.monitors.requirements[tc.first_req + k];
      const std::string& req = spec.text;
      if (k >= n_class) {
        finish(r, Outcome::Fail, fmt::format("forbidden reaction at +{}: {}", rel(x.time_ns), req));
      } else if (x.cause == monitor::Cause::Delay) {
        finish(r, Outcome::Fail,
               fmt::format("deadline missed: {} not seen within {} of the start (start at +{}, checked at +{})", spec.reaction.text,
                           human_duration(tc.deadline_ns), rel(x.trigger_time_ns), rel(x.time_ns)));
      } else {
        finish(r, Outcome::Fail,
               fmt::format("invariant broken at +{}: {} (start at +{})", rel(x.time_ns), req, rel(x.trigger_time_ns)));
      }
      return;
    }
    if (all_met) {
      int64_t start = INT64_MAX, react = 0;
      for (size_t k = 0; k < n_class; ++k) {
        start = std::min(start, start_time_[k]);
        react = std::max(react, react_time_[k]);
      }
      exec_.start_ns = start;
      exec_.reaction_ns = react;
      exec_.latency_ns = react - start;
      std::string reason = fmt::format("reaction {} ms after the start (deadline {})", static_cast<double>(react - start) * 1e-6,
                                       human_duration(tc.deadline_ns));
      if (tc.recovery) {  // then the recovery: the fault withdrawn, the alarm latched, acknowledged
        r.input_overlay().clear();
        r.output_overlay().clear();
        r.reapply_input_overlay();
        phase_ = Phase::Hold;
        withdrawn_ns_ = t;
        reaction_reason_ = std::move(reason);
        return;
      }
      finish(r, Outcome::Pass, std::move(reason));
      return;
    }
    if (r.stopped()) {
      finish(r, Outcome::Fail, "program stopped: " + r.stop_reason());
      return;
    }
    if (t - exec_.inject_ns >= tc.max_duration_ns) {
      std::string open;
      for (size_t k = 0; k < n_class; ++k)
        if (!v[k].holds)
          open += fmt::format("{}{} ({})", open.empty() ? "" : ", ", cb_.monitors.requirements[tc.first_req + k].text,
                              v[k].triggers ? "pending" : "start condition never held");
      finish(r, Outcome::Fail, fmt::format("maximum test duration {} reached: {}", human_duration(tc.max_duration_ns), open));
    }
  }

 private:
  std::string rel(int64_t t) const { return human_duration(t - exec_.inject_ns); }

  // The recovery after the reaction (FaultClass::recovery): the alarm stays latched while
  // the fault is gone, the test presses the acknowledgement, the module clears.
  void recovery_after_scan(rt::Runtime& r, const TestCase& tc, int64_t t) {
    const Recovery& rc = tc.cls->recovery;
    const st::Machine& m = r.machine();
    const std::string ack = fmt::format("{} ({})", rc.acknowledge, tc.ack_ref.text);
    if (r.stopped()) {
      finish(r, Outcome::Fail, reaction_reason_ + "; then the program stopped in the recovery: " + r.stop_reason());
      return;
    }
    if (phase_ == Phase::Hold) {
      if (!st::read_bool(m, tc.cleared[0])) {
        finish(r, Outcome::Fail,
               fmt::format("{}; then {} cleared without acknowledgement {} after the fault was withdrawn (it must stay "
                           "latched {} until {} is pressed)",
                           reaction_reason_, tc.cleared[0].path, human_duration(t - withdrawn_ns_), human_duration(rc.hold_ns),
                           ack));
        return;
      }
      if (t - withdrawn_ns_ < rc.hold_ns) return;
      faults::FaultSpec press;
      press.kind = faults::Kind::StuckAt;
      press.value = 1;
      press.text = "stuck_at(1)";
      faults::InjectionContext ctx;
      ctx.ref = tc.ack_ref;
      ctx.baseline = tc.ack_ref.get(r.raw_inputs());
      ctx.inject_ns = t;
      ctx.tick_ns = r.schedule().tick_ns();
      std::string err;
      auto rule = faults::make_rule(press, ctx, &err);
      if (!rule) {  // checked at generation: a BOOL input
        error_ = tc.id + ": " + err;
        done_ = true;
        return;
      }
      r.input_overlay().add(std::move(rule));
      r.reapply_input_overlay();
      phase_ = Phase::Pressed;
      pressed_ns_ = t;
      return;
    }
    if (phase_ == Phase::Pressed && t - pressed_ns_ >= rc.press_ns) {
      r.input_overlay().clear();  // released
      r.reapply_input_overlay();
      phase_ = Phase::Released;
    }
    std::string still;
    for (const auto& h : tc.cleared)
      if (st::read_bool(m, h)) still += (still.empty() ? "" : ", ") + h.path;
    if (still.empty()) {
      finish(r, Outcome::Pass,
             fmt::format("{}; recovered {} after pressing {}", reaction_reason_, human_duration(t - pressed_ns_), ack));
    } else if (t - pressed_ns_ >= rc.within_ns) {
      finish(r, Outcome::Fail,
             fmt::format("{}; then not recovered: {} still TRUE {} after pressing {} (fault withdrawn {} before the press)",
                         reaction_reason_, still, human_duration(rc.within_ns), ack, human_duration(rc.hold_ns)));
    }
  }

  // The verdict of an explored case: its class's forbidden reactions (monitors), then the
  // exploration oracle (detected or tolerated, explore.hpp).
  void explore_after_scan(rt::Runtime& r, const TestCase& tc, const std::vector<monitor::Verdict>& v, int64_t t) {
    // [0, forbidden): the class's forbidden reactions; then the campaign's requirements.
    for (size_t k = 0; k < v.size(); ++k) {
      if (!v[k].violated()) continue;
      const auto& spec = cb_.monitors.requirements[tc.first_req + k];
      if (k < tc.forbidden) {
        finish(r, Outcome::Fail, fmt::format("forbidden reaction at +{}: {}", rel(v[k].violations.front().time_ns), spec.text));
        return;
      }
      if (req_violation_.empty())
        req_violation_ = fmt::format("requirement {} violated at +{} ({})", spec.id.substr(tc.id.size() + 1),
                                     rel(v[k].violations.front().time_ns), spec.text);
    }
    auto state = oracle_->step(r.machine(), t);
    if (state == ExploreOracle::State::Tolerated && !req_violation_.empty()) {
      finish(r, Outcome::Fail, "the TSD's transitions in time, but " + req_violation_);
      return;
    }
    if (state == ExploreOracle::State::Detected || state == ExploreOracle::State::Tolerated) {
      if (state == ExploreOracle::State::Detected) {
        exec_.reaction_ns = oracle_->verdict_ns();
        exec_.latency_ns = exec_.reaction_ns - exec_.inject_ns;
      }
      finish(r, Outcome::Pass, oracle_->reason());
    } else if (state == ExploreOracle::State::Failed) {
      finish(r, Outcome::Fail, oracle_->reason());
    } else if (r.stopped()) {
      finish(r, Outcome::Fail, "program stopped: " + r.stop_reason());
    } else if (t - exec_.inject_ns >= tc.max_duration_ns) {
      finish(r, Outcome::Fail, fmt::format("maximum test duration {} reached: neither detected nor the scenario done",
                                           human_duration(tc.max_duration_ns)));
    }
  }

  // The control-flow path the coming scan takes, as a hash of the program's branch ids.
  void path_of_scan(rt::Runtime& r) {
    const auto& taken = r.probe_branches();
    branches_.clear();
    uint64_t h = 1469598103934665603ull;
    for (size_t w = 0; w < taken.size(); ++w) {
      uint64_t bits = taken[w];
      while (bits) {
        uint32_t b = static_cast<uint32_t>(w * 64 + static_cast<size_t>(__builtin_ctzll(bits)));
        bits &= bits - 1;
        if (b < user_branch_.size() && user_branch_[b]) {
          branches_.push_back(b);
          for (int k = 0; k < 4; ++k) h = (h ^ ((b >> (8 * k)) & 0xff)) * 1099511628211ull;
        }
      }
    }
    hash_ = h;
  }

  // A run of another share: the case and path are taken, as the injection would take
  // them, and the run ends here; its test is another process's.
  void claim(rt::Runtime& r, size_t i) {
    take(r, i);
    injected_ = claimed_ = done_ = true;
  }

  // Case i on the path of this scan is tested from now on: its execution record begins.
  void take(rt::Runtime& r, size_t i) {
    const TestCase& tc = cb_.cases[i];
    ++paths_[i];
    tested_.insert({i, hash_});
    exec_ = Execution{};
    exec_.case_id = tc.id;
    exec_.case_index = i;
    exec_.path = paths_[i];
    exec_.path_hash = hash_;
    exec_.branches = branches_;
    exec_.run = run_;
    exec_.inject_ns = r.now();
  }

  void inject(rt::Runtime& r, size_t i) {
    const TestCase& tc = cb_.cases[i];
    faults::InjectionContext ctx;
    ctx.ref = tc.target_ref;
    ctx.baseline = tc.target_ref.area == 'I' ? tc.target_ref.get(r.raw_inputs()) : tc.target_ref.get(r.delivered_outputs());
    ctx.inject_ns = r.now();
    ctx.tick_ns = r.schedule().tick_ns();
    ctx.seed = cb_.spec.seed * 1000003u + run_;
    std::string err;
    auto rule = faults::make_rule(tc.fault, ctx, &err);
    if (!rule) {  // checked at generation already: a broken build, stop the campaign
      error_ = tc.id + ": " + err;
      done_ = true;
      return;
    }
    if (tc.target_ref.area == 'I') {
      r.input_overlay().add(std::move(rule));
      r.reapply_input_overlay();
    } else {
      r.output_overlay().add(std::move(rule));
    }
    monitors_ = monitor::MonitorSet::create(*cb_.build->app, cb_.monitors, tc.first_req, tc.reqs, &err);
    if (!monitors_) {
      error_ = tc.id + ": " + err;
      done_ = true;
      return;
    }
    if (tc.explored) {
      oracle_ = std::make_unique<ExploreOracle>(cb_, i, r.now());
      req_violation_.clear();
    }
    active_ = i;
    injected_ = true;
    state_ = 0;
    start_time_.assign(tc.reqs, -1);
    react_time_.assign(tc.reqs, -1);
    take(r, i);
    if (opt_.vcd && !opt_.out_dir.empty()) {
      exec_.vcd = fmt::format("{}_path{}.vcd", tc.id, exec_.path);
      trace_ = report::open_vcd((std::filesystem::path(opt_.out_dir) / exec_.vcd).string(), cb_.watch, &err,
                                fmt::format("campaign {} case {} path {} on plant {}", cb_.spec.name, tc.id, exec_.path,
                                            cb_.spec.plant));
      if (!trace_) exec_.vcd.clear();
    }
  }

  void finish(rt::Runtime& r, Outcome o, std::string reason) {
    const TestCase& tc = cb_.cases[active_];
    if (exec_.start_ns < 0)  // a FAIL: still say when the class requirements' start held
      for (size_t k = 0; k < tc.reqs - tc.forbidden; ++k)
        if (start_time_[k] >= 0 && (exec_.start_ns < 0 || start_time_[k] < exec_.start_ns)) exec_.start_ns = start_time_[k];
    exec_.outcome = o;
    exec_.reason = std::move(reason);
    phase_ = Phase::Test;
    exec_.end_ns = r.now();
    // Completion: withdraw the fault at once; the caller restarts program and plant.
    r.input_overlay().clear();
    r.output_overlay().clear();
    if (trace_) {
      std::string err;
      trace_->close(&err);
      trace_.reset();
    }
    monitors_.reset();
    oracle_.reset();
    active_ = SIZE_MAX;
    done_ = true;
  }

  CampaignBuild& cb_;
  const DriverOptions& opt_;
  std::vector<uint8_t> prev_;
  std::vector<int> paths_;  // paths tested per case
  std::set<std::pair<size_t, uint64_t>> tested_;
  std::vector<bool> user_branch_;
  std::vector<uint32_t> branches_;
  uint64_t hash_ = 0;
  uint64_t run_ = 0;
  size_t active_ = SIZE_MAX;
  bool done_ = false, injected_ = false, claimed_ = false;
  enum class Phase { Test, Hold, Pressed, Released };  // the recovery's phases after the reaction
  Phase phase_ = Phase::Test;
  int64_t withdrawn_ns_ = 0, pressed_ns_ = 0;
  std::string reaction_reason_;
  uint64_t state_ = 0;
  std::unique_ptr<monitor::MonitorSet> monitors_;
  std::unique_ptr<ExploreOracle> oracle_;  // explored cases only
  std::string req_violation_;              // the first campaign requirement an explored case violated
  std::unique_ptr<report::TraceWriter> trace_;
  std::vector<int64_t> start_time_, react_time_;
  Execution exec_;
  std::string error_;
};

}  // namespace

bool run_campaign_on(CampaignBuild& cb, rt::IoBackend* backend, const DriverOptions& opt, CampaignResult* out,
                     std::string* err) {
  auto wall0 = std::chrono::steady_clock::now();
  const Campaign& c = cb.spec;
  const st::Application& app = *cb.build->app;
  rt::Runtime runtime(app, cb.schedule, backend);
  runtime.machine().set_native(opt.native);
  runtime.machine().set_count_hits(opt.branch_hits != nullptr);
  runtime.set_safe_state(opt.safe_state);
  // Every way out of this function, errors included: the fault withdrawn (both overlays
  // cleared) and the safe output state written to the backend.
  struct SafeExit {
    rt::Runtime& r;
    ~SafeExit() {
      r.input_overlay().clear();
      r.output_overlay().clear();
      r.write_safe_outputs();
    }
  } safe_exit{runtime};
  rt::ScanLoop loop(runtime, opt.realtime, opt.signals, opt.io_lost);
  loop.start();
  PassiveDriver driver(cb, opt);
  runtime.add_hooks(&driver);

  Journal journal;
  const bool shared = static_cast<bool>(opt.on_run);  // a share of the runs: records, no journal
  Progress pr;
  pr.cases = cb.cases.size();
  auto adopt = [&](const JournalState& st) {
    for (const auto& e : st.executions) {
      driver.mark_tested(e);
      ++(e.outcome == Outcome::Pass ? pr.pass : pr.fail);
      out->executions.push_back(e);
    }
    out->resumed = st.executions.size();
    pr.run = st.next_run;
    pr.campaign_ns = st.campaign_ns;
    pr.scans = st.scans;
  };
  if (!opt.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(opt.out_dir, ec);
    if (ec) {
      *err = opt.out_dir + ": cannot create the output folder: " + ec.message();
      return false;
    }
    if (!shared) {
      std::string path = (std::filesystem::path(opt.out_dir) / "results.jsonl").string();
      JournalState st;
      journal.set_plant(c.plant);
      if (!journal.open(path, opt.resume, c.name, campaign_fingerprint(cb), cb.cases, &st, err)) return false;
      adopt(st);
    }
  }
  if (shared && opt.resumed) adopt(*opt.resumed);
  pr.executions = out->executions.size();

  int64_t next_progress = pr.campaign_ns + 1'000'000'000;
  while (true) {
    if (driver.all_done()) {
      out->end_reason = fmt::format("every case tested on {} path(s)", c.max_paths);
      break;
    }
    if (pr.campaign_ns >= c.budget_ns) {
      out->end_reason = fmt::format("time budget of {} spent", human_duration(c.budget_ns));
      break;
    }
    uint64_t seed = c.seed + pr.run;
    if (c.restart == RestartKind::Warm && pr.run > 0) runtime.warm_restart(seed);
    else runtime.cold_restart(seed);
    driver.begin_run(pr.run);
    bool search_over = false;
    RunRecord rec;  // what a share of the runs reports of this one
    rec.run = pr.run;
    while (!driver.done()) {
      if (rt::LoopEnd end = loop.check_stop(); end != rt::LoopEnd::None) {
        out->end_reason = end == rt::LoopEnd::Signal ? "interrupted by a signal" : loop.end_reason();
        out->interrupted = true;
        break;
      }
      const int64_t before = runtime.now();
      loop.scan();
      ++pr.scans;
      const int64_t dt = runtime.now() - before;  // one tick, or more after an overrun on the bench
      pr.campaign_ns += dt;
      ++rec.scans;
      rec.ns += dt;
      if (rec.inject_scan == 0 && driver.injected()) rec.inject_scan = rec.scans;
      if (!driver.active()) {
        // Not testing: the run searches for a precondition on an untested path.
        if (runtime.now() >= c.search_window_ns || runtime.stopped()) {
          search_over = true;
          break;
        }
        if (pr.campaign_ns >= c.budget_ns) break;
      }
      if (opt.on_progress && pr.campaign_ns >= next_progress) {
        next_progress = pr.campaign_ns + 1'000'000'000;
        pr.cases_tested = driver.cases_tested();
        opt.on_progress(pr);
      }
    }
    if (out->interrupted) break;  // SafeExit withdraws the fault and writes the safe state
    if (!driver.error().empty()) {
      *err = "internal error: " + driver.error();
      return false;
    }
    if (driver.done() && driver.claimed()) {  // another share tests this run
      ++pr.run;
      rec.kind = RunRecord::Kind::Claimed;
      rec.exec = driver.result();
      if (!opt.on_run(rec)) {
        out->end_reason = "stopped by the caller";
        break;
      }
      continue;
    }
    if (driver.done()) {
      Execution e = driver.result();
      ++(e.outcome == Outcome::Pass ? pr.pass : pr.fail);
      pr.executions = out->executions.size() + 1;
      pr.cases_tested = driver.cases_tested();
      ++pr.run;
      if (journal.is_open() && !journal.append(e, pr, err)) return false;
      out->executions.push_back(e);
      if (opt.on_verdict) opt.on_verdict(e, pr);
      if (opt.stop_after && opt.stop_after(out->executions.back())) {
        out->end_reason = "stopped after " + e.case_id + " path " + std::to_string(e.path);
        break;
      }
      if (shared) {
        rec.kind = RunRecord::Kind::Executed;
        rec.line = journal_line(e, cb.cases[e.case_index], Progress{});
        rec.exec = std::move(e);
        if (!opt.on_run(rec)) {
          out->end_reason = "stopped by the caller";
          break;
        }
      }
      continue;
    }
    ++pr.run;
    if (shared) {
      rec.kind = RunRecord::Kind::Ended;
      rec.end = !search_over ? "budget" : runtime.stopped() ? "stopped: " + runtime.stop_reason() : "window";
      if (!opt.on_run(rec)) {
        out->end_reason = "stopped by the caller";
        break;
      }
    }
    if (search_over) {
      out->end_reason = runtime.stopped() ? "the program stopped outside a test: " + runtime.stop_reason()
                                          : fmt::format("no untested case or path within the search window of {}",
                                                        human_duration(c.search_window_ns));
      break;
    }
  }
  runtime.remove_hooks(&driver);
  if (opt.branch_hits) *opt.branch_hits = runtime.machine().hits();
  if (loop.paced()) {
    out->realtime = loop.pacer().properties();
    for (const auto& line : loop.figures()) out->realtime_text += (out->realtime_text.empty() ? "" : "\n") + line;
  }
  std::vector<bool> seen(cb.cases.size(), false);
  for (const auto& e : out->executions) seen[e.case_index] = true;
  for (size_t i = 0; i < seen.size(); ++i)
    if (!seen[i]) (out->interrupted ? out->pending : out->not_reached).push_back(i);
  pr.cases_tested = driver.cases_tested();
  out->progress = pr;
  out->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return true;
}

bool run_campaign(CampaignBuild& cb, const DriverOptions& opt, CampaignResult* out, std::string* err) {
  auto plant = io::open_plant(cb.spec.plant, cb.spec.plant_config, err);
  if (!plant) {
    *err = cb.spec.path + ": plant: " + *err;
    return false;
  }
  auto backend = io::SimBackend::create(*cb.build->app, std::move(plant), err);
  if (!backend) {
    *err = cb.spec.path + ": " + *err;
    return false;
  }
  return run_campaign_on(cb, backend.get(), opt, out, err);
}

}  // namespace plcfi::campaign

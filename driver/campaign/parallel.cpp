// Shares of a campaign's runs: the sequencer, worker processes, shard files and merging.
#include "parallel.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <iostream>
#include <set>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include "common/file.hpp"
#include "common/json.hpp"

namespace plcfi::campaign {

using common::Json;

namespace {

constexpr const char* kShardJournal = "plcfi campaign shard";

RunSequencer::Limits limits_of(const CampaignBuild& cb) {
  RunSequencer::Limits l;
  l.budget_ns = cb.spec.budget_ns;
  l.tick_ns = cb.schedule.tick_ns();
  l.search_window_ns = cb.spec.search_window_ns;
  l.max_paths = cb.spec.max_paths;
  l.cases = cb.cases.size();
  return l;
}

const Json* member(const Json& o, const char* k) {
  auto it = o.find(k);
  return it == o.end() ? nullptr : &*it;
}

bool get_i64(const Json& o, const char* k, int64_t* v) {
  const Json* m = member(o, k);
  if (!m || !m->is_number_integer()) return false;
  *v = m->get<int64_t>();
  return true;
}

bool get_string(const Json& o, const char* k, std::string* v) {
  const Json* m = member(o, k);
  if (!m || !m->is_string()) return false;
  *v = m->get<std::string>();
  return true;
}

std::string status_text(int status) {
  if (WIFEXITED(status)) return fmt::format("exit status {}", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return fmt::format("killed by signal {} ({})", WTERMSIG(status), strsignal(WTERMSIG(status)));
  return "ended";
}

}  // namespace

// ---------------------------------------------------------------------------------------
// The sequencer

RunSequencer::RunSequencer(const Limits& lim, const JournalState& start) : lim_(lim) {
  paths_.assign(lim.cases, 0);
  pr_.cases = lim.cases;
  for (const auto& e : start.executions) {
    if (e.case_index < paths_.size()) paths_[e.case_index] = std::max(paths_[e.case_index], e.path);
    ++(e.outcome == Outcome::Pass ? pr_.pass : pr_.fail);
  }
  pr_.executions = start.executions.size();
  pr_.run = start.next_run;
  pr_.campaign_ns = start.campaign_ns;
  pr_.scans = start.scans;
  pr_.cases_tested = static_cast<size_t>(std::count_if(paths_.begin(), paths_.end(), [](int p) { return p > 0; }));
  check_end();
}

void RunSequencer::check_end() {
  if (ended_) return;
  if (std::all_of(paths_.begin(), paths_.end(), [&](int p) { return p >= lim_.max_paths; })) {
    ended_ = true;
    end_reason_ = fmt::format("every case tested on {} path(s)", lim_.max_paths);
  } else if (pr_.campaign_ns >= lim_.budget_ns) {
    ended_ = true;
    end_reason_ = fmt::format("time budget of {} spent", human_duration(lim_.budget_ns));
  }
}

bool RunSequencer::feed(const RunRecord& rec, Fed* out, std::string* err) {
  *out = Fed{};
  if (ended_) {
    *err = fmt::format("run {}: the campaign has ended already ({})", rec.run, end_reason_);
    return false;
  }
  if (rec.run != pr_.run) {
    *err = fmt::format("expected the record of run {}, found run {}", pr_.run, rec.run);
    return false;
  }
  if (rec.kind == RunRecord::Kind::Claimed) {
    *err = fmt::format("run {}: a claimed run is tested by its owner, its record cannot stand for it", rec.run);
    return false;
  }
  if (lim_.tick_ns <= 0 || rec.ns != static_cast<int64_t>(rec.scans) * lim_.tick_ns) {
    *err = fmt::format("run {}: {} scans took {} ns, not one tick of {} ns each: shares need virtual time", rec.run,
                       rec.scans, rec.ns, lim_.tick_ns);
    return false;
  }
  const bool executed = rec.kind == RunRecord::Kind::Executed;
  if (executed && (rec.inject_scan == 0 || rec.inject_scan > rec.scans)) {
    *err = fmt::format("run {}: an execution without its injection scan", rec.run);
    return false;
  }
  const size_t c = rec.exec.case_index;
  if (executed && (c >= paths_.size() || rec.exec.path != paths_[c] + 1)) {
    *err = fmt::format("run {}: case {} path {} does not follow the paths tested before", rec.run, rec.exec.case_id,
                       rec.exec.path);
    return false;
  }
  // The single run checks the budget after each scan of the search: the scans before the
  // injection, or all but a last one that ended the search (window, stop).
  uint64_t checked = executed ? rec.inject_scan - 1 : rec.end == "budget" ? rec.scans : rec.scans > 0 ? rec.scans - 1 : 0;
  const int64_t left = lim_.budget_ns - pr_.campaign_ns;  // > 0: not ended
  const uint64_t cut = static_cast<uint64_t>((left + lim_.tick_ns - 1) / lim_.tick_ns);  // scans until it is spent
  if (cut <= checked) {
    pr_.scans += cut;
    pr_.campaign_ns += static_cast<int64_t>(cut) * lim_.tick_ns;
    ++pr_.run;
    ended_ = true;
    end_reason_ = fmt::format("time budget of {} spent", human_duration(lim_.budget_ns));
    return true;
  }
  if (!executed && rec.end == "budget") {
    *err = fmt::format("run {}: its share stopped on the time budget, the campaign would not have: shards of another budget?",
                       rec.run);
    return false;
  }
  pr_.scans += rec.scans;
  pr_.campaign_ns += rec.ns;
  ++pr_.run;
  if (!executed) {
    ended_ = true;
    if (rec.end == "window")
      end_reason_ = fmt::format("no untested case or path within the search window of {}", human_duration(lim_.search_window_ns));
    else if (rec.end.rfind("stopped: ", 0) == 0)
      end_reason_ = "the program stopped outside a test: " + rec.end.substr(9);
    else {
      *err = fmt::format("run {}: unknown end '{}'", rec.run, rec.end);
      return false;
    }
    return true;
  }
  paths_[c] = rec.exec.path;
  ++pr_.executions;
  ++(rec.exec.outcome == Outcome::Pass ? pr_.pass : pr_.fail);
  pr_.cases_tested = static_cast<size_t>(std::count_if(paths_.begin(), paths_.end(), [](int p) { return p > 0; }));
  Json line;
  std::string why;
  size_t column = 0;
  if (!common::json_parse(rec.line, &line, &why, &column) || !line.is_object() || !member(line, "campaign_ns") ||
      !member(line, "scans")) {
    *err = fmt::format("run {}: not a journal line: {}", rec.run, rec.line.substr(0, 80));
    return false;
  }
  line["campaign_ns"] = pr_.campaign_ns;
  line["scans"] = pr_.scans;
  out->executed = true;
  out->line = common::json_compact(line);
  out->object = std::move(line);
  check_end();
  return true;
}

// ---------------------------------------------------------------------------------------
// Records

std::string record_json(const RunRecord& r) {
  Json j;
  j["run"] = r.run;
  j["kind"] = r.kind == RunRecord::Kind::Executed ? "executed" : r.kind == RunRecord::Kind::Claimed ? "claimed" : "ended";
  j["scans"] = r.scans;
  j["ns"] = r.ns;
  j["inject_scan"] = r.inject_scan;
  if (r.kind == RunRecord::Kind::Ended) {
    j["end"] = r.end;
  } else {
    j["case"] = r.exec.case_index;
    j["case_id"] = r.exec.case_id;
    j["path"] = r.exec.path;
    j["verdict"] = outcome_name(r.exec.outcome);
    j["vcd"] = r.exec.vcd;
    j["line"] = r.line;
  }
  return common::json_compact(j);
}

bool parse_record(const std::string& text, RunRecord* r, std::string* why) {
  Json j;
  size_t column = 0;
  if (!common::json_parse(text, &j, why, &column)) {
    *why = fmt::format("column {}: {}", column, *why);
    return false;
  }
  *r = RunRecord{};
  std::string kind;
  int64_t run = 0, scans = 0, inject = 0;
  if (!j.is_object() || !get_i64(j, "run", &run) || !get_string(j, "kind", &kind) || !get_i64(j, "scans", &scans) ||
      !get_i64(j, "ns", &r->ns) || !get_i64(j, "inject_scan", &inject) || run < 0 || scans < 0 || inject < 0) {
    *why = "not a run record (run, kind, scans, ns, inject_scan)";
    return false;
  }
  r->run = static_cast<uint64_t>(run);
  r->scans = static_cast<uint64_t>(scans);
  r->inject_scan = static_cast<uint64_t>(inject);
  if (kind == "ended") {
    r->kind = RunRecord::Kind::Ended;
    if (!get_string(j, "end", &r->end)) {
      *why = "an ended run without its end";
      return false;
    }
    return true;
  }
  if (kind != "executed") {
    *why = "kind '" + kind + "' is not executed or ended";
    return false;
  }
  r->kind = RunRecord::Kind::Executed;
  int64_t c = 0, path = 0;
  std::string verdict;
  if (!get_i64(j, "case", &c) || c < 0 || !get_i64(j, "path", &path) || path < 1 || path > 1'000'000 ||
      !get_string(j, "case_id", &r->exec.case_id) || !get_string(j, "verdict", &verdict) ||
      !get_string(j, "line", &r->line)) {
    *why = "an executed run without case, case_id, path, verdict or line";
    return false;
  }
  get_string(j, "vcd", &r->exec.vcd);
  r->exec.case_index = static_cast<size_t>(c);
  r->exec.path = static_cast<int>(path);
  r->exec.run = r->run;
  r->exec.outcome = verdict == "PASS" ? Outcome::Pass : Outcome::Fail;
  return true;
}

bool parse_share(const std::string& text, int* k, int* n, std::string* why) {
  const size_t slash = text.find('/');
  auto number = [](const std::string& s, long* v) {
    if (s.empty() || s.size() > 5 || !std::all_of(s.begin(), s.end(), [](char ch) { return ch >= '0' && ch <= '9'; }))
      return false;
    *v = std::stol(s);
    return true;
  };
  long kk = 0, nn = 0;
  if (slash == std::string::npos || !number(text.substr(0, slash), &kk) || !number(text.substr(slash + 1), &nn)) {
    *why = "'" + text + "' is not K/N (e.g. 0/4: the first of four shares)";
    return false;
  }
  if (nn < 1 || nn > 1024) {
    *why = fmt::format("'{}': N must be 1..1024", text);
    return false;
  }
  if (kk >= nn) {
    *why = fmt::format("'{}': K must be 0..{} (shares count from 0, as Slurm array and Kubernetes job indexes do)", text, nn - 1);
    return false;
  }
  *k = static_cast<int>(kk);
  *n = static_cast<int>(nn);
  return true;
}

// ---------------------------------------------------------------------------------------
// Worker processes

namespace {

struct Worker {
  pid_t pid = -1;
  int fd = -1;
  std::string buf;
  std::deque<RunRecord> queue;
  bool done = false;   // sent its closing line
  bool eof = false;
  int status = 0;
  bool reaped = false;
};

void reap_all(std::vector<Worker>& w, bool kill_them) {
  for (auto& x : w) {
    if (x.pid > 0 && !x.reaped) {
      if (kill_them) ::kill(x.pid, SIGKILL);
      while (::waitpid(x.pid, &x.status, 0) < 0 && errno == EINTR) {
      }
      x.reaped = true;
    }
    if (x.fd >= 0) {
      ::close(x.fd);
      x.fd = -1;
    }
  }
}

[[noreturn]] void worker_main(CampaignBuild& cb, const DriverOptions& opt, const JournalState& st, int k, int n, int fd) {
  ::signal(SIGPIPE, SIG_IGN);
  DriverOptions o;
  o.out_dir = opt.out_dir;
  o.vcd = opt.vcd;
  o.native = opt.native;
  o.share_k = k;
  o.share_n = n;
  o.resumed = &st;
  o.on_run = [&](const RunRecord& r) {
    if (r.kind == RunRecord::Kind::Claimed || r.run % static_cast<uint64_t>(n) != static_cast<uint64_t>(k)) return true;
    return common::write_all(fd, record_json(r) + "\n");
  };
  CampaignResult res;
  std::string err;
  bool ok = run_campaign(cb, o, &res, &err);
  Json last;
  if (ok) last["done"] = true;
  else last["error"] = err;
  common::write_all(fd, common::json_compact(last) + "\n");
  ::close(fd);
  ::_exit(ok ? 0 : 2);
}

}  // namespace

bool run_campaign_jobs(CampaignBuild& cb, int jobs, const DriverOptions& opt, CampaignResult* out, std::string* err) {
  auto wall0 = std::chrono::steady_clock::now();
  Journal journal;
  JournalState st;
  if (!opt.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(opt.out_dir, ec);
    if (ec) {
      *err = opt.out_dir + ": cannot create the output folder: " + ec.message();
      return false;
    }
    journal.set_plant(cb.spec.plant);
    if (!journal.open((std::filesystem::path(opt.out_dir) / "results.jsonl").string(), opt.resume, cb.spec.name,
                      campaign_fingerprint(cb), cb.cases, &st, err))
      return false;
  }
  RunSequencer seq(limits_of(cb), st);
  out->executions = st.executions;
  out->resumed = st.executions.size();

  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::vector<Worker> w(static_cast<size_t>(jobs));
  for (int k = 0; k < jobs; ++k) {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) {
      reap_all(w, true);
      *err = std::string("cannot create a pipe to a worker: ") + std::strerror(errno);
      return false;
    }
    pid_t pid = ::fork();
    if (pid < 0) {
      ::close(fds[0]);
      ::close(fds[1]);
      reap_all(w, true);
      *err = std::string("cannot start a worker process: ") + std::strerror(errno);
      return false;
    }
    if (pid == 0) {
      ::close(fds[0]);
      for (auto& x : w)
        if (x.fd >= 0) ::close(x.fd);
      worker_main(cb, opt, st, k, jobs, fds[1]);
    }
    ::close(fds[1]);
    w[static_cast<size_t>(k)].pid = pid;
    w[static_cast<size_t>(k)].fd = fds[0];
  }
  auto fail = [&](std::string msg) {
    reap_all(w, true);
    *err = std::move(msg);
    return false;
  };

  while (true) {
    // Take the owners' records in run order as far as they have arrived.
    while (!seq.ended()) {
      Worker& o = w[seq.next_run() % static_cast<uint64_t>(jobs)];
      if (o.queue.empty()) break;
      RunRecord rec = std::move(o.queue.front());
      o.queue.pop_front();
      RunSequencer::Fed fed;
      std::string why;
      if (!seq.feed(rec, &fed, &why)) return fail("worker " + std::to_string(seq.next_run() % jobs) + ": " + why);
      if (!fed.executed) {
        if (rec.kind == RunRecord::Kind::Executed) o.queue.push_front(std::move(rec));  // cut by the budget: not the campaign's
        continue;
      }
      if (journal.is_open() && !journal.append_line(fed.line, err)) return fail(*err);
      Execution e;
      if (!parse_execution(fed.object, cb.cases, &e, &why)) return fail("worker record: " + why);
      out->executions.push_back(e);
      if (opt.on_verdict) opt.on_verdict(out->executions.back(), seq.progress());
    }
    bool all_done = std::all_of(w.begin(), w.end(), [](const Worker& x) { return x.eof; });
    if (all_done) break;
    if (!seq.ended()) {
      const size_t owner = seq.next_run() % static_cast<uint64_t>(jobs);
      if (w[owner].eof && w[owner].queue.empty())
        return fail(fmt::format("worker {} ended before run {}", owner, seq.next_run()));
    }
    std::vector<pollfd> fds;
    std::vector<size_t> who;
    for (size_t k = 0; k < w.size(); ++k)
      if (!w[k].eof) {
        fds.push_back({w[k].fd, POLLIN, 0});
        who.push_back(k);
      }
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      return fail(std::string("poll: ") + std::strerror(errno));
    }
    for (size_t i = 0; i < fds.size(); ++i) {
      if (!(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      Worker& x = w[who[i]];
      char buf[65536];
      ssize_t n = ::read(x.fd, buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        x.eof = true;
        while (::waitpid(x.pid, &x.status, 0) < 0 && errno == EINTR) {
        }
        x.reaped = true;
        ::close(x.fd);
        x.fd = -1;
        if (!x.done) return fail(fmt::format("worker {} (pid {}) ended without a result: {}", who[i], x.pid, status_text(x.status)));
        continue;
      }
      x.buf.append(buf, static_cast<size_t>(n));
      for (size_t nl; (nl = x.buf.find('\n')) != std::string::npos;) {
        std::string line = x.buf.substr(0, nl);
        x.buf.erase(0, nl + 1);
        Json j;
        std::string why;
        size_t column = 0;
        if (common::json_parse(line, &j, &why, &column) && j.is_object()) {
          if (member(j, "done")) {
            x.done = true;
            continue;
          }
          if (member(j, "error")) {
            std::string msg;
            get_string(j, "error", &msg);
            return fail(msg);
          }
        }
        RunRecord rec;
        if (!parse_record(line, &rec, &why)) return fail(fmt::format("worker {}: {}", who[i], why));
        x.queue.push_back(std::move(rec));
      }
    }
  }
  reap_all(w, false);
  if (!seq.ended()) {
    *err = fmt::format("the workers ended before the campaign did (run {})", seq.next_run());
    return false;
  }
  // Runs a worker tested past the campaign's end (its share could not know the budget
  // was spent) are not the campaign's: their traces go.
  for (auto& x : w)
    for (const auto& r : x.queue)
      if (r.kind == RunRecord::Kind::Executed && !r.exec.vcd.empty() && !opt.out_dir.empty()) {
        std::error_code ec;
        std::filesystem::remove(std::filesystem::path(opt.out_dir) / r.exec.vcd, ec);
      }
  out->end_reason = seq.end_reason();
  out->progress = seq.progress();
  std::vector<bool> seen(cb.cases.size(), false);
  for (const auto& e : out->executions) seen[e.case_index] = true;
  for (size_t i = 0; i < seen.size(); ++i)
    if (!seen[i]) out->not_reached.push_back(i);
  out->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return true;
}

// ---------------------------------------------------------------------------------------
// Shard files

bool run_campaign_shard(CampaignBuild& cb, int k, int n, const DriverOptions& opt, const std::string& shard_path,
                        ShardSummary* out, std::string* err) {
  std::error_code ec;
  auto parent = std::filesystem::path(shard_path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  std::FILE* f = std::fopen(shard_path.c_str(), "w");
  if (!f) {
    *err = shard_path + ": cannot write the shard file: " + std::strerror(errno);
    return false;
  }
  const RunSequencer::Limits lim = limits_of(cb);
  Json head;
  head["journal"] = kShardJournal;
  head["campaign"] = cb.spec.name;
  head["shard"] = k;
  head["shards"] = n;
  head["fingerprint"] = campaign_fingerprint(cb);
  head["header"] = journal_header(cb.spec.name, cb.spec.plant, campaign_fingerprint(cb), cb.cases.size());
  head["budget_ns"] = lim.budget_ns;
  head["tick_ns"] = lim.tick_ns;
  head["search_window_ns"] = lim.search_window_ns;
  head["max_paths"] = lim.max_paths;
  Json ids = Json::array();
  for (const auto& c : cb.cases) ids.push_back(c.id);
  head["case_ids"] = ids;
  bool ok = true;
  auto put = [&](const std::string& line) {
    ok = ok && std::fputs((line + "\n").c_str(), f) >= 0;
    return ok;
  };
  put(common::json_compact(head));
  DriverOptions o;
  o.out_dir = opt.out_dir;
  o.vcd = opt.vcd;
  o.native = opt.native;
  o.on_progress = opt.on_progress;
  o.share_k = k;
  o.share_n = n;
  o.on_run = [&](const RunRecord& r) {
    if (r.kind == RunRecord::Kind::Claimed || r.run % static_cast<uint64_t>(n) != static_cast<uint64_t>(k)) return true;
    if (r.kind == RunRecord::Kind::Executed) {
      ++out->executions;
      ++(r.exec.outcome == Outcome::Pass ? out->pass : out->fail);
      if (opt.on_verdict) opt.on_verdict(r.exec, Progress{});
    }
    return put(record_json(r));
  };
  CampaignResult res;
  if (!run_campaign(cb, o, &res, err)) {
    std::fclose(f);
    return false;
  }
  Json tail;
  tail["complete"] = true;
  tail["runs"] = res.progress.run;
  put(common::json_compact(tail));
  ok = ok && std::fflush(f) == 0 && ::fsync(fileno(f)) == 0;
  ok = std::fclose(f) == 0 && ok;
  if (!ok) {
    *err = shard_path + ": cannot write the shard file";
    return false;
  }
  out->runs = res.progress.run;
  out->end_reason = res.end_reason;
  return true;
}

bool is_campaign_shard(const std::string& path) {
  std::string text, err;
  if (!common::read_file(path, common::kMaxJournalBytes, &text, &err)) return false;
  Json j;
  size_t column = 0;
  std::string first = text.substr(0, text.find('\n'));
  std::string journal;
  return common::json_parse(first, &j, &err, &column) && j.is_object() && get_string(j, "journal", &journal) &&
         journal == kShardJournal;
}

bool merge_shards(const std::vector<std::string>& files, const std::string& journal_path, MergeResult* out,
                  std::string* err) {
  struct Shard {
    std::string path;
    std::vector<std::pair<uint32_t, RunRecord>> records;  // (line, record)
    size_t next = 0;
  };
  Json first_head;
  std::string first_path;
  std::vector<Shard> shards;
  std::vector<std::string> owner_path;
  int n = 0;
  for (const auto& path : files) {
    std::string text;
    if (!common::read_file(path, common::kMaxJournalBytes, &text, err)) return false;
    Shard s;
    s.path = path;
    Json head;
    bool complete = false;
    uint32_t line_no = 0;
    for (size_t begin = 0; begin < text.size();) {
      size_t end = text.find('\n', begin);
      ++line_no;
      if (end == std::string::npos) {
        *err = fmt::format("{}:{}:1: the last line is cut off (was the shard stopped while writing?); run the shard again",
                           path, line_no);
        return false;
      }
      std::string line = text.substr(begin, end - begin);
      begin = end + 1;
      if (complete) {
        *err = fmt::format("{}:{}:1: a line after the shard's closing line", path, line_no);
        return false;
      }
      Json j;
      std::string why;
      size_t column = 1;
      if (!common::json_parse(line, &j, &why, &column) || !j.is_object()) {
        *err = fmt::format("{}:{}:{}: not a shard line ({})", path, line_no, column, why.empty() ? "not an object" : why);
        return false;
      }
      if (line_no == 1) {
        std::string journal;
        int64_t k = -1, nn = 0;
        if (!get_string(j, "journal", &journal) || journal != kShardJournal || !get_i64(j, "shard", &k) ||
            !get_i64(j, "shards", &nn) || nn < 1 || k < 0 || k >= nn) {
          *err = path + ":1:1: not a plcfi campaign shard file (written by plcfi campaign --shard K/N)";
          return false;
        }
        // The campaign's limits and cases, as a shard writes them.
        int64_t budget = 0, tick = 0, window = 0, paths = 0;
        std::string name;
        const Json* ids = member(j, "case_ids");
        bool ok = get_i64(j, "budget_ns", &budget) && budget > 0 && get_i64(j, "tick_ns", &tick) && tick > 0 &&
                  get_i64(j, "search_window_ns", &window) && window > 0 && get_i64(j, "max_paths", &paths) &&
                  paths >= 1 && paths <= 1'000'000 && get_string(j, "campaign", &name) && get_string(j, "header", &name) &&
                  ids && ids->is_array();
        for (size_t i = 0; ok && i < ids->size(); ++i) ok = (*ids)[i].is_string();
        if (!ok) {
          *err = path + ":1:1: the shard header lacks the campaign's limits or cases (budget_ns, tick_ns, search_window_ns, "
                        "max_paths > 0, campaign, header, case_ids): not written by plcfi campaign --shard";
          return false;
        }
        head = j;
        if (shards.empty()) {
          first_head = j;
          first_path = path;
          n = static_cast<int>(nn);
          owner_path.assign(static_cast<size_t>(n), "");
        } else {
          Json a = first_head, b = j;
          a.erase("shard");
          b.erase("shard");
          if (a != b) {
            *err = fmt::format("{}:1:1: another campaign, program or share count than {} (every shard of a merge must come "
                               "from the same campaign file, program, seed and N)",
                               path, first_path);
            return false;
          }
        }
        const size_t kk = static_cast<size_t>(k);
        if (!owner_path[kk].empty()) {
          *err = fmt::format("{}: shard {}/{} given twice (also {})", path, k, n, owner_path[kk]);
          return false;
        }
        owner_path[kk] = path;
        continue;
      }
      if (member(j, "complete")) {
        complete = true;
        continue;
      }
      RunRecord r;
      if (!parse_record(line, &r, &why)) {
        *err = fmt::format("{}:{}:1: {}", path, line_no, why);
        return false;
      }
      s.records.emplace_back(line_no, std::move(r));
    }
    if (line_no == 0) {
      *err = path + ": empty file, not a shard";
      return false;
    }
    if (!complete) {
      *err = path + ": incomplete: no closing line (the shard was stopped before its end); run it again";
      return false;
    }
    shards.push_back(std::move(s));
  }
  if (shards.empty()) {
    *err = "no shard files given";
    return false;
  }
  for (int k = 0; k < n; ++k)
    if (owner_path[static_cast<size_t>(k)].empty()) {
      *err = fmt::format("shard {}/{} is missing (given: {} of {})", k, n, shards.size(), n);
      return false;
    }
  std::vector<Shard*> by_k(static_cast<size_t>(n));
  for (auto& s : shards)
    for (int k = 0; k < n; ++k)
      if (owner_path[static_cast<size_t>(k)] == s.path) by_k[static_cast<size_t>(k)] = &s;

  RunSequencer::Limits lim;
  get_i64(first_head, "budget_ns", &lim.budget_ns);
  get_i64(first_head, "tick_ns", &lim.tick_ns);
  get_i64(first_head, "search_window_ns", &lim.search_window_ns);
  int64_t mp = 1;
  get_i64(first_head, "max_paths", &mp);
  lim.max_paths = static_cast<int>(mp);
  std::vector<std::string> ids;
  for (const auto& id : first_head["case_ids"])
    if (id.is_string()) ids.push_back(id.get<std::string>());
  lim.cases = ids.size();
  RunSequencer seq(lim, JournalState{});
  std::string journal = first_head["header"].is_string() ? first_head["header"].get<std::string>() + "\n" : "";
  get_string(first_head, "campaign", &out->campaign);
  std::vector<bool> seen(ids.size(), false);
  std::vector<std::filesystem::path> traces;  // of the campaign's executions, beside their shard files
  while (!seq.ended()) {
    Shard& s = *by_k[seq.next_run() % static_cast<uint64_t>(n)];
    if (s.next >= s.records.size()) {
      *err = fmt::format("{}: has no record of run {}, which the campaign needs (shards of different programs or plants?)",
                         s.path, seq.next_run());
      return false;
    }
    auto& [line_no, rec] = s.records[s.next++];
    if (rec.kind == RunRecord::Kind::Executed && rec.exec.case_index >= ids.size()) {
      *err = fmt::format("{}:{}:1: case {} does not exist", s.path, line_no, rec.exec.case_index);
      return false;
    }
    RunSequencer::Fed fed;
    std::string why;
    if (!seq.feed(rec, &fed, &why)) {
      *err = fmt::format("{}:{}:1: {}", s.path, line_no, why);
      return false;
    }
    if (!fed.executed) continue;
    journal += fed.line + "\n";
    if (!rec.exec.vcd.empty()) traces.emplace_back(std::filesystem::path(s.path).parent_path() / rec.exec.vcd);
    seen[rec.exec.case_index] = true;
    const Json& j = fed.object;
    MergedExecution m;
    m.case_id = rec.exec.case_id;
    m.path = rec.exec.path;
    m.run = rec.run;
    get_string(j, "transition", &m.transition);
    get_string(j, "verdict", &m.verdict);
    get_string(j, "reason", &m.reason);
    out->executions.push_back(std::move(m));
  }
  for (size_t i = 0; i < ids.size(); ++i)
    if (!seen[i]) out->not_reached.push_back(ids[i]);
  out->cases = ids.size();
  out->progress = seq.progress();
  out->end_reason = seq.end_reason();
  auto parent = std::filesystem::path(journal_path).parent_path();
  std::error_code ec;
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  // The traces join the journal, so the folder is the one a single run fills.
  for (const auto& t : traces) {
    std::error_code cec;
    if (std::filesystem::exists(t, cec) &&
        std::filesystem::copy_file(t, (parent.empty() ? std::filesystem::path(".") : parent) / t.filename(),
                                   std::filesystem::copy_options::overwrite_existing, cec))
      ++out->traces_copied;
    else
      out->traces_missing.push_back(t.string());
  }
  std::FILE* f = std::fopen(journal_path.c_str(), "w");
  bool ok = f && std::fwrite(journal.data(), 1, journal.size(), f) == journal.size() && std::fflush(f) == 0 &&
            ::fsync(fileno(f)) == 0;
  if (f) ok = std::fclose(f) == 0 && ok;
  if (!ok) *err = journal_path + ": cannot write the journal";
  return ok;
}

}  // namespace plcfi::campaign

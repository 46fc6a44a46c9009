// Mutation analysis: the campaign on the original (the baseline) and on each mutant, in
// this process or in forked workers, the mutants.jsonl journal, shard merging, the report.
#include "mutate.hpp"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include "common/file.hpp"
#include "common/hash.hpp"
#include "common/json.hpp"

namespace plcfi::campaign {

const char* mutant_status_name(MutantStatus s) {
  switch (s) {
    case MutantStatus::Killed: return "killed";
    case MutantStatus::Survived: return "survived";
    case MutantStatus::Equivalent: return "equivalent";
  }
  return "?";
}

bool run_baseline(CampaignBuild& cb, Baseline* out, std::string* err) {
  DriverOptions opt;
  opt.vcd = false;
  CampaignResult res;
  if (!run_campaign(cb, opt, &res, err)) return false;
  out->passed.assign(cb.cases.size(), false);
  out->tested.assign(cb.cases.size(), false);
  for (const auto& e : res.executions) {
    out->tested[e.case_index] = true;
    if (e.outcome == Outcome::Pass) out->passed[e.case_index] = true;
    ++(e.outcome == Outcome::Pass ? out->pass : out->fail);
  }
  out->executions = res.executions.size();
  out->end_reason = res.end_reason;
  return true;
}

namespace {

constexpr const char* kStopped = "program stopped: ";
constexpr const char* kStoppedOutside = "the program stopped outside a test: ";

bool bit_set(const std::vector<uint64_t>& bits, int32_t b) {
  auto w = static_cast<size_t>(b) / 64;
  return b >= 0 && w < bits.size() && (bits[w] >> (static_cast<size_t>(b) % 64) & 1u);
}

std::string short_file(const std::string& f) { return std::filesystem::path(f).filename().string(); }

}  // namespace

MutantResult evaluate_mutant(CampaignBuild& cb, const Baseline& base, const Mutant& m, std::string* err) {
  MutantResult r;
  if (m.equivalent) {
    r.status = MutantStatus::Equivalent;
    r.detail = m.proof;
    return r;
  }
  std::vector<CodePatch> undo_code;
  std::vector<ImagePatch> undo_image;
  apply_mutant(cb, m, &undo_code, &undo_image);
  std::vector<uint64_t> window;
  const Execution* killer = nullptr;
  DriverOptions opt;
  opt.vcd = false;
  opt.window_branches = &window;
  opt.stop_after = [&](const Execution& e) {
    bool trap = e.reason.rfind(kStopped, 0) == 0;
    if (e.outcome == Outcome::Fail && (trap || base.passed[e.case_index])) {
      killer = &e;
      return true;
    }
    return false;
  };
  CampaignResult res;
  bool ok = run_campaign(cb, opt, &res, err);
  undo_mutant(cb, undo_code, undo_image);
  if (!ok) return r;
  r.executions = res.executions.size();
  r.reached = m.branch >= 0 ? bit_set(window, m.branch) : m.branch_known && r.executions > 0;
  if (killer) {
    const Execution& e = res.executions.back();  // stop_after ended the campaign on it
    r.status = MutantStatus::Killed;
    r.kill = e.reason.rfind(kStopped, 0) == 0 ? "trap" : "fail";
    r.killed_by = fmt::format("{} path {}", e.case_id, e.path);
    r.detail = e.reason;
    return r;
  }
  if (res.end_reason.rfind(kStoppedOutside, 0) == 0) {
    r.status = MutantStatus::Killed;
    r.kill = "trap";
    r.detail = res.end_reason;
    return r;
  }
  std::vector<bool> tested(cb.cases.size(), false);
  for (const auto& e : res.executions) tested[e.case_index] = true;
  for (size_t i = 0; i < tested.size(); ++i)
    if (base.tested[i] && !tested[i]) {
      r.status = MutantStatus::Killed;
      r.kill = "not-reached";
      r.killed_by = cb.cases[i].id;
      r.detail = fmt::format("{} NOT REACHED: its precondition never held on the mutant ({})", cb.cases[i].id, res.end_reason);
      return r;
    }
  r.status = MutantStatus::Survived;
  std::string where = fmt::format("{}:{}", short_file(m.file), m.line);
  const st::Application& app = *cb.build->app;
  if (m.branch >= 0 && !r.reached) {
    const auto& bp = app.branches[static_cast<size_t>(m.branch)];
    r.detail = fmt::format("no test window executed {}: its {} branch at line {} was never taken after an injection "
                           "({} execution(s), all as on the original)",
                           where, bp.kind, bp.loc.line, r.executions);
  } else if (m.branch >= 0) {
    const auto& bp = app.branches[static_cast<size_t>(m.branch)];
    r.detail = fmt::format("the {} branch at line {} holding it ran in test windows, yet every verdict stayed as on the original "
                           "({} execution(s)): the requirement is met without it, or no case observes what it changes",
                           bp.kind, bp.loc.line, r.executions);
  } else if (m.branch_known && r.reached) {
    r.detail = fmt::format("it runs on every call of {}, in test windows too, yet every verdict stayed as on the original "
                           "({} execution(s)): the requirement is met without it, or no case observes what it changes",
                           m.pou ? m.pou->name : "its POU", r.executions);
  } else {
    r.detail = fmt::format("every verdict stayed as on the original ({} execution(s)); branch coverage cannot tell whether a "
                           "test window executed {} (code after a join)",
                           r.executions, where);
  }
  if (!m.writers.empty() && (r.reached || m.branch < 0)) r.detail += fmt::format("; {} also written at {}", m.variable, m.writers);
  return r;
}

namespace {

common::Json result_json(const MutantResult& r) {
  common::Json j;
  j["status"] = mutant_status_name(r.status);
  j["kill"] = r.kill;
  j["killed_by"] = r.killed_by;
  j["detail"] = r.detail;
  j["executions"] = r.executions;
  j["reached"] = r.reached;
  return j;
}

bool result_from_json(const common::Json& j, MutantResult* r) {
  try {
    std::string s = j.at("status").get<std::string>();
    r->status = s == "killed" ? MutantStatus::Killed : s == "survived" ? MutantStatus::Survived : MutantStatus::Equivalent;
    r->kill = j.at("kill").get<std::string>();
    r->killed_by = j.at("killed_by").get<std::string>();
    r->detail = j.at("detail").get<std::string>();
    r->executions = j.at("executions").get<size_t>();
    r->reached = j.at("reached").get<bool>();
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

// Reads one '\n'-terminated message; false at end of file.
bool read_line(int fd, std::string* buf, std::string* line) {
  while (true) {
    size_t nl = buf->find('\n');
    if (nl != std::string::npos) {
      *line = buf->substr(0, nl);
      buf->erase(0, nl + 1);
      return true;
    }
    char tmp[4096];
    ssize_t n = ::read(fd, tmp, sizeof tmp);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    buf->append(tmp, static_cast<size_t>(n));
  }
}

// A worker: reads mutant indexes, one per line, answers each with its result as JSON.
[[noreturn]] void worker_main(CampaignBuild& cb, const Baseline& base, const std::vector<Mutant>& mutants, int in, int out) {
  std::string buf, line;
  while (read_line(in, &buf, &line)) {
    size_t i = std::stoul(line);
    std::string err;
    MutantResult r = evaluate_mutant(cb, base, mutants[i], &err);
    common::Json j;
    j["index"] = i;
    j["error"] = err;
    j["result"] = result_json(r);
    if (!common::write_all(out, common::json_compact(j) + "\n")) _exit(3);
  }
  _exit(0);
}

struct Worker {
  pid_t pid = -1;
  int to = -1, from = -1;
  std::string buf;
  bool busy = false;
};

bool run_parallel(CampaignBuild& cb, const Baseline& base, const std::vector<Mutant>& mutants, const std::vector<size_t>& todo,
                  unsigned jobs, std::vector<MutantResult>* results, std::string* err) {
  std::vector<Worker> ws(std::min<size_t>(jobs, todo.size()));
  bool ok = true;
  // A worker that died must show as an error here (EPIPE), not end this process.
  struct IgnorePipe {
    struct sigaction old {};
    IgnorePipe() {
      struct sigaction sa {};
      sa.sa_handler = SIG_IGN;
      ::sigaction(SIGPIPE, &sa, &old);
    }
    ~IgnorePipe() { ::sigaction(SIGPIPE, &old, nullptr); }
  } ignore_pipe;
  for (auto& w : ws) {
    int a[2], b[2];
    if (::pipe(a) != 0 || ::pipe(b) != 0) {
      *err = std::string("cannot create a pipe: ") + std::strerror(errno);
      ok = false;
      break;
    }
    pid_t pid = ::fork();
    if (pid < 0) {
      *err = std::string("cannot fork a worker: ") + std::strerror(errno);
      ok = false;
      break;
    }
    if (pid == 0) {
      ::close(a[1]);
      ::close(b[0]);
      for (auto& o : ws)  // the earlier workers' pipe ends are not this worker's
        if (o.pid > 0) {
          ::close(o.to);
          ::close(o.from);
        }
      worker_main(cb, base, mutants, a[0], b[1]);
    }
    ::close(a[0]);
    ::close(b[1]);
    w.pid = pid;
    w.to = a[1];
    w.from = b[0];
  }
  size_t next = 0, done = 0;
  auto hand_out = [&](Worker& w) {
    if (next < todo.size()) {
      w.busy = common::write_all(w.to, fmt::format("{}\n", todo[next++]));
      if (!w.busy) {
        *err = "a worker stopped taking mutants";
        ok = false;
      }
    }
  };
  if (ok)
    for (auto& w : ws) hand_out(w);
  while (ok && done < todo.size()) {
    std::vector<pollfd> fds;
    for (auto& w : ws) fds.push_back({w.from, POLLIN, 0});
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      *err = std::string("poll: ") + std::strerror(errno);
      ok = false;
      break;
    }
    for (size_t k = 0; k < ws.size() && ok; ++k) {
      if (!(fds[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      std::string line;
      if (!read_line(ws[k].from, &ws[k].buf, &line)) {
        *err = fmt::format("worker {} ended before its mutant was judged", ws[k].pid);
        ok = false;
        break;
      }
      common::Json j;
      std::string perr;
      size_t col = 0;
      MutantResult r;
      if (!common::json_parse(line, &j, &perr, &col) || !result_from_json(j["result"], &r)) {
        *err = "a worker's answer is garbled: " + perr;
        ok = false;
        break;
      }
      if (!j["error"].get<std::string>().empty()) {
        *err = j["error"].get<std::string>();
        ok = false;
        break;
      }
      (*results)[j["index"].get<size_t>()] = r;
      ++done;
      ws[k].busy = false;
      hand_out(ws[k]);
    }
  }
  for (auto& w : ws) {
    if (w.to >= 0) ::close(w.to);  // end of input: the worker exits
    if (w.from >= 0) ::close(w.from);
  }
  for (auto& w : ws) {
    if (w.pid <= 0) continue;
    if (!ok) ::kill(w.pid, SIGTERM);
    int status = 0;
    while (::waitpid(w.pid, &status, 0) < 0 && errno == EINTR) {
    }
  }
  return ok;
}

std::string run_fingerprint(const CampaignBuild& cb, const std::vector<Mutant>& mutants) {
  common::Fnv64 h;
  h.add(campaign_fingerprint(cb));
  for (const auto& m : mutants) {
    h.add(mutation_op_name(m.op));
    h.add(m.change);
    for (const auto& c : m.code)
      for (uint32_t w : c.words) h.add(fmt::format("{}:{}", c.pc, w));
    for (const auto& i : m.image)
      for (uint8_t b : i.bytes) h.add(fmt::format("{}:{}", i.addr, b));
  }
  return h.hex();
}

}  // namespace

bool run_mutation(CampaignBuild& cb, const MutateOptions& opt, MutationRun* out, std::string* err) {
  auto wall0 = std::chrono::steady_clock::now();
  if (cb.build->app->condition_chains || cb.build->app->copied_statements || cb.build->app->if_selects ||
      cb.build->app->elsif_reuse || cb.build->app->cold_arms) {
    // The operators patch one jump per IF and one store per assignment (mutate_gen.cpp).
    *err = "plcfi mutate: internal: the program was compiled with conditions as chains of jumps, statements copied "
           "into arms, IFs as selects, ELSIFs reading their predecessor's element or arms that leave a loop placed last "
           "(Campaign::for_mutation)";
    return false;
  }
  out->mutants = generate_mutants(cb);
  out->fingerprint = run_fingerprint(cb, out->mutants);
  if (!run_baseline(cb, &out->baseline, err)) return false;
  size_t n = out->mutants.size();
  out->results.assign(n, MutantResult{});
  out->evaluated.assign(n, false);
  std::vector<size_t> todo;
  for (size_t i = 0; i < n; ++i) {
    if (opt.shards && i % opt.shards != opt.shard) continue;
    out->evaluated[i] = true;
    if (out->mutants[i].equivalent) {
      out->results[i].status = MutantStatus::Equivalent;
      out->results[i].detail = out->mutants[i].proof;
    } else {
      todo.push_back(i);
    }
  }
  if (opt.jobs > 1 && todo.size() > 1) {
    if (!run_parallel(cb, out->baseline, out->mutants, todo, opt.jobs, &out->results, err)) return false;
  } else {
    for (size_t i : todo) {
      std::string e;
      out->results[i] = evaluate_mutant(cb, out->baseline, out->mutants[i], &e);
      if (!e.empty()) {
        *err = e;
        return false;
      }
    }
  }
  out->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (!opt.out_dir.empty() && !write_mutation_journal(cb, *out, opt, err)) return false;
  return true;
}

std::string mutation_header_line(const CampaignBuild& cb, const MutationRun& run, const MutateOptions& opt) {
  common::Json j;
  j["plcfi"] = "mutants";
  j["version"] = 1;
  j["campaign"] = cb.spec.name;
  common::Json programs = common::Json::array();
  for (const auto& p : cb.spec.programs) programs.push_back(short_file(p));
  j["programs"] = programs;
  j["seed"] = cb.spec.seed;
  j["fingerprint"] = run.fingerprint;
  j["mutants"] = run.mutants.size();
  j["baseline"] = {{"executions", run.baseline.executions}, {"pass", run.baseline.pass}, {"fail", run.baseline.fail}};
  j["shard"] = opt.shards ? common::Json(fmt::format("{}/{}", opt.shard, opt.shards)) : common::Json(nullptr);
  return common::json_compact(j);
}

std::string mutant_line(const Mutant& m, const MutantResult& r) {
  common::Json j;
  j["index"] = m.index;
  j["operator"] = mutation_op_name(m.op);
  j["file"] = short_file(m.file);
  j["line"] = m.line;
  j["col"] = m.col;
  j["variable"] = m.variable;
  j["change"] = m.change;
  const common::Json result = result_json(r);
  for (auto it = result.begin(); it != result.end(); ++it) j[it.key()] = *it;  // the result's fields, in their order
  return common::json_compact(j);
}

namespace {

bool write_text(const std::string& path, const std::string& text, std::string* err) {
  std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << text;
    if (!f.flush()) {
      *err = tmp + ": cannot write";
      return false;
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    *err = path + ": " + ec.message();
    return false;
  }
  return true;
}

}  // namespace

bool write_mutation_journal(const CampaignBuild& cb, const MutationRun& run, const MutateOptions& opt, std::string* err) {
  std::error_code ec;
  std::filesystem::create_directories(opt.out_dir, ec);
  if (ec) {
    *err = opt.out_dir + ": cannot create the output folder: " + ec.message();
    return false;
  }
  std::string text = mutation_header_line(cb, run, opt) + "\n";
  for (size_t i = 0; i < run.mutants.size(); ++i)
    if (run.evaluated[i]) text += mutant_line(run.mutants[i], run.results[i]) + "\n";
  return write_text((std::filesystem::path(opt.out_dir) / "mutants.jsonl").string(), text, err);
}

bool merge_mutant_journals(const std::vector<std::string>& inputs, const std::string& out_path, std::string* err) {
  if (inputs.empty()) {
    *err = "no shard journals to merge";
    return false;
  }
  std::string header_rest;  // the header without its shard, as a single run writes it
  size_t total = 0, shards = 0;
  std::map<size_t, std::string> shard_file;
  std::map<size_t, std::string> lines;
  for (const auto& path : inputs) {
    std::string text, rerr;
    if (!common::read_file(path, common::kMaxJournalBytes, &text, &rerr)) {
      *err = rerr;
      return false;
    }
    size_t pos = 0, line_no = 0;
    common::Json header;
    size_t k = 0;
    while (pos < text.size()) {
      size_t nl = text.find('\n', pos);
      if (nl == std::string::npos) {
        *err = fmt::format("{}:{}: the journal ends inside a line (an interrupted run?)", path, line_no + 1);
        return false;
      }
      std::string line = text.substr(pos, nl - pos);
      pos = nl + 1;
      ++line_no;
      common::Json j;
      std::string perr;
      size_t col = 0;
      if (!common::json_parse(line, &j, &perr, &col) || !j.is_object()) {
        *err = fmt::format("{}:{}:{}: not a JSON object: {}", path, line_no, col, perr);
        return false;
      }
      if (line_no == 1) {
        const bool named = j.contains("plcfi") && j["plcfi"].is_string() && j["plcfi"].get<std::string>() == "mutants";
        if (!named || !j.contains("shard") || !j.contains("mutants") || !j["mutants"].is_number_unsigned()) {
          *err = fmt::format("{}:1:1: not a plcfi mutants journal", path);
          return false;
        }
        if (!j["shard"].is_string()) {
          *err = fmt::format("{}:1:1: not a shard journal (no shard in its header)", path);
          return false;
        }
        std::string s = j["shard"].get<std::string>();
        unsigned a = 0, b = 0;
        char slash = 0;
        if (std::sscanf(s.c_str(), "%u%c%u", &a, &slash, &b) != 3 || slash != '/' || b == 0 || a >= b) {
          *err = fmt::format("{}:1:1: bad shard '{}'", path, s);
          return false;
        }
        k = a;
        size_t n = j["mutants"].get<size_t>();
        j["shard"] = nullptr;
        std::string rest = common::json_compact(j);
        if (header_rest.empty()) {
          header_rest = rest;
          total = n;
          shards = b;
        } else if (rest != header_rest || b != shards) {
          *err = fmt::format("{}:1:1: another mutation run than {} (fingerprint, campaign or shard count differ)", path,
                             inputs.front());
          return false;
        }
        if (!shard_file.emplace(k, path).second) {
          *err = fmt::format("{}:1:1: shard {}/{} also in {}", path, k, shards, shard_file[k]);
          return false;
        }
        header = j;
        continue;
      }
      if (!j.contains("index") || !j["index"].is_number_unsigned()) {
        *err = fmt::format("{}:{}:1: a mutant line without an index", path, line_no);
        return false;
      }
      size_t i = j["index"].get<size_t>();
      if (i >= total || i % shards != k) {
        *err = fmt::format("{}:{}:1: mutant #{} does not belong to shard {}/{}", path, line_no, i, k, shards);
        return false;
      }
      if (!lines.emplace(i, line).second) {
        *err = fmt::format("{}:{}:1: mutant #{} twice", path, line_no, i);
        return false;
      }
    }
    if (line_no == 0) {
      *err = path + ": empty journal";
      return false;
    }
  }
  for (size_t k = 0; k < shards; ++k)
    if (!shard_file.count(k)) {
      *err = fmt::format("shard {}/{} is missing", k, shards);
      return false;
    }
  for (size_t i = 0; i < total; ++i)
    if (!lines.count(i)) {
      *err = fmt::format("mutant #{} is missing from shard {}/{} ({})", i, i % shards, shards, shard_file[i % shards]);
      return false;
    }
  std::string text = header_rest + "\n";
  for (const auto& [i, line] : lines) text += line + "\n";
  return write_text(out_path, text, err);
}

double mutation_score(const MutationRun& run) {
  size_t killed = 0, counted = 0;
  for (size_t i = 0; i < run.mutants.size(); ++i) {
    if (!run.evaluated[i] || run.results[i].status == MutantStatus::Equivalent) continue;
    ++counted;
    killed += run.results[i].status == MutantStatus::Killed;
  }
  return counted ? static_cast<double>(killed) / static_cast<double>(counted) : -1;
}

std::string mutation_report(const CampaignBuild& cb, const MutationRun& run) {
  std::string s;
  std::string progs;
  for (const auto& p : cb.spec.programs) progs += (progs.empty() ? "" : ", ") + short_file(p);
  s += fmt::format("mutation analysis of campaign {} on {} (bytecode patches, interpreted VM)\n", cb.spec.name, progs);
  s += fmt::format("original: {} execution(s), {} PASS, {} FAIL; {}\n", run.baseline.executions, run.baseline.pass,
                   run.baseline.fail, run.baseline.end_reason);
  struct Row {
    size_t gen = 0, eq = 0, killed = 0, survived = 0;
  };
  std::map<int, Row> rows;
  Row all;
  for (size_t i = 0; i < run.mutants.size(); ++i) {
    if (!run.evaluated[i]) continue;
    Row& r = rows[static_cast<int>(run.mutants[i].op)];
    for (Row* x : {&r, &all}) {
      ++x->gen;
      switch (run.results[i].status) {
        case MutantStatus::Equivalent: ++x->eq; break;
        case MutantStatus::Killed: ++x->killed; break;
        case MutantStatus::Survived: ++x->survived; break;
      }
    }
  }
  s += fmt::format("\n{:<15} {:>9} {:>10} {:>6} {:>8}\n", "operator", "generated", "equivalent", "killed", "survived");
  for (int k = 0; k < kMutationOps; ++k) {
    const Row& r = rows[k];
    s += fmt::format("{:<15} {:>9} {:>10} {:>6} {:>8}\n", mutation_op_name(static_cast<MutationOp>(k)), r.gen, r.eq, r.killed,
                     r.survived);
  }
  s += fmt::format("{:<15} {:>9} {:>10} {:>6} {:>8}\n", "total", all.gen, all.eq, all.killed, all.survived);
  auto head = [&](const Mutant& m) {
    return fmt::format("#{:<3} {}:{}:{} [{}] {}", m.index, short_file(m.file), m.line, m.col, mutation_op_name(m.op), m.change);
  };
  std::string killed, survived, equivalent;
  for (size_t i = 0; i < run.mutants.size(); ++i) {
    if (!run.evaluated[i]) continue;
    const Mutant& m = run.mutants[i];
    const MutantResult& r = run.results[i];
    if (r.status == MutantStatus::Killed)
      killed += fmt::format("  {}\n        killed ({}) by {}: {}\n", head(m), r.kill, r.killed_by.empty() ? "-" : r.killed_by,
                            r.detail);
    else if (r.status == MutantStatus::Survived)
      survived += fmt::format("  {}\n        survived: {}\n", head(m), r.detail);
    else
      equivalent += fmt::format("  {}\n        equivalent: {}\n", head(m), r.detail);
  }
  if (!survived.empty()) s += "\nsurviving mutants:\n" + survived;
  if (!equivalent.empty()) s += "\nequivalent mutants (not counted):\n" + equivalent;
  if (!killed.empty()) s += "\nkilled mutants:\n" + killed;
  double score = mutation_score(run);
  s += fmt::format("\nmutation score: {} killed of {} non-equivalent = {}\n", all.killed, all.gen - all.eq,
                   score < 0 ? std::string("n/a") : fmt::format("{:.1f} %", score * 100.0));
  return s;
}

}  // namespace plcfi::campaign

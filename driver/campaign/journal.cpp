// Results journal: writing, fsync per verdict, reading back for --resume.
#include "journal.hpp"

#include <filesystem>

#include <unistd.h>

#include <fmt/format.h>

#include "common/file.hpp"
#include "common/json.hpp"

namespace plcfi::campaign {

namespace {

using common::Json;

const std::string* get_str(const Json& o, const char* k) {
  auto it = o.find(k);
  return it == o.end() || !it->is_string() ? nullptr : it->get_ptr<const std::string*>();
}

bool get_int(const Json& o, const char* k, int64_t* out) {
  auto it = o.find(k);
  if (it == o.end() || !it->is_number_integer()) return false;
  *out = it->get<int64_t>();
  return true;
}

}  // namespace

std::string journal_line(const Execution& e, const TestCase& tc, const Progress& p) {
  Json j;
  j["case"] = e.case_id;
  j["fmea"] = tc.row->id;
  if (tc.explored) j["explore"] = true;  // a case the FMEA does not have (explore.hpp)
  j["transition"] = tc.transition_ref();
  j["path"] = e.path;
  j["path_hash"] = fmt::format("{:016x}", e.path_hash);
  j["branches"] = e.branches;
  j["verdict"] = outcome_name(e.outcome);
  j["reason"] = e.reason;
  j["run"] = e.run;
  j["inject_ns"] = e.inject_ns;
  j["start_ns"] = e.start_ns;
  j["reaction_ns"] = e.reaction_ns;
  j["end_ns"] = e.end_ns;
  j["latency_ns"] = e.latency_ns;
  j["vcd"] = e.vcd;
  j["campaign_ns"] = p.campaign_ns;
  j["scans"] = p.scans;
  return common::json_compact(j);
}

std::string journal_header(const std::string& campaign, const std::string& plant, const std::string& fingerprint,
                           size_t cases) {
  Json head;
  head["journal"] = "plcfi campaign";
  head["campaign"] = campaign;
  if (!plant.empty()) head["plant"] = plant;
  head["fingerprint"] = fingerprint;
  head["cases"] = cases;
  return common::json_compact(head);
}

bool parse_execution(const common::Json& o, const std::vector<TestCase>& cases, Execution* out, std::string* why) {
  Execution e;
  const std::string* id = get_str(o, "case");
  const std::string* verdict = get_str(o, "verdict");
  const std::string* hash = get_str(o, "path_hash");
  if (!id || !verdict || !hash) {
    *why = "journal line lacks case, verdict or path_hash";
    return false;
  }
  e.case_id = *id;
  e.case_index = SIZE_MAX;
  for (size_t i = 0; i < cases.size(); ++i)
    if (cases[i].id == *id) e.case_index = i;
  if (e.case_index == SIZE_MAX) {
    *why = fmt::format("unknown case '{}'", *id);
    return false;
  }
  e.outcome = *verdict == "PASS" ? Outcome::Pass : Outcome::Fail;
  try {
    size_t used = 0;
    e.path_hash = std::stoull(*hash, &used, 16);
    if (used != hash->size()) throw std::invalid_argument(*hash);
  } catch (const std::exception&) {
    *why = fmt::format("path_hash '{}' is not hexadecimal", *hash);
    return false;
  }
  int64_t v = 0;
  if (get_int(o, "path", &v)) e.path = static_cast<int>(v);
  if (auto it = o.find("branches"); it != o.end() && it->is_array())
    for (const auto& b : *it)
      if (b.is_number_integer()) e.branches.push_back(b.get<uint32_t>());
  if (const std::string* s = get_str(o, "reason")) e.reason = *s;
  if (const std::string* s = get_str(o, "vcd")) e.vcd = *s;
  std::pair<const char*, int64_t*> ints[] = {{"inject_ns", &e.inject_ns}, {"start_ns", &e.start_ns},
                                             {"reaction_ns", &e.reaction_ns}, {"end_ns", &e.end_ns},
                                             {"latency_ns", &e.latency_ns}};
  for (auto& [k, dst] : ints) get_int(o, k, dst);
  if (get_int(o, "run", &v)) e.run = static_cast<uint64_t>(v);
  *out = std::move(e);
  return true;
}

Journal::~Journal() {
  if (f_) std::fclose(f_);
}

bool Journal::write_line(const std::string& line, std::string* err) {
  std::string l = line + "\n";
  if (std::fwrite(l.data(), 1, l.size(), f_) != l.size() || std::fflush(f_) != 0 || ::fsync(fileno(f_)) != 0) {
    *err = path_ + ": cannot write the journal";
    return false;
  }
  return true;
}

bool Journal::open(const std::string& path, bool resume, const std::string& campaign, const std::string& fingerprint,
                   const std::vector<TestCase>& cases, JournalState* state, std::string* err) {
  path_ = path;
  cases_ = &cases;
  const std::string header = journal_header(campaign, plant_, fingerprint, cases.size());
  std::error_code ec;
  if (resume && std::filesystem::exists(path, ec)) {
    std::string text;
    if (!common::read_file(path, common::kMaxJournalBytes, &text, err)) return false;
    std::string good;
    uint32_t n = 0;
    bool torn = false;
    for (size_t begin = 0; begin < text.size();) {
      const size_t end = text.find('\n', begin);
      ++n;
      if (end == std::string::npos) {
        torn = true;  // no newline: killed while writing this line
        break;
      }
      const std::string line = text.substr(begin, end - begin);
      begin = end + 1;
      Json o;
      std::string why;
      size_t column = 1;
      if (!common::json_parse(line, &o, &why, &column)) {
        *err = fmt::format("{}:{}:{}: not a journal line ({})", path, n, column, why);
        return false;
      }
      if (!o.is_object()) {
        *err = fmt::format("{}:{}:1: not a journal line (expected a JSON object)", path, n);
        return false;
      }
      if (n == 1) {
        const std::string* fp = get_str(o, "fingerprint");
        if (!get_str(o, "journal") || !fp) {
          *err = path + ":1:1: not a plcfi campaign journal";
          return false;
        }
        if (*fp != fingerprint) {
          *err = path + ":1:1: the journal belongs to another campaign or program (fingerprint " + *fp + ", this one " +
                 fingerprint + "); remove it or use another --out folder";
          return false;
        }
        good += line + "\n";
        continue;
      }
      Execution e;
      if (!parse_execution(o, cases, &e, &why)) {
        *err = fmt::format("{}:{}:1: {}", path, n, why);
        return false;
      }
      int64_t v = 0;
      state->executions.push_back(e);
      state->next_run = e.run + 1;
      get_int(o, "campaign_ns", &state->campaign_ns);
      if (get_int(o, "scans", &v)) state->scans = static_cast<uint64_t>(v);
      good += line + "\n";
    }
    if (n == 0 || (n == 1 && torn)) {
      // Empty or only a torn header: start afresh.
      state->executions.clear();
      good.clear();
    }
    // Rewrite without a torn tail, then append from there.
    f_ = std::fopen(path.c_str(), "w");
    if (!f_) {
      *err = path + ": cannot write the journal";
      return false;
    }
    if (good.empty()) return write_line(header, err);
    if (std::fwrite(good.data(), 1, good.size(), f_) != good.size() || std::fflush(f_) != 0) {
      *err = path + ": cannot write the journal";
      return false;
    }
    return true;
  }
  f_ = std::fopen(path.c_str(), "w");
  if (!f_) {
    *err = path + ": cannot write the journal";
    return false;
  }
  return write_line(header, err);
}

bool Journal::append_line(const std::string& line, std::string* err) { return write_line(line, err); }

bool Journal::append(const Execution& e, const Progress& p, std::string* err) {
  return write_line(journal_line(e, (*cases_)[e.case_index], p), err);
}

}  // namespace plcfi::campaign

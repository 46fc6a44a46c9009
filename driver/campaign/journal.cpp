// Results journal: writing, fsync per verdict, reading back for --resume.
#include "journal.hpp"

#include <cctype>
#include <fstream>
#include <map>
#include <variant>

#include <unistd.h>

#include <fmt/format.h>

namespace plcfi::campaign {

namespace {

std::string esc(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (c == '\n') out += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20) out += fmt::format("\\u{:04x}", static_cast<int>(c));
    else out += c;
  }
  return out;
}

// A flat JSON object as the journal writes it: string, integer or integer-array values.
using Value = std::variant<std::string, int64_t, std::vector<int64_t>>;
using Object = std::map<std::string, Value>;

class LineParser {
 public:
  explicit LineParser(const std::string& s) : s_(s) {}
  bool parse(Object* out) {
    ws();
    if (!eat('{')) return false;
    ws();
    if (eat('}')) return true;
    while (true) {
      std::string key;
      ws();
      if (!str(&key)) return false;
      ws();
      if (!eat(':')) return false;
      ws();
      Value v;
      if (peek() == '"') {
        std::string x;
        if (!str(&x)) return false;
        v = x;
      } else if (peek() == '[') {
        ++i_;
        std::vector<int64_t> arr;
        ws();
        if (!eat(']')) {
          while (true) {
            int64_t n;
            ws();
            if (!num(&n)) return false;
            arr.push_back(n);
            ws();
            if (eat(']')) break;
            if (!eat(',')) return false;
          }
        }
        v = arr;
      } else {
        int64_t n;
        if (!num(&n)) return false;
        v = n;
      }
      (*out)[key] = v;
      ws();
      if (eat('}')) break;
      if (!eat(',')) return false;
    }
    ws();
    return i_ == s_.size();
  }

 private:
  char peek() const { return i_ < s_.size() ? s_[i_] : '\0'; }
  bool eat(char c) {
    if (peek() != c) return false;
    ++i_;
    return true;
  }
  void ws() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  bool str(std::string* out) {
    if (!eat('"')) return false;
    while (i_ < s_.size() && s_[i_] != '"') {
      char c = s_[i_++];
      if (c == '\\') {
        if (i_ >= s_.size()) return false;
        char e = s_[i_++];
        if (e == 'n') *out += '\n';
        else if (e == 'u') {
          if (i_ + 4 > s_.size()) return false;
          int code = 0;
          for (size_t k = 0; k < 4; ++k) {
            char h = s_[i_ + k];
            int d = std::isdigit(static_cast<unsigned char>(h)) ? h - '0'
                    : (h >= 'a' && h <= 'f') ? h - 'a' + 10
                    : (h >= 'A' && h <= 'F') ? h - 'A' + 10
                                             : -1;
            if (d < 0) return false;
            code = code * 16 + d;
          }
          *out += static_cast<char>(code);
          i_ += 4;
        } else *out += e;
      } else {
        *out += c;
      }
    }
    return eat('"');
  }
  bool num(int64_t* n) {
    size_t b = i_;
    if (peek() == '-') ++i_;
    while (std::isdigit(static_cast<unsigned char>(peek()))) ++i_;
    if (i_ == b || (i_ == b + 1 && s_[b] == '-')) return false;
    try {
      *n = std::stoll(s_.substr(b, i_ - b));
    } catch (const std::exception&) {
      return false;
    }
    return true;
  }
  const std::string& s_;
  size_t i_ = 0;
};

const std::string* get_str(const Object& o, const char* k) {
  auto it = o.find(k);
  return it == o.end() ? nullptr : std::get_if<std::string>(&it->second);
}
const int64_t* get_int(const Object& o, const char* k) {
  auto it = o.find(k);
  return it == o.end() ? nullptr : std::get_if<int64_t>(&it->second);
}

}  // namespace

std::string journal_line(const Execution& e, const TestCase& tc, const Progress& p) {
  std::string br;
  for (uint32_t b : e.branches) br += (br.empty() ? "" : ",") + std::to_string(b);
  return fmt::format(
      "{{\"case\":\"{}\",\"fmea\":\"{}\",\"transition\":\"{}\",\"path\":{},\"path_hash\":\"{:016x}\",\"branches\":[{}],"
      "\"verdict\":\"{}\",\"reason\":\"{}\",\"run\":{},\"inject_ns\":{},\"start_ns\":{},\"reaction_ns\":{},\"end_ns\":{},"
      "\"latency_ns\":{},\"vcd\":\"{}\",\"campaign_ns\":{},\"scans\":{}}}",
      esc(e.case_id), esc(tc.row->id), esc(tc.transition_ref()), e.path, e.path_hash, br, outcome_name(e.outcome),
      esc(e.reason), e.run, e.inject_ns, e.start_ns, e.reaction_ns, e.end_ns, e.latency_ns, esc(e.vcd), p.campaign_ns,
      p.scans);
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
  std::string header = fmt::format("{{\"journal\":\"plcfi campaign\",\"campaign\":\"{}\",\"fingerprint\":\"{}\",\"cases\":{}}}",
                                    esc(campaign), fingerprint, cases.size());
  std::ifstream in(path);
  if (resume && in) {
    std::string line, good;
    uint32_t n = 0;
    bool torn = false;
    while (std::getline(in, line)) {
      ++n;
      if (in.eof()) {
        torn = true;  // no newline: killed while writing this line
        break;
      }
      Object o;
      if (!LineParser(line).parse(&o)) {
        *err = fmt::format("{}:{}:1: not a journal line", path, n);
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
      const std::string* id = get_str(o, "case");
      const std::string* verdict = get_str(o, "verdict");
      const std::string* hash = get_str(o, "path_hash");
      if (!id || !verdict || !hash) {
        *err = fmt::format("{}:{}:1: journal line lacks case, verdict or path_hash", path, n);
        return false;
      }
      e.case_id = *id;
      e.case_index = SIZE_MAX;
      for (size_t i = 0; i < cases.size(); ++i)
        if (cases[i].id == *id) e.case_index = i;
      if (e.case_index == SIZE_MAX) {
        *err = fmt::format("{}:{}:1: unknown case '{}'", path, n, *id);
        return false;
      }
      e.outcome = *verdict == "PASS" ? Outcome::Pass : Outcome::Fail;
      try {
        size_t used = 0;
        e.path_hash = std::stoull(*hash, &used, 16);
        if (used != hash->size()) throw std::invalid_argument(*hash);
      } catch (const std::exception&) {
        *err = fmt::format("{}:{}:1: path_hash '{}' is not hexadecimal", path, n, *hash);
        return false;
      }
      if (const int64_t* v = get_int(o, "path")) e.path = static_cast<int>(*v);
      if (auto it = o.find("branches"); it != o.end())
        if (auto* arr = std::get_if<std::vector<int64_t>>(&it->second))
          for (int64_t b : *arr) e.branches.push_back(static_cast<uint32_t>(b));
      if (const std::string* s = get_str(o, "reason")) e.reason = *s;
      if (const std::string* s = get_str(o, "vcd")) e.vcd = *s;
      std::pair<const char*, int64_t*> ints[] = {{"inject_ns", &e.inject_ns}, {"start_ns", &e.start_ns},
                                                 {"reaction_ns", &e.reaction_ns}, {"end_ns", &e.end_ns},
                                                 {"latency_ns", &e.latency_ns}};
      for (auto& [k, dst] : ints)
        if (const int64_t* v = get_int(o, k)) *dst = *v;
      if (const int64_t* v = get_int(o, "run")) e.run = static_cast<uint64_t>(*v);
      state->executions.push_back(e);
      state->next_run = e.run + 1;
      if (const int64_t* v = get_int(o, "campaign_ns")) state->campaign_ns = *v;
      if (const int64_t* v = get_int(o, "scans")) state->scans = static_cast<uint64_t>(*v);
      good += line + "\n";
    }
    in.close();
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

bool Journal::append(const Execution& e, const Progress& p, std::string* err) {
  return write_line(journal_line(e, (*cases_)[e.case_index], p), err);
}

}  // namespace plcfi::campaign

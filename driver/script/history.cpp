// SQLite run history and the hashes that decide which runs count for p_lst.
#include "script/history.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <map>
#include <set>
#include <string_view>

#include <fmt/format.h>

#include "common/hash.hpp"

namespace plcfi::script {

namespace {

constexpr const char* kSchema = R"SQL(
CREATE TABLE IF NOT EXISTS runs (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  test TEXT NOT NULL,
  verdict TEXT NOT NULL,
  time TEXT NOT NULL,
  mci REAL,
  cycles INTEGER,
  program_hash TEXT NOT NULL,
  pou_hash TEXT NOT NULL,
  reason TEXT NOT NULL DEFAULT ''
);
CREATE INDEX IF NOT EXISTS runs_by_test ON runs (test, id);
)SQL";

// A prepared statement, finalized on every way out.
class Stmt {
 public:
  Stmt(sqlite3* db, const char* sql) { rc_ = sqlite3_prepare_v2(db, sql, -1, &s_, nullptr); }
  ~Stmt() { sqlite3_finalize(s_); }
  bool ok() const { return rc_ == SQLITE_OK; }
  sqlite3_stmt* get() { return s_; }
  void text(int i, const std::string& v) { sqlite3_bind_text(s_, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT); }
  void integer(int i, int64_t v) { sqlite3_bind_int64(s_, i, v); }

 private:
  sqlite3_stmt* s_ = nullptr;
  int rc_ = SQLITE_ERROR;
};

std::string col_text(sqlite3_stmt* s, int i) {
  const unsigned char* t = sqlite3_column_text(s, i);
  return t ? reinterpret_cast<const char*>(t) : "";
}

}  // namespace

std::string History::error_text() const { return fmt::format("{}: {}", path_, db_ ? sqlite3_errmsg(db_) : "cannot open"); }

std::unique_ptr<History> History::open(const std::string& path, std::string* err) {
  std::unique_ptr<History> h(new History());
  h->path_ = path;
  std::error_code ec;
  std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  if (std::filesystem::is_directory(path, ec)) {
    *err = path + ": is a directory (the history is a file)";
    return nullptr;
  }
  if (sqlite3_open_v2(path.c_str(), &h->db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, nullptr) != SQLITE_OK) {
    *err = h->error_text();
    return nullptr;
  }
  // Another process writing at the same moment makes us wait, not fail.
  sqlite3_busy_timeout(h->db_, 10000);
  char* msg = nullptr;
  if (sqlite3_exec(h->db_, "PRAGMA journal_mode=WAL;", nullptr, nullptr, &msg) != SQLITE_OK ||
      sqlite3_exec(h->db_, kSchema, nullptr, nullptr, &msg) != SQLITE_OK) {
    *err = fmt::format("{}: {} (not a plcfi history?)", path, msg ? msg : sqlite3_errmsg(h->db_));
    sqlite3_free(msg);
    return nullptr;
  }
  // A database of another kind that happens to have a table called runs.
  Stmt probe(h->db_, "SELECT id, test, verdict, time, mci, cycles, program_hash, pou_hash, reason FROM runs LIMIT 0");
  if (!probe.ok()) {
    *err = fmt::format("{}: not a plcfi history ({})", path, sqlite3_errmsg(h->db_));
    return nullptr;
  }
  return h;
}

History::~History() {
  if (db_) sqlite3_close_v2(db_);
}

bool History::passes_since_change(const std::string& test, const std::string& pou_hash, int64_t psi, int64_t* out,
                                  std::string* err) {
  Stmt s(db_, "SELECT verdict, pou_hash FROM runs WHERE test = ?1 ORDER BY id DESC LIMIT ?2");
  if (!s.ok()) {
    *err = error_text();
    return false;
  }
  s.text(1, test);
  s.integer(2, psi);
  int64_t n = 0;
  int rc;
  while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
    if (col_text(s.get(), 1) != pou_hash) break;
    if (col_text(s.get(), 0) == "passed") ++n;
  }
  if (rc != SQLITE_ROW && rc != SQLITE_DONE) {
    *err = error_text();
    return false;
  }
  *out = n;
  return true;
}

bool History::add(const HistoryRow& r, std::string* err) {
  Stmt s(db_,
         "INSERT INTO runs (test, verdict, time, mci, cycles, program_hash, pou_hash, reason) "
         "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)");
  if (!s.ok()) {
    *err = error_text();
    return false;
  }
  s.text(1, r.test);
  s.text(2, r.verdict);
  s.text(3, r.time);
  if (r.mci) sqlite3_bind_double(s.get(), 4, *r.mci);
  if (r.cycles) s.integer(5, *r.cycles);
  s.text(6, r.program_hash);
  s.text(7, r.pou_hash);
  s.text(8, r.reason);
  if (sqlite3_step(s.get()) != SQLITE_DONE) {
    *err = error_text();
    return false;
  }
  return true;
}

bool History::list(const std::string& test, size_t limit, std::vector<HistoryRow>* out, std::string* err) {
  Stmt s(db_,
         "SELECT id, test, verdict, time, mci, cycles, program_hash, pou_hash, reason FROM runs "
         "WHERE ?1 = '' OR test = ?1 ORDER BY id DESC LIMIT ?2");
  if (!s.ok()) {
    *err = error_text();
    return false;
  }
  s.text(1, test);
  s.integer(2, limit == 0 ? -1 : static_cast<int64_t>(limit));
  out->clear();
  int rc;
  while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
    HistoryRow r;
    r.id = sqlite3_column_int64(s.get(), 0);
    r.test = col_text(s.get(), 1);
    r.verdict = col_text(s.get(), 2);
    r.time = col_text(s.get(), 3);
    if (sqlite3_column_type(s.get(), 4) != SQLITE_NULL) r.mci = sqlite3_column_double(s.get(), 4);
    if (sqlite3_column_type(s.get(), 5) != SQLITE_NULL) r.cycles = sqlite3_column_int64(s.get(), 5);
    r.program_hash = col_text(s.get(), 6);
    r.pou_hash = col_text(s.get(), 7);
    r.reason = col_text(s.get(), 8);
    out->push_back(std::move(r));
  }
  if (rc != SQLITE_DONE) {
    *err = error_text();
    return false;
  }
  return true;
}

std::string default_history_path() {
  if (const char* p = std::getenv("PLCFI_HISTORY"); p && *p) return p;
  if (const char* x = std::getenv("XDG_STATE_HOME"); x && *x) return std::string(x) + "/plcfi/history.sqlite";
  if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.local/state/plcfi/history.sqlite";
  return "plcfi-history.sqlite";
}

std::string utc_now() {
  std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  return fmt::format("{:04}-{:02}-{:02}T{:02}:{:02}:{:02}Z", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour,
                     tm.tm_min, tm.tm_sec);
}

// ---- which POUs a test involves

namespace {

std::string upper(std::string_view s) {
  std::string u(s);
  for (char& c : u) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u;
}

// The identifiers of ST text (upper case), comments and string literals skipped.
std::set<std::string> identifiers(std::string_view t) {
  std::set<std::string> ids;
  size_t i = 0;
  auto is_id = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  while (i < t.size()) {
    char c = t[i];
    if (c == '(' && i + 1 < t.size() && t[i + 1] == '*') {
      size_t e = t.find("*)", i + 2);
      i = e == std::string_view::npos ? t.size() : e + 2;
    } else if (c == '/' && i + 1 < t.size() && t[i + 1] == '/') {
      size_t e = t.find('\n', i);
      i = e == std::string_view::npos ? t.size() : e;
    } else if (c == '\'' || c == '"') {
      size_t j = i + 1;
      while (j < t.size() && t[j] != c) j += t[j] == '$' ? 2 : 1;
      i = j + 1;
    } else if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      size_t j = i;
      while (j < t.size() && is_id(t[j])) ++j;
      ids.insert(upper(t.substr(i, j - i)));
      i = j;
    } else {
      ++i;
    }
  }
  return ids;
}

// The text of a POU: from its declaration's line to the END_ keyword of its kind.
std::string_view pou_text(const st::SourceFile& f, const st::PouInfo& p) {
  if (p.loc.line == 0 || p.loc.line > f.line_starts.size()) return {};
  size_t from = f.line_starts[p.loc.line - 1];
  const char* end_kw = p.kind == st::PouKind::Program         ? "END_PROGRAM"
                       : p.kind == st::PouKind::FunctionBlock ? "END_FUNCTION_BLOCK"
                       : p.kind == st::PouKind::Function      ? "END_FUNCTION"
                       : p.kind == st::PouKind::Interface     ? "END_INTERFACE"
                                                              : nullptr;
  if (!end_kw) return {};
  std::string up = upper(std::string_view(f.text).substr(from));
  size_t at = 0;
  for (;;) {
    at = up.find(end_kw, at);
    if (at == std::string::npos) return std::string_view(f.text).substr(from);
    size_t after = at + std::string_view(end_kw).size();
    // END_FUNCTION must not be the start of END_FUNCTION_BLOCK.
    if (after < up.size() && (std::isalnum(static_cast<unsigned char>(up[after])) || up[after] == '_')) {
      at = after;
      continue;
    }
    return std::string_view(f.text).substr(from, after);
  }
}

}  // namespace

std::string involved_pous_hash(const st::Build& b, const std::vector<std::string>& var_paths, std::vector<std::string>* names) {
  const st::Application& app = *b.app;
  struct Pou {
    std::string text;
    std::set<std::string> ids;
  };
  std::map<std::string, Pou> pous;  // by upper-case name
  for (const auto& p : app.pous) {
    if (p->is_stdlib || p->is_test || p->file >= b.sm.size()) continue;
    std::string_view t = pou_text(b.sm.file(p->file), *p);
    if (t.empty()) continue;
    pous[upper(p->name)] = Pou{std::string(t), identifiers(t)};
  }
  std::set<std::string> involved;
  std::vector<std::string> work;
  auto take = [&](const std::string& name) {
    if (pous.count(name) && involved.insert(name).second) work.push_back(name);
  };
  for (const auto& path : var_paths) {
    std::string head = upper(path.substr(0, path.find_first_of(".[")));
    bool program = false;
    for (const auto& pi : app.programs)
      if (upper(pi.name) == head) {
        take(upper(pi.pou->name));
        program = true;
      }
    if (program) continue;
    // A global (or a direct address): the POUs that use it by name, or every PROGRAM
    // for an address (its located variable may go by any name).
    for (const auto& [n, p] : pous) {
      bool uses = head.empty() || head[0] == '%' ? false : p.ids.count(head) > 0;
      if (uses) take(n);
    }
    if (!head.empty() && head[0] == '%')
      for (const auto& pi : app.programs) take(upper(pi.pou->name));
  }
  while (!work.empty()) {
    std::string n = work.back();
    work.pop_back();
    for (const auto& id : pous[n].ids) take(id);
  }
  common::Fnv64 h;
  names->clear();
  for (const auto& n : involved) {  // sorted: the hash does not depend on the search order
    names->push_back(n);
    h.add(n).add(pous[n].text);
  }
  return h.hex();
}

std::string program_hash(const st::Build& b) {
  common::Fnv64 h;
  for (size_t i = 0; i < b.sm.size(); ++i) {
    const auto& f = b.sm.file(static_cast<uint32_t>(i));
    if (!f.origins.empty() || f.path.rfind('<', 0) == 0) continue;  // generated text, the standard library
    h.add(f.path).add(f.text);
  }
  return h.hex();
}

}  // namespace plcfi::script

// Rendering of a campaign's safety evidence (JSON, text, JUnit, CSV) and the comparison
// with an earlier run's safety.json.
#include "report/safety.hpp"

#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "common/csv.hpp"
#include "common/json.hpp"

namespace plcfi::report {

namespace {

using common::csv_field;
using common::Json;

Json ms_json(int64_t ns) {
  if (ns % 1'000'000 == 0) return ns / 1'000'000;
  return static_cast<double>(ns) * 1e-6;
}

std::string percent(double fraction) { return fmt::format("{:.1f} %", fraction * 100.0); }

// A rate as written: 1400, 12.5.
std::string fit(double v) { return fmt::format("{}", v); }

std::string exec_key(const std::string& case_id, int path) { return fmt::format("{} path {}", case_id, path); }

}  // namespace

std::string SafetyFunctionEvidence::band() const {
  if (!has_dc()) return "n/a";
  // Compared without a division, so 99 % of a rate is "high" however it rounds.
  if (lambda_dd * 100 >= lambda_d * 99) return "high";
  if (lambda_dd * 100 >= lambda_d * 90) return "medium";
  if (lambda_dd * 100 >= lambda_d * 60) return "low";
  return "none";
}

std::string ms_text(int64_t ns) {
  if (ns % 1'000'000 == 0) return std::to_string(ns / 1'000'000);
  return fmt::format("{}", static_cast<double>(ns) * 1e-6);
}

std::string safety_json(const SafetyReport& r) {
  Json j;
  j["campaign"] = r.campaign;
  Json fp = Json::object();
  for (const auto& [k, v] : r.fingerprint) fp[k] = v;
  j["fingerprint"] = fp;
  Json fns = Json::array();
  for (const auto& f : r.functions) {
    Json o;
    o["id"] = f.id;
    o["lambda_d"] = f.lambda_d;
    o["lambda_dd"] = f.lambda_dd;
    o["lambda_s"] = f.lambda_s;
    o["dc"] = f.has_dc() ? Json(f.dc()) : Json(nullptr);
    o["band"] = f.band();
    o["sff"] = f.has_safe ? Json(f.sff()) : Json(nullptr);
    o["worst_reaction_ms"] = f.worst_reaction_ns >= 0 ? ms_json(f.worst_reaction_ns) : Json(nullptr);
    o["worst_execution"] = f.worst_execution;
    o["reacted"] = f.reacted;
    o["unreacted"] = f.unreacted;
    o["safety_time_ms"] = f.safety_time_ns >= 0 ? ms_json(f.safety_time_ns) : Json(nullptr);
    o["margin"] = f.has_margin() ? ms_json(f.margin_ns()) : Json(nullptr);
    o["rows"] = f.rows;
    Json und = Json::array(), why = Json::object();
    for (const auto& [row, reason] : f.undetected) {
      und.push_back(row);
      why[row] = reason;
    }
    o["undetected"] = und;
    o["undetected_reasons"] = why;
    fns.push_back(o);
  }
  j["safety_functions"] = fns;
  Json un = Json::array();
  for (const auto& u : r.unassessed) {
    Json o;
    o["case"] = u.case_id;
    o["path"] = u.path;
    o["transition"] = u.transition;
    o["fault"] = u.fault;
    o["verdict"] = u.verdict;
    o["reason"] = u.reason;
    un.push_back(o);
  }
  j["unassessed"] = un;
  Json ex = Json::array();
  for (const auto& e : r.executions) {
    Json o;
    o["case"] = e.case_id;
    o["fmea"] = e.fmea;
    o["path"] = e.path;
    o["verdict"] = e.verdict;
    o["reaction_ms"] = e.reaction_ns >= 0 ? ms_json(e.reaction_ns) : Json(nullptr);
    ex.push_back(o);
  }
  j["executions"] = ex;
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

std::string safety_text(const SafetyReport& r, const std::string& out_dir) {
  std::string o = "\nsafety evidence (rates in FIT; DC bands of IEC 61508-2; reaction from the injection)\n";
  for (const auto& f : r.functions) {
    o += fmt::format("  {}: lambda_D {} FIT, lambda_DD {} FIT, DC {}", f.id, fit(f.lambda_d), fit(f.lambda_dd),
                     f.has_dc() ? percent(f.dc()) + " (" + f.band() + ")" : std::string("n/a (no dangerous rate)"));
    if (f.has_safe) o += fmt::format(", lambda_S {} FIT, SFF {}", fit(f.lambda_s), percent(f.sff()));
    o += "\n";
    std::string rows;
    for (const auto& id : f.rows) rows += (rows.empty() ? "" : " ") + id;
    o += "    rows " + rows + "\n";
    if (f.worst_reaction_ns >= 0) {
      o += fmt::format("    worst reaction {} ms ({})", ms_text(f.worst_reaction_ns), f.worst_execution);
      if (f.has_margin())
        o += fmt::format(", safety time {} ms, margin {} ms{}", ms_text(f.safety_time_ns), ms_text(f.margin_ns()),
                         f.margin_ns() < 0 ? " (EXCEEDED)" : "");
      else
        o += ", no safety time given";
      if (f.unreacted) o += fmt::format("; {} execution(s) without a reaction", f.unreacted);
      o += "\n";
    } else {
      o += fmt::format("    no reaction seen ({} execution(s) without one)\n", f.unreacted);
    }
    for (const auto& [row, why] : f.undetected) o += fmt::format("    undetected {}: {}\n", row, why);
  }
  if (!r.unassessed.empty()) {
    o += fmt::format("  unassessed failure modes (explored, no FMEA row): {}\n", r.unassessed.size());
    for (const auto& u : r.unassessed)
      o += fmt::format("    {} path {} {}: {}: {}\n", u.case_id, u.path, u.verdict, u.transition, u.fault);
  }
  o += fmt::format("safety evidence {}/safety.json, traceability matrix {}/traceability.csv\n", out_dir, out_dir);
  return o;
}

std::vector<std::pair<std::string, std::string>> safety_junit_properties(const SafetyReport& r) {
  std::vector<std::pair<std::string, std::string>> p;
  for (const auto& [k, v] : r.fingerprint) p.emplace_back("fingerprint." + k, v);
  for (const auto& f : r.functions) {
    const std::string s = "safety." + f.id + ".";
    p.emplace_back(s + "lambda_d", fit(f.lambda_d));
    p.emplace_back(s + "lambda_dd", fit(f.lambda_dd));
    p.emplace_back(s + "dc", f.has_dc() ? fmt::format("{:.4f}", f.dc()) : "");
    p.emplace_back(s + "band", f.band());
    if (f.has_safe) p.emplace_back(s + "sff", fmt::format("{:.4f}", f.sff()));
    p.emplace_back(s + "worst_reaction_ms", f.worst_reaction_ns >= 0 ? ms_text(f.worst_reaction_ns) : "");
    p.emplace_back(s + "safety_time_ms", f.safety_time_ns >= 0 ? ms_text(f.safety_time_ns) : "");
    p.emplace_back(s + "margin_ms", f.has_margin() ? ms_text(f.margin_ns()) : "");
    std::string und;
    for (const auto& u : f.undetected) und += (und.empty() ? "" : " ") + u.first;
    p.emplace_back(s + "undetected", und);
  }
  p.emplace_back("safety.unassessed", std::to_string(r.unassessed.size()));
  return p;
}

std::string traceability_csv(const SafetyReport& r) {
  std::string o;
  for (const auto& [k, v] : r.fingerprint) o += "# " + csv_field(k) + "," + csv_field(v) + "\n";
  o += "fmea,safety_function,failure_rate,dangerous,failure_mode,case,transition,fault,path,verdict,inject_ms,"
       "reaction_ms,latency_ms,safety_time_ms,journal_line,vcd,sequence_diagram,timing_diagram\n";
  auto ms = [](int64_t ns) { return ns >= 0 ? ms_text(ns) : std::string(); };
  for (const auto& t : r.trace) {
    std::vector<std::string> f = {t.fmea,
                                  t.safety_function,
                                  t.failure_rate >= 0 ? fit(t.failure_rate) : "",
                                  t.dangerous,
                                  t.failure_mode,
                                  t.case_id,
                                  t.transition,
                                  t.fault,
                                  t.path ? std::to_string(t.path) : "",
                                  t.verdict,
                                  ms(t.inject_ns),
                                  ms(t.reaction_ns),
                                  ms(t.latency_ns),
                                  ms(t.safety_time_ns),
                                  t.journal_line ? std::to_string(t.journal_line) : "",
                                  t.vcd,
                                  t.sequence_diagram,
                                  t.timing_diagram};
    std::string line;
    for (size_t i = 0; i < f.size(); ++i) line += (i ? "," : "") + csv_field(f[i]);
    o += line + "\n";
  }
  return o;
}

bool parse_safety_json(const std::string& text, const std::string& path, SafetyReport* out, std::string* err) {
  Json j;
  std::string why;
  size_t col = 0;
  if (!common::json_parse(text, &j, &why, &col)) {
    // The column counts from the start of the text; name the line and column of the file.
    size_t line = 1, line_start = 0;
    for (size_t i = 0; i + 1 < col && i < text.size(); ++i)
      if (text[i] == '\n') {
        ++line;
        line_start = i + 1;
      }
    *err = fmt::format("{}:{}:{}: not a safety.json: {}", path, line, col > line_start ? col - line_start : 1, why);
    return false;
  }
  auto bad = [&](const std::string& what) {
    *err = path + ": not a safety.json of plcfi campaign: " + what;
    return false;
  };
  if (!j.is_object()) return bad("expected an object");
  SafetyReport r;
  if (auto it = j.find("campaign"); it != j.end() && it->is_string()) r.campaign = it->get<std::string>();
  auto fns = j.find("safety_functions");
  if (fns == j.end() || !fns->is_array()) return bad("no safety_functions list");
  // Milliseconds to ns; null, negative or beyond a year (no reaction of a scan program)
  // reads as "none" rather than overflowing.
  auto ns_of = [](const Json& v) -> int64_t {
    if (!v.is_number()) return -1;
    double ms = v.get<double>();
    if (!(ms >= 0 && ms <= 3.2e10)) return -1;
    return static_cast<int64_t>(std::llround(ms * 1e6));
  };
  for (const auto& f : *fns) {
    if (!f.is_object() || !f.contains("id") || !f["id"].is_string()) return bad("a safety function without an id");
    SafetyFunctionEvidence e;
    e.id = f["id"].get<std::string>();
    for (auto [key, dst] : {std::pair{"lambda_d", &e.lambda_d}, {"lambda_dd", &e.lambda_dd}, {"lambda_s", &e.lambda_s}}) {
      auto it = f.find(key);
      if (it == f.end() || !it->is_number()) return bad(fmt::format("safety function {}: no number {}", e.id, key));
      *dst = it->get<double>();
    }
    if (auto it = f.find("worst_reaction_ms"); it != f.end()) e.worst_reaction_ns = ns_of(*it);
    if (auto it = f.find("worst_execution"); it != f.end() && it->is_string()) e.worst_execution = it->get<std::string>();
    if (auto it = f.find("safety_time_ms"); it != f.end()) e.safety_time_ns = ns_of(*it);
    if (auto it = f.find("sff"); it != f.end() && it->is_number()) e.has_safe = true;
    if (auto it = f.find("undetected"); it != f.end() && it->is_array())
      for (const auto& u : *it)
        if (u.is_string()) e.undetected.emplace_back(u.get<std::string>(), "");
    r.functions.push_back(std::move(e));
  }
  if (auto un = j.find("unassessed"); un != j.end() && un->is_array())
    for (const auto& u : *un) {
      if (!u.is_object() || !u.contains("case") || !u["case"].is_string()) return bad("an unassessed failure mode without a case");
      UnassessedMode m;
      m.case_id = u["case"].get<std::string>();
      if (u.contains("path") && u["path"].is_number_integer()) m.path = static_cast<int>(u["path"].get<int64_t>() & 0x7fffffff);
      r.unassessed.push_back(m);
    }
  if (auto ex = j.find("executions"); ex != j.end() && ex->is_array())
    for (const auto& e : *ex) {
      if (!e.is_object() || !e.contains("case") || !e["case"].is_string() || !e.contains("verdict") ||
          !e["verdict"].is_string() || !e.contains("path") || !e["path"].is_number_integer())
        return bad("an execution without case, path or verdict");
      SafetyExecution x;
      x.case_id = e["case"].get<std::string>();
      x.path = static_cast<int>(e["path"].get<int64_t>() & 0x7fffffff);
      x.verdict = e["verdict"].get<std::string>();
      if (e.contains("fmea") && e["fmea"].is_string()) x.fmea = e["fmea"].get<std::string>();
      if (e.contains("reaction_ms")) x.reaction_ns = ns_of(e["reaction_ms"]);
      r.executions.push_back(x);
    }
  *out = std::move(r);
  return true;
}

std::vector<BaselineChange> compare_safety(const SafetyReport& before, const SafetyReport& now) {
  std::vector<BaselineChange> c;
  std::map<std::string, const SafetyExecution*> old_x, new_x;
  for (const auto& e : before.executions) old_x[exec_key(e.case_id, e.path)] = &e;
  for (const auto& e : now.executions) new_x[exec_key(e.case_id, e.path)] = &e;
  for (const auto& [k, o] : old_x) {
    auto it = new_x.find(k);
    if (it == new_x.end()) {
      c.push_back({fmt::format("{}: {} before, not executed now", k, o->verdict), o->verdict == "PASS"});
    } else if (it->second->verdict != o->verdict) {
      c.push_back({fmt::format("{}: {} -> {}", k, o->verdict, it->second->verdict), o->verdict == "PASS"});
    }
  }
  for (const auto& [k, n] : new_x)
    if (!old_x.count(k)) c.push_back({fmt::format("{}: new, {}", k, n->verdict), n->verdict != "PASS"});
  std::map<std::string, const SafetyFunctionEvidence*> old_f;
  for (const auto& f : before.functions) old_f[f.id] = &f;
  std::set<std::string> seen;
  for (const auto& f : now.functions) {
    seen.insert(f.id);
    auto it = old_f.find(f.id);
    if (it == old_f.end()) {
      c.push_back({fmt::format("{}: new safety function, DC {}", f.id, f.has_dc() ? percent(f.dc()) : "n/a"), false});
      continue;
    }
    const auto& o = *it->second;
    if (o.has_dc() != f.has_dc() || std::abs(o.dc() - f.dc()) > 1e-12) {
      bool worse = f.dc() < o.dc() - 1e-12;
      c.push_back({fmt::format("{}: DC {} ({}) -> {} ({})", f.id, o.has_dc() ? percent(o.dc()) : "n/a", o.band(),
                               f.has_dc() ? percent(f.dc()) : "n/a", f.band()),
                   worse});
    }
    std::set<std::string> old_und;
    for (const auto& u : o.undetected) old_und.insert(u.first);
    for (const auto& u : f.undetected)
      if (!old_und.count(u.first)) c.push_back({fmt::format("{}: row {} undetected now", f.id, u.first), true});
    std::set<std::string> new_und;
    for (const auto& u : f.undetected) new_und.insert(u.first);
    for (const auto& u : old_und)
      if (!new_und.count(u)) c.push_back({fmt::format("{}: row {} detected now", f.id, u), false});
    if (o.worst_reaction_ns != f.worst_reaction_ns) {
      auto t = [](int64_t ns) { return ns >= 0 ? ms_text(ns) + " ms" : std::string("none"); };
      bool worse = f.worst_reaction_ns > o.worst_reaction_ns && o.worst_reaction_ns >= 0;
      c.push_back({fmt::format("{}: worst reaction {} -> {}", f.id, t(o.worst_reaction_ns), t(f.worst_reaction_ns)), worse});
    }
  }
  for (const auto& f : before.functions)
    if (!seen.count(f.id)) c.push_back({fmt::format("{}: safety function gone", f.id), true});
  std::set<std::string> old_un;
  for (const auto& u : before.unassessed) old_un.insert(exec_key(u.case_id, u.path));
  for (const auto& u : now.unassessed)
    if (!old_un.count(exec_key(u.case_id, u.path)))
      c.push_back({fmt::format("{}: new unassessed failure mode ({})", exec_key(u.case_id, u.path), u.transition), true});
  return c;
}

}  // namespace plcfi::report

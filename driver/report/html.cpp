// The HTML campaign report: one page, inline CSS and SVG, no scripts, no external resources.
#include "html.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <set>

#include <unistd.h>

#include <fmt/format.h>

#include "monitor/trace_reader.hpp"

namespace plcfi::report {

const char* html_verdict_name(HtmlVerdict v) {
  switch (v) {
    case HtmlVerdict::Pass: return "PASS";
    case HtmlVerdict::Fail: return "FAIL";
    case HtmlVerdict::NotReached: return "NOT REACHED";
    case HtmlVerdict::NotTested: return "NOT TESTED";
  }
  return "?";
}

const char* mutant_status_name(MutantStatus s) {
  switch (s) {
    case MutantStatus::Killed: return "killed";
    case MutantStatus::Survived: return "survived";
    case MutantStatus::Equivalent: return "equivalent";
  }
  return "?";
}

std::string html_escape(const std::string& s) {
  std::string o;
  o.reserve(s.size() + s.size() / 8);
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&#39;"; break;
      default: o += c;
    }
  }
  return o;
}

namespace {

std::string esc(const std::string& s) { return html_escape(s); }

// CSS class of a verdict badge: fixed names, never user text.
const char* verdict_class(HtmlVerdict v) {
  switch (v) {
    case HtmlVerdict::Pass: return "pass";
    case HtmlVerdict::Fail: return "fail";
    case HtmlVerdict::NotReached: return "nr";
    case HtmlVerdict::NotTested: return "nt";
  }
  return "nt";
}

std::string badge(HtmlVerdict v) {
  return fmt::format("<span class=\"badge {}\">{}</span>", verdict_class(v), html_verdict_name(v));
}

// "600 ms", "12.5 ms", "1.25 s": at most three significant decimals, no trailing zeros.
std::string duration(int64_t ns) {
  double a = std::fabs(static_cast<double>(ns));
  std::string s = a < 1e9 ? fmt::format("{:.3f}", static_cast<double>(ns) * 1e-6) : fmt::format("{:.3f}", static_cast<double>(ns) * 1e-9);
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  if (s == "-0") s = "0";
  return s + (a < 1e9 ? " ms" : " s");
}

std::string seconds(int64_t ns) { return fmt::format("{:.3f} s", static_cast<double>(ns) * 1e-9); }

// SVG text that must fit: cut to n characters with an ellipsis (the full text goes into a
// <title> by the caller).
std::string cut(const std::string& s, size_t n) {
  if (s.size() <= n) return s;
  size_t k = n - 1;
  while (k > 0 && (static_cast<unsigned char>(s[k]) & 0xC0) == 0x80) --k;  // not inside a UTF-8 sequence
  return s.substr(0, k) + "\u2026";
}

std::string num(double v) { return fmt::format("{:.1f}", v); }

// A value for a scale label: integers without a fraction.
std::string value_text(double v) {
  if (std::fabs(v) < 1e15 && v == std::floor(v)) return fmt::format("{}", static_cast<long long>(v));
  return fmt::format("{:.4g}", v);
}

// ---------------------------------------------------------------------------------------
// Waveforms

constexpr double kLabelW = 180, kPlotW = 840, kRightM = 24;
constexpr double kMarkerRowH = 14, kBoolLaneH = 26, kAnalogLaneH = 50, kAxisH = 30;
constexpr size_t kBuckets = 240;  // a lane with more changes is reduced to min/max per bucket

struct Lane {
  std::string name;
  monitor::TraceColumn::Kind kind = monitor::TraceColumn::Kind::Bool;
  std::vector<std::pair<int64_t, double>> pts;  // changes only
  bool faulted = false, alarm = false;
};

// Reduces a lane to at most 4 points per bucket of the time span: first, min, max, last
// of the bucket. Every edge still shows (a bucket with a change spans both levels).
std::vector<std::pair<int64_t, double>> decimate(const std::vector<std::pair<int64_t, double>>& pts, int64_t t0, int64_t t1) {
  if (pts.size() <= 2 * kBuckets) return pts;
  std::vector<std::pair<int64_t, double>> out;
  double span = static_cast<double>(t1 - t0);
  size_t i = 0;
  while (i < pts.size()) {
    auto bucket = [&](int64_t t) {
      return std::min(kBuckets - 1, static_cast<size_t>(std::max(0.0, static_cast<double>(t - t0) / span * kBuckets)));
    };
    size_t b = bucket(pts[i].first), j = i;
    double lo = pts[i].second, hi = pts[i].second;
    size_t lo_at = i, hi_at = i;
    while (j < pts.size() && bucket(pts[j].first) == b) {
      if (pts[j].second < lo) lo = pts[j].second, lo_at = j;
      if (pts[j].second > hi) hi = pts[j].second, hi_at = j;
      ++j;
    }
    std::set<size_t> keep = {i, lo_at, hi_at, j - 1};  // in time order
    for (size_t k : keep) out.push_back(pts[k]);
    i = j;
  }
  return out;
}

bool read_lanes(const HtmlExecution& e, std::vector<Lane>* lanes, int64_t* first, int64_t* last, std::string* err) {
  auto reader = monitor::TraceReader::open(e.vcd, 0, err);
  if (!reader) return false;
  const auto& cols = reader->columns();
  std::vector<Lane> all(cols.size());
  for (size_t i = 0; i < cols.size(); ++i) {
    all[i].name = cols[i].name;
    all[i].kind = cols[i].kind;
    all[i].faulted = cols[i].name == e.faulted;
    all[i].alarm = std::find(e.alarms.begin(), e.alarms.end(), cols[i].name) != e.alarms.end();
  }
  int64_t t = 0;
  std::vector<double> values;
  bool any = false;
  while (reader->next(&t, &values, err)) {
    if (!any) *first = t;
    any = true;
    *last = t;
    for (size_t i = 0; i < all.size() && i < values.size(); ++i) {
      double v = values[i];
      if (!std::isfinite(v)) continue;
      auto& p = all[i].pts;
      if (p.empty() || p.back().second != v) p.emplace_back(t, v);
    }
  }
  if (!err->empty()) return false;
  if (!any) {
    *err = e.vcd + ": the trace holds no samples";
    return false;
  }
  // The faulted signal first, then the alarms, then the rest in the trace's order.
  for (int pass = 0; pass < 3; ++pass)
    for (auto& l : all) {
      int rank = l.faulted ? 0 : l.alarm ? 1 : 2;
      if (rank == pass) lanes->push_back(l);
    }
  return true;
}

// A "nice" tick step (1, 2, 5 times a power of ten) for about n ticks over span.
int64_t tick_step(int64_t span, int n) {
  double raw = static_cast<double>(span) / n;
  double p = std::pow(10.0, std::floor(std::log10(std::max(raw, 1.0))));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw) return std::max<int64_t>(1, static_cast<int64_t>(m * p));
  return static_cast<int64_t>(10 * p);
}

}  // namespace

bool waveform_svg(const HtmlExecution& e, std::string* svg, std::string* err) {
  std::vector<Lane> lanes;
  int64_t first = 0, last = 0;
  err->clear();
  if (!read_lanes(e, &lanes, &first, &last, err)) return false;
  int64_t t0 = std::min(first, e.inject_ns);
  if (e.start_ns >= 0) t0 = std::min(t0, e.start_ns);  // every marker inside the plot
  int64_t t1 = std::max({last, e.end_ns, e.deadline_ns, e.reaction_ns, e.start_ns});
  if (t1 <= t0) t1 = t0 + 1'000'000;
  // The signals are known up to the end of the recording (the test's end): a deadline after
  // that is marked, but no value is drawn up to it.
  int64_t t_data = std::max(last, std::min(e.end_ns, t1));
  auto x = [&](int64_t t) { return kLabelW + static_cast<double>(t - t0) / static_cast<double>(t1 - t0) * kPlotW; };

  struct Marker {
    const char* what;
    const char* cls;
    int64_t t;
  };
  std::vector<Marker> markers = {{"fault injected", "m-inject", e.inject_ns}};
  if (e.start_ns >= 0) markers.push_back({"start", "m-start", e.start_ns});
  if (e.deadline_ns >= 0) markers.push_back({"deadline", "m-deadline", e.deadline_ns});
  if (e.reaction_ns >= 0) markers.push_back({"reaction", "m-reaction", e.reaction_ns});
  double top = kMarkerRowH * static_cast<double>(markers.size()) + 6;
  double h = top;
  for (const auto& l : lanes) h += l.kind == monitor::TraceColumn::Kind::Bool ? kBoolLaneH : kAnalogLaneH;
  double lanes_bottom = h;
  h += kAxisH;
  double w = kLabelW + kPlotW + kRightM;

  std::string o = fmt::format(
      "<svg class=\"wave\" xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {} {}\" width=\"{}\" height=\"{}\" role=\"img\">\n",
      num(w), num(h), num(w), num(h));
  o += fmt::format("<title>{}</title>\n", esc(e.title));
  // Lanes.
  double y = top;
  for (size_t li = 0; li < lanes.size(); ++li) {
    const auto& l = lanes[li];
    bool digital = l.kind == monitor::TraceColumn::Kind::Bool;
    double lh = digital ? kBoolLaneH : kAnalogLaneH;
    const char* hl = l.faulted ? " faulted" : l.alarm ? " alarm" : "";
    o += fmt::format("<g class=\"lane{}\" data-signal=\"{}\">\n", hl, esc(l.name));
    o += fmt::format("<rect class=\"lane-bg{}\" x=\"0\" y=\"{}\" width=\"{}\" height=\"{}\"/>\n", li % 2 ? " odd" : "", num(y),
                     num(w), num(lh));
    std::string tag = l.faulted ? " (faulted)" : l.alarm ? " (alarm)" : "";
    o += fmt::format("<text class=\"name\" x=\"6\" y=\"{}\">{}<title>{}</title></text>\n", num(y + 16),
                     esc(cut(l.name + tag, 26)), esc(l.name + tag));
    double hi_y = y + 5, lo_y = y + lh - 6;
    double vmin = 0, vmax = 1;
    if (!digital && !l.pts.empty()) {
      vmin = vmax = l.pts[0].second;
      for (const auto& p : l.pts) vmin = std::min(vmin, p.second), vmax = std::max(vmax, p.second);
      if (vmin == vmax) {  // constant: the line in the middle, its value as the only label
        o += fmt::format("<text class=\"scale\" x=\"{}\" y=\"{}\">{}</text>\n", num(kLabelW - 4), num((hi_y + lo_y) / 2 + 4),
                         esc(value_text(vmin)));
        vmin -= 1, vmax += 1;
      } else {
        o += fmt::format("<text class=\"scale\" x=\"{}\" y=\"{}\">{}</text>\n", num(kLabelW - 4), num(hi_y + 8), esc(value_text(vmax)));
        o += fmt::format("<text class=\"scale\" x=\"{}\" y=\"{}\">{}</text>\n", num(kLabelW - 4), num(lo_y), esc(value_text(vmin)));
      }
    }
    auto vy = [&](double v) {
      if (digital) return v != 0 ? hi_y : lo_y;
      return lo_y - (v - vmin) / (vmax - vmin) * (lo_y - hi_y);
    };
    auto pts = decimate(l.pts, t0, t1);
    if (!pts.empty()) {
      std::string d = fmt::format("M{},{}", num(x(pts[0].first)), num(vy(pts[0].second)));
      for (size_t k = 1; k < pts.size(); ++k) d += fmt::format("H{}V{}", num(x(pts[k].first)), num(vy(pts[k].second)));
      d += fmt::format("H{}", num(x(t_data)));
      if (digital) {  // the TRUE phases filled, so a glance shows when a signal is on
        std::string f = fmt::format("M{},{}", num(x(pts[0].first)), num(lo_y));
        for (const auto& p : pts) f += fmt::format("H{}V{}", num(x(p.first)), num(vy(p.second)));
        f += fmt::format("H{}V{}Z", num(x(t_data)), num(lo_y));
        o += fmt::format("<path class=\"fill\" d=\"{}\"/>\n", f);
      }
      o += fmt::format("<path class=\"sig\" d=\"{}\"/>\n", d);
    }
    o += "</g>\n";
    y += lh;
  }
  // The allowed reaction window, start to deadline, tinted over the lanes.
  if (e.start_ns >= 0 && e.deadline_ns >= e.start_ns)
    o += fmt::format("<rect class=\"window\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>\n", num(x(e.start_ns)), num(top),
                     num(x(e.deadline_ns) - x(e.start_ns)), num(lanes_bottom - top));
  // Markers, their labels staggered one row each at the top.
  for (size_t k = 0; k < markers.size(); ++k) {
    const auto& m = markers[k];
    double mx = x(m.t), ly = kMarkerRowH * static_cast<double>(k + 1);
    o += fmt::format("<line class=\"marker {}\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>\n", m.cls, num(mx), num(ly + 2), num(mx),
                     num(lanes_bottom));
    bool right = mx > kLabelW + kPlotW * 0.7;  // labels near the right edge grow to the left
    o += fmt::format("<text class=\"mlabel {}\" x=\"{}\" y=\"{}\" text-anchor=\"{}\">{} {}</text>\n", m.cls,
                     num(mx + (right ? -4 : 4)), num(ly), right ? "end" : "start", m.what,
                     esc(fmt::format("+{}", duration(m.t - e.inject_ns))));
  }
  // Time axis, relative to the injection.
  o += fmt::format("<line class=\"axis\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>\n", num(kLabelW), num(lanes_bottom), num(kLabelW + kPlotW),
                   num(lanes_bottom));
  int64_t step = tick_step(t1 - t0, 8);
  int64_t k0 = (t0 - e.inject_ns) / step - 1;
  for (int64_t k = k0;; ++k) {
    int64_t t = e.inject_ns + k * step;
    if (t > t1) break;
    if (t < t0) continue;
    double tx = x(t);
    o += fmt::format("<line class=\"tick\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>\n", num(tx), num(lanes_bottom), num(tx),
                     num(lanes_bottom + 5));
    o += fmt::format("<text class=\"tlabel\" x=\"{}\" y=\"{}\">{}</text>\n", num(tx), num(lanes_bottom + 17),
                     esc(k == 0 ? std::string("0") : fmt::format("{}{}", k > 0 ? "+" : "", duration(t - e.inject_ns))));
  }
  o += fmt::format("<text class=\"tlabel axis-name\" x=\"{}\" y=\"{}\">time since injection</text>\n", num(kLabelW - 16),
                   num(lanes_bottom + 17));
  o += "</svg>\n";
  *svg = std::move(o);
  return true;
}

namespace {

// ---------------------------------------------------------------------------------------
// Timing sequence diagram of a scenario: lifelines as lanes, steps as columns; in each
// column the precondition's values, the start, and each expected transition with its
// allowed time window.

constexpr double kTsdLabelW = 150, kStepW = 266, kPreW = 100, kTsdHeadH = 66, kTsdLaneH = 36;

bool is_bool_literal(const std::string& v) {
  std::string u;
  for (char c : v) u += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u == "TRUE" || u == "FALSE" || u == "1" || u == "0";
}
bool is_true_literal(const std::string& v) {
  std::string u;
  for (char c : v) u += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u == "TRUE" || u == "1";
}

std::string window_text(const HtmlTransition& t) {
  std::string w = t.min_ns >= 0 ? duration(t.min_ns) + " \u2026 " + duration(t.max_ns) : "\u2264 " + duration(t.max_ns);
  if (t.tolerance > 0) w += " \u00b1" + value_text(t.tolerance);
  return w;
}

// verdicts: the worst verdict of each case id (FAIL over NOT REACHED over PASS).
std::string tsd_svg(const HtmlScenario& sc, const std::vector<HtmlLifeline>& lifelines,
                    const std::map<std::string, HtmlVerdict>& verdicts) {
  // The lanes: lifelines this scenario mentions, in the TSD's order.
  std::vector<std::string> lanes;
  std::set<std::string> used;
  for (const auto& s : sc.steps) {
    for (const auto& p : s.pre) used.insert(p.first);
    for (const auto& t : s.transitions) used.insert(t.lifeline);
  }
  for (const auto& l : lifelines)
    if (used.count(l.name)) lanes.push_back(l.name);
  for (const auto& s : sc.steps) {  // anything not declared (a model filled by hand) at the end
    auto add = [&](const std::string& n) {
      if (std::find(lanes.begin(), lanes.end(), n) == lanes.end()) lanes.push_back(n);
    };
    for (const auto& p : s.pre) add(p.first);
    for (const auto& t : s.transitions) add(t.lifeline);
  }
  auto kind_of = [&](const std::string& n) {
    for (const auto& l : lifelines)
      if (l.name == n) return l.kind;
    return std::string();
  };
  double w = kTsdLabelW + kStepW * static_cast<double>(std::max<size_t>(1, sc.steps.size())) + 8;
  double h = kTsdHeadH + kTsdLaneH * static_cast<double>(lanes.size()) + 8;
  std::string o = fmt::format(
      "<svg class=\"tsd\" xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {} {}\" width=\"{}\" height=\"{}\" role=\"img\">\n",
      num(w), num(h), num(w), num(h));
  o += fmt::format("<title>scenario {}</title>\n", esc(sc.id));
  for (size_t li = 0; li < lanes.size(); ++li) {
    double y = kTsdHeadH + kTsdLaneH * static_cast<double>(li);
    o += fmt::format("<rect class=\"lane-bg{}\" x=\"0\" y=\"{}\" width=\"{}\" height=\"{}\"/>\n", li % 2 ? " odd" : "", num(y), num(w),
                     num(kTsdLaneH));
    std::string k = kind_of(lanes[li]);
    o += fmt::format("<text class=\"name\" x=\"6\" y=\"{}\">{}<title>{}</title></text>\n", num(y + 16), esc(cut(lanes[li], 20)),
                     esc(lanes[li]));
    if (!k.empty()) o += fmt::format("<text class=\"kind\" x=\"6\" y=\"{}\">{}</text>\n", num(y + 29), esc(k));
  }
  for (size_t si = 0; si < sc.steps.size(); ++si) {
    const auto& s = sc.steps[si];
    double x0 = kTsdLabelW + kStepW * static_cast<double>(si);
    o += fmt::format("<line class=\"step-sep\" x1=\"{}\" y1=\"0\" x2=\"{}\" y2=\"{}\"/>\n", num(x0), num(x0), num(h - 8));
    o += fmt::format("<text class=\"step-id\" x=\"{}\" y=\"16\">{}. {}<title>{}</title></text>\n", num(x0 + 8), si + 1,
                     esc(cut(s.id, 34)), esc(s.id));
    o += fmt::format("<text class=\"step-text\" x=\"{}\" y=\"32\">{}<title>{}</title></text>\n", num(x0 + 8), esc(cut(s.text, 42)),
                     esc(s.text));
    std::string start = s.start.empty() ? "start: previous transition" : "start: " + s.start;
    o += fmt::format("<text class=\"step-start\" x=\"{}\" y=\"48\">{}<title>{}</title></text>\n", num(x0 + 8),
                     esc(cut(start, 40)), esc(start));
    if (!s.condition.empty())
      o += fmt::format("<text class=\"step-cond\" x=\"{}\" y=\"62\">{}<title>{}</title></text>\n", num(x0 + 8),
                       esc(cut("and " + s.condition, 40)), esc("precondition also: " + s.condition));
    // The time area: the start at tx0, scaled so the longest window ends at 80 %.
    double tx0 = x0 + kPreW + 6, tw = kStepW - kPreW - 16;
    int64_t tmax = 1;
    for (const auto& t : s.transitions) tmax = std::max(tmax, t.max_ns);
    auto tx = [&](int64_t t) { return tx0 + static_cast<double>(t) / static_cast<double>(tmax) * tw * 0.8; };
    o += fmt::format("<line class=\"tsd-start\" x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\"/>\n", num(tx0), num(kTsdHeadH - 2), num(tx0),
                     num(h - 8));
    for (size_t li = 0; li < lanes.size(); ++li) {
      double y = kTsdHeadH + kTsdLaneH * static_cast<double>(li);
      for (const auto& p : s.pre) {
        if (p.first != lanes[li]) continue;
        std::string v = cut(p.second, 13);
        double chars = static_cast<double>(std::min<size_t>(p.second.size(), 13));
        double tw_tag = std::min(kPreW - 6, 12 + 6.6 * chars);
        o += fmt::format("<g class=\"pre\"><title>precondition {} = {}</title><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"18\" rx=\"9\"/>"
                         "<text x=\"{}\" y=\"{}\">{}</text></g>\n",
                         esc(p.first), esc(p.second), num(x0 + 6), num(y + 9), num(tw_tag), num(x0 + 11), num(y + 22), esc(v));
      }
      for (const auto& t : s.transitions) {
        if (t.lifeline != lanes[li]) continue;
        double xa = tx(std::max<int64_t>(0, t.min_ns)), xb = tx(t.max_ns), xe = tx0 + tw;
        bool tested = !t.cases.empty(), failed = false;
        for (const auto& id : t.cases) {
          auto v = verdicts.find(id);
          failed |= v != verdicts.end() && v->second != HtmlVerdict::Pass;
        }
        const char* cls = failed ? "tr tested failed" : tested ? "tr tested" : "tr";
        o += fmt::format("<g class=\"{}\"><title>{} \u2192 {} ({}){}</title>\n", cls, esc(t.lifeline), esc(t.to), esc(window_text(t)),
                         esc(tested ? "; faulted by " + [&] {
                           std::string c;
                           for (const auto& id : t.cases) c += (c.empty() ? "" : ", ") + id;
                           return c;
                         }()
                                    : std::string()));
        double ly = y + 30, hy = y + 18;  // low and high level
        o += fmt::format("<rect class=\"allowed\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>\n", num(xa), num(hy - 2),
                         num(std::max(2.0, xb - xa)), num(ly - hy + 4));
        if (is_bool_literal(t.to) && (t.from.empty() || is_bool_literal(t.from))) {
          bool to_hi = is_true_literal(t.to);
          double fy = to_hi ? ly : hy, ty = to_hi ? hy : ly;
          o += fmt::format("<path class=\"level\" d=\"M{},{}H{}L{},{}H{}\"/>\n", num(tx0), num(fy), num(xa), num(xb), num(ty), num(xe));
        } else {  // a bus: the value changes somewhere in the window
          o += fmt::format("<path class=\"level\" d=\"M{},{}H{}L{},{}H{}M{},{}H{}L{},{}H{}\"/>\n", num(tx0), num(hy), num(xa), num(xb),
                           num(ly), num(xe), num(tx0), num(ly), num(xa), num(xb), num(hy), num(xe));
        }
        std::string label = "\u2192 " + t.to + "  " + window_text(t);
        o += fmt::format("<text class=\"tr-label\" x=\"{}\" y=\"{}\">{}</text>\n", num(tx0 + 2), num(y + 12), esc(cut(label, 30)));
        if (tested) {  // the case ids coloured by their verdicts
          std::string ids;
          for (size_t k = 0; k < t.cases.size() && k < 3; ++k) {
            auto v = verdicts.find(t.cases[k]);
            ids += fmt::format("<tspan class=\"{}\">{}{}</tspan>", v == verdicts.end() ? "nt" : verdict_class(v->second),
                               k ? " " : "", esc(t.cases[k]));
          }
          if (t.cases.size() > 3) ids += "\u2026";
          o += fmt::format("<text class=\"tr-cases\" x=\"{}\" y=\"{}\" text-anchor=\"end\">{}</text>\n", num(xe + 6), num(y + 12),
                           ids);
        }
        o += "</g>\n";
      }
    }
  }
  o += "</svg>\n";
  return o;
}

const char* kCss = R"(
body{font:14px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",sans-serif;color:#1f2328;margin:0;background:#f6f8fa}
main{max-width:1280px;margin:0 auto;padding:20px 28px 60px;background:#fff}
h1{font-size:24px;margin:8px 0 2px}h2{font-size:19px;margin:34px 0 10px;border-bottom:2px solid #d0d7de;padding-bottom:4px}
h3{font-size:15px;margin:22px 0 4px}
.sub{color:#57606a;margin:0 0 12px}
.facts{display:grid;grid-template-columns:max-content auto;gap:2px 14px;margin:10px 0}
.facts dt{color:#57606a}.facts dd{margin:0}
.cards{display:flex;gap:12px;flex-wrap:wrap;margin:14px 0}
.card{border-radius:8px;padding:8px 16px;min-width:110px;border:1px solid #d0d7de}
.card b{display:block;font-size:26px;line-height:1.1}
.card.pass{background:#e6f4ea;border-color:#2b8a3e}.card.fail{background:#fdecec;border-color:#c92a2a}
.card.nr{background:#fff4e0;border-color:#e67700}.card.nt{background:#f1f3f5;border-color:#868e96}.card.zero{opacity:.45}
.badge{display:inline-block;padding:1px 8px;border-radius:10px;font-weight:700;font-size:12px;color:#fff;white-space:nowrap}
.badge.pass{background:#2b8a3e}.badge.fail{background:#c92a2a}.badge.nr{background:#e67700}.badge.nt{background:#868e96}
.badge.killed{background:#2b8a3e}.badge.survived{background:#c92a2a}.badge.equivalent{background:#868e96}
table{border-collapse:collapse;width:100%;font-size:13px}
th{background:#f1f3f5;text-align:left;position:sticky;top:0}
th,td{padding:5px 8px;border-bottom:1px solid #e1e4e8;vertical-align:top}
tr.fail td{background:#fff5f5}tr.nr td{background:#fffaf0}
td.num{text-align:right;font-variant-numeric:tabular-nums}
td.reason{max-width:360px}
.small{color:#57606a;font-size:12px}
code,.mono{font-family:ui-monospace,"DejaVu Sans Mono",monospace;font-size:12px}
ul.failures{margin:6px 0 0 0;padding-left:20px}ul.failures li{margin:2px 0}
.note{background:#fff8c5;border:1px solid #d4a72c;border-radius:6px;padding:8px 12px}
.error{background:#fdecec;border:1px solid #c92a2a;border-radius:6px;padding:8px 12px}
.exec{border:1px solid #d0d7de;border-radius:8px;padding:4px 14px 10px;margin:14px 0}
.exec.fail{border-color:#c92a2a;border-left-width:6px}
.scroll{overflow-x:auto}
svg{display:block;margin:6px 0;font-family:system-ui,"DejaVu Sans",sans-serif}
svg .lane-bg{fill:#fff}svg .lane-bg.odd{fill:#f6f8fa}
svg .faulted .lane-bg{fill:#fff0e0}svg .alarm .lane-bg{fill:#fdecec}
svg .name{font-size:12px;fill:#1f2328}svg .faulted .name{font-weight:700;fill:#b35900}svg .alarm .name{font-weight:700;fill:#a61e1e}
svg .scale{font-size:10px;fill:#57606a;text-anchor:end}
svg .sig{fill:none;stroke:#1864ab;stroke-width:1.6}svg .fill{fill:#d0e4f7;stroke:none}
svg .faulted .sig{stroke:#d9480f}svg .faulted .fill{fill:#ffd8b0}svg .alarm .sig{stroke:#c92a2a}svg .alarm .fill{fill:#f8c4c4}
svg .window{fill:#1c7ed6;fill-opacity:.08}
svg .marker{stroke-width:1.5}svg .mlabel{font-size:11px;font-weight:600}
svg line.m-inject{stroke:#d9480f}svg line.m-start{stroke:#1c7ed6}svg line.m-deadline{stroke:#c92a2a;stroke-dasharray:6 3}
svg line.m-reaction{stroke:#2b8a3e}svg text.m-inject{fill:#d9480f}svg text.m-start{fill:#1c7ed6}svg text.m-deadline{fill:#c92a2a}
svg text.m-reaction{fill:#2b8a3e}
svg .axis,svg .tick{stroke:#57606a}svg .tlabel{font-size:10px;fill:#57606a;text-anchor:middle}svg .axis-name{text-anchor:end}
svg .kind{font-size:10px;fill:#8c959f}
svg .step-sep{stroke:#adb5bd}svg .step-id{font-size:13px;font-weight:700}svg .step-text{font-size:11px;fill:#57606a}
svg .step-start{font-size:11px;fill:#1c7ed6}svg .step-cond{font-size:11px;fill:#57606a}
svg .tsd-start{stroke:#1c7ed6;stroke-dasharray:3 3}
svg .pre rect{fill:#e9ecef;stroke:#adb5bd}svg .pre text{font-size:11px;fill:#343a40}
svg .allowed{fill:#d3f9d8;stroke:#2b8a3e;stroke-dasharray:2 2}
svg .level{fill:none;stroke:#495057;stroke-width:1.6}svg .tested .level{stroke:#1864ab}svg .failed .level{stroke:#c92a2a;stroke-width:2.2}
svg .tr-label{font-size:11px;fill:#1f2328}svg .tr-cases{font-size:10px;font-weight:700}
svg tspan.pass{fill:#2b8a3e}svg tspan.fail{fill:#c92a2a}svg tspan.nr{fill:#e67700}svg tspan.nt{fill:#868e96}
svg.tsd{max-width:100%;height:auto}
.legend span{display:inline-block;margin-right:14px;font-size:12px}
.legend i{display:inline-block;width:14px;height:10px;margin-right:4px;vertical-align:middle}
)";

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string o;
  for (const auto& s : v) o += (o.empty() ? "" : sep) + s;
  return o;
}

void header_section(const HtmlReport& r, std::string& o) {
  const auto& h = r.header;
  o += fmt::format("<h1>{}</h1>\n", esc(h.title.empty() ? "Campaign " + h.name : h.title));
  if (!h.text.empty()) o += fmt::format("<p class=\"sub\">{}</p>\n", esc(h.text));
  o += "<div class=\"cards\">\n";
  auto card = [&](const char* cls, size_t n, const char* what) {
    o += fmt::format("<div class=\"card {}{}\"><b>{}</b>{}</div>\n", cls, n ? "" : " zero", n, what);
  };
  card("fail", h.fail, "FAIL");
  card("pass", h.pass, "PASS");
  card("nr", h.not_reached, "NOT REACHED");
  if (h.not_tested) card("nt", h.not_tested, "NOT TESTED");
  o += fmt::format("<div class=\"card\"><b>{}</b>execution(s) of {} case(s)</div>\n", h.executions, h.cases);
  o += "</div>\n<dl class=\"facts\">\n";
  auto fact = [&](const std::string& k, const std::string& v) {
    o += fmt::format("<dt>{}</dt><dd>{}</dd>\n", esc(k), esc(v));
  };
  if (!h.programs.empty()) fact(h.programs.size() > 1 ? "programs" : "program", join(h.programs, ", "));
  fact("plant", h.plant);
  fact("seed", std::to_string(h.seed));
  if (!h.end_reason.empty()) fact("ended", h.end_reason);
  for (const auto& [k, v] : h.facts) fact(k, v);
  o += "</dl>\n";
  // The failures at a glance, each linked to its waveform.
  std::vector<const HtmlRow*> bad;
  for (const auto& row : r.rows)
    if (row.verdict == HtmlVerdict::Fail || row.verdict == HtmlVerdict::NotReached) bad.push_back(&row);
  if (!bad.empty()) {
    o += "<h3>What failed</h3>\n<ul class=\"failures\">\n";
    for (const auto* row : bad) {
      std::string what = row->case_id + (row->path ? " path " + std::to_string(row->path) : std::string());
      std::string link = row->execution >= 0 ? fmt::format("<a href=\"#x{}\">{}</a>", row->execution, esc(what)) : esc(what);
      o += fmt::format("<li>{} {} <code>{}</code>: {}</li>\n", badge(row->verdict), link, esc(row->transition), esc(row->reason));
    }
    o += "</ul>\n";
  }
}

void table_section(const HtmlReport& r, std::string& o) {
  o += "<h2 id=\"verdicts\">Verdicts by case and path</h2>\n<div class=\"scroll\"><table class=\"verdicts\">\n";
  o += "<tr><th>case</th><th>path</th><th>verdict</th><th>RPN</th><th>class</th><th>transition</th><th>FMEA</th>"
       "<th>fault</th><th>latency</th><th>reason</th></tr>\n";
  for (const auto& row : r.rows) {
    std::string id = row.execution >= 0 ? fmt::format("<a href=\"#x{}\">{}</a>", row.execution, esc(row.case_id)) : esc(row.case_id);
    std::string cls = esc(row.class_id) + (row.class_name.empty() ? "" : " <span class=\"small\">" + esc(row.class_name) + "</span>");
    std::string fault = esc(row.fault);
    if (!row.failure_mode.empty()) fault = esc(row.failure_mode) + "<br><span class=\"small\">" + fault + "</span>";
    std::string reason = esc(row.reason);
    if (!row.expected.empty()) reason += "<br><span class=\"small\">expected: " + esc(row.expected) + "</span>";
    if (!row.branches.empty()) reason += "<br><span class=\"small\">path: <code>" + esc(join(row.branches, ", ")) + "</code></span>";
    o += fmt::format(
        "<tr class=\"{}\"><td>{}</td><td class=\"num\">{}</td><td>{}</td><td class=\"num\">{}</td><td>{}</td><td><code>{}</code></td>"
        "<td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"reason\">{}</td></tr>\n",
        verdict_class(row.verdict), id, row.path ? std::to_string(row.path) : "-", badge(row.verdict), row.rpn, cls,
        esc(row.transition), row.fmea_id.empty() ? "<span class=\"small\">generated</span>" : esc(row.fmea_id), fault,
        row.latency_ns >= 0 ? esc(duration(row.latency_ns)) : "-", reason);
  }
  o += "</table></div>\n";
}

void executions_section(const HtmlReport& r, std::string& o) {
  if (r.executions.empty() && r.waveform_note.empty()) return;
  o += "<h2 id=\"waveforms\">Test windows</h2>\n";
  if (!r.waveform_note.empty()) {
    o += fmt::format("<p class=\"note\">{}</p>\n", esc(r.waveform_note));
  } else {
    o += "<p class=\"legend\"><span><i style=\"background:#d9480f\"></i>fault injected</span>"
         "<span><i style=\"background:#1c7ed6\"></i>start</span><span><i style=\"background:#e7f0ff;border:1px solid #1c7ed6\"></i>"
         "reaction window (start to deadline)</span><span><i style=\"background:#c92a2a\"></i>deadline</span>"
         "<span><i style=\"background:#2b8a3e\"></i>reaction</span><span><i style=\"background:#ffd8b0\"></i>faulted signal</span>"
         "<span><i style=\"background:#f8c4c4\"></i>alarm</span></p>\n";
  }
  // The executions that did not pass first: they are what the reader came for.
  std::vector<size_t> order;
  for (int pass = 0; pass < 2; ++pass)
    for (size_t i = 0; i < r.executions.size(); ++i)
      if ((r.executions[i].verdict == HtmlVerdict::Pass) == (pass == 1)) order.push_back(i);
  for (size_t i : order) {
    const auto& e = r.executions[i];
    o += fmt::format("<section class=\"exec {}\" id=\"x{}\">\n<h3>{} {}</h3>\n", verdict_class(e.verdict), i, badge(e.verdict), esc(e.title));
    if (!e.summary.empty()) o += fmt::format("<p>{}</p>\n", esc(e.summary));
    std::string times = "injected at " + seconds(e.inject_ns);
    times += e.start_ns >= 0 ? ", start +" + duration(e.start_ns - e.inject_ns) : ", start never held";
    if (e.deadline_ns >= 0) times += ", deadline +" + duration(e.deadline_ns - e.inject_ns);
    times += e.reaction_ns >= 0 ? ", reaction +" + duration(e.reaction_ns - e.inject_ns) : ", no reaction";
    times += ", end +" + duration(e.end_ns - e.inject_ns);
    o += fmt::format("<p class=\"small\">{}</p>\n", esc(times));
    if (!r.waveform_note.empty()) {
    } else if (e.vcd.empty()) {
      o += "<p class=\"note\">no trace was recorded for this execution</p>\n";
    } else {
      std::string svg, err;
      if (waveform_svg(e, &svg, &err))
        o += "<div class=\"scroll\">" + svg + "</div>\n" + fmt::format("<p class=\"small\">trace: <code>{}</code></p>\n", esc(e.vcd));
      else
        o += fmt::format("<p class=\"error\">trace not drawn: {}</p>\n", esc(err));
    }
    o += "</section>\n";
  }
}

void tsd_section(const HtmlReport& r, std::string& o) {
  if (r.scenarios.empty()) return;
  o += "<h2 id=\"tsd\">Timing sequence diagram</h2>\n";
  if (!r.tsd_path.empty()) o += fmt::format("<p class=\"small\">from <code>{}</code>: per step the precondition (grey), the start "
                                            "(blue dashed line) and each expected transition with its allowed window (green); "
                                            "a transition faulted by test cases names them, coloured by verdict, and is red when one "
                                            "of them did not pass.</p>\n",
                                            esc(r.tsd_path));
  std::map<std::string, HtmlVerdict> verdicts;
  auto rank = [](HtmlVerdict v) { return v == HtmlVerdict::Fail ? 3 : v == HtmlVerdict::NotReached ? 2 : v == HtmlVerdict::NotTested ? 1 : 0; };
  for (const auto& row : r.rows) {
    auto [it, fresh] = verdicts.emplace(row.case_id, row.verdict);
    if (!fresh && rank(row.verdict) > rank(it->second)) it->second = row.verdict;
  }
  for (const auto& sc : r.scenarios) {
    o += fmt::format("<h3>Scenario {}{}</h3>\n", esc(sc.id), sc.text.empty() ? "" : ": " + esc(sc.text));
    o += "<div class=\"scroll\">" + tsd_svg(sc, r.lifelines, verdicts) + "</div>\n";
  }
}

void suggestions_section(const HtmlReport& r, std::string& o) {
  if (r.suggestions.empty()) return;
  o += "<h2 id=\"suggestions\">FMEA suggestions</h2>\n<div class=\"scroll\"><table>\n";
  o += "<tr><th>component</th><th>failure mode</th><th>effect seen</th><th>detected by</th><th>case</th><th>transition</th></tr>\n";
  for (const auto& s : r.suggestions)
    o += fmt::format("<tr class=\"{}\"><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td><code>{}</code></td></tr>\n",
                     s.alarm.empty() ? "fail" : "", esc(s.component), esc(s.failure_mode), esc(s.effect),
                     s.alarm.empty() ? "<b>none</b>" : "<code>" + esc(s.alarm) + "</code>", esc(s.case_id), esc(s.transition));
  o += "</table></div>\n";
}

// Diagnostic coverage and reaction per safety function, the unassessed failures, then the
// traceability matrix and the fingerprint that lets an assessor reproduce each line.
void safety_section(const HtmlReport& r, std::string& o) {
  if (!r.safety) return;
  const SafetyReport& s = *r.safety;
  o += "<h2 id=\"safety\">Safety evidence</h2>\n";
  o += "<p class=\"small\">Rates in FIT (failures per 10<sup>9</sup> h). A row is detected when every execution of "
       "every case and path PASSED; DC = &lambda;<sub>DD</sub> / &lambda;<sub>D</sub>, banded as IEC 61508-2 (none &lt; "
       "60 %, low, medium from 90 %, high from 99 %). Reaction: from the injection of the fault to the scan in which the "
       "class's reaction was complete; margin = safety time &minus; worst reaction.</p>\n";
  o += "<div class=\"scroll\"><table class=\"safety\">\n<tr><th>safety function</th><th>rows</th><th>&lambda;<sub>D</sub></th>"
       "<th>&lambda;<sub>DD</sub></th><th>DC</th><th>band</th><th>SFF</th><th>worst reaction</th><th>safety time</th>"
       "<th>margin</th><th>undetected</th></tr>\n";
  auto ms = [](int64_t ns) { return ns >= 0 ? ms_text(ns) + " ms" : std::string("-"); };
  for (const auto& f : s.functions) {
    std::string und;
    for (const auto& [row, why] : f.undetected) und += fmt::format("<div><b>{}</b>: {}</div>", esc(row), esc(why));
    bool bad = !f.undetected.empty() || (f.has_margin() && f.margin_ns() < 0);
    o += fmt::format("<tr class=\"{}\" data-function=\"{}\"><td><b>{}</b></td><td>{}</td><td class=\"num\">{}</td>"
                     "<td class=\"num\">{}</td><td class=\"num dc\">{}</td><td class=\"band\">{}</td><td class=\"num\">{}</td>"
                     "<td class=\"num worst\">{}{}</td><td class=\"num\">{}</td><td class=\"num margin\">{}</td><td>{}</td></tr>\n",
                     bad ? "fail" : "", esc(f.id), esc(f.id), esc(join(f.rows, " ")), fmt::format("{}", f.lambda_d),
                     fmt::format("{}", f.lambda_dd), f.has_dc() ? fmt::format("{:.1f} %", f.dc() * 100) : "n/a", esc(f.band()),
                     f.has_safe ? fmt::format("{:.1f} %", f.sff() * 100) : "-", ms(f.worst_reaction_ns),
                     f.worst_execution.empty() ? "" : " <span class=\"small\">(" + esc(f.worst_execution) + ")</span>",
                     ms(f.safety_time_ns), f.has_margin() ? ms(f.margin_ns()) : "-", und.empty() ? "none" : und);
  }
  o += "</table></div>\n";
  if (!s.unassessed.empty()) {
    o += "<h3>Unassessed failure modes (found by exploring, no FMEA row)</h3>\n<div class=\"scroll\"><table class=\"unassessed\">\n"
         "<tr><th>case</th><th>path</th><th>verdict</th><th>transition</th><th>fault</th><th>reason</th></tr>\n";
    for (const auto& u : s.unassessed)
      o += fmt::format("<tr class=\"fail\"><td>{}</td><td class=\"num\">{}</td><td>{}</td><td><code>{}</code></td><td>{}</td>"
                       "<td class=\"reason\">{}</td></tr>\n",
                       esc(u.case_id), u.path, esc(u.verdict), esc(u.transition), esc(u.fault), esc(u.reason));
    o += "</table></div>\n";
  }
  o += "<h3 id=\"traceability\">Traceability: FMEA row, case, path, verdict, evidence</h3>\n"
       "<div class=\"scroll\"><table class=\"trace\">\n<tr><th>FMEA</th><th>function</th><th>FIT</th><th>dangerous</th>"
       "<th>case</th><th>path</th><th>verdict</th><th>reaction</th><th>latency</th><th>safety time</th><th>journal line</th>"
       "<th>VCD</th><th>diagrams</th></tr>\n";
  for (const auto& t : s.trace) {
    const char* cls = t.verdict == "PASS" ? "" : t.verdict == "FAIL" ? "fail" : "nr";
    o += fmt::format("<tr class=\"{}\"><td>{}</td><td>{}</td><td class=\"num\">{}</td><td>{}</td><td>{}</td><td class=\"num\">{}</td>"
                     "<td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
                     "<td><code>{}</code></td><td><code>{}</code> <code>{}</code></td></tr>\n",
                     cls, t.fmea.empty() ? "-" : esc(t.fmea), esc(t.safety_function),
                     t.failure_rate >= 0 ? fmt::format("{}", t.failure_rate) : "", esc(t.dangerous), esc(t.case_id),
                     t.path ? std::to_string(t.path) : "-", esc(t.verdict), ms(t.reaction_ns), ms(t.latency_ns),
                     ms(t.safety_time_ns), t.journal_line ? std::to_string(t.journal_line) : "-", esc(t.vcd),
                     esc(t.sequence_diagram), esc(t.timing_diagram));
  }
  o += "</table></div>\n<h3>Fingerprint</h3>\n<dl class=\"facts fingerprint\">\n";
  for (const auto& [k, v] : s.fingerprint) o += fmt::format("<dt>{}</dt><dd><code>{}</code></dd>\n", esc(k), esc(v));
  o += "</dl>\n";
}

void mutants_section(const HtmlReport& r, std::string& o) {
  if (r.mutants.empty()) return;
  size_t killed = 0, survived = 0, equivalent = 0;
  for (const auto& m : r.mutants)
    (m.status == MutantStatus::Killed ? killed : m.status == MutantStatus::Survived ? survived : equivalent)++;
  o += "<h2 id=\"mutants\">Mutants</h2>\n";
  size_t scored = killed + survived;
  o += fmt::format("<p>{} killed, {} survived, {} equivalent{}</p>\n", killed, survived, equivalent,
                   scored ? fmt::format("; mutation score {:.1f} %", 100.0 * static_cast<double>(killed) / static_cast<double>(scored))
                          : std::string());
  o += "<div class=\"scroll\"><table>\n<tr><th>mutant</th><th>location</th><th>change</th><th>status</th><th>killed by</th><th>reason</th></tr>\n";
  // Survivors first: they are what the reader has to act on.
  for (int pass = 0; pass < 2; ++pass)
    for (const auto& m : r.mutants) {
      if ((m.status == MutantStatus::Survived) != (pass == 0)) continue;
      o += fmt::format("<tr class=\"{}\"><td>{}</td><td><code>{}</code></td><td><code>{}</code></td><td><span class=\"badge {}\">{}</span></td>"
                       "<td>{}</td><td>{}</td></tr>\n",
                       m.status == MutantStatus::Survived ? "fail" : "", esc(m.id), esc(m.location), esc(m.change),
                       mutant_status_name(m.status), mutant_status_name(m.status), esc(m.killed_by), esc(m.reason));
    }
  o += "</table></div>\n";
}

}  // namespace

std::string html_report(const HtmlReport& r) {
  std::string o = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  o += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  o += fmt::format("<title>plcfi {}</title>\n",
                   esc(r.header.title.empty() ? "campaign " + r.header.name : r.header.title));
  o += "<style>" + std::string(kCss) + "</style>\n</head>\n<body>\n<main>\n";
  header_section(r, o);
  if (!r.rows.empty() || r.mutants.empty()) table_section(r, o);  // a mutation page has no verdict rows
  safety_section(r, o);
  suggestions_section(r, o);
  mutants_section(r, o);
  executions_section(r, o);
  tsd_section(r, o);
  o += "<p class=\"small\" style=\"margin-top:40px\">written by plcfi</p>\n</main>\n</body>\n</html>\n";
  return o;
}

bool write_html_report(const HtmlReport& r, const std::string& dir, std::string* err) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    *err = dir + ": cannot create the folder (" + ec.message() + ")";
    return false;
  }
  std::string path = (std::filesystem::path(dir) / "index.html").string();
  std::string text = html_report(r);
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) {
    *err = path + ": cannot write (" + std::strerror(errno) + ")";
    return false;
  }
  bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  ok = std::fclose(f) == 0 && ok;
  if (!ok) *err = path + ": write failed";
  return ok;
}

bool html_dir_writable(const std::string& dir, std::string* err) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    *err = dir + ": cannot create the folder (" + ec.message() + ")";
    return false;
  }
  if (::access(dir.c_str(), W_OK) != 0) {
    *err = dir + ": the folder is not writable";
    return false;
  }
  return true;
}

}  // namespace plcfi::report

// The HTML campaign report: hostile strings escaped, optional sections only when filled,
// waveforms drawn from a VCD with their edges (also after decimation), same model same bytes.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "report/html.hpp"

namespace plcfi::report {
namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("plcfi_html_" + std::to_string(::getpid()) + "_" + name)).string();
}

std::string write_temp(const std::string& name, const std::string& text) {
  std::string p = temp_path(name);
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

size_t count(const std::string& s, const std::string& what) {
  size_t n = 0;
  for (size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

// A trace of a BOOL x that rises at 50 ms and an INT n, 0..100 ms.
const char* kEdgeVcd =
    "$timescale 1ns $end\n"
    "$var wire 1 ! x $end\n"
    "$var integer 16 \" n $end\n"
    "$enddefinitions $end\n"
    "#0\n$dumpvars\n0!\nb0 \"\n$end\n"
    "#50000000\n1!\n"
    "#100000000\nb101 \"\n";

HtmlReport small_report() {
  HtmlReport r;
  r.header.name = "stamping";
  r.header.plant = "stamping";
  r.header.seed = 7;
  r.header.cases = 1;
  r.header.executions = 1;
  r.header.fail = 1;
  HtmlRow row;
  row.case_id = "TC1";
  row.path = 1;
  row.verdict = HtmlVerdict::Fail;
  row.rpn = 45;
  row.class_id = "1";
  row.class_name = "stop";
  row.transition = "init.ref_lower.StampLowered";
  row.fmea_id = "F3";
  row.fault = "StampLowered (%IX0.4): stuck";
  row.reason = "deadline missed";
  r.rows.push_back(row);
  return r;
}

// The d attribute of the signal path in the lane of `signal`.
std::string lane_path(const std::string& svg, const std::string& signal) {
  size_t g = svg.find("data-signal=\"" + signal + "\"");
  if (g == std::string::npos) return "";
  size_t p = svg.find("<path class=\"sig\" d=\"", g);
  if (p == std::string::npos) return "";
  p += std::strlen("<path class=\"sig\" d=\"");
  return svg.substr(p, svg.find('"', p) - p);
}

TEST(HtmlReport, EscapesHostileStringsEverywhere) {
  HtmlReport r = small_report();
  const std::string evil = "<script>alert(\"x\")</script> & 'q'";
  r.header.name = evil;
  r.header.text = evil;
  r.header.programs = {evil};
  r.header.facts = {{evil, evil}};
  r.rows[0].case_id = evil;
  r.rows[0].reason = evil;
  r.rows[0].fault = evil;
  r.rows[0].branches = {evil};
  HtmlExecution e;
  e.title = evil;
  e.summary = evil;
  e.vcd = temp_path("missing<&>.vcd");  // unreadable: its name is shown with the error
  r.executions.push_back(e);
  r.rows[0].execution = 0;
  r.lifelines = {{evil, "sensor"}};
  HtmlScenario sc{evil, evil, {}};
  HtmlStep st{evil, evil, {{evil, evil}}, evil, evil, {}};
  st.transitions.push_back({evil, evil, evil, -1, 500'000'000, 0, {evil}});
  sc.steps.push_back(st);
  r.scenarios.push_back(sc);
  r.suggestions.push_back({evil, evil, evil, evil, evil, evil});
  r.mutants.push_back({evil, evil, evil, MutantStatus::Killed, evil, evil});
  std::string html = html_report(r);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("'q'"), std::string::npos);
  EXPECT_EQ(html.find("\"x\""), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt; &amp; &#39;q&#39;"), std::string::npos);
  EXPECT_NE(html.find("missing&lt;&amp;&gt;.vcd"), std::string::npos);
  EXPECT_NE(html.find("trace not drawn"), std::string::npos);
  EXPECT_EQ(html_escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&#39;");
}

TEST(HtmlReport, OptionalSectionsOnlyWhenFilled) {
  HtmlReport r = small_report();
  std::string plain = html_report(r);
  EXPECT_EQ(plain.find("FMEA suggestions"), std::string::npos);
  EXPECT_EQ(plain.find("id=\"mutants\""), std::string::npos);
  EXPECT_EQ(plain.find("id=\"tsd\""), std::string::npos);

  r.suggestions.push_back({"StampLowered sensor", "stuck at FALSE in hold", "stamp stays down", "", "X12", "normal.hold.StampUp"});
  r.suggestions.push_back({"Slider", "slow", "late delivery", "gSliderError", "X13", "normal.deliver.PosStamp"});
  r.mutants.push_back({"M1", "stamping.st:10:5", "AND -> OR", MutantStatus::Killed, "TC3", "alarm raised early"});
  r.mutants.push_back({"M2", "stamping.st:22:9", "T#500ms -> T#5s", MutantStatus::Survived, "", "no case saw the change"});
  r.mutants.push_back({"M3", "stamping.st:30:1", "x := x -> x := x", MutantStatus::Equivalent, "", "same code"});
  std::string html = html_report(r);
  EXPECT_NE(html.find("FMEA suggestions"), std::string::npos);
  EXPECT_NE(html.find("stuck at FALSE in hold"), std::string::npos);
  EXPECT_NE(html.find("<b>none</b>"), std::string::npos);        // undetected: no alarm
  EXPECT_NE(html.find("<code>gSliderError</code>"), std::string::npos);
  EXPECT_NE(html.find("id=\"mutants\""), std::string::npos);
  EXPECT_NE(html.find("1 killed, 1 survived, 1 equivalent; mutation score 50.0 %"), std::string::npos);
  // The survivor is listed before the others.
  size_t m1 = html.find("<td>M1</td>"), m2 = html.find("<td>M2</td>"), m3 = html.find("<td>M3</td>");
  ASSERT_NE(m1, std::string::npos);
  ASSERT_NE(m2, std::string::npos);
  ASSERT_NE(m3, std::string::npos);
  EXPECT_LT(m2, m1);
  EXPECT_LT(m1, m3);
  EXPECT_NE(html.find("<span class=\"badge survived\">survived</span>"), std::string::npos);
}

TEST(HtmlReport, WaveformDrawsTheEdgeWhereItIs) {
  HtmlExecution e;
  e.title = "TC1 path 1";
  e.vcd = write_temp("edge.vcd", kEdgeVcd);
  e.inject_ns = 0;
  e.start_ns = 10'000'000;
  e.deadline_ns = 60'000'000;
  e.end_ns = 100'000'000;
  e.faulted = "x";
  e.alarms = {"n"};
  std::string svg, err;
  ASSERT_TRUE(waveform_svg(e, &svg, &err)) << err;
  std::string d = lane_path(svg, "x");
  // M<x0>,<low>H<x_edge>V<high>H<x_end>: one rise, halfway through the window.
  double x0, ylo, xe, yhi, x1;
  ASSERT_EQ(std::sscanf(d.c_str(), "M%lf,%lfH%lfV%lfH%lf", &x0, &ylo, &xe, &yhi, &x1), 5) << d;
  EXPECT_EQ(count(d, "V"), 1u) << d;
  EXPECT_LT(yhi, ylo);  // goes up
  EXPECT_NEAR(xe, (x0 + x1) / 2, 0.11);
  EXPECT_NE(svg.find("class=\"lane faulted\" data-signal=\"x\""), std::string::npos);
  EXPECT_NE(svg.find("class=\"lane alarm\" data-signal=\"n\""), std::string::npos);
  // The integer lane steps once, with its range as the scale.
  EXPECT_EQ(count(lane_path(svg, "n"), "V"), 1u);
  EXPECT_NE(svg.find("\">5</text>"), std::string::npos);  // b101: the scale's top is 5
  for (const char* m : {"m-inject", "m-start", "m-deadline"}) EXPECT_NE(svg.find(m), std::string::npos) << m;
  EXPECT_EQ(svg.find("m-reaction"), std::string::npos);  // no reaction seen: no marker
  std::remove(e.vcd.c_str());
}

TEST(HtmlReport, LongTraceIsDecimatedKeepingBothLevels) {
  std::string vcd = "$timescale 1ns $end\n$var wire 1 ! fast $end\n$enddefinitions $end\n";
  const int n = 20000;
  for (int i = 0; i < n; ++i) vcd += "#" + std::to_string(int64_t(i) * 1'000'000) + "\n" + (i % 2 ? "1!\n" : "0!\n");
  HtmlExecution e;
  e.vcd = write_temp("fast.vcd", vcd);
  e.end_ns = int64_t(n) * 1'000'000;
  std::string svg, err;
  ASSERT_TRUE(waveform_svg(e, &svg, &err)) << err;
  std::string d = lane_path(svg, "fast");
  size_t segments = count(d, "V");
  EXPECT_GT(segments, 100u);
  EXPECT_LT(segments, 1000u);  // 20000 edges reduced to a few per bucket
  EXPECT_LT(svg.size(), 60'000u);
  std::remove(e.vcd.c_str());
}

TEST(HtmlReport, SameModelSameBytesAndUnwritableFolder) {
  HtmlReport r = small_report();
  HtmlExecution e;
  e.title = "TC1 path 1";
  e.vcd = write_temp("det.vcd", kEdgeVcd);
  e.end_ns = 100'000'000;
  r.executions.push_back(e);
  r.rows[0].execution = 0;
  std::string a = temp_path("a"), b = temp_path("b"), err;
  ASSERT_TRUE(write_html_report(r, a, &err)) << err;
  ASSERT_TRUE(write_html_report(r, b, &err)) << err;
  std::string ta = slurp(a + "/index.html"), tb = slurp(b + "/index.html");
  EXPECT_FALSE(ta.empty());
  EXPECT_EQ(ta, tb);
  EXPECT_EQ(ta, html_report(r));
  EXPECT_NE(ta.find("<a href=\"#x0\">TC1</a>"), std::string::npos);
  EXPECT_NE(ta.find("<section class=\"exec fail\" id=\"x0\">"), std::string::npos);
  // A passing execution added before it in the model is drawn after the failure.
  HtmlExecution ok = e;
  ok.title = "TC0 path 1";
  ok.verdict = HtmlVerdict::Pass;
  r.executions.insert(r.executions.begin(), ok);
  r.rows[0].execution = 1;
  std::string two = html_report(r);
  size_t fail_at = two.find("<section class=\"exec fail\" id=\"x1\">"), pass_at = two.find("<section class=\"exec pass\" id=\"x0\">");
  ASSERT_NE(fail_at, std::string::npos);
  ASSERT_NE(pass_at, std::string::npos);
  EXPECT_LT(fail_at, pass_at);
  // Self-contained: nothing is loaded from elsewhere.
  for (const char* ext : {"src=", "<link", "@import", "url("}) EXPECT_EQ(ta.find(ext), std::string::npos) << ext;
  std::filesystem::remove_all(a);
  std::filesystem::remove_all(b);
  std::remove(e.vcd.c_str());

  std::string blocker = write_temp("file", "x");  // a file where the folder should be
  EXPECT_FALSE(write_html_report(r, blocker + "/sub", &err));
  EXPECT_NE(err.find(blocker + "/sub"), std::string::npos) << err;
  std::remove(blocker.c_str());
}

TEST(HtmlReport, TsdMarksTheTestedTransitionWithItsWindow) {
  HtmlReport r = small_report();
  r.lifelines = {{"StampDown", "actuator"}, {"StampLowered", "sensor"}, {"Unused", "sensor"}};
  HtmlStep st{"ref_lower", "lower the stamp", {{"StampLowered", "FALSE"}}, "", "StampDown", {}};
  st.transitions.push_back({"StampLowered", "FALSE", "TRUE", 100'000'000, 500'000'000, 0, {"TC1", "TC9"}});
  r.scenarios.push_back({"init", "Initialization", {st}});
  std::string html = html_report(r);
  EXPECT_NE(html.find("<svg class=\"tsd\""), std::string::npos);
  EXPECT_NE(html.find("\u2192 TRUE  100 ms \u2026 500 ms"), std::string::npos);
  // The case ids coloured by verdict: TC1 failed (a row says so), TC9 has no row.
  EXPECT_NE(html.find("<tspan class=\"fail\">TC1</tspan><tspan class=\"nt\"> TC9</tspan>"), std::string::npos);
  EXPECT_NE(html.find("start: StampDown"), std::string::npos);
  EXPECT_NE(html.find("<g class=\"tr tested failed\">"), std::string::npos);
  r.rows[0].verdict = HtmlVerdict::Pass;
  html = html_report(r);
  EXPECT_NE(html.find("<g class=\"tr tested\">"), std::string::npos);
  EXPECT_NE(html.find("<tspan class=\"pass\">TC1</tspan>"), std::string::npos);
  EXPECT_EQ(html.find(">Unused<"), std::string::npos);  // lifelines the scenario does not use are left out
}

}  // namespace
}  // namespace plcfi::report

// EDTL monitors against the definition (shared/reference/edtl.md): every operator at the
// trace start, each phase of the checking procedure, pending instances, PASSED with a
// time column and with a cycle time, and a property test comparing the incremental
// monitor with a direct implementation on random traces.
#include <gtest/gtest.h>

#include "../../support/temp_files.hpp"

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <set>

#include <unistd.h>

#include "monitor/edtl.hpp"

namespace plcfi::monitor {
namespace {

using testing_support::remember_temp;

// Temporary files are unique per test and process: ctest runs tests in parallel.
std::string write_temp(const std::string& name, const std::string& text) {
  static int counter = 0;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string unique = std::string(info ? info->test_suite_name() : "x") + "_" + (info ? info->name() : "y") + "_" +
                       std::to_string(::getpid()) + "_" + std::to_string(++counter) + "_" + name;
  auto p = (std::filesystem::temp_directory_path() / unique).string();
  std::ofstream f(p);
  f << text;
  return remember_temp(p);
}

// Runs one requirements text on one CSV text; cycle_ns as for `plcfi edtl check`.
std::vector<Verdict> check(const std::string& reqs_yaml, const std::string& csv, int64_t cycle_ns = 0) {
  auto rp = write_temp("plcfi_edtl_test.yaml", reqs_yaml);
  auto tp = write_temp("plcfi_edtl_test.csv", csv);
  RequirementsFile reqs;
  std::string err;
  EXPECT_TRUE(load_requirements(rp, &reqs, &err)) << err;
  TraceCheck out;
  EXPECT_TRUE(check_trace(reqs, tp, cycle_ns, &out, &err)) << err;
  std::filesystem::remove(rp);
  std::filesystem::remove(tp);
  if (out.verdicts.empty()) out.verdicts.resize(1);  // a failed check is reported above; keep v[0] valid
  return out.verdicts;
}

// The states where `expr` is TRUE: a requirement triggered by it with invariant FALSE
// is violated exactly at each of those states.
std::vector<uint64_t> true_states(const std::string& expr, const std::string& csv) {
  auto v = check("requirements:\n  - id: R\n    trigger: \"" + expr + "\"\n    invariant: \"FALSE\"\n    final: \"FALSE\"\n", csv);
  std::vector<uint64_t> out;
  for (const auto& x : v.at(0).violations) out.push_back(x.state);
  return out;
}

// x: 1 0 0 1 1 0 ; n: 5 5 7 3 3 9
const char* kTrace = "x,n\n1,5\n0,5\n0,7\n1,3\n1,3\n0,9\n";

TEST(EdtlOperators, EdgeFormsAreFalseInTheFirstStateAndCorrectAfter) {
  using V = std::vector<uint64_t>;
  EXPECT_EQ(V({3}), true_states("RISING(x)", kTrace));
  EXPECT_EQ(V({3}), true_states("/x", kTrace));
  EXPECT_EQ(V({1, 5}), true_states("FALLING(x)", kTrace));
  EXPECT_EQ(V({1, 5}), true_states("\\\\x", kTrace));
  EXPECT_EQ(V({4}), true_states("HIGH(x)", kTrace));
  EXPECT_EQ(V({4}), true_states("~x", kTrace));
  EXPECT_EQ(V({2}), true_states("LOW(x)", kTrace));
  EXPECT_EQ(V({2}), true_states("_x", kTrace));
  EXPECT_EQ(V({2, 3, 5}), true_states("CHANGES(n)", kTrace));
  EXPECT_EQ(V({2, 5}), true_states("INCREASES(n)", kTrace));
  EXPECT_EQ(V({3}), true_states("DECREASES(n)", kTrace));
  EXPECT_EQ(V({0, 3, 4}), true_states("x", kTrace)) << "a plain formula holds at state 0";
  EXPECT_EQ(V({3, 4}), true_states("x AND n < 5", kTrace));
}

TEST(EdtlPhases, ReleaseInPhaseAHolds) {
  auto v = check("requirements:\n  - id: R\n    trigger: \"/a\"\n    invariant: \"b\"\n    final: \"FALSE\"\n    release: \"c\"\n",
                 "a,b,c\n0,1,0\n1,1,0\n1,1,0\n1,1,1\n0,0,0\n");
  EXPECT_FALSE(v[0].violated());
  EXPECT_EQ(1u, v[0].holds);
  EXPECT_EQ(0u, v[0].pending);
}

TEST(EdtlPhases, InvariantBrokenInPhaseA) {
  auto v = check("requirements:\n  - id: R\n    trigger: \"/a\"\n    invariant: \"b\"\n    final: \"FALSE\"\n",
                 "a,b\n0,1\n1,1\n1,1\n1,0\n");
  ASSERT_TRUE(v[0].violated());
  EXPECT_EQ(1u, v[0].violations[0].trigger_state);
  EXPECT_EQ(3u, v[0].violations[0].state);
  EXPECT_EQ(Cause::Invariant, v[0].violations[0].cause);
}

TEST(EdtlPhases, FinalStartsPhaseBInTheSameStateAndDelayTrueNeedsTheReactionThere) {
  const char* reqs = "requirements:\n  - id: R\n    trigger: \"/a\"\n    final: \"f\"\n    delay: \"TRUE\"\n    reaction: \"r\"\n";
  auto ok = check(reqs, "a,f,r\n0,0,0\n1,0,0\n0,1,1\n");
  EXPECT_FALSE(ok[0].violated());
  EXPECT_EQ(1u, ok[0].holds);
  auto bad = check(reqs, "a,f,r\n0,0,0\n1,0,0\n0,1,0\n0,0,1\n");
  ASSERT_TRUE(bad[0].violated());
  EXPECT_EQ(2u, bad[0].violations[0].state);
  EXPECT_EQ(Cause::Delay, bad[0].violations[0].cause);
}

TEST(EdtlPhases, ReactionWithinTheDelayAndInvariantInPhaseB) {
  const char* reqs =
      "requirements:\n  - id: R\n    trigger: \"/a\"\n    invariant: \"i\"\n    final: \"TRUE\"\n    delay: \"PASSED(T#3s)\"\n"
      "    reaction: \"r\"\n";
  // One state per second (no time column, default cycle 1 s).
  auto in_time = check(reqs, "a,i,r\n0,1,0\n1,1,0\n0,1,0\n0,1,1\n");
  EXPECT_FALSE(in_time[0].violated());
  auto late = check(reqs, "a,i,r\n0,1,0\n1,1,0\n0,1,0\n0,1,0\n0,1,0\n0,1,1\n");
  ASSERT_TRUE(late[0].violated());
  EXPECT_EQ(4u, late[0].violations[0].state) << "PASSED(3s) from the final state 1 is true at state 4";
  EXPECT_EQ(Cause::Delay, late[0].violations[0].cause);
  auto broken = check(reqs, "a,i,r\n0,1,0\n1,1,0\n0,0,0\n0,1,1\n");
  ASSERT_TRUE(broken[0].violated());
  EXPECT_EQ(2u, broken[0].violations[0].state);
  EXPECT_EQ(Cause::Invariant, broken[0].violations[0].cause);
}

TEST(EdtlPhases, ReleaseInPhaseBAndOverlappingInstances) {
  const char* reqs =
      "requirements:\n  - id: R\n    trigger: \"/a\"\n    final: \"TRUE\"\n    delay: \"PASSED(T#2s)\"\n    reaction: \"r\"\n"
      "    release: \"c\"\n";
  // Triggers at 1 and 3; the first is released at 2; the second times out at 5.
  auto v = check(reqs, "a,r,c\n0,0,0\n1,0,0\n0,0,1\n1,0,0\n0,0,0\n0,0,0\n");
  EXPECT_EQ(2u, v[0].triggers);
  EXPECT_EQ(1u, v[0].holds);
  ASSERT_EQ(1u, v[0].violated_instances);
  EXPECT_EQ(3u, v[0].violations[0].trigger_state);
  EXPECT_EQ(5u, v[0].violations[0].state);
}

TEST(EdtlPhases, InstancesOpenAtTheEndArePendingNotViolated) {
  auto v = check("requirements:\n  - id: R\n    trigger: \"/a\"\n    delay: \"PASSED(T#10s)\"\n    reaction: \"r\"\n",
                 "a,r\n0,0\n1,0\n0,0\n1,0\n");
  EXPECT_FALSE(v[0].violated());
  EXPECT_EQ(2u, v[0].pending);
  EXPECT_EQ(2u, v[0].triggers);
}

TEST(EdtlTime, PassedUsesTheTimeColumn) {
  const char* reqs = "requirements:\n  - id: R\n    trigger: \"/a\"\n    delay: \"PASSED(T#500ms)\"\n    reaction: \"r\"\n";
  // Irregular time stamps: 0.4 s after the trigger nothing is due yet, 0.6 s after it is.
  auto in_time = check(reqs, "time,a,r\n0,0,0\n0.1,1,0\n0.5,0,0\n0.55,0,1\n");
  EXPECT_FALSE(in_time[0].violated());
  // The reaction in the state where the delay expires still counts (reaction is checked
  // first): it must come after that state to be late.
  auto on_the_edge = check(reqs, "time,a,r\n0,0,0\n0.1,1,0\n0.5,0,0\n0.7,0,1\n");
  EXPECT_FALSE(on_the_edge[0].violated());
  auto late = check(reqs, "time,a,r\n0,0,0\n0.1,1,0\n0.5,0,0\n0.7,0,0\n0.8,0,1\n");
  ASSERT_TRUE(late[0].violated());
  EXPECT_EQ(3u, late[0].violations[0].state);
  EXPECT_EQ(700'000'000, late[0].violations[0].time_ns);
}

TEST(EdtlTime, PassedUsesTheCycleTimeWithoutATimeColumn) {
  const char* reqs = "requirements:\n  - id: R\n    trigger: \"/a\"\n    delay: \"PASSED(T#30ms)\"\n    reaction: \"r\"\n";
  const char* csv = "a,r\n0,0\n1,0\n0,0\n0,0\n0,0\n0,1\n";
  auto at_10ms = check(reqs, csv, 10'000'000);
  ASSERT_TRUE(at_10ms[0].violated());
  EXPECT_EQ(4u, at_10ms[0].violations[0].state) << "30 ms after state 1 at a 10 ms cycle";
  EXPECT_EQ(40'000'000, at_10ms[0].violations[0].time_ns);
  auto at_5ms = check(reqs, csv, 5'000'000);
  EXPECT_FALSE(at_5ms[0].violated()) << "at 5 ms the reaction (state 5) comes 20 ms after the trigger: in time";
  EXPECT_EQ(1u, at_5ms[0].holds);
}

TEST(EdtlExample, HandDryerOfTheReference) {
  auto v = check("requirements:\n  - id: R\n    trigger: \"FALLING(H) AND D\"\n    invariant: \"D\"\n    final: \"PASSED(T#2s)\"\n"
                 "    delay: \"TRUE\"\n    reaction: \"NOT D\"\n    release: \"H\"\n",
                 "H,D\n0,0\n1,0\n1,1\n0,1\n0,1\n0,0\n");
  EXPECT_EQ(1u, v[0].triggers);
  EXPECT_EQ(1u, v[0].holds);
  EXPECT_FALSE(v[0].violated());
}

TEST(EdtlErrors, FormulaErrorsPointIntoTheRequirementsFile) {
  auto rp = write_temp("plcfi_edtl_err.yaml", "requirements:\n  - id: R\n    trigger: \"a AND nosuchvar\"\n");
  auto tp = write_temp("plcfi_edtl_err.csv", "a\n1\n");
  RequirementsFile reqs;
  std::string err;
  ASSERT_TRUE(load_requirements(rp, &reqs, &err)) << err;
  TraceCheck out;
  EXPECT_FALSE(check_trace(reqs, tp, 0, &out, &err));
  EXPECT_NE(std::string::npos, err.find("plcfi_edtl_err.yaml:3:21: error[ST200]: unknown identifier 'nosuchvar'")) << err;
  auto bad = write_temp("plcfi_edtl_bad.yaml", "requirements:\n  - id: R\n    trigger: \"a\"\n    deadline: \"b\"\n");
  EXPECT_FALSE(load_requirements(bad, &reqs, &err));
  EXPECT_NE(std::string::npos, err.find("plcfi_edtl_bad.yaml:4:5: unknown key 'deadline'")) << err;
  auto notrig = write_temp("plcfi_edtl_notrig.yaml", "requirements:\n  - id: R\n    reaction: \"b\"\n");
  RequirementsFile r2;
  EXPECT_FALSE(load_requirements(notrig, &r2, &err));
  EXPECT_NE(std::string::npos, err.find("plcfi_edtl_notrig.yaml:2:5: missing key 'trigger' in requirement 'R'")) << err;
}

// ---------------------------------------------------------------- property test

// A direct, non-incremental reading of the definition.
struct Direct {
  using F = std::function<bool(size_t k, int64_t elapsed)>;
  F trigger, invariant, final_, delay, reaction, release;
  struct Result {
    uint64_t holds = 0, violated = 0, pending = 0;
    std::multiset<std::pair<uint64_t, int>> violations;  // (state, cause)
  };
  Result run(size_t n, const std::vector<int64_t>& time) const {
    Result r;
    for (size_t s = 0; s < n; ++s) {
      if (!trigger(s, 0)) continue;
      bool done = false;
      size_t k = s;
      size_t f = 0;
      bool phase_b = false;
      for (; k < n && !done; ++k) {
        if (!phase_b) {
          int64_t el = time[k] - time[s];
          if (release(k, el)) {
            ++r.holds;
            done = true;
            break;
          }
          if (final_(k, el)) {
            phase_b = true;
            f = k;
          } else if (!invariant(k, el)) {
            ++r.violated;
            r.violations.insert({k, 0});
            done = true;
            break;
          } else {
            continue;
          }
        }
        int64_t el = time[k] - time[f];
        if (release(k, el) || reaction(k, el)) {
          ++r.holds;
          done = true;
        } else if (!invariant(k, el)) {
          ++r.violated;
          r.violations.insert({k, 0});
          done = true;
        } else if (delay(k, el)) {
          ++r.violated;
          r.violations.insert({k, 1});
          done = true;
        }
      }
      if (!done) ++r.pending;
    }
    return r;
  }
};

TEST(EdtlProperty, IncrementalMonitorEqualsTheDefinitionOnRandomTraces) {
  std::mt19937 rng(20261122);
  // Requirement shapes: ST text for the monitor and the same formulas as C++ over the
  // trace columns a, b (BOOL) and n (INT); PASSED(T#ms) compares the elapsed time.
  struct Shape {
    const char* yaml;
    std::function<Direct(const std::vector<int>&, const std::vector<int>&, const std::vector<int>&)> make;
  };
  auto rising = [](const std::vector<int>& v) {
    return [v](size_t k, int64_t) { return k > 0 && v[k] && !v[k - 1]; };
  };
  auto val = [](const std::vector<int>& v) { return [v](size_t k, int64_t) { return v[k] != 0; }; };
  auto nval = [](const std::vector<int>& v) { return [v](size_t k, int64_t) { return v[k] == 0; }; };
  auto passed = [](int64_t ns) { return [ns](size_t, int64_t el) { return el >= ns; }; };
  auto konst = [](bool c) { return [c](size_t, int64_t) { return c; }; };
  std::vector<Shape> shapes = {
      {"trigger: \"/a\"\n    delay: \"PASSED(T#30ms)\"\n    reaction: \"b\"\n",
       [&](auto& a, auto& b, auto&) { return Direct{rising(a), konst(true), konst(true), passed(30'000'000), val(b), konst(false)}; }},
      {"trigger: \"/a\"\n    invariant: \"a\"\n    final: \"PASSED(T#20ms)\"\n    delay: \"TRUE\"\n    reaction: \"b\"\n    release: \"NOT a\"\n",
       [&](auto& a, auto& b, auto&) { return Direct{rising(a), val(a), passed(20'000'000), konst(true), val(b), nval(a)}; }},
      {"trigger: \"a\"\n    invariant: \"b\"\n    final: \"FALSE\"\n    release: \"n > 5\"\n",
       [&](auto& a, auto& b, auto& n) {
         return Direct{val(a), val(b), konst(false), konst(true), konst(true), [n](size_t k, int64_t) { return n[k] > 5; }};
       }},
      {"trigger: \"/b OR \\\\a\"\n    delay: \"PASSED(T#50ms)\"\n    reaction: \"n = 3\"\n    release: \"a AND b\"\n",
       [&](auto& a, auto& b, auto& n) {
         auto t = [a, b](size_t k, int64_t) { return k > 0 && ((b[k] && !b[k - 1]) || (!a[k] && a[k - 1])); };
         return Direct{t, konst(true), konst(true), passed(50'000'000), [n](size_t k, int64_t) { return n[k] == 3; },
                       [a, b](size_t k, int64_t) { return a[k] && b[k]; }};
       }},
      {"trigger: \"INCREASES(n)\"\n    invariant: \"NOT b\"\n    final: \"PASSED(T#10ms)\"\n    delay: \"PASSED(T#20ms)\"\n    reaction: \"a\"\n",
       [&](auto& a, auto& b, auto& n) {
         return Direct{[n](size_t k, int64_t) { return k > 0 && n[k] > n[k - 1]; }, nval(b), passed(10'000'000), passed(20'000'000),
                       val(a), konst(false)};
       }},
      // Level triggers open an instance at every state: many open instances with their own
      // timer points (the merge and the evaluation per threshold interval must not change
      // a count).
      {"trigger: \"a\"\n    delay: \"PASSED(T#40ms)\"\n    reaction: \"b\"\n",
       [&](auto& a, auto& b, auto&) { return Direct{val(a), konst(true), konst(true), passed(40'000'000), val(b), konst(false)}; }},
      {"trigger: \"a OR b\"\n    invariant: \"NOT PASSED(T#70ms) OR n < 6\"\n    final: \"PASSED(T#20ms) AND b\"\n    delay: \"PASSED(T#30ms)\"\n    reaction: \"n = 2\"\n",
       [&](auto& a, auto& b, auto& n) {
         return Direct{[a, b](size_t k, int64_t) { return a[k] || b[k]; },
                       [n](size_t k, int64_t el) { return el < 70'000'000 || n[k] < 6; },
                       [b](size_t k, int64_t el) { return el >= 20'000'000 && b[k]; }, passed(30'000'000),
                       [n](size_t k, int64_t) { return n[k] == 2; }, konst(false)};
       }},
      {"trigger: \"HIGH(a) AND CHANGES(n)\"\n    final: \"b\"\n    delay: \"TRUE\"\n    reaction: \"NOT a\"\n",
       [&](auto& a, auto& b, auto& n) {
         return Direct{[a, n](size_t k, int64_t) { return k > 0 && a[k] && a[k - 1] && n[k] != n[k - 1]; }, konst(true), val(b),
                       konst(true), nval(a), konst(false)};
       }},
  };
  int runs = 0;
  for (int round = 0; round < 60; ++round) {
    size_t n = 5 + rng() % 36;
    std::vector<int> a(n), b(n), nn(n);
    std::vector<int64_t> time(n);
    bool with_time = rng() % 2;
    int64_t t = 0;
    std::string csv = with_time ? "time,a,b,n\n" : "a,b,n\n";
    for (size_t k = 0; k < n; ++k) {
      a[k] = static_cast<int>(rng() % 2);
      b[k] = static_cast<int>(rng() % 3 == 0);
      nn[k] = static_cast<int>(rng() % 8);
      time[k] = with_time ? t : static_cast<int64_t>(k) * 10'000'000;
      if (with_time) csv += std::to_string(t / 1000) + "e-6,";
      csv += std::to_string(a[k]) + "," + std::to_string(b[k]) + "," + std::to_string(nn[k]) + "\n";
      t += 1'000'000 * (1 + rng() % 20);
    }
    for (const auto& sh : shapes) {
      SCOPED_TRACE(std::string(sh.yaml) + "\n" + csv);
      auto v = check(std::string("requirements:\n  - id: R\n    ") + sh.yaml, csv, with_time ? 0 : 10'000'000);
      ASSERT_EQ(1u, v.size());
      Direct d = sh.make(a, b, nn);
      auto expect = d.run(n, time);
      EXPECT_EQ(expect.holds, v[0].holds);
      EXPECT_EQ(expect.violated, v[0].violated_instances);
      EXPECT_EQ(expect.pending, v[0].pending);
      std::multiset<std::pair<uint64_t, int>> got;
      for (const auto& x : v[0].violations) {
        for (uint64_t i = 0; i < x.instances; ++i) got.insert({x.state, x.cause == Cause::Invariant ? 0 : 1});
      }
      if (expect.violations.size() <= Verdict::kMaxListed) {
        EXPECT_EQ(expect.violations, got);
      }
      ++runs;
    }
  }
  EXPECT_EQ(480, runs);
}

}  // namespace
}  // namespace plcfi::monitor

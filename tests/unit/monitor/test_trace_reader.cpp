// Unit tests of the CSV and VCD trace readers: what they read, and that hostile inputs
// (deep nesting, wide rows, time going back, binary and endless data) end in an error at
// the right line and column, in time linear in the input.
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "monitor/trace_reader.hpp"

using plcfi::monitor::TraceColumn;
using plcfi::monitor::TraceFormat;
using plcfi::monitor::TraceLimits;
using plcfi::monitor::TraceReader;
using plcfi::monitor::trace_program;

namespace {

struct State {
  int64_t t;
  std::vector<double> values;
};

// Reads every state; *err holds the reader's error (empty at a clean end).
std::vector<State> read_all(TraceReader& r, std::string* err) {
  std::vector<State> out;
  State s;
  err->clear();
  while (r.next(&s.t, &s.values, err)) out.push_back(s);
  return out;
}

std::unique_ptr<TraceReader> csv(const std::string& text, std::string* err, int64_t cycle = 1'000'000'000) {
  return TraceReader::from_text("t.csv", text, TraceFormat::Csv, cycle, err);
}

std::unique_ptr<TraceReader> vcd(const std::string& text, std::string* err, int64_t cycle = 0) {
  return TraceReader::from_text("t.vcd", text, TraceFormat::Vcd, cycle, err);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A scratch directory for tests that need real paths.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "plcfi-trace-XXXXXX").string();
    path_ = mkdtemp(tmpl.data()) ? tmpl : "";
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace

// TIME/LTIME, DATE, TOD and DT literals as plcfi's CSV traces write them: each column is
// typed by its literals, the values are nanoseconds (exact in time_values()), and a plain
// number in such a column keeps its old meaning (nanoseconds).
TEST(TraceReaderCsv, ReadsTimeLiterals) {
  std::string err;
  auto r = csv("time,v_t,v_d,v_tod,v_dt,n\n"
               "0,T#1s500ms,D#2024-03-01,TOD#01:00:00,DT#2024-03-01-12:00:00.25,3\n"
               "0.01,LTIME#-2ms,DATE#1970-01-02,TIME_OF_DAY#00:00:00.001,1709294400250000001,4\n",
               &err);
  ASSERT_TRUE(r) << err;
  ASSERT_EQ(r->columns().size(), 5u);
  EXPECT_EQ(r->columns()[0].kind, TraceColumn::Kind::Time);
  EXPECT_EQ(r->columns()[1].kind, TraceColumn::Kind::Date);
  EXPECT_EQ(r->columns()[2].kind, TraceColumn::Kind::Tod);
  EXPECT_EQ(r->columns()[3].kind, TraceColumn::Kind::Dt);
  EXPECT_EQ(r->columns()[4].kind, TraceColumn::Kind::Int);
  int64_t t = 0;
  std::vector<double> v;
  ASSERT_TRUE(r->next(&t, &v, &err)) << err;
  ASSERT_EQ(r->time_values().size(), 5u);
  EXPECT_EQ(r->time_values()[0], 1'500'000'000);
  EXPECT_EQ(r->time_values()[1], 19'783 * 86'400'000'000'000);
  EXPECT_EQ(r->time_values()[2], 3'600'000'000'000);
  EXPECT_EQ(r->time_values()[3], 1'709'294'400'250'000'000);
  EXPECT_DOUBLE_EQ(v[0], 1.5e9);
  EXPECT_DOUBLE_EQ(v[4], 3);
  ASSERT_TRUE(r->next(&t, &v, &err)) << err;
  EXPECT_EQ(r->time_values()[0], -2'000'000);
  EXPECT_EQ(r->time_values()[1], 86'400'000'000'000);
  EXPECT_EQ(r->time_values()[2], 1'000'000);
  EXPECT_EQ(r->time_values()[3], 1'709'294'400'250'000'001);  // a plain number: nanoseconds, exactly
  EXPECT_FALSE(r->next(&t, &v, &err));
  EXPECT_EQ(err, "");
  std::string program;
  ASSERT_TRUE(trace_program(r->columns(), &program, &err)) << err;
  EXPECT_NE(program.find("v_t : TIME;"), std::string::npos) << program;
  EXPECT_NE(program.find("v_dt : DT;"), std::string::npos) << program;
}

TEST(TraceReaderCsv, MalformedTimeLiteralsAreErrorsAtTheirPlace) {
  std::string err;
  EXPECT_FALSE(csv("time,t\n0,T#1s\n0.1,T#1x\n", &err));
  EXPECT_EQ(err.rfind("t.csv:3:", 0), 0u) << err;
  EXPECT_NE(err.find("'T#1x' in column t is not a number or a TIME, DATE, TOD or DT literal"), std::string::npos) << err;
  EXPECT_FALSE(csv("time,a,d\n0,1,D#2024-02-30\n", &err));
  EXPECT_EQ(err.rfind("t.csv:2:", 0), 0u) << err;
  EXPECT_NE(err.find("'D#2024-02-30' in column d"), std::string::npos) << err;
  EXPECT_FALSE(csv("time,d\n0,D#2024-03-01\n0.1,TOD#12:00:00\n", &err));
  EXPECT_EQ(err, "t.csv:3:5: 'TOD#12:00:00' in column d is a TOD literal; the column's earlier literals are DATE");
  EXPECT_FALSE(csv("time,x\n0,INT#5\n", &err));
  EXPECT_EQ(err, "t.csv:2:3: 'INT#5' in column x is not a number or a TIME, DATE, TOD or DT literal");
  EXPECT_FALSE(csv("time,x\n0,T#1s T#2s\n", &err));
  EXPECT_EQ(err, "t.csv:2:8: 'T#1s T#2s' in column x is not a number or a TIME, DATE, TOD or DT literal: unexpected text after the literal");
  // A plain number in a TIME column is nanoseconds; one past what int64 holds is an error
  // at its place, read in the second pass, not a wrapped time.
  auto r = csv("time,d\n0,T#1s\n0.1,1e21\n", &err);
  ASSERT_TRUE(r) << err;
  int64_t t = 0;
  std::vector<double> v;
  ASSERT_TRUE(r->next(&t, &v, &err)) << err;
  EXPECT_FALSE(r->next(&t, &v, &err));
  EXPECT_EQ(err, "t.csv:3:5: '1e21' in column d is outside what a TIME can hold (nanoseconds within +-9.2e18)");
}

TEST(TraceReaderCsv, ReadsTimeKindsAndValues) {
  std::string err;
  auto r = csv("time, a, n, x\n0.0, 0, 1, 0.5\n\n0.5, 1, 7, 2\r\n1.0, TRUE, -3, 1\n", &err);
  ASSERT_TRUE(r) << err;
  ASSERT_EQ(r->columns().size(), 3u);
  EXPECT_TRUE(r->has_time());
  EXPECT_EQ(r->columns()[0].kind, TraceColumn::Kind::Bool);
  EXPECT_EQ(r->columns()[1].kind, TraceColumn::Kind::Int);
  EXPECT_EQ(r->columns()[2].kind, TraceColumn::Kind::Real);
  auto states = read_all(*r, &err);
  EXPECT_EQ(err, "");
  ASSERT_EQ(states.size(), 3u);
  EXPECT_EQ(states[1].t, 500'000'000);
  EXPECT_EQ(states[1].values, (std::vector<double>{1, 7, 2}));
  EXPECT_EQ(states[2].values[1], -3);
}

TEST(TraceReaderCsv, WithoutTimeColumnStatesAreCyclesApart) {
  std::string err;
  auto r = csv("H,D\n0,0\n1,0\n1,1\n", &err, 10'000'000);
  ASSERT_TRUE(r) << err;
  EXPECT_FALSE(r->has_time());
  auto states = read_all(*r, &err);
  ASSERT_EQ(states.size(), 3u);
  EXPECT_EQ(states[2].t, 20'000'000);
}

TEST(TraceReaderCsv, TimeGoingBackIsAnErrorAtItsLine) {
  std::string err;
  EXPECT_FALSE(csv("time,a\n0,0\n0.3,1\n0.2,0\n0.4,1\n", &err));
  EXPECT_EQ(err, "t.csv:4:1: time 0.2 s goes back (the row before is at 0.3 s)");
  // Equal times are allowed (two states at one instant).
  EXPECT_TRUE(csv("time,a\n0,0\n0,1\n", &err)) << err;
}

TEST(TraceReaderCsv, NulAndControlBytesAreErrors) {
  std::string err;
  EXPECT_FALSE(csv("time,a\n0,1\n0.1," + std::string(1, '\0') + "2\n", &err));
  EXPECT_EQ(err, "t.csv:3:5: NUL byte (not a text trace)");
  EXPECT_FALSE(csv(std::string("a,b\0c\n", 6), &err));
  EXPECT_EQ(err, "t.csv:1:4: NUL byte (not a text trace)");
  EXPECT_FALSE(csv("a\n1\x1b\n", &err));
  EXPECT_EQ(err, "t.csv:2:2: control character 0x1b (not a text trace)");
}

TEST(TraceReaderCsv, BadFieldsNameTheirColumn) {
  std::string err;
  EXPECT_FALSE(csv("time,a,b\n0,1,1\n1,1\n", &err));
  EXPECT_EQ(err, "t.csv:3:4: 2 fields, the header has 3");
  EXPECT_FALSE(csv("time,a,b\n0,1,1,1\n", &err));
  EXPECT_EQ(err, "t.csv:2:7: 4 fields, the header has 3");
  EXPECT_FALSE(csv("time,a,b\n0, 1, 1x\n", &err));
  EXPECT_EQ(err, "t.csv:2:7: '1x' in column b is not a number");
  EXPECT_FALSE(csv("time,a\n1e300,1\n", &err));
  EXPECT_EQ(err, "t.csv:2:1: time '1e300' is not a number of seconds (within +-292 years)");
  EXPECT_FALSE(csv("time,a,,b\n", &err));
  EXPECT_EQ(err, "t.csv:1:8: column 3 has no name");
  EXPECT_FALSE(csv("", &err));
  EXPECT_EQ(err, "t.csv:1:1: empty trace (a header line 'time,var,...' is expected)");
}

TEST(TraceReaderCsv, FiftyThousandColumnsTakeLinearTime) {
  constexpr int kColumns = 50'000;
  std::string text = "time";
  // Plain names (globals): the ST compiler's check of one POU's variables is itself
  // quadratic, so 50,000 members of one program are not the reader's to make fast.
  for (int i = 0; i < kColumns; ++i) text += ",v" + std::to_string(i);
  text += "\n";
  for (int row = 0; row < 3; ++row) {
    text += std::to_string(row);
    for (int i = 0; i < kColumns; ++i) text += row == 2 && i == kColumns - 1 ? ",5" : ",1";
    text += "\n";
  }
  auto t0 = std::chrono::steady_clock::now();
  std::string err, program;
  auto r = csv(text, &err);
  ASSERT_TRUE(r) << err;
  ASSERT_EQ(r->columns().size(), static_cast<size_t>(kColumns));
  EXPECT_EQ(r->columns().back().kind, TraceColumn::Kind::Int);
  EXPECT_EQ(read_all(*r, &err).size(), 3u);
  ASSERT_TRUE(trace_program(r->columns(), &program, &err)) << err;
  EXPECT_NE(program.find("  v49999 : LINT;"), std::string::npos);
  // The handles of all columns in one pass, the same as st::resolve finds one by one.
  plcfi::st::CompileOptions opt;
  opt.warnings = false;
  auto b = plcfi::st::build_sources({{"<trace>", program}}, opt);
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  std::vector<plcfi::st::VarHandle> handles;
  ASSERT_TRUE(plcfi::monitor::resolve_trace_columns(*b->app, r->columns(), &handles, &err)) << err;
  ASSERT_EQ(handles.size(), static_cast<size_t>(kColumns));
  for (size_t i : {size_t{0}, size_t{12345}, size_t{kColumns - 1}}) {
    auto one = plcfi::st::resolve(*b->app, r->columns()[i].name, &err);
    ASSERT_TRUE(one) << err;
    EXPECT_EQ(handles[i].addr, one->addr);
    EXPECT_EQ(handles[i].type, one->type);
  }
  // Linear: under a second in a RelWithDebInfo build (a column-by-column st::resolve
  // took about 15 s). Generous for loaded machines and sanitizer builds.
  EXPECT_LT(seconds_since(t0), 10.0);
}

TEST(TraceReaderCsv, OverlongLineIsAnError) {
  std::string err;
  std::string text = "a\n" + std::string(TraceLimits::kMaxLineBytes + 10, '1');
  EXPECT_FALSE(csv(text, &err));
  EXPECT_EQ(err, "t.csv:2:" + std::to_string(TraceLimits::kMaxLineBytes + 1) + ": line longer than 16 MiB (not a text trace?)");
}

TEST(TraceReaderCsv, DeeplyDottedColumnIsAnError) {
  std::string name = "a";
  for (int i = 0; i < 10'000; ++i) name += ".a";
  std::string err;
  EXPECT_FALSE(csv("x," + name + "\n1,1\n", &err));
  EXPECT_EQ(err, "t.csv:1:3: column name with more than 64 dotted parts");
  std::vector<TraceColumn> cols{{name, TraceColumn::Kind::Bool}};
  std::string program;
  EXPECT_FALSE(trace_program(cols, &program, &err));
  EXPECT_NE(err.find("nested deeper than 64"), std::string::npos) << err;
}

TEST(TraceReaderVcd, ReadsScopesTimescaleAndChanges) {
  const char* text =
      "$date today $end\n$timescale 1ms $end\n"
      "$scope module Main $end\n$var wire 1 ! start $end\n$var integer 8 \" n $end\n"
      "$var real 64 # x $end\n$scope module seq $end\n$var wire 4 $ step [3:0] $end\n$upscope $end\n$upscope $end\n"
      "$scope module Alias $end\n$var wire 1 ! start $end\n$upscope $end\n"
      "$enddefinitions $end\n"
      "#0\n$dumpvars 0! b11111110 \" r0.5 # b0 $ $end\n#10\n1! b101 $\n#20\n$comment a note $end r-1.25 #\n";
  std::string err;
  auto r = vcd(text, &err);
  ASSERT_TRUE(r) << err;
  ASSERT_EQ(r->columns().size(), 5u);
  EXPECT_EQ(r->columns()[0].name, "Main.start");
  EXPECT_EQ(r->columns()[3].name, "Main.seq.step");
  EXPECT_EQ(r->columns()[4].name, "Alias.start");
  EXPECT_EQ(r->columns()[2].kind, TraceColumn::Kind::Real);
  auto states = read_all(*r, &err);
  EXPECT_EQ(err, "");
  ASSERT_EQ(states.size(), 3u);
  EXPECT_EQ(states[0].values, (std::vector<double>{0, -2, 0.5, 0, 0}));
  EXPECT_EQ(states[1].t, 10'000'000);
  EXPECT_EQ(states[1].values, (std::vector<double>{1, -2, 0.5, 5, 1}));  // the alias follows
  EXPECT_EQ(states[2].values[2], -1.25);
  // Resampled every 4 ms up to the last time stamp.
  r = vcd(text, &err, 4'000'000);
  ASSERT_TRUE(r) << err;
  states = read_all(*r, &err);
  ASSERT_EQ(states.size(), 6u);
  EXPECT_EQ(states[2].t, 8'000'000);
  EXPECT_EQ(states[2].values[0], 0);
  EXPECT_EQ(states[3].values[0], 1);
}

TEST(TraceReaderVcd, TenThousandNestedScopesAreAnError) {
  std::string text;
  for (int i = 0; i < 10'000; ++i) text += "$scope module m $end\n";
  text += "$var wire 1 ! a $end\n$enddefinitions $end\n#0\n1!\n";
  std::string err;
  EXPECT_FALSE(vcd(text, &err));
  EXPECT_EQ(err, "t.vcd:64:1: more than 63 nested $scope sections");
}

TEST(TraceReaderVcd, TimeGoingBackIsAnErrorAtItsLine) {
  std::string err;
  auto r = vcd("$var wire 1 ! a $end $enddefinitions $end\n#10\n1!\n#30\n0!\n  #20\n1!\n", &err);
  ASSERT_TRUE(r) << err;
  auto states = read_all(*r, &err);
  EXPECT_EQ(states.size(), 1u);
  EXPECT_EQ(err, "t.vcd:6:3: time #20 goes back (the time before is #30)");
}

TEST(TraceReaderVcd, MalformedInputNamesLineAndColumn) {
  const std::string head = "$var wire 1 ! a $end\n$enddefinitions $end\n";
  std::string err;
  auto first_error = [&](const std::string& text) {
    auto r = vcd(text, &err);
    if (r) read_all(*r, &err);
    return err;
  };
  EXPECT_EQ(first_error(head + "#x\n"), "t.vcd:3:1: '#x' is not a time stamp (#, then a non-negative integer)");
  EXPECT_EQ(first_error("$timescale 1s $end " + head + "#99999999999999999\n"),
            "t.vcd:3:1: time stamp '#99999999999999999' overflows 64-bit nanoseconds");
  EXPECT_EQ(first_error(head + "#0 1?\n"), "t.vcd:3:4: value change for undeclared identifier '?'");
  EXPECT_EQ(first_error(head + "#0 b102 !\n"), "t.vcd:3:4: 'b102' is not a value of a (1 bit)");
  EXPECT_EQ(first_error(head + "1!\n"), "t.vcd:3:1: value change before the first #time");
  EXPECT_EQ(first_error("$comment never ends\n"), "t.vcd:1:1: $comment without $end");
  EXPECT_EQ(first_error("$upscope $end\n"), "t.vcd:1:1: $upscope without an open $scope");
  EXPECT_EQ(first_error("$var wire 99 ! a $end\n"), "t.vcd:1:11: width '99' is not 1..64");
  EXPECT_EQ(first_error("$var wire 1 ! $end\n"), "t.vcd:1:15: $var: expected its name");
  EXPECT_EQ(first_error("$timescale 1 fs $end\n"), "t.vcd:1:1: unsupported $timescale '1 fs' (s, ms, us or ns)");
  EXPECT_EQ(first_error("$timescale 99999999999999999999ns $end\n"),
            "t.vcd:1:12: $timescale '99999999999999999999ns': the factor is not 1..1000");
  EXPECT_EQ(first_error(std::string("$var wire 1 ! a\0 $end\n", 22)), "t.vcd:1:16: NUL byte (not a text trace)");
  EXPECT_EQ(first_error("$enddefinitions $end\n"), "t.vcd:1:1: no $var in the VCD header");
  EXPECT_EQ(first_error(std::string(TraceLimits::kMaxWordBytes + 1, 'x')),
            "t.vcd:1:1: a word longer than 1 MiB (not a VCD trace?)");
}

TEST(TraceReaderFiles, DirectoriesDevicesAndEndlessInputFailAtOnce) {
  TempDir dir;
  ASSERT_FALSE(dir.path().empty());
  auto t0 = std::chrono::steady_clock::now();
  std::string err;
  EXPECT_FALSE(TraceReader::open(dir.path(), 0, &err));
  EXPECT_EQ(err, dir.path() + ": is a directory, not a trace");
  EXPECT_FALSE(TraceReader::open(dir.path() + "/nope.csv", 0, &err));
  EXPECT_EQ(err, dir.path() + "/nope.csv: cannot open: No such file or directory");
  EXPECT_FALSE(TraceReader::open("/dev/zero", 0, &err));
  EXPECT_EQ(err, "/dev/zero: not a regular file (a CSV trace is read twice)");
  // A VCD may come from a pipe or a device, so endless binary data must stop the reader.
  std::string zero = dir.path() + "/zero.vcd", random = dir.path() + "/random.vcd";
  ASSERT_EQ(symlink("/dev/zero", zero.c_str()), 0);
  ASSERT_EQ(symlink("/dev/urandom", random.c_str()), 0);
  EXPECT_FALSE(TraceReader::open(zero, 0, &err));
  EXPECT_EQ(err, zero + ":1:1: NUL byte (not a text trace)");
  for (int i = 0; i < 20; ++i) {
    EXPECT_FALSE(TraceReader::open(random, 0, &err));
    EXPECT_EQ(err.rfind(random + ":", 0), 0u) << err;
  }
  EXPECT_LT(seconds_since(t0), 2.0);
}

TEST(TraceReaderColumns, PlainDottedAndAddressColumnsResolve) {
  std::vector<TraceColumn> cols{{"Speed", TraceColumn::Kind::Real},
                                {"Main.seq.step", TraceColumn::Kind::Int},
                                {"Main.On", TraceColumn::Kind::Bool}};
  std::string program, err;
  ASSERT_TRUE(trace_program(cols, &program, &err)) << err;
  plcfi::st::CompileOptions opt;
  opt.warnings = false;
  auto b = plcfi::st::build_sources({{"<trace>", program}}, opt);
  ASSERT_TRUE(b->ok()) << b->diags.render_all();
  std::vector<plcfi::st::VarHandle> handles;
  ASSERT_TRUE(plcfi::monitor::resolve_trace_columns(*b->app, cols, &handles, &err)) << err;
  for (size_t i = 0; i < cols.size(); ++i) {
    auto one = plcfi::st::resolve(*b->app, cols[i].name, &err);
    ASSERT_TRUE(one) << err;
    EXPECT_EQ(handles[i].addr, one->addr) << cols[i].name;
    EXPECT_EQ(handles[i].type, one->type) << cols[i].name;
  }
  cols.push_back({"Main.nothing.here", TraceColumn::Kind::Bool});
  EXPECT_FALSE(plcfi::monitor::resolve_trace_columns(*b->app, cols, &handles, &err));
  EXPECT_EQ(err.rfind("column Main.nothing.here: ", 0), 0u) << err;
}

TEST(TraceReaderFiles, ReadsAFile) {
  TempDir dir;
  std::string path = dir.path() + "/ok.csv";
  std::ofstream(path) << "t,a\n0,1\n1,0\n";
  std::string err;
  auto r = TraceReader::open(path, 0, &err);
  ASSERT_TRUE(r) << err;
  EXPECT_EQ(read_all(*r, &err).size(), 2u);
  EXPECT_EQ(err, "");
}

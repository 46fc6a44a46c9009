// The CPTest+ script reader and its binding to a program: every command, line numbers,
// comments, and each kind of error with its file:line:col.
#include <gtest/gtest.h>

#include <string>

#include "engine.hpp"
#include "script/bind.hpp"
#include "script/cpt.hpp"

namespace plcfi::script {
namespace {

Script parse_ok(const std::string& text) {
  Script s;
  std::string err;
  EXPECT_TRUE(parse_script("t.cpt", text, &s, &err)) << err;
  return s;
}

std::string parse_err(const std::string& text) {
  Script s;
  std::string err;
  EXPECT_FALSE(parse_script("t.cpt", text, &s, &err));
  return err;
}

TEST(Cpt, ThePublishedScript) {
  Script s = parse_ok(
      "01: SET PASS_ONE_BALL\n02: LOG ONE BALL MODE ON\n03: WAIT 500 MS\n04: RESET PASS_ONE_BALL\n"
      "05: LOG ONE BALL MODE OFF\n06: ASSERT_COM ISTRUE IS_BEAD_SEEN\n");
  ASSERT_EQ(s.commands.size(), 6u);
  EXPECT_EQ(s.name, "t");
  EXPECT_EQ(s.commands[0].kind, CmdKind::Set);
  EXPECT_EQ(s.commands[0].number, "01");
  EXPECT_EQ(s.commands[0].var, "PASS_ONE_BALL");
  EXPECT_EQ(s.commands[0].var_at.col, 9u);
  EXPECT_EQ(s.commands[1].kind, CmdKind::Log);
  EXPECT_EQ(s.commands[1].message, "ONE BALL MODE ON");
  EXPECT_EQ(s.commands[2].kind, CmdKind::Wait);
  EXPECT_EQ(s.commands[2].amount, 500);
  EXPECT_EQ(s.commands[2].unit, WaitUnit::Ms);
  EXPECT_EQ(s.commands[3].kind, CmdKind::Reset);
  EXPECT_EQ(s.commands[5].kind, CmdKind::AssertCom);
  EXPECT_EQ(s.commands[5].op, CmpOp::IsTrue);
  EXPECT_FALSE(s.commands[5].has_value);
  EXPECT_EQ(s.commands[5].text, "ASSERT_COM ISTRUE IS_BEAD_SEEN");
  EXPECT_EQ(s.commands[5].at.line, 6u);
}

TEST(Cpt, EveryCommandAnyCaseWithComments) {
  Script s = parse_ok(
      "// a comment line\n\n"
      "assign Main.step 'it''s // not a comment'  // but this is\n"
      "wait 3 c\n"
      "Wait 2 S\n"
      "assert gte Main.count 2\n"
      "ASSERT neq Main.t T#1s500ms\n"
      "fault link plant for 300 ms\n"
      "LOG keeps // this text\n");
  ASSERT_EQ(s.commands.size(), 7u);
  EXPECT_EQ(s.commands[0].kind, CmdKind::Assign);
  EXPECT_EQ(s.commands[0].value, "'it''s // not a comment'");
  EXPECT_EQ(s.commands[0].at.line, 3u);
  EXPECT_EQ(s.commands[1].unit, WaitUnit::Cycles);
  EXPECT_EQ(s.commands[1].amount, 3);
  EXPECT_EQ(s.commands[2].unit, WaitUnit::S);
  EXPECT_EQ(s.commands[3].op, CmpOp::Gte);
  EXPECT_EQ(s.commands[3].value, "2");
  EXPECT_EQ(s.commands[4].op, CmpOp::Neq);
  EXPECT_EQ(s.commands[4].value, "T#1s500ms");
  EXPECT_EQ(s.commands[5].kind, CmdKind::FaultLink);
  EXPECT_EQ(s.commands[5].device, "plant");
  EXPECT_EQ(duration_ns(s.commands[5].amount, s.commands[5].unit), 300'000'000);
  EXPECT_EQ(s.commands[6].message, "keeps // this text");
}

TEST(Cpt, ErrorsNameLineAndColumn) {
  EXPECT_EQ(parse_err("SET X\nJUMP 3\n"),
            "t.cpt:2:1: unknown command 'JUMP' (expected SET, RESET, ASSIGN, WAIT, LOG, ASSERT, ASSERT_COM or FAULT)");
  EXPECT_EQ(parse_err("WAIT 500\n"), "t.cpt:1:9: WAIT 500: the unit is missing (MS, S or C)");
  EXPECT_EQ(parse_err("WAIT 5 MIN\n"), "t.cpt:1:8: WAIT: unknown unit 'MIN' (expected MS, S or C)");
  EXPECT_EQ(parse_err("WAIT -5 MS\n"), "t.cpt:1:6: WAIT: '-5' is not a whole number of milliseconds, seconds or cycles");
  EXPECT_EQ(parse_err("  ASSERT ISTRUE\n"), "t.cpt:1:16: ASSERT needs a variable");
  EXPECT_EQ(parse_err("ASSERT BIGGER X 3\n"),
            "t.cpt:1:8: ASSERT: unknown operator 'BIGGER' (expected EQ, NEQ, LT, LTE, GT, GTE, ISTRUE or ISFALSE)");
  EXPECT_EQ(parse_err("ASSERT EQ X\n"), "t.cpt:1:12: ASSERT EQ X needs a value to compare with");
  EXPECT_EQ(parse_err("ASSERT ISTRUE X 1\n"), "t.cpt:1:17: ASSERT ISTRUE: unexpected '1' at the end of the line");
  EXPECT_EQ(parse_err("SET 3x\n"), "t.cpt:1:5: SET: '3x' is not a variable name");
  EXPECT_EQ(parse_err("FAULT LINK plant 300 MS\n"), "t.cpt:1:18: FAULT LINK plant: expected FOR n MS");
  EXPECT_EQ(parse_err("FAULT LINK plant FOR 3 C\n"), "t.cpt:1:24: FAULT LINK: unknown unit 'C' (expected MS, S)");
  EXPECT_EQ(parse_err("WAIT 9999999999999999999 S\n"),
            "t.cpt:1:6: WAIT: '9999999999999999999' is not a whole number of milliseconds, seconds or cycles");
  EXPECT_EQ(parse_err("WAIT 9999999999999 S\n"), "t.cpt:1:20: WAIT 9999999999999 S: too long");
  EXPECT_EQ(parse_err(std::string("SET X\nSET \0Y\n", 13)), "t.cpt:2:5: a NUL byte in the script (a binary file?)");
}

TEST(Cpt, NotAFile) {
  Script s;
  std::string err;
  EXPECT_FALSE(load_script("/nonexistent/x.cpt", &s, &err));
  EXPECT_NE(err.find("/nonexistent/x.cpt: cannot open"), std::string::npos) << err;
  EXPECT_FALSE(load_script("/tmp", &s, &err));
  EXPECT_EQ(err, "/tmp: is a directory");
}

// ---- binding

const char* kProgram = R"ST(
TYPE Mode : (Idle, Busy); END_TYPE
PROGRAM P
VAR count : INT; t : TIME; m : Mode; name : STRING[20]; r : REAL; arr : ARRAY[1..3] OF INT; END_VAR
count := count + 1;
END_PROGRAM
CONFIGURATION C
  VAR_GLOBAL flag : BOOL; lamp AT %QX0.0 : BOOL; END_VAR
  RESOURCE R ON PLC
    TASK T (INTERVAL := T#10ms, PRIORITY := 1);
    PROGRAM Main WITH T : P;
  END_RESOURCE
END_CONFIGURATION
)ST";

class CptBind : public ::testing::Test {
 protected:
  void SetUp() override {
    st::CompileOptions opt;
    opt.warnings = false;
    b_ = st::build_sources({{"p.st", kProgram}}, opt);
    ASSERT_TRUE(b_->ok()) << b_->diags.render_all();
  }
  std::string bind_err(const std::string& text) {
    s_ = parse_ok(text);
    BoundScript bs;
    std::string err;
    EXPECT_FALSE(bind_script(*b_->app, s_, {"plant"}, &bs, &err));
    return err;
  }
  std::unique_ptr<st::Build> b_;
  Script s_;
};

TEST_F(CptBind, GoodScriptBindsWithItsValues) {
  s_ = parse_ok("SET flag\nASSIGN Main.count 7\nASSERT GT Main.count -3\nASSERT EQ Main.m Busy\nASSERT LT Main.t T#2s\n"
                "ASSERT EQ Main.name 'abc'\nASSERT LTE Main.r 1.5\nASSERT_COM ISFALSE %QX0.0\nFAULT LINK plant FOR 1 S\n");
  BoundScript bs;
  std::string err;
  ASSERT_TRUE(bind_script(*b_->app, s_, {"plant"}, &bs, &err)) << err;
  ASSERT_EQ(bs.cmds.size(), 9u);
  EXPECT_EQ(bs.cmds[2].value.i, -3);
  EXPECT_EQ(bs.cmds[3].value.i, 1);  // Busy
  EXPECT_EQ(bs.cmds[4].value.i, 2'000'000'000);
  EXPECT_EQ(bs.cmds[5].value.s, "'abc'");
  EXPECT_EQ(bs.cmds[6].value.k, Operand::K::Real);
  EXPECT_DOUBLE_EQ(bs.cmds[6].value.r, 1.5);
  EXPECT_EQ(bs.var_paths, (std::vector<std::string>{"flag", "Main.count", "Main.m", "Main.t", "Main.name", "Main.r", "%QX0.0"}));
}

TEST_F(CptBind, ErrorsPointIntoTheScript) {
  EXPECT_NE(bind_err("SET nosuch\n").find("t.cpt:1:5: "), std::string::npos);
  EXPECT_EQ(bind_err("WAIT 1 C\nSET Main.count\n"), "t.cpt:2:5: SET needs a BOOL variable; Main.count is INT (use ASSIGN)");
  EXPECT_EQ(bind_err("ASSERT ISTRUE Main.count\n"),
            "t.cpt:1:15: ASSERT ISTRUE needs a BOOL variable; Main.count is INT (compare it with EQ)");
  EXPECT_EQ(bind_err("ASSIGN Main.count TRUE\n"), "t.cpt:1:19: 'TRUE' does not fit Main.count (INT)");
  EXPECT_EQ(bind_err("ASSERT EQ Main.t 5\n"), "t.cpt:1:18: '5' does not fit Main.t (TIME)");
  EXPECT_EQ(bind_err("ASSERT GT flag FALSE\n"), "t.cpt:1:1: ASSERT GT: flag (BOOL) has no order; use EQ or NEQ");
  EXPECT_EQ(bind_err("ASSERT EQ Main.arr 1\n"), "t.cpt:1:11: Main.arr is ARRAY [1..3] OF INT, not a single value");
  EXPECT_EQ(bind_err("FAULT LINK remote1 FOR 1 S\n"), "t.cpt:1:12: unknown device 'remote1' (known: plant)");
}

TEST(CptCompare, EveryOperator) {
  Operand a, b;
  a.i = 3;
  b.i = 5;
  EXPECT_TRUE(compare(a, CmpOp::Lt, b));
  EXPECT_TRUE(compare(a, CmpOp::Lte, b));
  EXPECT_FALSE(compare(a, CmpOp::Gt, b));
  EXPECT_FALSE(compare(a, CmpOp::Gte, b));
  EXPECT_TRUE(compare(a, CmpOp::Neq, b));
  EXPECT_FALSE(compare(a, CmpOp::Eq, b));
  EXPECT_TRUE(compare(a, CmpOp::IsTrue, b));
  a.i = 0;
  EXPECT_TRUE(compare(a, CmpOp::IsFalse, b));
  Operand x, y;
  x.k = y.k = Operand::K::Real;
  x.r = 1.5;
  y.r = 1.5;
  EXPECT_TRUE(compare(x, CmpOp::Eq, y));
  EXPECT_TRUE(compare(x, CmpOp::Gte, y));
}

}  // namespace
}  // namespace plcfi::script

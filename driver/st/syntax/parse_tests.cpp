// The test-file format: SETUP, TEARDOWN and TEST blocks, and the MOCK and MOCK_FUNCTION
// statements that only test files allow.
#include "parser_impl.hpp"

namespace plcfi::st::detail {

// ================================================================ test files

// mock_stmt := MOCK postfix ';'
StmtPtr Parser::parse_mock() {
  const Token& kw = advance();
  auto s = std::make_unique<MockStmt>(kw.loc);
  s->target = parse_postfix();
  expect_semi("MOCK");
  return s;
}

// mock_function_stmt := MOCK_FUNCTION name RETURNS expr ';'
StmtPtr Parser::parse_mock_function() {
  const Token& kw = advance();
  auto s = std::make_unique<MockFunctionStmt>(kw.loc);
  expect_ident(&s->function, "ST100", "the function name after MOCK_FUNCTION");
  if (at_word("RETURNS")) {
    advance();
  } else {
    error("ST100", missing_loc(), "expected RETURNS after 'MOCK_FUNCTION " + s->function.text + "', found " +
                                      describe(cur()));
  }
  s->value = parse_expr();
  expect_semi("MOCK_FUNCTION");
  return s;
}

// test_case := (SETUP | TEARDOWN | TEST string) {var_block} stmt_list (END_SETUP | END_TEARDOWN | END_TEST)
void Parser::parse_test_case(TestCase& tc, Tok end, const char* what) {
  FrameGuard frame(*this, {end, Tok::Eof, Tok::Eof}, false);
  bool seen_statements = false;
  for (;;) {
    const size_t before = pos_;
    if (is_var_keyword(cur().kind)) {
      if (seen_statements)
        error("ST130", cur().loc, std::string("variable declarations must come before the statements of ") + what);
      tc.var_blocks.push_back(parse_var_block());
    } else if (at(Tok::Eof) || is_unit_end(cur().kind) || is_top_level_start(cur().kind) || at_test_block_start() ||
               at(Tok::Method) || at(Tok::Property) || at(Tok::Resource)) {
      break;
    } else {
      const size_t first = tc.body.size();
      parse_stmt_list(tc.body, false);
      if (tc.body.size() > first) seen_statements = true;
    }
    if (pos_ == before) break;
  }
  SourceLoc end_loc;
  expect_unit_end(end, what, tc.loc, &end_loc);
}

// test_file := {setup | teardown | test | top_level}
std::unique_ptr<TestFile> Parser::parse_test_file() {
  auto tf = std::make_unique<TestFile>();
  tf->file = file_;
  tf->decls.file = file_;
  while (!at(Tok::Eof)) {
    release_tokens();
    const size_t before = pos_;
    if (at_test_block_start()) {
      const Token& kw = advance();
      TestCase tc;
      tc.loc = kw.loc;
      if (iequals(kw.text, "TEST")) {
        tc.name = advance().str_value;
        parse_test_case(tc, Tok::EndTest, "TEST");
        tf->tests.push_back(std::move(tc));
      } else {
        const bool setup = iequals(kw.text, "SETUP");
        tc.name = setup ? "SETUP" : "TEARDOWN";
        parse_test_case(tc, setup ? Tok::EndSetup : Tok::EndTeardown, setup ? "SETUP" : "TEARDOWN");
        auto& slot = setup ? tf->setup : tf->teardown;
        if (slot) error("ST130", kw.loc, std::string("duplicate ") + tc.name + " block (only one is allowed)", true);
        else slot = std::move(tc);
      }
    } else if (at_word("TEST")) {
      error("ST130", cur().loc, "expected the test name as a string after TEST (e.g. TEST 'counts up'), found " +
                                    describe(la(1)));
      const Token& kw = advance();
      if (at(Tok::Ident) && cur().loc.line == kw.loc.line) advance();  // an unquoted name
      TestCase tc;
      tc.loc = kw.loc;
      parse_test_case(tc, Tok::EndTest, "TEST");
      tf->tests.push_back(std::move(tc));
    } else {
      parse_top_level(tf->decls);
    }
    if (pos_ == before) advance();
  }
  return tf;
}

}  // namespace plcfi::st::detail

// The contract between plcfi's TcUnit library (stdlib/tcunit.cpp, written in ST) and its
// runner (testing/tcunit.cpp): the only place both sides read it from.
//
// The library keeps no bookkeeping of its own. Every TcUnit call (TEST, an assertion,
// TEST_FINISHED, ...) fills the suite instance's mailbox (the FB_TestSuite variables named
// below) and calls the built-in __TCUNIT(event, ADR(THIS^)); the runner, the machine's
// library hook, reads the mailbox of the suite at that address, applies TcUnit's rules
// (tests registered by name, DISABLED_, ordered tests, an assertion reported once per
// occurrence in a cycle, ...) and returns the call's result.
#pragma once

#include <cstdint>

namespace plcfi::st::tcunit_abi {

enum Event : int32_t {
  kActive = 0,         // -> 1 when assertions count now (a test is current, not finished, not ignored)
  kTest = 1,           // TEST(mailbox name) -> 1
  kTestOrdered = 2,    // TEST_ORDERED(mailbox name) -> 1 when it is this test's turn
  kFinished = 3,       // TEST_FINISHED() -> 1
  kFinishedNamed = 4,  // TEST_FINISHED_NAMED(mailbox name) -> 1 when the suite has such a test
  kIsFinished = 5,     // IS_TEST_FINISHED(mailbox name) -> 1 when that test is finished
  kAssert = 6,         // an assertion: mailbox ok, exp, act, msg, key, type, loc
  kAssertArray = 7,    // an array assertion: exp holds ARRAY_DIFF's TcUnit-style record
};

// The mailbox: variables of FB_TestSuite (the runner finds their offsets by these names).
inline constexpr const char* kOk = "_tcuOk";      // BOOL: the assertion held
inline constexpr const char* kExp = "_tcuExp";    // STRING(255): EXP's text
inline constexpr const char* kAct = "_tcuAct";    // STRING(255): ACT's text
inline constexpr const char* kMsg = "_tcuMsg";    // STRING(255): the user's message
inline constexpr const char* kKey = "_tcuKey";    // STRING(255): what identifies the assertion ('' : EXP and ACT)
inline constexpr const char* kType = "_tcuType";  // STRING(40): TcUnit's assertion type (INT, Array_INT, ...)
inline constexpr const char* kName = "_tcuName";  // STRING(255): the test name of TEST and the like
inline constexpr const char* kLoc = "_tcuLoc";    // LINT: the call's source location (Compiler::pack_location)

// ARRAY_DIFF in TcUnit style (ArrayDiffShape::style = 1) returns, separated by kSep:
// '=' (equal), 'S' (sizes differ) or 'C' (an element differs); EXP's text; ACT's text;
// and the key TcUnit identifies an array assertion by (the sizes, not the contents).
inline constexpr char kSep = '\x1f';

}  // namespace plcfi::st::tcunit_abi

#!/usr/bin/env bash
# --until text that closes the generated assignment and goes on (its ';' cannot pass
# through CMake's argument lists, hence this script): exit 2, a clear message.
#   usage: until_not_one_expression.sh PLCFI
set -u
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
snap=$here/../../support/cli_snapshot.sh
status=0
"$snap" "$1" "$here" not_one_expression test --dialect codesys counter.st passing.st --until 'TRUE; END_PROGRAM PROGRAM Extra' || status=1
"$snap" "$1" "$here" two_statements test --dialect codesys counter.st passing.st --until 'TRUE; PRG_PASS.fbTest.bDone := TRUE' || status=1
exit $status

#!/bin/sh
# Runs the TcUnit suites of this folder (plcfi test --dialect codesys *.st) and checks
# plcfi's standard output against expectations.txt: the lines TcUnit itself prints for
# these suites (README.md). Prints every expectation that does not hold, then
# "N of M expectations hold"; exit status 0 when all hold, 1 otherwise.
#   usage: check.sh PLCFI
#   PLCFI_TCUNIT_EXTENDED_ARGS="..." adds these arguments to the plcfi command line (the
#   option that prints TcUnit's extended per-test lines) and checks the ext-* expectations
#   too; without it they are counted as not checked.
#
# Matching is TcUnit's verifier's: a message matches a line that contains it, ignoring
# case; %f stands for a number. The checks other than summary and ext-* look at the
# reported lines: those that report something wrong (they contain FAIL, ERROR, EXCEEDED
# or ALREADY EXISTS in any case, or start with "| ", after an optional file:line:col:
# prefix), so that a line like "PASS: Test_X" does not count as a report about Test_X.
# ext-* look at the extended lines ("| Test name=...", "| Test status=...", ...); summary
# looks for a line that is exactly the text (after the optional prefix).
set -u
if [ $# -ne 1 ]; then
  echo "usage: check.sh PLCFI" >&2
  exit 2
fi
case $1 in
  /*) plcfi=$1 ;;
  *) plcfi=$(pwd)/$1 ;;
esac
dir=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM

cd "$dir" || exit 1
# shellcheck disable=SC2086,SC2035  # the extra arguments are meant to be split; no file here starts with -
"$plcfi" test --dialect codesys *.st ${PLCFI_TCUNIT_EXTENDED_ARGS:-} \
  >"$tmp/out" 2>"$tmp/err"
status=$?
lines=$(wc -l <"$tmp/out" | tr -d ' ')
echo "plcfi test: exit status $status, $lines line(s) of output"
if [ "$status" -gt 1 ] || [ "$lines" -eq 0 ]; then
  echo "plcfi did not run the suites (first lines of its diagnostics):"
  head -n 12 "$tmp/err" | sed 's/^/  | /'
fi

awk -v outfile="$tmp/out" -v extended="${PLCFI_TCUNIT_EXTENDED_ARGS:+1}" -v ran="$([ "$status" -le 1 ] && [ "$lines" -gt 0 ] && echo 1)" '
function bare(s) {
  sub(/^[ \t]*[^ \t:]+(:[0-9]+)+:[ \t]*/, "", s)
  sub(/^[ \t]+/, "", s)
  sub(/[ \t\r]+$/, "", s)
  return s
}
function starts(s, p) { return substr(s, 1, length(p)) == p }
function is_ext(b) {
  return starts(b, "| Test suite ID=") || starts(b, "| ID=") || starts(b, "| Test name=") ||
         starts(b, "| Test class name=") || starts(b, "| Test status=") ||
         starts(b, "| Test assert message=") || starts(b, "| Test assert type=")
}
# length of the number at the start of s (0: none)
function number_at(s) {
  if (match(s, /^[+-]?([0-9]+([.][0-9]*)?([eE][+-]?[0-9]+)?|[.][0-9]+([eE][+-]?[0-9]+)?)/))
    return RLENGTH
  return 0
}
# does s, from position at on, match the pieces k..np of the current message (%f between them)?
function rest_matches(s, at, k, anchored,    p, n) {
  if (k > np) return anchored ? at == length(s) + 1 : 1
  p = piece[k]
  if (k > 1) {
    n = number_at(substr(s, at))
    if (n == 0) return 0
    at += n
  }
  if (substr(s, at, length(p)) != p) return 0
  return rest_matches(s, at + length(p), k + 1, anchored)
}
# does line s contain message m (anchored: is s exactly m)? Case is ignored unless anchored.
function matches(s, m, anchored,    i, at, off) {
  np = split(m, piece, "%f")
  if (!anchored) { s = toupper(s); for (i = 1; i <= np; i++) piece[i] = toupper(piece[i]); m = toupper(m) }
  if (np <= 1) return anchored ? s == m : index(s, m) > 0
  if (anchored) return rest_matches(s, 1, 1, 1)
  off = 0
  while ((i = index(substr(s, off + 1), piece[1])) > 0) {
    at = off + i
    if (rest_matches(s, at + length(piece[1]), 2, 0)) return 1
    off = at
  }
  return 0
}
function count_in(kind, m,    i, c) {
  c = 0
  for (i = 1; i <= nout; i++) {
    if (kind == "summary") { if (matches(b[i], m, 1)) c++ }
    else if (kind == "ext") { if (ext[i] && matches(out[i], m, 0)) c++ }
    else if (rep[i] && matches(out[i], m, 0)) c++
  }
  return c
}
function fail(why, m,    i, id, msg, shown) {
  printf "FAIL expectations.txt:%d: %s\n     -> %s\n", FNR, $0, why
  # plcfi'"'"'s report of the same assertion (same test and message), if any
  if (m == "" || !match(m, /^FAILED TEST '"'"'[^'"'"']*'"'"'/)) return
  id = toupper(substr(m, 1, RLENGTH))
  msg = (i = index(m, ", MSG: ")) ? toupper(substr(m, i)) : ""
  for (i = 1; i <= nout && shown < 3; i++) {
    if (index(toupper(out[i]), id) && (msg == "" || substr(toupper(out[i]), length(out[i]) - length(msg) + 1) == msg)) {
      print "        plcfi: " out[i]; shown++
    }
  }
}
BEGIN {
  while ((getline line < outfile) > 0) {
    nout++; out[nout] = line; b[nout] = bare(line); ext[nout] = is_ext(b[nout])
    rep[nout] = !ext[nout] && (toupper(line) ~ /FAIL|ERROR|EXCEEDED|ALREADY EXISTS/ || starts(b[nout], "| "))
  }
}
/^#/ || /^[ \t]*$/ { next }
{
  n = split($0, f, "\t")
  kind = f[1]; scope = "rep"
  if (substr(kind, 1, 4) == "ext-") {
    kind = substr(kind, 5); scope = "ext"
    if (!extended) { skipped++; next }
  }
  if (kind == "summary") scope = "summary"
  total++
  if (kind == "contains" || kind == "summary") {
    c = count_in(scope, f[2]); ok = c > 0; why = "not printed"
    needed++
  } else if (kind == "absent") {
    c = count_in(scope, f[2]); ok = c == 0; why = "printed " c " time(s)"
  } else if (kind == "count" && n == 3 && f[2] ~ /^[0-9]+$/) {
    c = count_in(scope, f[3]); ok = c == f[2] + 0; why = "printed " c " time(s), expected " f[2]
    if (f[2] + 0 > 0) needed++
  } else {
    ok = 0; why = "not an expectation this script knows"
  }
  if (ok) held++; else fail(why, kind == "count" ? f[3] : f[2])
}
END {
  printf "%d of %d expectations hold (%d messages expected exactly)\n", held, total, needed
  if (skipped) printf "  %d extended-information expectation(s) not checked (set PLCFI_TCUNIT_EXTENDED_ARGS)\n", skipped
  if (!ran) print "  plcfi did not run the suites: the absence checks hold only because nothing was printed"
  exit held == total ? 0 : 1
}
' "$dir/expectations.txt"

#!/bin/sh
# Writes the hostile trace inputs of the cli.edtl_trace_* tests into DIR: deep nesting, a
# wide row, time going back, NUL bytes, endless devices behind a .vcd name.
set -eu
dir=$1
rm -rf "$dir"
mkdir -p "$dir"
awk 'BEGIN { for (i = 0; i < 10000; i++) print "$scope module m $end"; print "$var wire 1 ! H $end"; print "$enddefinitions $end"; print "#0"; print "1!" }' >"$dir/deep_scopes.vcd"
# 50,000 columns: the requirements' H and D and 49,998 others, three rows.
awk 'BEGIN {
  n = 49998
  printf "time,H,D"; for (i = 0; i < n; i++) printf ",c%d", i; printf "\n"
  for (r = 0; r < 3; r++) { printf "%d,%d,%d", r, r == 1, r == 1; for (i = 0; i < n; i++) printf ",%d", (i + r) % 2; printf "\n" }
}' >"$dir/wide.csv"
printf 'time,H,D\n0,0,0\n0.2,1,0\n0.1,1,1\n' >"$dir/back.csv"
printf '$var wire 1 ! H $end $var wire 1 " D $end $enddefinitions $end\n#0\n0!\n0"\n#30\n1!\n#20\n1"\n' >"$dir/back.vcd"
printf 'H,D\n0,0\n1,\0001\n' >"$dir/nul.csv"
ln -s /dev/zero "$dir/zero.vcd"
ln -s /dev/urandom "$dir/urandom.vcd"

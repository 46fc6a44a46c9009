#!/usr/bin/env python3
"""The harness must be able to fail: scripts/qualify on manifests with deliberately wrong
expectations exits 1 and records those checks FAIL (the honest one PASS), and broken
manifests and bad usage exit 2 with a precise message, before anything runs.
usage: test_qualify.py PLCFI WORK_DIR"""
import json
import os
import shutil
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
qualify = os.path.join(os.path.dirname(os.path.dirname(here)), "scripts", "qualify")
plcfi, work = sys.argv[1], sys.argv[2]
failures = []
shutil.rmtree(work, ignore_errors=True)  # a record left by an earlier run must not count


def run(*args):
    p = subprocess.run([sys.executable, qualify, *args], capture_output=True, text=True, timeout=120)
    return p.returncode, p.stdout, p.stderr


def expect(cond, what):
    print(("ok    " if cond else "FAIL  ") + what)
    if not cond:
        failures.append(what)


# 1. Wrong expectations: exit 1, each wrong check FAIL with the evidence that shows why.
out = os.path.join(work, "wrong")
status, stdout, stderr = run("--plcfi", plcfi, "--out", out, "--manifest", os.path.join(here, "selftest", "wrong_expectation.json"))
print(stdout, stderr, sep="")
expect(status == 1, f"a wrong expectation makes qualify exit 1 (got {status})")
record = json.load(open(os.path.join(out, "qualification.json")))
verdicts = {c["id"]: c["verdict"] for c in record["checks"]}
expect(verdicts == {"honest.station_correct": "PASS", "wrong.off_by_one_expected_to_pass": "FAIL",
                    "wrong.published_tc3_expected_to_pass": "FAIL"}, f"the record's verdicts: {verdicts}")
expect(record["result"] == "FAIL", "the record's result is FAIL")
wrong = next(c for c in record["checks"] if c["id"] == "wrong.off_by_one_expected_to_pass")
ev = wrong["steps"][0]["evidence"]
expect(any(e.get("exit") == 0 and e.get("actual") == 1 and not e["ok"] for e in ev),
       "the off-by-one check's evidence: exit status 1 where 0 was expected")
expect(any(e.get("expected") == "4 passed, 0 failed" and e.get("found") is None for e in ev),
       "the off-by-one check's evidence: the line '4 passed, 0 failed' is missing")
tc3 = next(c for c in record["checks"] if c["id"] == "wrong.published_tc3_expected_to_pass")
ev = tc3["steps"][0]["evidence"]
expect([e["ok"] for e in ev if "exit" in e or "in" in e] == [True, True],
       "the TC3 check: exit status and summary line as expected (only the journal is wrong)")
expect([(e["case"], e["actual"]) for e in ev if "case" in e and not e["ok"]] == [("TC3", ["FAIL"])],
       "the TC3 check: the journal comparison alone fails, on TC3 (FAIL, expected PASS)")
md = open(os.path.join(out, "qualification.md")).read()
expect("## wrong.off_by_one_expected_to_pass: FAIL" in md and "| honest.station_correct | PASS |" in md,
       "qualification.md shows the wrong check FAIL and the honest one PASS")
expect("FAILED: wrong.off_by_one_expected_to_pass, wrong.published_tc3_expected_to_pass" in stdout,
       "the summary line names the failed checks")

# 2. Broken manifests: exit 2, FILE:LINE:COL and what is wrong, and no record written.
def broken(name, message):
    out = os.path.join(work, name)
    status, stdout, stderr = run("--plcfi", plcfi, "--out", out, "--manifest", os.path.join(here, "selftest", name))
    print(stderr, end="")
    expect(status == 2, f"{name}: exit 2 (got {status})")
    expect(f"selftest/{name}:{message}" in stderr, f"{name}: message '{name}:{message}'")
    expect(not os.path.exists(os.path.join(out, "qualification.json")), f"{name}: nothing run, no record")


broken("malformed.json", "6:7: expected ',' or '}'")
broken("missing_source.json", "3:5: a check lacks 'source'")
broken("unknown_key.json", "8:58: unknown key 'stdot' in an expectation")

# 3. Bad usage: exit 2 with the reason.
status, _, stderr = run("--plcfi", os.path.join(work, "no-such-plcfi"), "--out", os.path.join(work, "x"))
expect(status == 2 and "no-such-plcfi: no such executable" in stderr, f"a missing plcfi: exit 2 ({status}: {stderr.strip()})")
status, _, stderr = run("--plcfi", plcfi, "--out", os.path.join(work, "x"), "--filter", "no.such.check")
expect(status == 2 and "selects none of the" in stderr, f"a filter that selects nothing: exit 2 ({status}: {stderr.strip()})")
status, _, stderr = run("--no-such-option")
expect(status == 2, f"an unknown option: exit 2 ({status})")
status, _, stderr = run("--plcfi", "/bin/true", "--out", os.path.join(work, "x"))
expect(status == 2 and "is it plcfi?" in stderr, f"an executable that is not plcfi: exit 2 ({status}: {stderr.strip()})")

print(f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)

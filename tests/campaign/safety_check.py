#!/usr/bin/env python3
"""An independent recomputation of a campaign's safety evidence (issue 30).

Written apart from plcfi's code: it reads only the inputs (the FMEA CSV, the fault-class
YAML) and what plcfi recorded (results.jsonl, the journal), recomputes per safety function
lambda_D, lambda_DD, DC and its IEC 61508-2 band, the safe failure fraction, the worst
detection-plus-reaction time (reaction_ns - inject_ns of every execution of a dangerous
row), the safety time and the margin, the undetected rows and the unassessed failures of
--explore, and compares all of it with OUT/safety.json. It also checks each line of
OUT/traceability.csv against the journal line it names.

usage: safety_check.py OUT FMEA.csv CLASSES.yaml [--undetected ROW,...] [--unassessed]
  --undetected: the dangerous rows that must be undetected (empty: none)
  --unassessed: the run explored; at least one unassessed failure mode is expected
Exit 0 when everything agrees, 1 otherwise (each difference printed).
"""
import argparse
import csv
import json
import re
import sys

import yaml


def duration_ms(text):
    """'2s', '150ms', '1m30s' -> milliseconds (the units the stamping files use)."""
    units = {"h": 3600e3, "m": 60e3, "s": 1e3, "ms": 1.0, "us": 1e-3, "ns": 1e-6}
    parts = re.findall(r"(\d+(?:\.\d+)?)(ms|us|ns|h|m|s)", str(text))
    if not parts or "".join(a + b for a, b in parts) != str(text).replace("T#", ""):
        raise ValueError(f"cannot read duration {text!r}")
    return sum(float(n) * units[u] for n, u in parts)


def band(dc):
    if dc is None:
        return "n/a"
    if dc >= 0.99:
        return "high"
    if dc >= 0.90:
        return "medium"
    if dc >= 0.60:
        return "low"
    return "none"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("fmea")
    ap.add_argument("classes")
    ap.add_argument("--undetected", default="")
    ap.add_argument("--unassessed", action="store_true")
    a = ap.parse_args()
    problems = []

    def check(what, mine, theirs, tol=1e-9):
        if isinstance(mine, float) or isinstance(theirs, float):
            ok = mine is not None and theirs is not None and abs(mine - theirs) <= tol
        else:
            ok = mine == theirs
        if not ok:
            problems.append(f"{what}: recomputed {mine!r}, safety.json has {theirs!r}")

    with open(a.fmea, newline="") as f:
        rows = [{k.strip().lower(): (v or "").strip() for k, v in r.items()} for r in csv.DictReader(f)]
    with open(a.classes) as f:
        classes = {str(c["id"]): c for c in yaml.safe_load(f)["fault_classes"]}
    with open(f"{a.out}/results.jsonl") as f:
        journal = [json.loads(line) for line in f if line.strip()]
    header, verdicts = journal[0], journal[1:]
    with open(f"{a.out}/safety.json") as f:
        got = json.load(f)

    by_row = {}
    for v in verdicts:
        if not v.get("explore"):
            by_row.setdefault(v["fmea"], []).append(v)

    functions = {}
    for r in rows:
        sf = r["safety_function"]
        if not sf:
            continue
        fn = functions.setdefault(sf, {"rows": [], "ld": 0.0, "ldd": 0.0, "ls": 0.0, "safe": False,
                                       "worst": None, "st": None, "undetected": []})
        fn["rows"].append(r["id"])
        rate = float(r["failure_rate"])
        if r.get("dangerous", "").lower() == "no":
            fn["ls"] += rate
            fn["safe"] = True
            continue
        fn["ld"] += rate
        runs = by_row.get(r["id"], [])
        if runs and all(v["verdict"] == "PASS" for v in runs):
            fn["ldd"] += rate
        else:
            fn["undetected"].append(r["id"])
        st = classes[r["fault_class"]].get("safety_time")
        if st is not None:
            st = duration_ms(st)
            fn["st"] = st if fn["st"] is None else min(fn["st"], st)
        for v in runs:
            if v["reaction_ns"] >= 0:
                t = (v["reaction_ns"] - v["inject_ns"]) / 1e6
                fn["worst"] = t if fn["worst"] is None else max(fn["worst"], t)

    got_fns = {f["id"]: f for f in got["safety_functions"]}
    check("safety functions", sorted(functions), sorted(got_fns))
    for name, fn in functions.items():
        g = got_fns.get(name)
        if g is None:
            continue
        dc = fn["ldd"] / fn["ld"] if fn["ld"] > 0 else None
        check(f"{name} rows", fn["rows"], g["rows"])
        check(f"{name} lambda_d", fn["ld"], float(g["lambda_d"]))
        check(f"{name} lambda_dd", fn["ldd"], float(g["lambda_dd"]))
        check(f"{name} dc", dc, g["dc"])
        check(f"{name} band", band(dc), g["band"])
        sff = (fn["ls"] + fn["ldd"]) / (fn["ls"] + fn["ld"]) if fn["safe"] else None
        check(f"{name} sff", sff, g["sff"])
        check(f"{name} worst_reaction_ms", fn["worst"], None if g["worst_reaction_ms"] is None else float(g["worst_reaction_ms"]))
        check(f"{name} safety_time_ms", fn["st"], None if g["safety_time_ms"] is None else float(g["safety_time_ms"]))
        margin = fn["st"] - fn["worst"] if fn["st"] is not None and fn["worst"] is not None else None
        check(f"{name} margin", margin, None if g["margin"] is None else float(g["margin"]))
        check(f"{name} undetected", fn["undetected"], g["undetected"])
        print(f"{name}: lambda_D {fn['ld']:g} FIT, lambda_DD {fn['ldd']:g} FIT, DC {dc if dc is None else round(dc * 100, 2)} % "
              f"({band(dc)}), worst {fn['worst']} ms, safety time {fn['st']} ms, margin {margin} ms, undetected {fn['undetected']}")

    want = [x for x in a.undetected.split(",") if x]
    all_undetected = sorted(u for fn in functions.values() for u in fn["undetected"])
    check("undetected rows (expected)", sorted(want), all_undetected)

    unassessed = sorted((v["case"], v["path"]) for v in verdicts if v.get("explore") and v["verdict"] != "PASS")
    check("unassessed", unassessed, sorted((u["case"], u["path"]) for u in got["unassessed"]))
    if a.unassessed and not unassessed:
        problems.append("--unassessed: the explored run found no failure without an FMEA row")
    if not a.unassessed and any(v.get("explore") for v in verdicts):
        problems.append("explored verdicts in the journal, but --unassessed not given")

    # The traceability matrix: every journal line it names holds that case, path and verdict.
    with open(f"{a.out}/traceability.csv", newline="") as f:
        lines = [line for line in f if not line.startswith("#")]
    trace = list(csv.DictReader(lines))
    all_lines = [None] + journal  # 1-based
    executed = 0
    for t in trace:
        if not t["journal_line"]:
            continue
        executed += 1
        j = all_lines[int(t["journal_line"])]
        if (j["case"], str(j["path"]), j["verdict"]) != (t["case"], t["path"], t["verdict"]):
            problems.append(f"traceability line for {t['case']} path {t['path']} points at journal line {t['journal_line']}: {j}")
        if (j.get("fmea") or "") != (t["fmea"] if not j.get("explore") else j.get("fmea", "")):
            problems.append(f"traceability line for {t['case']}: FMEA {t['fmea']} but the journal says {j.get('fmea')}")
        react = (j["reaction_ns"] - j["inject_ns"]) / 1e6 if j["reaction_ns"] >= 0 else None
        mine = float(t["reaction_ms"]) if t["reaction_ms"] else None
        if react != mine:
            problems.append(f"traceability reaction of {t['case']} path {t['path']}: {mine}, journal {react}")
    check("traceability lines with a verdict", executed, len(verdicts))
    check("fingerprint names the journal's", got["fingerprint"].get("journal fingerprint"), header["fingerprint"])

    for p in problems:
        print("MISMATCH:", p)
    print("safety evidence agrees with the independent calculation" if not problems else f"{len(problems)} mismatch(es)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())

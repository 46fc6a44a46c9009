#!/usr/bin/env python3
"""An lcov tracefile and a Cobertura file of one run tell the same numbers: the totals, and
per line the hits and the branches taken of how many. Usage: coverage_totals.py LCOV XML"""
import sys
import xml.etree.ElementTree as ET

lcov_path, xml_path = sys.argv[1], sys.argv[2]
lf = lh = brf = brh = 0
lines = {}     # (file, line) -> hits
branches = {}  # (file, line) -> [taken, total]
sf = None
records = 0
with open(lcov_path) as f:
    for raw in f:
        key, _, val = raw.rstrip("\n").partition(":")
        if key == "SF":
            sf = val
        elif key == "DA":
            n, hits = val.split(",")
            lines[(sf, int(n))] = int(hits)
        elif key == "BRDA":
            n, _block, _branch, taken = val.split(",")
            b = branches.setdefault((sf, int(n)), [0, 0])
            b[1] += 1
            b[0] += taken != "-" and int(taken) > 0
        elif key == "LF":
            lf += int(val)
        elif key == "LH":
            lh += int(val)
        elif key == "BRF":
            brf += int(val)
        elif key == "BRH":
            brh += int(val)
        elif key == "end_of_record":
            records += 1

problems = []
if records == 0:
    problems.append("no records in the tracefile")
if lf != len(lines) or lh != sum(1 for h in lines.values() if h > 0):
    problems.append(f"LF/LH {lf}/{lh} do not match the DA records")
if brf != sum(b[1] for b in branches.values()) or brh != sum(b[0] for b in branches.values()):
    problems.append(f"BRF/BRH {brf}/{brh} do not match the BRDA records")

root = ET.parse(xml_path).getroot()
want = {"lines-valid": lf, "lines-covered": lh, "branches-valid": brf, "branches-covered": brh}
for k, v in want.items():
    if int(root.get(k)) != v:
        problems.append(f"Cobertura {k}={root.get(k)}, lcov says {v}")
source = root.find("sources/source").text
xml_lines = {}
for cls in root.iter("class"):
    path = source.rstrip("/") + "/" + cls.get("filename")
    for line in cls.iter("line"):
        key = (path, int(line.get("number")))
        xml_lines[key] = int(line.get("hits"))
        if line.get("branch") == "true":
            taken, total = branches.get(key, [None, None])
            cc = line.get("condition-coverage")
            if total is None or cc != f"{taken * 100 // total}% ({taken}/{total})":
                problems.append(f"{key}: condition-coverage {cc}, lcov branches {taken}/{total}")
        elif key in branches:
            problems.append(f"{key}: lcov has branches, Cobertura none")
if xml_lines != lines:
    problems.append("the lines and hits differ between the files")
for p in problems:
    print(p)
print(f"lines {lh}/{lf}, branches {brh}/{brf}, {records} file(s)")
sys.exit(1 if problems else 0)

#!/usr/bin/env python3
"""Every ctest of the tree must carry a TIMEOUT: a test that hangs should fail on its own,
not stall CI until its global limit. Usage: check_timeouts.py BUILD_DIR"""
import json
import subprocess
import sys

build = sys.argv[1]
out = subprocess.run(["ctest", "--test-dir", build, "--show-only=json-v1"], check=True,
                     capture_output=True, text=True).stdout
tests = json.loads(out)["tests"]
missing = []
for t in tests:
    props = {p["name"]: p["value"] for p in t.get("properties", [])}
    if "TIMEOUT" not in props or float(props["TIMEOUT"]) <= 0:
        missing.append(t["name"])
for name in missing:
    print(f"no TIMEOUT: {name}")
print(f"{len(tests)} test(s), {len(missing)} without a TIMEOUT")
sys.exit(1 if missing or not tests else 0)

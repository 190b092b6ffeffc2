#!/usr/bin/env python3
"""The lever table of docs/EVAL.md from `betr eval goals --suite` runs: one row per run
(the base, then each part turned off or on), one column group per set of requests, with
the answer after the checks and the gold among the readings, and the change from the base.

Usage: lever_table.py BASE_DIR NAME=DIR [NAME=DIR ...]
"""
import json
import os
import sys


def tallies(run_dir):
    out = {}
    for name in sorted(os.listdir(run_dir)):
        path = os.path.join(run_dir, name, "results.json")
        if not os.path.exists(path):
            continue
        with open(path) as f:
            cases = json.load(f)["cases"]
        out[name] = (
            sum(1 for c in cases if c.get("first_correct")),
            sum(1 for c in cases if c.get("correct")),
            sum(1 for c in cases if c.get("gold_in_readings")),
            len(cases),
        )
    return out


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    base = tallies(sys.argv[1])
    sets = list(base)
    print("| run | " + " | ".join(f"{s}: after checks (Δ) / readings" for s in sets) + " |")
    print("|---|" + "---|" * len(sets))
    rows = [("base (every part on)", base)]
    for arg in sys.argv[2:]:
        name, _, d = arg.partition("=")
        rows.append((name, tallies(d)))
    for name, t in rows:
        cells = []
        for s in sets:
            if s not in t:
                cells.append("—")
                continue
            _, after, readings, total = t[s]
            delta = after - base[s][1]
            sign = f"{delta:+d}" if t is not base else ""
            cells.append(f"{after}/{total} ({sign}) / {readings}" if sign else f"{after}/{total} / {readings}")
        print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""The light atlas's before/after table: for every VPL-shooting run (the old presets), the
cheapest final-gather run whose error is at or below it, and the speed-up in bake seconds.

    python3 tools/light-atlas-speedup.py SHOOT.csv GATHER.csv > speedup.md

Reads gi-sweep CSVs (gi/src/sweep/sweep_csv.h). The error is the error against the truth
(column extra:truth_rel_rmse: the reference's own sampling variance removed) when both files
have it, else rel_rmse against the reference. tools/sweep-light-atlas-128.sh runs both sweeps
and this script.
"""
import csv
import math
import sys


def rows_of(path):
    with open(path, newline="") as f:
        return [r for r in csv.DictReader(f) if r["status"] == "ok"]


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def knobs(row, names):
    return ", ".join(f"{k} {row['knob:' + k]}" for k in names if row.get("knob:" + k, ""))


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    shoot, gather = rows_of(sys.argv[1]), rows_of(sys.argv[2])
    truth = all(r.get("extra:truth_rel_rmse", "") for r in shoot + gather)
    col = "extra:truth_rel_rmse" if truth else "rel_rmse"
    name = "error vs truth" if truth else "rel RMSE"
    print(f"| VPL shooting | {name} | bake s | cheapest gather at that {name} or lower | {name} | bake s | speed-up |")
    print("|---|---|---|---|---|---|---|")
    for s in sorted(shoot, key=lambda r: number(r["bake_s"])):
        e, t = number(s[col]), number(s["bake_s"])
        ok = [g for g in gather if number(g[col]) <= e]
        label = knobs(s, ["vpls", "bounces"])
        if not ok:
            print(f"| {label} | {e:.4f} | {t:.2f} | none | | | |")
            continue
        g = min(ok, key=lambda r: number(r["bake_s"]))
        ge, gt = number(g[col]), number(g["bake_s"])
        print(f"| {label} | {e:.4f} | {t:.2f} | {knobs(g, ['solve_rays', 'rays', 'filter', 'direct_samples'])} "
              f"| {ge:.4f} | {gt:.3f} | {t / gt:.1f}x |")
    best = min(gather, key=lambda r: number(r[col]))
    print()
    print(f"Most accurate gather run: {knobs(best, ['solve_rays', 'rays', 'filter', 'direct_samples'])}: "
          f"{name} {number(best[col]):.4f} in {number(best['bake_s']):.2f} s.")
    if truth:
        noise = number(gather[0].get("extra:ref_noise", ""))
        print(f"Reference noise (its own relative RMSE from the truth): {noise:.4f}.")


if __name__ == "__main__":
    main()

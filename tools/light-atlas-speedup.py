#!/usr/bin/env python3
"""The light atlas's before/after table: for every VPL-shooting run (the old presets), the
cheapest final-gather run whose error is at or below it, and the speed-up in bake seconds.

    python3 tools/light-atlas-speedup.py SHOOT.csv GATHER.csv > speedup.md

With --vs-pathtracer, the light atlas against the path tracer baking the same texels, on the
split truth's two measures (gi-sweep --split-truth: extra:indirect_dominated, extra:whole):
for every light-atlas run, the path tracer's seconds at the same error and the speed-up.

    python3 tools/light-atlas-speedup.py --vs-pathtracer PATHTRACER_ATLAS.csv LIGHT_ATLAS.csv... > speedup.md

The path tracer is unbiased, so its error against the noise-free truth falls as 1/sqrt(spp)
and its seconds grow as spp: error^2 x seconds is its constant, taken as the geometric mean
over its runs (each run's is listed); its seconds at error e are that constant / e^2.

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


MEASURES = [("extra:indirect_dominated", "indirect-dominated texels"), ("extra:whole", "whole lightmap")]


def pathtracer_constant(rows, col):
    """Geometric mean of error^2 x seconds over the runs with a finite, positive error."""
    logs = [math.log(number(r[col]) ** 2 * number(r["bake_s"])) for r in rows
            if number(r[col]) > 0 and number(r["bake_s"]) > 0]
    return math.exp(sum(logs) / len(logs)) if logs else math.nan


def vs_pathtracer(pt_path, atlas_paths):
    pt = rows_of(pt_path)
    atlas = [r for path in atlas_paths for r in rows_of(path)]
    const = {col: pathtracer_constant(pt, col) for col, _ in MEASURES}
    print("The path tracer's own runs (error from the noise-free truth; error^2 x s is the constant the "
          "speed-ups use):")
    print()
    print("| path tracer | bake s | indirect-dominated | whole | whole bias | error^2 x s (ind.-dom.) "
          "| error^2 x s (whole) |")
    print("|---|---|---|---|---|---|---|")
    for r in sorted(pt, key=lambda r: number(r["bake_s"])):
        t = number(r["bake_s"])
        products = [number(r[col]) ** 2 * t for col, _ in MEASURES]
        print(f"| {r['knob:spp']} spp | {t:.1f} | {number(r[MEASURES[0][0]]):.4f} | {number(r[MEASURES[1][0]]):.4f} "
              f"| {number(r['extra:whole_bias']):+.4f} | {products[0]:.3g} | {products[1]:.3g} |")
    print()
    print("The light atlas's runs, and the path tracer's seconds at the same error (constant / error^2):")
    print()
    print("| light atlas | bake s | indirect-dominated | path tracer s | speed-up | whole | whole bias "
          "| path tracer s | speed-up |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in sorted(atlas, key=lambda r: number(r["bake_s"])):
        t = number(r["bake_s"])
        cells = []
        for col, _ in MEASURES:
            e = number(r[col])
            pt_s = const[col] / (e * e) if e > 0 else math.nan
            cells.append((e, pt_s, pt_s / t))
        label = knobs(r, ["solve_rays", "rays", "emitter_rays", "filter", "denoise", "landing_direct", "source_filter", "near_rays", "near_depth", "adaptive", "direct_samples", "vpls", "bounces"])
        print(f"| {label} | {t:.1f} | {cells[0][0]:.4f} | {cells[0][1]:.0f} | {cells[0][2]:.1f}x "
              f"| {cells[1][0]:.4f} | {number(r['extra:whole_bias']):+.4f} | {cells[1][1]:.0f} | {cells[1][2]:.1f}x |")
    share = number(atlas[0].get("extra:indirect_dominated_share", "")) if atlas else math.nan
    print()
    print(f"Indirect-dominated texels (truth indirect >= 80% of the truth total): {100 * share:.1f}% of the texels.")


def main():
    if len(sys.argv) >= 4 and sys.argv[1] == "--vs-pathtracer":
        vs_pathtracer(sys.argv[2], sys.argv[3:])
        return
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

#!/usr/bin/env python3
"""Plots gi-sweep CSV files: relative RMSE against cost, log-log, one series per method,
the Pareto front highlighted. Writes <csv stem>.png next to each CSV.

    python3 tools/plot-sweep.py out/sweeps/pathtracer_cornell_box.csv [more.csv ...] [--cost frame]

Needs Debian's python3-matplotlib. Reads the columns written by gi/src/sweep/sweep_csv.h;
failed runs (status != ok) and non-positive values (no log scale for them) are skipped.
When the reference carried its own variance (column extra:truth_rel_rmse), the error axis is
the error against the noise-free truth, as the front and presets of the Markdown summary.
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def number(text):
    try:
        v = float(text)
    except ValueError:
        return math.nan
    return v


def pareto(points):
    """Indices of points (error, cost) not dominated by another, cheapest first."""
    front = []
    for i, (e, c) in enumerate(points):
        dominated = any(
            j != i and e2 <= e and c2 <= c and (e2 < e or c2 < c) for j, (e2, c2) in enumerate(points))
        if not dominated:
            front.append(i)
    return sorted(front, key=lambda i: (points[i][1], -points[i][0]))


def knob_label(row, knobs):
    return " ".join(f"{k}={row['knob:' + k]}" for k in knobs if row.get("knob:" + k, ""))


def varying_knobs(rows, knobs):
    """The knobs that take more than one value in these rows (labels skip constant ones)."""
    return [k for k in knobs if len({r.get("knob:" + k, "") for r in rows}) > 1]


def plot(csv_path, cost_axis):
    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))
    knobs = [c[len("knob:"):] for c in (rows[0].keys() if rows else []) if c.startswith("knob:")]
    cost_col, cost_unit = ("bake_s", "bake time (s)") if cost_axis == "bake" else ("frame_ms", "frame time (ms)")
    fig, ax = plt.subplots(figsize=(7, 5), dpi=120)
    methods = sorted({r["method"] for r in rows})
    truth = any(r.get("extra:truth_rel_rmse", "") for r in rows)
    error_col = "extra:truth_rel_rmse" if truth else "rel_rmse"
    plotted = 0
    for m in methods:
        pts, labels = [], []
        label_knobs = varying_knobs([r for r in rows if r["method"] == m], knobs)
        for r in rows:
            if r["method"] != m or r["status"] != "ok":
                continue
            e, c = number(r.get(error_col, "")), number(r[cost_col])
            if not (e > 0 and c > 0 and math.isfinite(e) and math.isfinite(c)):
                continue
            pts.append((e, c))
            labels.append(knob_label(r, label_knobs))
        if not pts:
            continue
        plotted += len(pts)
        line = ax.scatter([c for _, c in pts], [e for e, _ in pts], s=18, alpha=0.6, label=m)
        front = pareto(pts)
        ax.plot([pts[i][1] for i in front], [pts[i][0] for i in front], "-o", color=line.get_facecolor()[0],
                markersize=6, linewidth=1.5, label=f"{m} Pareto front")
        for i in front:
            ax.annotate(labels[i], (pts[i][1], pts[i][0]), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(cost_unit)
    ax.set_ylabel("relative RMSE vs truth (reference noise removed)" if truth else "relative RMSE vs reference")
    scene = rows[0]["scene"] if rows else ""
    ax.set_title(f"Accuracy vs cost: {scene}")
    ax.grid(True, which="both", alpha=0.3)
    if plotted:
        ax.legend(fontsize=8)
    else:
        ax.text(0.5, 0.5, "no valid runs to plot", transform=ax.transAxes, ha="center")
    out = os.path.splitext(csv_path)[0] + ".png"
    fig.tight_layout()
    fig.savefig(out + ".tmp.png")
    os.replace(out + ".tmp.png", out)
    plt.close(fig)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv", nargs="+", help="gi-sweep CSV files")
    parser.add_argument("--cost", choices=["bake", "frame"], default="bake", help="cost axis (default: bake)")
    args = parser.parse_args()
    for path in args.csv:
        print(plot(path, args.cost))
    return 0


if __name__ == "__main__":
    sys.exit(main())

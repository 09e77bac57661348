#!/usr/bin/env python3
"""Basis radiance fields: per-frame milliseconds against the number of objects (pairs grow as
n^2), from brf_bench's JSON output. Writes <out>.csv and <out>.png.

    ./build/gi/benchmarks/brf_bench --benchmark_format=json --benchmark_out=out/brf_bench.json \
        --benchmark_out_format=json
    /usr/bin/python3 tools/plot-brf-scaling.py out/brf_bench.json docs/sweeps/brf_scaling

Series: the CPU runtime (direct light + interreflection, one thread) with pair culling off
and at 1%, and the GPU pass with every object moving and with nothing moving (every pair's
basis irradiance reused). Needs Debian's python3-matplotlib.
"""
import csv
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SERIES = {
    # name prefix, args -> label
    ("BM_BrfUpdate", "0"): "CPU, no culling",
    ("BM_BrfUpdate", "1"): "CPU, culling 1%",
    ("BM_BrfGpu", "1/0"): "GPU, all moving",
    ("BM_BrfGpu", "1/1"): "GPU, all moving, culling 1%",
    ("BM_BrfGpu", "0/0"): "GPU, nothing moving",
}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    runs = json.load(open(sys.argv[1]))["benchmarks"]
    rows = []
    for r in runs:
        if r.get("run_type") == "aggregate":
            continue
        parts = r["name"].split("/")
        name, n, rest = parts[0], int(parts[1]), "/".join(parts[2:])
        label = SERIES.get((name, rest))
        if label is None:
            continue
        ms = r["real_time"] if r["time_unit"] == "ms" else r["real_time"] / 1e6
        rows.append({"series": label, "objects": n, "pairs": n * (n - 1), "ms": round(ms, 4),
                     "pairs_evaluated": int(r.get("pairs_evaluated", 0)),
                     "pairs_culled": int(r.get("pairs_culled", 0)),
                     "pairs_reused": int(r.get("pairs_reused", 0)),
                     "gpu_MB": round(r.get("gpu_MB", 0.0), 2)})
    out = sys.argv[2]
    with open(out + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for label in SERIES.values():
        pts = sorted((r["objects"], r["ms"]) for r in rows if r["series"] == label)
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", label=label)
    ns = sorted({r["objects"] for r in rows})
    ref = [r for r in rows if r["series"] == "CPU, no culling"]
    if ref:
        top = max(ref, key=lambda r: r["objects"])
        scale = top["ms"] / max(top["pairs"], 1)
        ax.plot(ns, [max(n * (n - 1), 1) * scale for n in ns], "k:", label="n(n-1), through CPU at 30")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("dynamic objects (crates, 150 vertices, 3 bounces)")
    ax.set_ylabel("ms per update")
    ax.set_title("Basis radiance fields: update cost vs objects (llvmpipe, 2 cores)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out + ".png", dpi=110)
    print(f"wrote {out}.csv and {out}.png")


if __name__ == "__main__":
    main()

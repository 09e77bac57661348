#!/usr/bin/env python3
"""The PRM's runtime cluster budget K per configuration and light pose, from gi-sweep prm CSVs
run with --knob active=0,32: error against the path tracer with every lit cluster and with the
K heaviest, the share of reflected energy the K-sum drops, and the error the K-sum would have if
it were rescaled to the full energy (gi-sweep's extra:* columns, gi/src/sweep/prm_sweep.cpp).
Writes one Markdown table per CSV, one row per (entries, clusters, N_s) x pose; poses are never
averaged.

    /usr/bin/python3 tools/prm-active-clusters.py --k 32 --out docs/sweeps/prm_active_clusters.md \
        docs/sweeps/prm_spot_chamber_active_clusters.csv [more.csv ...]
"""
import argparse
import csv
import os
import re


def pose_name(row):
    pose = row["knob:pose"]
    swing = float(row.get("knob:swing") or 0)
    return pose if swing == 0 else f"{pose}, swung {swing:+g}°"


def regenerate_command(csv_path):
    md = os.path.splitext(csv_path)[0] + ".md"
    try:
        text = open(md, encoding="utf-8").read()
    except OSError:
        return None
    m = re.search(r"```sh\n(gi-sweep [^\n]*)\n```", text)
    return m.group(1) if m else None


def table(csv_path, k):
    rows = list(csv.DictReader(open(csv_path, newline="", encoding="utf-8")))
    runs = {}
    configs, poses = [], []
    for r in rows:
        if r["status"] != "ok":
            continue
        c = (int(r["knob:entries"]), int(r["knob:clusters"]), r["knob:splitting"], r.get("knob:world", "all"))
        p = pose_name(r)
        if c not in configs:
            configs.append(c)
        if p not in poses:
            poses.append(p)
        runs[(c, p, int(r["knob:active"]))] = r
    scene = rows[0]["scene"] if rows else "(none)"
    out = [f"### {scene}: `{csv_path}`", ""]
    cmd = regenerate_command(csv_path)
    if cmd:
        out += ["Made by (the CSV's .md states it too):", "", "```sh", cmd, "```", ""]
    out += [
        f"| entries / clusters / N_s | pose | lit clusters | rel RMSE, all | rel RMSE, K = {k} | "
        f"energy dropped, K = {k} | K = {k} rescaled to all | relight ms all / K = {k} |",
        "|---|---|---|---|---|---|---|---|",
    ]
    worlds = {c[3] for c in configs}
    for c in configs:
        label = f"{c[0]} / {c[1]} / {c[2]}" + (f", world {c[3]}" if worlds != {"all"} else "")
        for p in poses:
            a, b = runs.get((c, p, 0)), runs.get((c, p, k))
            if a is None or b is None:
                continue
            out.append(
                f"| {label} | {p} | {int(float(a['extra:clusters_lit']))} | "
                f"{float(a['rel_rmse']):.3f} | {float(b['rel_rmse']):.3f} | "
                f"{100 * float(b['extra:dropped_energy']):.1f}% | {float(b['extra:rescaled_rel_rmse']):.3f} | "
                f"{float(a['frame_ms']):.2f} / {float(b['frame_ms']):.2f} |"
            )
    if worlds != {"all"}:
        out += ["", "World: what the reference path-traces (gi-sweep knob `world`): `all` instances, or the "
                "`static` ones the PRM models (no lamp shade, no crates)."]
    return "\n".join(out) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", nargs="+", help="gi-sweep prm CSV files with active=0 and active=K runs")
    parser.add_argument("--k", type=int, default=32, help="the runtime's K (GISystemSettings::prm_active_clusters)")
    parser.add_argument("--out", required=True, help="Markdown file to write")
    args = parser.parse_args()
    command = " ".join(["/usr/bin/python3 tools/prm-active-clusters.py", "--k", str(args.k), "--out", args.out] + args.csv)
    text = [
        "# PRM: the runtime's K heaviest clusters against all of them, per configuration and pose\n",
        "Generated from the gi-sweep CSVs below (do not edit; the CSVs' own commands are quoted per table):\n",
        "```sh\n" + command + "\n```\n",
        "Columns: *lit clusters* have a non-zero weight at that pose (the rest are never summed);",
        "*energy dropped* = 1 - sum of the K-sum's luminance / sum of the all-cluster sum's, over the",
        "valid texels; *rescaled* = the K-sum times (all / K-sum energy), which the runtime does not do;",
        "*relight ms* = CPU entry irradiance + selection + pane sum, one run each (noisy).\n",
    ]
    text += [table(path, args.k) for path in args.csv]
    with open(args.out, "w", encoding="utf-8") as f:
        f.write("\n".join(text))


if __name__ == "__main__":
    main()

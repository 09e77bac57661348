#!/usr/bin/env python3
"""The planner's bake estimates against measured bakes, one command (docs/plan.md, "Calibration").

    python3 tools/plan-calibration.py [--build build] [--out docs/plan-calibration.md] [--quick]

Bakes every (scene, method, preset) row below with `gi-bake --methods <m>` into a temporary
directory and reads, from the bundle it wrote, the planner's estimate of that method's wall
seconds (manifest.json, plan section) and the bake's own wall seconds (bake_stats.json); the
CPU seconds (user + sys of the gi-bake process) come from the operating system. Dabrovic
Sponza rows run when GI_EXTERNAL_ASSETS_DIR (or ../shared/external-assets) holds it. Prints
a Markdown table and the load average before and after: the estimates are of a quiet
machine's wall time, so a loaded machine reads slower than estimated. The last ratio,
(CPU s / 2) / estimate, holds less of the load: the bakes run on 2 threads, and CPU time
grows with the load only by the cache and the cores the other jobs share.
"""

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SUN = "direction:0.25,-1,0.15;irradiance:700,650,600"
SKY = "zenith:10,16,30;horizon:28,30,34;ground:6,6,6"


def rows(assets: Path, external: Path | None, quick: bool):
    out = []
    for preset in ("preview", "medium", "high"):
        out.append(("cornell_box", assets / "cornell_box.gltf", "light_atlas", preset, []))
        out.append(("cornell_box 128/m", assets / "cornell_box.gltf", "light_atlas", preset, ["--density", "128"]))
    # spot_chamber's PRM is planned only once its spot moves (docs/plan.md): no estimate to check.
    for preset in ("preview", "medium"):
        out.append(("spot_chamber", assets / "spot_chamber.gltf", "light_atlas", preset, []))
        out.append(("demo_level", assets / "demo_level.gltf", "light_atlas", preset, []))
        out.append(("demo_level", assets / "demo_level.gltf", "prm", preset, []))
    sponza = external / "dabrovic-sponza" / "sponza.gltf" if external else None
    if sponza and sponza.exists():
        lit = ["--untextured", "--sun", SUN, "--sky", SKY]
        out.append(("dabrovic-sponza", sponza, "light_atlas", "preview", lit))
        if not quick:
            out.append(("dabrovic-sponza", sponza, "light_atlas", "medium", lit))
    if quick:
        out = [r for r in out if not (r[3] == "medium" and r[2] == "prm" and r[0] == "demo_level")]
    return out


def bake(gi_bake: Path, scene: Path, method: str, preset: str, extra: list[str], tmp: Path):
    bundle = tmp / "calib.gibake"
    cmd = [str(gi_bake), "--scene", str(scene), "--methods", method, "--preset", preset, "--out", str(bundle), *extra]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    run = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    process_wall = time.monotonic() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if run.returncode != 0:
        sys.exit(f"plan-calibration: {' '.join(cmd)} failed:\n{run.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    manifest = json.loads((bundle / "manifest.json").read_text())
    estimate = next(e["estimate"] for e in manifest["plan"]["effects"] if e["method"] == method)
    stats = json.loads((bundle / "bake_stats.json").read_text())["methods"][method]
    return estimate, stats["seconds"], cpu, process_wall


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build", help="the CMake build directory (default: build)")
    parser.add_argument("--out", help="also write the table to this Markdown file")
    parser.add_argument("--quick", action="store_true", help="skip the two slowest rows (demo PRM medium, Sponza medium)")
    args = parser.parse_args()
    root = Path(__file__).resolve().parent.parent
    gi_bake = Path(args.build) / "tools" / "gi-bake" / "gi-bake"
    if not gi_bake.exists():
        sys.exit(f"plan-calibration: {gi_bake} not found (build first: bash tools/build.sh)")
    external_env = os.environ.get("GI_EXTERNAL_ASSETS_DIR")
    external = Path(external_env) if external_env else root.parent / "shared" / "external-assets"
    load_before = os.getloadavg()
    lines = [
        "| scene | method | preset | estimate s | measured s | measured / estimate | CPU s | process s "
        "| (CPU / 2) / estimate |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    with tempfile.TemporaryDirectory(prefix="gi-plan-calibration-") as tmp:
        for name, scene, method, preset, extra in rows(root / "assets", external, args.quick):
            estimate, seconds, cpu, process_wall = bake(gi_bake, scene, method, preset, extra, Path(tmp))
            est = estimate["bake_seconds"]
            ratio = seconds / est if est > 0 else float("inf")
            cpu_ratio = cpu / 2.0 / est if est > 0 else float("inf")
            line = (
                f"| {name} | {method} | {preset} | {est:.3f} | {seconds:.3f} | {ratio:.2f} | {cpu:.2f} "
                f"| {process_wall:.2f} | {cpu_ratio:.2f} |"
            )
            lines.append(line)
            print(line, flush=True)
    load_after = os.getloadavg()
    footer = (
        f"\nLoad average before: {load_before[0]:.2f} {load_before[1]:.2f} {load_before[2]:.2f}; "
        f"after: {load_after[0]:.2f} {load_after[1]:.2f} {load_after[2]:.2f} ({os.cpu_count()} cores). "
        "`measured s` is the method's wall seconds in bake_stats.json (the bake alone, without "
        "loading the scene); `process s` is the whole gi-bake run; `CPU s` (user + sys of the whole run, "
        "the scene's loading included) over 2 threads stands for a quiet machine's wall time, inflated far less by "
        "the load than the wall columns."
    )
    print(footer)
    if args.out:
        header = (
            "# The planner's estimates against measured bakes\n\n"
            "Regenerate: `python3 tools/plan-calibration.py --out docs/plan-calibration.md` (docs/plan.md, "
            '"Calibration").\n\n'
        )
        Path(args.out).write_text(header + "\n".join(lines) + "\n" + footer + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())

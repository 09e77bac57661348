#!/usr/bin/env python3
"""Turns the JSON of tools/perf-report.sh into docs/performance.md's measured block (between
the perf-report markers) and a plot: cost against the object count (BRF) and against the atlas
texels (PRM pane sum, with the yardstick streaming the same bytes).

    /usr/bin/python3 tools/perf-report.py out/perf docs/performance.md docs/images/performance.png

Medians of the repetitions (Google Benchmark's "median" aggregates) where present. Needs
Debian's python3-matplotlib.
"""
import json
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

BEGIN = "<!-- perf-report:begin (tools/perf-report.sh regenerates this block) -->"
END = "<!-- perf-report:end -->"


def load(path):
    """{run_name: benchmark entry}, the median aggregate when repeated."""
    if not os.path.exists(path):
        return {}, {}
    with open(path) as f:
        data = json.load(f)
    runs = {}
    for b in data["benchmarks"]:
        name = b.get("run_name", b["name"])
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") == "median":
                runs[name] = b
        elif name not in runs:
            runs[name] = b
    return runs, data.get("context", {})


def ms(entry):
    unit = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[entry.get("time_unit", "ns")]
    return entry["real_time"] * unit


def fmt(v, digits=3):
    if v is None:
        return "—"
    if abs(v) >= 100:
        return f"{v:.0f}"
    return f"{v:.{digits}g}"


FRAME_TARGETS = {"960x540": 15.0, "640x360": 30.0}
# A run small enough that shading costs nothing: its frame is the part that does not scale
# with the pixel count (the GI's per-frame update, the shadow maps, draw and state overhead).
FRAME_FIXED_SIZE = "96x54"


def medians(values):
    return " / ".join(fmt(v) for v in values) if values else "—"


def load_frame(out_dir, size, variant=""):
    """The demo's headless summary for one size (tools/perf-report.sh writes frame_WxH.txt, and frame_WxH_flat.txt for the flat-shading yardstick):
    frames/s, the pass medians, CPU seconds. None when the run was skipped; an error naming the
    file when it ran but the summary is not there (a failed run, or the summary's format moved)."""
    path = os.path.join(out_dir, f"frame_{size}{variant}.txt")
    if not os.path.exists(path):
        return None
    text = open(path).read()
    fps = re.search(r"gi_demo: (\d+) frames in ([\d.]+) s \(([\d.]+) frames/s\)", text)
    cpu = re.search(r"process CPU s: ([\d.]+) user ([\d.]+) sys", text)
    if not fps or not cpu:
        sys.exit(f"perf-report: {path}: no gi_demo summary in it (did the run fail?):\n{text[-2000:]}")

    def median(label):
        """The pass's median ms; a pass split over several labels (the shadow maps' view count
        moves with the flashlight) gives each median, joined."""
        found = re.findall(r"\n\s*" + re.escape(label) + r"[^\n]*?median\s+([\d.]+)", text)
        return [float(v) for v in found]

    frames = int(fps.group(1))
    return {"size": size, "flat": variant == "_flat", "frames": frames, "fps": frames / float(fps.group(2)),
            "total_median_ms": median("total")[0] if median("total") else None,
            "gi_update_median_ms": median("indirect light update"),
            "forward_median_ms": median("forward + indirect"), "shadow_median_ms": median("shadow maps"),
            "tonemap_median_ms": median("tonemap"), "cpu_s": float(cpu.group(1)) + float(cpu.group(2))}


def main():
    out_dir, doc, png = sys.argv[1], sys.argv[2], sys.argv[3]
    prm, ctx = load(os.path.join(out_dir, "prm_gpu_bench.json"))
    before, _ = load(os.path.join(out_dir, "prm_gpu_bench_before.json"))
    relight, _ = load(os.path.join(out_dir, "prm_relight_bench.json"))
    brf, _ = load(os.path.join(out_dir, "brf_bench.json"))
    load_txt = open(os.path.join(out_dir, "load.txt")).read().strip().splitlines()

    lines = [BEGIN, ""]
    lines.append(f"Measured {ctx.get('date', '?')} on {ctx.get('num_cpus', '?')} CPUs at "
                 f"{ctx.get('mhz_per_cpu', '?')} MHz (llvmpipe for the GPU passes), "
                 f"Google Benchmark library: {ctx.get('library_build_type', '?')} build (Debian's); load average "
                 + "; ".join(load_txt) + ". Medians of interleaved repetitions.")
    lines.append("")

    # PRM light change: one row per pane encoding (the benchmark's argument rgb9e5:0 / rgb9e5:1).
    changes = [(n, e) for n, e in sorted(relight.items()) if n.startswith("BM_PrmLightChange")]
    lines.append("### PRM: one light change on the demo level (preview bake)")
    lines.append("")
    lines.append("| | CPU ms | GPU ms | total ms | atlas re-bake ms | re-bake / change | pane MB | target |")
    lines.append("|---|---|---|---|---|---|---|---|")
    lines.append("| before (docs/prm.md, idle machine) | 0.7 | 2.5 | 3.2 | 930 | 290 | 5.4 | ≥ 1000, ≤ 0.9 ms |")
    def change_label(name):
        threads = re.search(r"threads:(\d+)", name)
        label = "RGB9E5 panes (default)" if "rgb9e5:1" in name else "half-float panes"
        if threads and threads.group(1) != "1":
            label += f", flux check on {threads.group(1)} threads"
        if "base:1" in name:
            label += ", light atlas as base (the demo's case)"
        return label

    changes.sort(key=lambda ne: (("rgb9e5:1" in ne[0]), ne[0]))
    for name, c in changes:
        label = change_label(name)
        lines.append(f"| {label} (`prm_relight_bench`) | {fmt(c['cpu_ms'])} | {fmt(c['gpu_ms'])} | {fmt(c['total_ms'])} | "
                     f"{fmt(c['atlas_rebake_ms'])} | {fmt(c['vs_rebake'])} | {fmt(c.get('pane_mb'))} | "
                     f"≤ 0.9 ms {'met' if c['total_ms'] <= 0.9 else 'not met'}, "
                     f"≥ 1000× {'met' if c['vs_rebake'] >= 1000 else 'not met'} |")
    if changes:
        c = changes[0][1]
        lines.append("")
        lines.append(f"{int(c['texels'])} pane texels, {int(c['entries'])} entry points, {int(c['clusters'])} clusters "
                     f"lit; the pane sum with no cluster (its fixed part: texel list, every texel written) "
                     + ", ".join(f"{fmt(e['gpu_k0_ms'])} ms ({change_label(n)})" for n, e in changes)
                     + f"; {100 * c['nonzero_blocks']:.0f}% of the panes' 8-texel blocks hold light.")
        lines.append("")
        lines.append("The relit atlas's error per encoding, over the 8 poses' K-sums (lit texels; a texel's error is "
                     "max over channels |Δ| / its largest channel; rel RMSE as docs/prm.md measures the PRM against "
                     "the path tracer, 0.19 on this level):")
        lines.append("")
        lines.append("| encoding | against | max | p95 | rel RMSE | total |")
        lines.append("|---|---|---|---|---|---|")
        seen = set()
        for name, e in changes:
            label = "RGB9E5" if "rgb9e5:1" in name else "half"
            if label in seen:  # the same panes: the same error
                continue
            seen.add(label)
            for ref in ("float", "half"):
                if label == "half" and ref == "half":
                    continue
                lines.append(f"| {label} | {ref} panes | {e[f'err_vs_{ref}_max']:.2e} | {e[f'err_vs_{ref}_p95']:.2e} | "
                             f"{e[f'err_vs_{ref}_rmse']:.2e} | {e[f'err_vs_{ref}_total']:.1e} |")
    lines.append("")

    # PRM pane sum vs the stream yardstick.
    lines.append("### PRM pane sum against a plain vec4 stream of the same bytes (`prm_gpu_bench`)")
    lines.append("")
    lines.append("| T (texels) | K | sum ms | pane GB/s | stream GB/s | sum / stream | before: pane GB/s (old shader) |")
    lines.append("|---|---|---|---|---|---|---|")
    sums = []
    for name, e in sorted(prm.items(), key=lambda kv: [int(x) for x in re.findall(r":(\d+)", kv[0])]):
        m = re.match(r"BM_PrmGpuSum/T:(\d+)/K:(\d+)", name)
        if not m:
            continue
        t, k = int(m.group(1)), int(m.group(2))
        old = next((b for n, b in before.items() if n.startswith(f"BM_PrmGpuSum/T:{t}/K:{k}/")), None)
        sums.append((t, k, e))
        lines.append(f"| {t} | {k} | {fmt(ms(e))} | {fmt(e['pane_GB/s'])} | {fmt(e['stream_GB/s'])} | "
                     f"{fmt(e['vs_stream'], 2)} | {fmt(old['pane_GB/s']) if old else '—'} |")
    lines.append("")

    # BRF.
    lines.append("### BRF: all crates moving, default culling (1e-3), influence limit off (before) and on (`brf_bench`)")
    lines.append("")
    lines.append("| crates | all pairs | pairs evaluated (off → on) | GPU ms off | GPU ms on | process CPU ms on | Phi slots / GPU MB on |")
    lines.append("|---|---|---|---|---|---|---|")
    series = {}
    for name, e in brf.items():
        m = re.match(r"BM_BrfGpuInfluence/(\d+)/(\d)", name)
        if m:
            series.setdefault(int(m.group(2)), {})[int(m.group(1))] = e
    for n in sorted(set(series.get(0, {})) | set(series.get(1, {}))):
        off, on = series.get(0, {}).get(n), series.get(1, {}).get(n)
        any_ = off or on
        slots = f"{int(on['pair_slots'])} / {fmt(on['gpu_MB'])}" if on and 'pair_slots' in on else '—'
        lines.append(f"| {n} | {int(any_['all_pairs'])} | {int(off['pairs_evaluated']) if off else '—'} → "
                     f"{int(on['pairs_evaluated']) if on else '—'} | {fmt(ms(off)) if off else '—'} | "
                     f"{fmt(ms(on)) if on else '—'} | {fmt(on['process_cpu_ms']) if on and 'process_cpu_ms' in on else '—'} | "
                     f"{slots} |")
    g = next((e for n, e in brf.items() if n.startswith("BM_BrfGatherCpu")), None)
    if g:
        lines.append("")
        lines.append(f"CPU twin's bounce loop (`brf_gather`, 30 crates, {fmt(g['phi_MB'])} MB of Phi): "
                     f"{fmt(g['gather_GB/s'])} GB/s against memcpy {fmt(g['memcpy_GB/s'])} GB/s of the same bytes: "
                     f"**{fmt(g['vs_memcpy'], 2)}** (target ≥ 0.5).")
    # Issue 23's BRF target at the defaults (no bound culling, lod_distance 5), and the fixed part.
    moving, still = brf.get("BM_BrfGpu/30/1/0"), brf.get("BM_BrfGpu/30/0/0")
    if moving:
        lines.append("")
        lines.append(f"30 crates all moving at the default settings (`BM_BrfGpu/30/1/0`, no bound culling, "
                     f"`lod_distance` 5): **{fmt(ms(moving))} ms** GPU wall, process CPU "
                     f"{fmt(moving.get('process_cpu_ms'))} ms (target ≤ 20 ms); nothing moving (`BM_BrfGpu/30/0/0`): "
                     f"{fmt(ms(still)) if still else '—'} ms.")
    lines.append("")
    # The frame.
    runs = [(size, v) for size in FRAME_TARGETS for v in ("", "_flat")] + [(FRAME_FIXED_SIZE, "")]
    frames = [f for f in (load_frame(out_dir, size, v) for size, v in runs) if f]
    if frames:
        with open(os.path.join(out_dir, "frame.json"), "w") as f:
            json.dump(frames, f, indent=1)
        lines.append("### The demo level's frame (`gi_demo --headless --frames 60`, preview bundle, all GI on)")
        lines.append("")
        lines.append("| size | frames/s | frame median ms | indirect light update median ms "
                     "| forward + indirect median ms | shadow maps median ms | tonemap median ms "
                     "| process CPU s / frame | target |")
        lines.append("|---|---|---|---|---|---|---|---|---|")
        for f in frames:
            t = FRAME_TARGETS.get(f["size"])
            if f["flat"]:
                target = "— (yardstick: `--shading flat`, any shading costs at least this)"
            elif t:
                target = f"≥ {t:g} frames/s {'met' if f['fps'] >= t else 'not met'}"
            else:
                target = "— (what does not scale with pixels)"
            label = f"{f['size']} flat" if f["flat"] else f["size"]
            lines.append(f"| {label} | **{f['fps']:.1f}** | {fmt(f['total_median_ms'])} | "
                         f"{medians(f['gi_update_median_ms'])} | {medians(f['forward_median_ms'])} | "
                         f"{medians(f['shadow_median_ms'])} | {medians(f['tonemap_median_ms'])} | "
                         f"{fmt(f['cpu_s'] / f['frames'], 2)} | {target} |")
        lines.append("")
        by_size = {f["size"]: f for f in frames if not f["flat"]}
        flat = {f["size"]: f for f in frames if f["flat"]}
        fixed = by_size.get(FRAME_FIXED_SIZE)
        if fixed and fixed["total_median_ms"]:
            fw, fh = (int(v) for v in FRAME_FIXED_SIZE.split("x"))
            parts = []
            for size, t in FRAME_TARGETS.items():
                f = by_size.get(size)
                if not f or not f["total_median_ms"]:
                    continue
                w, h = (int(v) for v in size.split("x"))
                per_pixel_us = (f["total_median_ms"] - fixed["total_median_ms"]) * 1e3 / (w * h - fw * fh)
                budget = 1e3 / t
                part = (f"at {size} the target allows {fmt(budget)} ms a frame; the pixels add "
                        f"{fmt(per_pixel_us, 3)} µs each ({fmt(per_pixel_us * w * h / 1e3)} ms)")
                if size in flat and flat[size]["total_median_ms"]:
                    fl = flat[size]["total_median_ms"]
                    flat_us = (fl - fixed["total_median_ms"]) * 1e3 / (w * h - fw * fh)
                    # Medians of different runs: a flat frame can come out below the 96x54 one.
                    flat_txt = f"{fmt(flat_us, 3)} µs" if flat_us > 0 else "none measurable"
                    part += (f", {flat_txt} of it with flat shading (its frame {fmt(fl)} ms, "
                             f"{fmt(1e3 / fl)} frames/s at most)")
                parts.append(part)
            lines.append(f"What does not scale with the pixels: the {FRAME_FIXED_SIZE} run's median frame, "
                         f"**{fmt(fixed['total_median_ms'])} ms** (indirect light update "
                         f"{medians(fixed['gi_update_median_ms'])}, shadow maps {medians(fixed['shadow_median_ms'])}, "
                         f"forward {medians(fixed['forward_median_ms'])}), caps any size at "
                         f"{fmt(1e3 / fixed['total_median_ms'])} frames/s; " + "; ".join(parts) + ".")
            lines.append("")
        lines.append("The profile and what limits it: [performance-frame.md](performance-frame.md).")
        lines.append("")

    lines.append("![cost against object count and atlas texels](images/performance.png)")
    lines.append("")
    lines.append(END)
    block = "\n".join(lines)

    text = open(doc).read() if os.path.exists(doc) else f"# Performance\n\n{BEGIN}\n{END}\n"
    if BEGIN in text and END in text:
        text = text[: text.index(BEGIN)] + block + text[text.index(END) + len(END):]
    else:
        text += "\n" + block + "\n"
    with open(doc, "w") as f:
        f.write(text)

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    for flag, label, style in ((0, "influence limit off (before)", "o-"), (1, "influence limit on", "s-")):
        pts = sorted(series.get(flag, {}).items())
        if pts:
            a.plot([n for n, _ in pts], [ms(e) for _, e in pts], style, label=label)
    ns = sorted(series.get(0, {}))
    if ns:
        base = ms(series[0][ns[0]]) / (ns[0] * (ns[0] - 1))
        a.plot(ns, [base * n * (n - 1) for n in ns], ":", color="grey", label="∝ n(n−1)")
    a.set_xscale("log")
    a.set_yscale("log")
    a.set_xlabel("crates (all moving)")
    a.set_ylabel("BRF GPU pass ms (llvmpipe)")
    a.set_title("BRF: cost against object count")
    a.legend(fontsize=8)
    for k in sorted({k for _, k, _ in sums}):
        pts = sorted((t, e) for t, kk, e in sums if kk == k)
        b.plot([t for t, _ in pts], [ms(e) for _, e in pts], "o-", label=f"pane sum K={k}")
        b.plot([t for t, _ in pts], [ms(e) * e["vs_stream"] for _, e in pts], "x:", color=b.lines[-1].get_color(),
               label=f"vec4 stream, same bytes (K={k})")
    b.set_xscale("log")
    b.set_yscale("log")
    b.set_xlabel("pane texels T")
    b.set_ylabel("ms (llvmpipe)")
    b.set_title("PRM pane sum: cost against atlas texels")
    b.legend(fontsize=7)
    fig.tight_layout()
    os.makedirs(os.path.dirname(png), exist_ok=True)
    fig.savefig(png, dpi=110)
    print(f"wrote {doc} and {png}")


if __name__ == "__main__":
    main()

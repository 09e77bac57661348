#!/usr/bin/env bash
# Regenerates the fuzz seed corpus tests/fuzz/corpus/ (tests/fuzz/README.md) from the project's
# assets and tiny bakes by the built gi-bake (GI_BAKE, or BUILD_DIR/tools/gi-bake/gi-bake, build/
# by default): run it after a bundle file format changes (the ctest
# Fuzz.<target>.ReplaysSeedsAndRegressions then refuses a seed). Usage:
#   tools/fuzz-seeds.sh                                            # the whole corpus
#   tools/fuzz-seeds.sh light_atlas_vpls manifest/atlas_prm.json   # only these targets' folders or seeds
#   tools/fuzz-seeds.sh --check [NAME...]                           # list stale seeds, change nothing
# Naming targets or seeds replaces only those, so a branch that changed one format re-makes its
# own seeds without touching the others'. --check makes the seeds in a scratch directory and
# lists those that differ from the committed ones (a manifest's bake_seconds aside, which differ
# every run); exit 1 when any does.
set -euo pipefail
cd "$(dirname "$0")/.."
check=0
if [ "${1:-}" = "--check" ]; then
  check=1
  shift
fi
root=$(pwd)
bake=${GI_BAKE:-"$root/${BUILD_DIR:-build}/tools/gi-bake/gi-bake"}
[ -x "$bake" ] || { echo "fuzz-seeds.sh: build gi-bake first ($bake)" >&2; exit 1; }
targets=(gltf exr session blob manifest atlas_layout light_atlas_vpls prm_panes brf_mesh antiradiance dlm)
for name in "$@"; do
  [[ " ${targets[*]} " == *" ${name%%/*} "* ]] || {
    echo "fuzz-seeds.sh: no target '${name%%/*}' (targets: ${targets[*]})" >&2
    exit 2
  }
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
corpus="$root/tests/fuzz/corpus"
out="$tmp/corpus"

python3 - "$root/assets" "$tmp" <<'PY'
import base64, json, struct, sys
assets, out = sys.argv[1] + "/", sys.argv[2] + "/"
# The Cornell box with its buffer as a data URI (a .gltf that needs no other file).
g = json.load(open(assets + "cornell_box.gltf"))
b = open(assets + g["buffers"][0]["uri"], "rb").read()
g["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(b).decode()
open(out + "cornell_box_embedded.gltf", "w").write(json.dumps(g, separators=(",", ":")))
# The spot chamber packed as a GLB.
g = json.load(open(assets + "spot_chamber.gltf"))
b = open(assets + g["buffers"][0]["uri"], "rb").read()
del g["buffers"][0]["uri"]
j = json.dumps(g, separators=(",", ":")).encode()
j += b" " * ((4 - len(j) % 4) % 4)
b += b"\0" * ((4 - len(b) % 4) % 4)
glb = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(j) + 8 + len(b)) + struct.pack("<I4s", len(j), b"JSON") + j
glb += struct.pack("<I4s", len(b), b"BIN\0") + b
open(out + "spot_chamber.glb", "wb").write(glb)
# The Cornell box with its short block deforming (antiradiance) and a glossy red wall (DLM).
g = json.load(open(assets + "cornell_box.gltf"))
short = [i for i, m in enumerate(g["meshes"]) if m["name"] == "short_block"][0]
for n in g["nodes"]:
    if n.get("mesh") == short:
        n.setdefault("extras", {}).setdefault("gi", {})["region"] = "deforming"
g["materials"][1]["pbrMetallicRoughness"]["roughnessFactor"] = 0.2
json.dump(g, open(out + "cb_deform.gltf", "w"))
PY
cp assets/cornell_box.bin "$tmp/"

"$bake" --scene assets/cornell_box.gltf --preset preview --methods light_atlas,prm --density 2 --vpls 16 --samples 2 \
  --threads 1 --out "$tmp/atlas_prm.gibake" >/dev/null
"$bake" --scene assets/crates_room.gltf --preset preview --methods brf --brf-basis 2 --brf-spheres 1 \
  --threads 1 --out "$tmp/brf.gibake" >/dev/null
# From the scratch directory, so the manifest names the scene "cb_deform.gltf", not a path that changes every run.
(cd "$tmp" && "$bake" --scene cb_deform.gltf --preset preview --methods antiradiance,dlm --density 2 --dlm-directions 8 \
  --dlm-photons 2000 --threads 1 --out ar_dlm.gibake >/dev/null)
"$bake" --scene assets/cornell_box.gltf --preset preview --methods light_atlas,dlm --density 3 --vpls 64 --dlm-directions 8 \
  --dlm-photons 2000 --threads 1 --out "$tmp/no_dlm_texels.gibake" >/dev/null

for t in "${targets[@]}"; do mkdir -p "$out/$t"; done
cp assets/crates_room.draco.glb assets/demo_level.draco.glb "$tmp/spot_chamber.glb" "$tmp/cornell_box_embedded.gltf" \
  "$out/gltf/"
cp "$tmp/atlas_prm.gibake/light_atlas.exr" "$out/exr/"
cp tests/sessions/open_door.girec "$out/session/"
cp "$tmp/ar_dlm.gibake/dlm.bin" "$out/blob/dlm.bin"
cp "$tmp/no_dlm_texels.gibake/dlm.bin" "$out/blob/dlm_empty.bin"
cp "$tmp/atlas_prm.gibake/manifest.json" "$out/manifest/atlas_prm.json"
cp "$tmp/brf.gibake/manifest.json" "$out/manifest/brf.json"
cp "$tmp/ar_dlm.gibake/manifest.json" "$out/manifest/antiradiance_dlm.json"
cp "$tmp/atlas_prm.gibake/light_atlas_vpls.bin" "$out/light_atlas_vpls/"
cp "$tmp/atlas_prm.gibake/prm_layout.bin" "$tmp/ar_dlm.gibake/dlm_layout.bin" "$out/atlas_layout/"
cp "$tmp/atlas_prm.gibake/prm_panes.bin" "$out/prm_panes/"
cp "$tmp/brf.gibake/brf_crate.bin" "$out/brf_mesh/"
cp "$tmp/ar_dlm.gibake/antiradiance.bin" "$out/antiradiance/"
cp "$tmp/ar_dlm.gibake/dlm.bin" "$out/dlm/"
cp "$tmp/no_dlm_texels.gibake/dlm.bin" "$out/dlm/dlm_no_texels.bin"

if [ $check -eq 1 ]; then
  stale=$(python3 - "$out" "$corpus" "$@" <<'PY'
import json, os, sys
out, corpus, names = sys.argv[1], sys.argv[2], sys.argv[3:]
def untimed(x):  # a manifest without its bake times
    if isinstance(x, dict):
        return {k: untimed(v) for k, v in x.items() if k != "bake_seconds"}
    return [untimed(v) for v in x] if isinstance(x, list) else x
for root, _, files in sorted(os.walk(out)):
    for f in sorted(files):
        rel = os.path.relpath(os.path.join(root, f), out)
        if names and not any(rel == n or rel.startswith(n.rstrip("/") + "/") for n in names):
            continue
        made = open(os.path.join(root, f), "rb").read()
        path = os.path.join(corpus, rel)
        committed = open(path, "rb").read() if os.path.exists(path) else None
        same = committed == made
        if not same and committed is not None and rel.endswith(".json"):
            same = untimed(json.loads(committed)) == untimed(json.loads(made))
        if not same:
            print(rel if committed is not None else rel + " (missing)")
PY
  )
  if [ -z "$stale" ]; then
    echo "fuzz-seeds.sh: every seed checked is what the sources make now"
    exit 0
  fi
  echo "fuzz-seeds.sh: stale seeds (re-make them with tools/fuzz-seeds.sh NAME...):"
  echo "$stale"
  exit 1
fi
if [ $# -eq 0 ]; then
  rm -rf "$corpus"
  cp -r "$out" "$corpus"
  echo "fuzz-seeds.sh: $(find "$corpus" -type f | wc -l) seeds, $(du -sh "$corpus" | cut -f1) in $corpus"
  exit 0
fi
for name in "$@"; do
  [ -e "$out/$name" ] || { echo "fuzz-seeds.sh: no seed '$name' (have: $(cd "$out" && find . -type f | sort | tr '\n' ' '))" >&2; exit 2; }
done
for name in "$@"; do
  rm -rf "${corpus:?}/$name"
  mkdir -p "$(dirname "$corpus/$name")"
  cp -r "$out/$name" "$corpus/$name"
  echo "fuzz-seeds.sh: re-made $name ($(find "$corpus/$name" -type f | wc -l) files)"
done

#!/usr/bin/env bash
# Each pipeline's real-time frame rate (`lightgrid play`) next to its analysis-run time
# (`lightgrid render --stats`) on robots-many at 640x360, as a Markdown table (README,
# "Real-time frames"). Run from the repository root after `cargo build --release`.
set -euo pipefail
B=${LIGHTGRID:-target/release/lightgrid}
OUT=${OUT:-play-vs-analysis}
SIZE=${SIZE:-640x360}
PIPELINES="forward tiled_forward tiled_forward_prez tiled_deferred tiled_deferred_single clustered_forward clustered_deferred deferred deferred_stencil light_prepass light_prepass_mono"
mkdir -p "$OUT"
for p in $PIPELINES; do
  # forward takes seconds per frame on a software adapter: three frames are enough.
  case $p in forward) F=199..201 ;; *) F=195..204 ;; esac
  "$B" play --scene robots-many --pipeline "$p" --assign gather --size "$SIZE" --frames "$F" \
    --warmup 2 --json "$OUT/$p.play.json" >/dev/null 2>"$OUT/$p.play.err"
  "$B" render --scene robots-many --frame 200 --pipeline "$p" --assign gather --size "$SIZE" \
    --stats "$OUT/$p.render.json" >/dev/null 2>"$OUT/$p.render.err"
done
OUT="$OUT" PIPELINES="$PIPELINES" python3 - <<'PY'
import json, os
out = os.environ["OUT"]
print("| pipeline | play fps | play frame ms (median / p95) | play GPU ms (median) | submits / readback B per frame | analysis GPU ms (frame 200) | analysis wall ms |")
print("|---|---:|---:|---:|---:|---:|---:|")
for p in os.environ["PIPELINES"].split():
    a = json.load(open(f"{out}/{p}.play.json"))
    r = json.load(open(f"{out}/{p}.render.json"))
    gpu = a["gpu_ms"]["median"] if a["gpu_ms"] else float("nan")
    print(f"| {p} | {a['fps']:.2f} | {a['frame_ms']['median']:.1f} / {a['frame_ms']['p95']:.1f} | {gpu:.1f} "
          f"| {a['submits_per_frame']:.0f} / {a['readback_bytes_per_frame']:.0f} | {r['gpu_ms']:.1f} | {r['wall_ms']:.1f} |")
PY

#!/usr/bin/env bash
# Feature tracking figures on simulated courses (issue 6): `drover features track` with each detector on a 20 s
# `straight` course and the `lighting` course (dark stretches), and the share of frames that keep >= 50 tracked
# features inside the dark stretches (the middle 20-45 % of each labelled `lighting` segment, where the scene
# light is at its night level, 5e-4 of daylight, below the camera's auto-exposure floor:
# src/sim/scenario_world.cpp LightingPlan::temporal, src/sim/camera_exposure.hpp).
# Courses are generated once (cached in $DROVER_OUT/sim/<name>_track). Writes bench/out/tracking/<course>_<detector>/
# (tracks.json) and bench/out/tracking.md (the table).
# Usage: bash bench/track_courses.sh [detector ...]   (default: shi-tomasi orb superpoint)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${DROVER_BUILD_DIR:-build}
OUT_ROOT=${DROVER_OUT:-out}
DROVER="$BUILD_DIR/apps/drover/drover"
DETECTORS=("$@")
[ ${#DETECTORS[@]} -gt 0 ] || DETECTORS=(shi-tomasi orb superpoint)
mkdir -p bench/out/tracking "$OUT_ROOT/sim"
for c in straight lighting; do
  data="$OUT_ROOT/sim/${c}_track"
  duration=()
  [ "$c" = straight ] && duration=(--duration 20)
  [ -f "$data/scenario.json" ] || "$DROVER" sim --scenario "$c" --seed 1 --out "$data" --force -q "${duration[@]}"
  for d in "${DETECTORS[@]}"; do
    "$DROVER" features track "$data" --format sim --detector "$d" --out "bench/out/tracking/${c}_$d" -q \
      --weights ../shared/models/superpoint_v1.onnx
    echo "== $c $d done"
  done
done
OUT_ROOT="$OUT_ROOT" /usr/bin/python3 - <<'PY'
import glob, json, os
root = os.environ["OUT_ROOT"]
rows = ["| course | detector | frames | features / frame | mean track length [frames] | RANSAC inliers | ms / frame | frames with >= 50 tracked | same, dark stretches only |",
        "|---|---|---|---|---|---|---|---|---|"]
for p in sorted(glob.glob("bench/out/tracking/*/tracks.json")):
    j = json.load(open(p))
    course = os.path.basename(os.path.dirname(p)).split("_")[0]
    scenario = json.load(open(os.path.join(root, "sim", course + "_track", "scenario.json")))
    dark = [(s["start_ns"] + 0.2 * (s["end_ns"] - s["start_ns"]), s["start_ns"] + 0.45 * (s["end_ns"] - s["start_ns"]))
            for s in scenario["segments"] if s["condition"] == "lighting"]
    frames = j["frames"][1:]
    in_dark = [f for f in frames if any(a <= f["stamp_ns"] <= b for a, b in dark)]
    dark_share = (f"{100 * sum(f['tracked'] >= 50 for f in in_dark) / len(in_dark):.1f} % of {len(in_dark)}"
                  if in_dark else "-")
    s = j["summary"]
    rows.append(f"| {course} | {j['detector']} | {s['frames']} | {s['mean_features']:.1f} | {s['mean_track_length']:.1f} | "
                f"{s['ransac_inlier_ratio']:.3f} | {s['ms_per_frame']:.1f} | {100 * s['fraction_tracked_ge_50']:.1f} % | {dark_share} |")
open("bench/out/tracking.md", "w").write("\n".join(rows) + "\n")
print("\n".join(rows))
PY

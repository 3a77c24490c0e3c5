#!/usr/bin/env bash
# Drover's main job. Installs what is missing, builds, then
#  1. generates the simulated farm course once (out/sim/farm, ~25 min on 2 cores, most of it the camera's rays,
#     2x2 a pixel and 4x4 where an edge crosses one;
#     cached: delete the folder to regenerate; lidar, camera,
#     IMU) and runs the full system on it -- the LIS, the VIS and loop closure -- twice, with the two presets of the
#     LVI-SAM comparison: lvi-sam (out/farm_lvi-sam) and drover (out/farm: trajectory, map, report with loops, APE),
#     then prints their accuracy and speed side by side. The drover run is the whole preset, SuperPoint included
#     (~9.5 min on 2 cores); DROVER_SUPERPOINT=0 runs it with Shi-Tomasi corners instead (--without superpoint,
#     ~6.5 min);
#  2. runs the lidar odometry on the shared KITTI odometry snippet (sequence 00, frames 0-9; out/kitti00).
# Results go to out/ (override with DROVER_OUT).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
BUILD_DIR=${DROVER_BUILD_DIR:-build}
OUT_ROOT=${DROVER_OUT:-out}
DROVER="$BUILD_DIR/apps/drover/drover"

# ---- simulated farm (default dataset) --------------------------------------------------------------------------
SIM_OUT="$OUT_ROOT/sim"
FARM="$SIM_OUT/farm"
mkdir -p "$SIM_OUT"
# (a cached course without camera frames, or rendered with other rays a pixel than the config's, is generated again)
# shellcheck source=scripts/sim_cache.sh
. scripts/sim_cache.sh
if ! course_is_current "$FARM" config/farm_sim.yaml || [ "$(wc -l < "$FARM/camera/timestamps.csv")" -le 1 ]; then
  "$DROVER" sim --scenario farm --seed 1 --config config/farm_sim.yaml --out "$FARM" --force
fi
DROVER_PRESET=(--preset drover)
[ "${DROVER_SUPERPOINT:-1}" = 0 ] && DROVER_PRESET=(--preset drover --without superpoint)
"$DROVER" run "$FARM" --format sim --config config/farm_sim.yaml --out "$OUT_ROOT/farm_lvi-sam" --preset lvi-sam
"$DROVER" run "$FARM" --format sim --config config/farm_sim.yaml --out "$OUT_ROOT/farm" "${DROVER_PRESET[@]}"
for run in farm_lvi-sam farm; do
  /usr/bin/python3 tools/course_report.py "$FARM" "$OUT_ROOT/$run" --json "$OUT_ROOT/$run/course_report.json" >/dev/null
done
/usr/bin/python3 - "$OUT_ROOT" <<'PY'
import json, sys
out = sys.argv[1]
print("\nThe farm course (650 s, 635 m), the full system with loop closure, SE(3)-aligned APE as evo_ape:")
print(f"{'preset':<36} {'APE rmse [m]':>12} {'APE max [m]':>11} {'end gap [m]':>11} {'loops':>5} {'x real time':>11}")
rows = {}
for run in ("farm_lvi-sam", "farm"):
    r = json.load(open(f"{out}/{run}/report.json"))
    c = json.load(open(f"{out}/{run}/course_report.json"))
    rows[run] = r["ape"]["rmse"]
    print(f"{r['preset']:<36} {r['ape']['rmse']:>12.3f} {r['ape']['max']:>11.3f} {c['start_end_m']:>11.3f} "
          f"{r['loops']['accepted']:>5} {r['real_time_factor']:>11.2f}")
print(f"drover / lvi-sam APE rmse: {rows['farm'] / rows['farm_lvi-sam']:.2f}")
PY

# ---- KITTI 00 snippet ------------------------------------------------------------------------------------------
OUT="$OUT_ROOT/kitti00"
SEQ=../shared/data/kitti/sequences/00
if [ ! -d "$SEQ" ]; then
  echo "error: $SEQ not found: the default dataset lives in ../shared/data beside the repository" >&2
  exit 2
fi
mkdir -p "$OUT"
"$DROVER" run "$SEQ" --format kitti --config config/kitti.yaml --max-frames 10 --out "$OUT"
echo "results in $OUT_ROOT/farm, $OUT_ROOT/farm_lvi-sam and $OUT"

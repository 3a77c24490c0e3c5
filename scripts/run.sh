#!/usr/bin/env bash
# Drover's main job. Installs what is missing, builds, then
#  1. generates the simulated farm course once (out/sim/farm, cached: delete the folder to regenerate) and runs the
#     lidar-inertial odometry with loop closure on it (out/farm: trajectory, map, report with loops, APE) --
#     Drover's default dataset. --no-camera: the VIS does not yet feed the LIS (it would only add its own trajectory),
#     and with the shipped SuperPoint detector it runs below real time on 2 cores (bench/RESULTS.md);
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
if [ ! -f "$FARM/calibration.yaml" ]; then
  "$DROVER" sim --scenario farm --seed 1 --config config/farm_sim.yaml --out "$FARM" --force
fi
"$DROVER" run "$FARM" --format sim --config config/farm_sim.yaml --out "$OUT_ROOT/farm" --no-camera
/usr/bin/python3 tools/course_report.py "$FARM" "$OUT_ROOT/farm" --json "$OUT_ROOT/farm/course_report.json"

# ---- KITTI 00 snippet ------------------------------------------------------------------------------------------
OUT="$OUT_ROOT/kitti00"
SEQ=../shared/data/kitti/sequences/00
if [ ! -d "$SEQ" ]; then
  echo "error: $SEQ not found: the default dataset lives in ../shared/data beside the repository" >&2
  exit 2
fi
mkdir -p "$OUT"
"$DROVER" run "$SEQ" --format kitti --config config/kitti.yaml --max-frames 10 --out "$OUT"
echo "results in $OUT_ROOT/farm and $OUT"

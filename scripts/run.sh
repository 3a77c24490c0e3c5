#!/usr/bin/env bash
# Drover's main job. Installs what is missing, builds, then
#  1. generates the simulated farm course once (out/sim/farm, cached: delete the folder to regenerate) and
#     summarises it -- the simulator's output is Drover's default dataset;
#  2. runs on the shared KITTI odometry snippet (sequence 00, frames 0-9).
# Until lidar odometry lands (issue 4) the job is the simulator, reader and evaluator path: stream every scan and
# image, export the ground truth, and evaluate it against itself. Results go to out/ (override with DROVER_OUT).
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
"$DROVER" info "$FARM" --format sim --config config/farm_sim.yaml --json "$SIM_OUT/farm_info.json" \
  --export-gt "$SIM_OUT/farm_groundtruth_imu.tum"
# Evaluator self-check on the farm ground truth (every statistic must print 0); Drover's own trajectory goes here
# once `drover run` exists.
"$DROVER" eval ape "$SIM_OUT/farm_groundtruth_imu.tum" "$SIM_OUT/farm_groundtruth_imu.tum" --format tum \
  --align se3 --json "$SIM_OUT/farm_ape_self.json"

# ---- KITTI 00 snippet ------------------------------------------------------------------------------------------
OUT="$OUT_ROOT/kitti00"
SEQ=../shared/data/kitti/sequences/00
if [ ! -d "$SEQ" ]; then
  echo "error: $SEQ not found: the default dataset lives in ../shared/data beside the repository" >&2
  exit 2
fi
mkdir -p "$OUT"
"$DROVER" info "$SEQ" --format kitti --config config/kitti.yaml --max-frames 10 --json "$OUT/info.json" \
  --export-gt "$OUT/groundtruth_lidar.tum"
# The evaluator end to end on the exported file (a self-check: every statistic must print 0). It will compare
# Drover's own trajectory here once `drover run` exists.
"$DROVER" eval ape "$OUT/groundtruth_lidar.tum" "$OUT/groundtruth_lidar.tum" --format tum --align se3 \
  --json "$OUT/ape_self.json"
echo "results in $SIM_OUT and $OUT"

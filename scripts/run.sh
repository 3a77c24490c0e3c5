#!/usr/bin/env bash
# Drover's main job on the default dataset. Installs what is missing, builds, then runs on the shared KITTI
# odometry snippet (sequence 00, frames 0-9). Until lidar odometry lands (issue 4) the job is the reader and
# evaluator path: stream every scan and image, export the ground truth in the lidar frame, and evaluate it.
# Results go to out/ (override with DROVER_OUT).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
BUILD_DIR=${DROVER_BUILD_DIR:-build}
OUT=${DROVER_OUT:-out}/kitti00
SEQ=../shared/data/kitti/sequences/00
if [ ! -d "$SEQ" ]; then
  echo "error: $SEQ not found: the default dataset lives in ../shared/data beside the repository" >&2
  exit 2
fi
mkdir -p "$OUT"
DROVER="$BUILD_DIR/apps/drover/drover"
"$DROVER" info "$SEQ" --format kitti --config config/kitti.yaml --max-frames 10 --json "$OUT/info.json" \
  --export-gt "$OUT/groundtruth_lidar.tum"
# The evaluator end to end on the exported file (a self-check: every statistic must print 0). It will compare
# Drover's own trajectory here once `drover run` exists.
"$DROVER" eval ape "$OUT/groundtruth_lidar.tum" "$OUT/groundtruth_lidar.tum" --format tum --align se3 \
  --json "$OUT/ape_self.json"
echo "results in $OUT"

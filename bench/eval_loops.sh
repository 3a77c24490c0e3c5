#!/usr/bin/env bash
# Loop closure on the simulated courses that revisit places (issue 5's figures): runs `drover run` with and without
# loop closure on `farm` and `kitti05-replay` (lidar + IMU, no camera; generated once into $DROVER_OUT/sim/), and
# writes bench/out/loops.md: APE rmse (SE(3)-aligned) with/without, start-end and end errors, loops accepted,
# precision and recall against the ground truth, the narrowed-vs-full shift agreement and the loop stage's cost.
# Usage: bash bench/eval_loops.sh [course ...]. Needs ../shared/data for kitti05-replay. About 10 min per course.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/sim_cache.sh
BUILD_DIR=${DROVER_BUILD_DIR:-build}
OUT_ROOT=${DROVER_OUT:-out}
DROVER="$BUILD_DIR/apps/drover/drover"
COURSES=("$@")
[ ${#COURSES[@]} -gt 0 ] || COURSES=(farm kitti05-replay)
mkdir -p bench/out/loops "$OUT_ROOT/sim"
for c in "${COURSES[@]}"; do
  data="$OUT_ROOT/sim/${c}_nocam"
  config=$(platform_config "$c")
  [ -f "$data/scenario.json" ] ||
    "$DROVER" sim --scenario "$c" --seed 1 --config "$config" --out "$data" --force -q --no-camera
  for mode in loop noloop; do
    flag=()
    [ "$mode" = noloop ] && flag=(--no-loop)
    run="$OUT_ROOT/runs/${c}_$mode"
    "$DROVER" run "$data" --format sim --config "$config" --out "$run" -q "${flag[@]}" >/dev/null
    /usr/bin/python3 tools/course_report.py "$data" "$run" --json "bench/out/loops/${c}_$mode.json" >/dev/null
    cp "$run/report.json" "bench/out/loops/${c}_${mode}_report.json"
  done
  echo "== $c done"
done
/usr/bin/python3 tools/loop_table.py bench/out/loops > bench/out/loops.md
cat bench/out/loops.md

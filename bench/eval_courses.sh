#!/usr/bin/env bash
# Lidar-inertial odometry on every simulated course, with and without the IMU, without loop closure (issue 4's
# accuracy figures).
# Generates each course once (lidar + IMU, no camera; cached in $DROVER_OUT/sim/<name>), runs `drover run` twice and
# writes bench/out/courses/<name>_{imu,lidar}.json (tools/course_report.py) and bench/out/courses.md (the table).
# Usage: bash bench/eval_courses.sh [course ...]   (default: all). Needs ../shared/data for kitti05-replay.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${DROVER_BUILD_DIR:-build}
OUT_ROOT=${DROVER_OUT:-out}
DROVER="$BUILD_DIR/apps/drover/drover"
COURSES=("$@")
[ ${#COURSES[@]} -gt 0 ] || COURSES=(straight uphill downhill garage-exit garage-entry jolting sharp-turns overlap
                                     corridor white-walls lighting kitti05-replay farm)
mkdir -p bench/out/courses "$OUT_ROOT/sim"
for c in "${COURSES[@]}"; do
  data="$OUT_ROOT/sim/$c"
  [ "$c" = farm ] || data="$OUT_ROOT/sim/${c}_nocam"
  if [ ! -f "$data/scenario.json" ]; then
    extra=(--no-camera)
    [ "$c" = farm ] && extra=()
    "$DROVER" sim --scenario "$c" --seed 1 --config config/farm_sim.yaml --out "$data" --force -q "${extra[@]}"
  fi
  for mode in imu lidar; do
    flag=(--no-loop)  # the LIS alone; loop closure is bench/eval_loops.sh's
    [ "$mode" = lidar ] && flag+=(--no-imu)
    run="$OUT_ROOT/runs/${c}_$mode"
    "$DROVER" run "$data" --format sim --config config/farm_sim.yaml --out "$run" -q "${flag[@]}" >/dev/null
    /usr/bin/python3 tools/course_report.py "$data" "$run" --json "bench/out/courses/${c}_$mode.json" >/dev/null
  done
  echo "== $c done"
done
/usr/bin/python3 - <<'PY'
import glob, json, os
rows = {}
for p in sorted(glob.glob("bench/out/courses/*.json")):
    name, mode = os.path.basename(p)[:-5].rsplit("_", 1)
    rows.setdefault(name, {})[mode] = json.load(open(p))
out = ["| course | path [m] | drift with IMU [% of path] | end error with IMU [m] | drift lidar only [%] | end error lidar only [m] |",
       "|---|---|---|---|---|---|"]
for name, r in rows.items():
    i, l = r.get("imu"), r.get("lidar")
    f = lambda x, k, fmt: (fmt % x[k]) if x else "-"
    out.append(f"| {name} | {f(i or l, 'path_length_m', '%.0f')} | {f(i, 'drift_percent', '%.2f')} | "
               f"{f(i, 'end_error_m', '%.3f')} | {f(l, 'drift_percent', '%.2f')} | {f(l, 'end_error_m', '%.3f')} |")
open("bench/out/courses.md", "w").write("\n".join(out) + "\n")
print("\n".join(out))
PY

#!/usr/bin/env bash
# The VIS's speed: drover run --no-lidar (camera + IMU, the VIS alone) on a simulated course (640x480 at 15 Hz,
# 200 Hz IMU), once per detector and repetition, on whatever cores the machine has. Prints one table row per run:
# the run's wall time and x real time (report.json's wall_s / data_s), and the VIS's mean ms a frame per stage
# (track includes detection and runs in a thread of its own; solve + marginalise is the estimator), with the frames
# estimated, resets and the VIS's APE rmse, so that a speed is never read without the accuracy it came with.
# Run it on a quiet machine.
#   bash bench/vis_speed.sh                                   # farm course (650 s), seed 1, Shi-Tomasi and SuperPoint
#   COURSE=sharp-turns DURATION=40 REPEAT=3 DETECTORS=shi-tomasi bash bench/vis_speed.sh
#   DROVER=/path/to/other/drover bash bench/vis_speed.sh       # another binary on the same data (before/after)
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/sim_cache.sh
DROVER=${DROVER:-build/apps/drover/drover}
COURSE=${COURSE:-farm}
SEED=${SEED:-1}
DURATION=${DURATION:-0}
REPEAT=${REPEAT:-1}
DETECTORS=${DETECTORS:-shi-tomasi superpoint}
OUT=${OUT:-bench/out/vis_speed}
DATA=${DATA:-$OUT/sim_${COURSE}_${SEED}_${DURATION}}
mkdir -p "$OUT"
course_is_current "$DATA" config/farm_sim.yaml || "$DROVER" sim --scenario "$COURSE" --seed "$SEED" --duration "$DURATION" \
  --config config/farm_sim.yaml --out "$DATA" --force -q
echo "| detector | run | wall [s] | x real time | track | solve | marginalise | estimator | frames estimated | resets | VIS APE rmse [m] |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for d in $DETECTORS; do
  cfg="$OUT/config_$d.yaml"
  sed -e "s/^    type: superpoint /    type: $d /" config/farm_sim.yaml > "$cfg"
  for i in $(seq 1 "$REPEAT"); do
    run="$OUT/run_${COURSE}_${d}_$i"
    "$DROVER" run "$DATA" --format sim --config "$cfg" --out "$run" --no-lidar --no-loop -q
    /usr/bin/python3 - "$run/report.json" "$d" "$i" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
v = r["vis"]
ms = v["ms_per_frame"]
print(f"| {sys.argv[2]} | {sys.argv[3]} | {r['wall_s']:.1f} | {r['real_time_factor']:.2f} | {ms['track']:.1f} | "
      f"{ms['solve']:.1f} | {ms['marginalize']:.1f} | {ms['solve'] + ms['marginalize']:.1f} | "
      f"{v['frames_estimated']} of {v['frames_in']} | {v['resets']} | {v.get('ape', {}).get('rmse', float('nan')):.3f} |")
PY
  done
done

#!/usr/bin/env bash
# The VIS alone on a simulated EuRoC sequence: the mav-room flight (a MAV in a textured room, EuRoC's Vicon-room
# class of motion, 100 s, ~72 m) on EuRoC's rig, written in EuRoC's ASL layout by `drover sim --format euroc` and run
# as a user runs a real sequence: `drover run SEQ --format euroc --config config/euroc.yaml` (visual-inertial
# initialisation, no lidar), once per detector. Sequences are rendered once per seed (2x2 rays a pixel, as the config
# says) into $DROVER_OUT/sim/mav-room_s<seed>. Writes bench/out/euroc_sim/<seed>_<detector>.json and
# bench/out/euroc_sim.md (APE rmse after SE(3) alignment, as evo_ape on EuRoC).
# With CAMERA_TIME_OFFSET=S (seconds, t_imu = t_camera + S) the rig's camera stamps are that far off the IMU's, as
# on a rig without hardware synchronisation (EuRoC's is synchronised), and each detector runs twice: with the
# config's estimate_time_offset: false and true (VINS-Mono's td); sequences go to mav-room_s<seed>_td<S>.
# Usage: bash bench/eval_euroc_sim.sh     env: SEEDS="1 2 3"  DETECTORS="shi-tomasi orb superpoint"  CAMERA_TIME_OFFSET
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${DROVER_BUILD_DIR:-build}
OUT_ROOT=${DROVER_OUT:-out}
DROVER="$BUILD_DIR/apps/drover/drover"
SEEDS=${SEEDS:-1 2 3}
DETECTORS=${DETECTORS:-shi-tomasi orb superpoint}
TD=${CAMERA_TIME_OFFSET:-}
mkdir -p bench/out/euroc_sim "$OUT_ROOT/sim" "$OUT_ROOT/euroc_configs" "$OUT_ROOT/runs"

# A sequence rendered with the config's camera rays (scenario.json records them). KEY:DEFAULT:ABSENT: the config's
# default, and what a sequence from before the key had (sequences from before pixel samples are stale).
current() {  # dir
  local k key default absent want have
  [ -f "$1/scenario.json" ] || return 1
  for k in camera_pixel_samples:1:0 camera_texture_filter:false:false camera_edge_pixel_samples:0:0; do
    IFS=: read -r key default absent <<< "$k"
    want=$(sed -n "s/^ *$key: *\([0-9a-z]*\).*/\1/p" config/euroc.yaml)
    have=$(sed -n "s/.*\"$key\": *\([0-9a-z]*\).*/\1/p" "$1/scenario.json")
    [ "${want:-$default}" = "${have:-$absent}" ] || return 1
  done
}

SIM_CONFIG=config/euroc.yaml
if [ -n "$TD" ]; then  # the sim: section with the camera's stamps off by TD
  SIM_CONFIG="$OUT_ROOT/euroc_configs/sim_td$TD.yaml"
  sed -e "s/^  rig: euroc /  camera_time_offset: $TD\n  rig: euroc /" config/euroc.yaml > "$SIM_CONFIG"
fi
VARIANTS=("")
[ -z "$TD" ] || VARIANTS=("_td$TD" "_td${TD}_estimated")

for seed in $SEEDS; do
  data="$OUT_ROOT/sim/mav-room_s$seed${TD:+_td$TD}"
  current "$data" || "$DROVER" sim --scenario mav-room --seed "$seed" --config "$SIM_CONFIG" --format euroc \
    --out "$data" --force -q
  for d in $DETECTORS; do
   for variant in "${VARIANTS[@]}"; do
    cfg="$OUT_ROOT/euroc_configs/$d$variant.yaml"
    estimate=false
    [[ "$variant" != *_estimated ]] || estimate=true
    sed -e "s/^    type: superpoint /    type: $d /" \
      -e "s/^  estimate_time_offset: false /  estimate_time_offset: $estimate /" config/euroc.yaml > "$cfg"
    out="$OUT_ROOT/runs/euroc_sim_s${seed}_$d$variant"
    rm -rf "$out"
    json="bench/out/euroc_sim/s${seed}_$d$variant.json"
    if "$DROVER" run "$data" --format euroc --config "$cfg" --out "$out" -q >/dev/null 2>&1; then
      /usr/bin/python3 - "$out/report.json" "$json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
v = r["vis"]
keep = ("first_init_s", "resets", "keyframes", "ms_per_frame", "ape", "frames_in", "frames_estimated", "detector")
out = {k: v.get(k) for k in keep}
out["init"] = next((e["what"] for e in v.get("events", []) if e["kind"] == "initialized"), None)
out["real_time_factor"] = r.get("real_time_factor")
out["time_offset_s"] = v.get("time_offset_s")
json.dump(out, open(sys.argv[2], "w"), indent=1)
PY
    else
      echo '{"failed": true}' > "$json"
    fi
    echo "== seed $seed $d$variant done"
   done
  done
done
/usr/bin/python3 - <<'PY'
import glob, json, os
rows = ["| seed | run | APE rmse [m] | max [m] | % of path | initialised at [s] | resets | frames estimated | "
        "VIS ms a frame | x real time | td estimated [ms] |", "|---|---|---|---|---|---|---|---|---|---|---|"]
for p in sorted(glob.glob("bench/out/euroc_sim/*.json")):
    seed, det = os.path.basename(p)[:-5].split("_", 1)
    x = json.load(open(p))
    if x.get("failed"):
        rows.append(f"| {seed[1:]} | {det} | failed | | | | | | | | |")
        continue
    a = x["ape"]
    rows.append(f"| {seed[1:]} | {det} | {a['rmse']:.3f} | {a['max']:.3f} | {a.get('rmse_percent_of_path', float('nan')):.2f} | "
                f"{x['first_init_s']:.2f} | {x['resets']} | {x['frames_estimated']} / {x['frames_in']} | "
                f"{x['ms_per_frame']['total']:.1f} | {x['real_time_factor']:.2f} | {1e3 * (x.get('time_offset_s') or 0):.1f} |")
open("bench/out/euroc_sim.md", "w").write("\n".join(rows) + "\n")
print("\n".join(rows))
PY

#!/usr/bin/env bash
# Why tracks end (issue 15): `drover features track` on short simulated courses and the shared EuRoC snippet with
# the tracker's forward-backward threshold (0.5, 1, 2 px) and RANSAC threshold (1, 2, 3 px) varied, every other key
# as shipped (config/farm_sim.yaml, config/euroc.yaml). Per run: mean finished track length, RANSAC inlier ratio,
# new features per frame, and the finished tracks by why they ended (tracks.json summary.ended_by).
# Courses are generated once into $DROVER_OUT/sim/<course>_len (20 s at 15 Hz, seed 1; `lighting` 30 s).
# Writes bench/out/track_length/<data>_<detector>_fb<F>_r<R>/tracks.json and bench/out/track_length.md.
# Usage: bash bench/track_length.sh [detector ...]   (default: shi-tomasi orb)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${DROVER_BUILD_DIR:-build}
OUT_ROOT=${DROVER_OUT:-out}
DROVER="$BUILD_DIR/apps/drover/drover"
DETECTORS=("$@")
[ ${#DETECTORS[@]} -gt 0 ] || DETECTORS=(shi-tomasi orb)
COURSES=${COURSES:-"straight sharp-turns jolting lighting"}
FB=${FB:-"0.5 1 2"}
RANSAC=${RANSAC:-"1 2 3"}
out=bench/out/track_length
mkdir -p "$out/configs" "$OUT_ROOT/sim"
variant() {  # variant BASE FB R -> config path
  local base=$1 fb=$2 r=$3 file="$out/configs/$(basename "$1" .yaml)_fb${2}_r${3}.yaml"
  sed -e "s/^\(    forward_backward_px:\) [0-9.]*/\1 $fb/" -e "s/^\(    ransac_threshold_px:\) [0-9.]*/\1 $r/" "$base" > "$file"
  echo "$file"
}
for c in $COURSES; do
  data="$OUT_ROOT/sim/${c}_len"
  duration=20
  [ "$c" = lighting ] && duration=30
  [ -f "$data/scenario.json" ] || "$DROVER" sim --scenario "$c" --seed 1 --duration "$duration" --camera-rate 15 \
    --out "$data" --force -q
done
for fb in $FB; do
  for r in $RANSAC; do
    sim_config=$(variant config/farm_sim.yaml "$fb" "$r")
    euroc_config=$(variant config/euroc.yaml "$fb" "$r")
    for d in "${DETECTORS[@]}"; do
      for c in $COURSES; do
        "$DROVER" features track "$OUT_ROOT/sim/${c}_len" --format sim --config "$sim_config" --detector "$d" \
          --out "$out/${c}_${d}_fb${fb}_r${r}" -q
      done
      "$DROVER" features track ../shared/data/euroc/V1_01_easy_micro --format euroc --config "$euroc_config" \
        --detector "$d" --out "$out/euroc_${d}_fb${fb}_r${r}" -q
    done
    echo "== fb $fb ransac $r done"
  done
done
/usr/bin/python3 - "$out" <<'PY'
import glob, json, os, sys
out = sys.argv[1]
causes = ["lost_flow", "rejected_fb", "rejected_border", "rejected_ransac", "dropped_crowded"]
rows = ["| data | detector | fb [px] | RANSAC [px] | mean track length [frames] (finished) | live age [frames] | inliers | new / frame | "
        + " | ".join(f"{c} % (mean len)" for c in causes) + " |", "|---" * (8 + len(causes)) + "|"]
for p in sorted(glob.glob(f"{out}/*/tracks.json")):
    name = os.path.basename(os.path.dirname(p))
    data, det, fb, r = name.rsplit("_", 3)
    s = json.load(open(p))["summary"]
    n = max(1, s["finished_tracks"])
    by = s["ended_by"]
    rows.append(f"| {data} | {det} | {fb[2:]} | {r[1:]} | {s['mean_track_length']:.1f} ({s['finished_tracks']}) | "
                f"{s['mean_live_length']:.1f} | "
                f"{s['ransac_inlier_ratio']:.3f} | {s['mean_new']:.1f} | "
                + " | ".join(f"{100 * by[c]['tracks'] / n:.0f} ({by[c]['mean_length']:.1f})" for c in causes) + " |")
open(f"{out}.md", "w").write("\n".join(rows) + "\n")
print("\n".join(rows))
PY

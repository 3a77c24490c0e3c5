#!/usr/bin/env bash
# The VIS on the simulated courses: alone (--no-lidar: camera + IMU, visual-inertial initialisation) with each
# detector, and beside the LIS (initialised from it, lidar depth) with each depth mode. Drift as tools/course_report.py
# measures it (end error after first-pose alignment / path length) on trajectory_vis.tum, plus the VIS's own APE,
# initialisation time, resets and ms per frame from report.json.
# Courses are generated once per seed (cached in $DROVER_OUT/sim/vis_<course>_s<seed>), cut to $DURATION s.
# Writes bench/out/vis/<course>_s<seed>_<variant>.json and bench/out/vis.md (the table).
# Usage: bash bench/eval_vis.sh [course ...]
#   env: SEEDS="1 2 3"  DETECTORS="shi-tomasi orb superpoint"  DEPTH_MODES="fixed factor off"  DURATION=40
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/sim_cache.sh
BUILD_DIR=${DROVER_BUILD_DIR:-build}
OUT_ROOT=${DROVER_OUT:-out}
DROVER="$BUILD_DIR/apps/drover/drover"
SEEDS=${SEEDS:-1}
DETECTORS=${DETECTORS:-shi-tomasi orb superpoint}
DEPTH_MODES=${DEPTH_MODES:-fixed factor off}
DURATION=${DURATION:-40}
COURSES=("$@")
[ ${#COURSES[@]} -gt 0 ] || COURSES=(straight uphill downhill garage-exit jolting sharp-turns overlap lighting)
mkdir -p bench/out/vis "$OUT_ROOT/sim" "$OUT_ROOT/vis_configs"

# A copy of config/farm_sim.yaml with the detector and the depth mode replaced.
config() {  # detector depth_mode -> path
  local f="$OUT_ROOT/vis_configs/$1_$2.yaml"
  sed -e "s/^    type: superpoint /    type: $1 /" -e "s/^  depth_mode: fixed /  depth_mode: $2 /" \
    config/farm_sim.yaml > "$f"
  echo "$f"
}

run() {  # data name config extra-flags...
  local data=$1 name=$2 cfg=$3
  shift 3
  local out="$OUT_ROOT/runs/vis_$name"
  # A VIS that never initialises leaves trajectory_vis.tum empty and course_report.py refuses it: "no init".
  if "$DROVER" run "$data" --format sim --config "$cfg" --out "$out" --no-loop -q "$@" >/dev/null 2>&1 &&
    /usr/bin/python3 tools/course_report.py "$data" "$out" --trajectory trajectory_vis.tum \
      --json "bench/out/vis/$name.json" >/dev/null 2>&1; then
    /usr/bin/python3 - "$out/report.json" "bench/out/vis/$name.json" <<'PY'
import json, sys
report, course = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
v = report["vis"]
course["vis"] = {k: v.get(k) for k in ("first_init_s", "resets", "keyframes", "ms_per_frame", "mean", "ape",
                                       "frames_in", "frames_estimated", "detector", "depth_mode")}
course["real_time_factor"] = report.get("real_time_factor")
course["wall_s"] = report.get("wall_s")
json.dump(course, open(sys.argv[2], "w"), indent=1)
PY
  else
    echo "{\"failed\": true}" > "bench/out/vis/$name.json"
  fi
}

for seed in $SEEDS; do
  for c in "${COURSES[@]}"; do
    data="$OUT_ROOT/sim/vis_${c}_s$seed"
    course_is_current "$data" config/farm_sim.yaml || "$DROVER" sim --scenario "$c" --seed "$seed" --duration "$DURATION" \
      --config config/farm_sim.yaml --out "$data" --force -q
    for d in $DETECTORS; do run "$data" "${c}_s${seed}_alone_$d" "$(config "$d" fixed)" --no-lidar; done
    for m in $DEPTH_MODES; do run "$data" "${c}_s${seed}_lis_$m" "$(config shi-tomasi "$m")"; done
    echo "== $c seed $seed done"
  done
done
/usr/bin/python3 - <<'PY'
import glob, json, os, collections
rows = collections.OrderedDict()
for p in sorted(glob.glob("bench/out/vis/*.json")):
    name = os.path.basename(p)[:-5]
    course, seed, kind, variant = name.rsplit("_", 3)
    rows.setdefault((course, seed), {})[f"{kind}_{variant}"] = json.load(open(p))
cols = sorted({k for r in rows.values() for k in r}, key=lambda k: (not k.startswith("alone"), k))
head = "| course | seed | path [m] | " + " | ".join(c.replace("_", " ") + " [%]" for c in cols) + " |"
out = [head, "|" + "---|" * (3 + len(cols))]
for (course, seed), r in rows.items():
    any_ok = next((x for x in r.values() if not x.get("failed")), {})
    cells = []
    for c in cols:
        x = r.get(c)
        if x is None: cells.append("-")
        elif x.get("failed"): cells.append("no init")
        else:
            # A VIS that reset and did not re-initialise (or initialised late) is measured over what it estimated:
            # say how much that was, or a short stretch reads as a small drift.
            v = x["vis"]
            share = v["frames_estimated"] / v["frames_in"] if v.get("frames_in") else 1.0
            notes = (["%d resets" % v["resets"]] if v["resets"] else []) + (["%.0f %% of frames" % (100 * share)] if share < 0.85 else [])
            cells.append("%.2f" % x["drift_percent"] + (" (%s)" % ", ".join(notes) if notes else ""))
    out.append(f"| {course} | {seed[1:]} | {any_ok.get('path_length_m', 0):.0f} | " + " | ".join(cells) + " |")
ms = collections.defaultdict(list)
for r in rows.values():
    for c, x in r.items():
        if not x.get("failed"): ms[c].append((x["vis"]["ms_per_frame"], x.get("real_time_factor") or 0))
out += ["", "| variant | track ms | depth ms | solve ms | marginalize ms | total ms | real-time factor |", "|---|---|---|---|---|---|---|"]
for c in cols:
    if not ms[c]: continue
    n = len(ms[c]); avg = lambda k: sum(m[0][k] for m in ms[c]) / n
    out.append(f"| {c.replace('_', ' ')} | {avg('track'):.1f} | {avg('depth'):.1f} | {avg('solve'):.1f} | "
               f"{avg('marginalize'):.1f} | {avg('total'):.1f} | {sum(m[1] for m in ms[c]) / n:.2f} |")
open("bench/out/vis.md", "w").write("\n".join(out) + "\n")
print("\n".join(out))
PY

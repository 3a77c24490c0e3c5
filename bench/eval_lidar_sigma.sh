#!/usr/bin/env bash
# How the lidar pose's sigma in the IMU smoother (odometry.lidar_sigma_position [m] / lidar_sigma_rotation [rad])
# decides the LIS's drift on simulated courses (issue 4's farm bound). For each pair below, config/farm_sim.yaml with
# those two keys set runs `drover run --no-loop --no-camera` (lidar + IMU, the LIS alone) on each dataset folder,
# and tools/course_report.py gives drift and the per-segment figures. Writes bench/out/lidar_sigma.md.
# Usage: bash bench/eval_lidar_sigma.sh [dataset ...]   (default: out/sim/farm, which scripts/run.sh generates)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${DROVER_BUILD_DIR:-build}
OUT_ROOT=${DROVER_OUT:-out}
DROVER="$BUILD_DIR/apps/drover/drover"
DATASETS=("$@")
[ ${#DATASETS[@]} -gt 0 ] || DATASETS=("$OUT_ROOT/sim/farm")
SIGMAS=("0.05 0.05" "0.05 0.002" "0.02 0.002" "0.01 0.002" "0.005 0.002")
mkdir -p bench/out/lidar_sigma
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for pair in "${SIGMAS[@]}"; do
  read -r pos rot <<<"$pair"
  cfg="$tmp/sigma_${pos}_${rot}.yaml"
  # Drop the keys if the config sets them, then put the pair first in the odometry: section.
  sed -e '/^  lidar_sigma_position:/d' -e '/^  lidar_sigma_rotation:/d' \
    -e "s/^odometry:\$/odometry:\n  lidar_sigma_position: $pos\n  lidar_sigma_rotation: $rot/" config/farm_sim.yaml >"$cfg"
  [ "$(grep -c "^  lidar_sigma_position: $pos\$" "$cfg")" = 1 ] || { echo "could not set the sigmas in $cfg" >&2; exit 1; }
  for data in "${DATASETS[@]}"; do
    name="$(basename "$data")_${pos}_${rot}"
    run="$OUT_ROOT/runs/sigma_$name"
    "$DROVER" run "$data" --format sim --config "$cfg" --out "$run" -q --no-loop --no-camera >/dev/null
    /usr/bin/python3 tools/course_report.py "$data" "$run" --json "bench/out/lidar_sigma/$name.json" >/dev/null
    echo "== $name done"
  done
done
SIGMAS_LIST="${SIGMAS[*]}" /usr/bin/python3 - "${DATASETS[@]}" <<'PY'
import json, os, sys
v = os.environ["SIGMAS_LIST"].split()
sigmas = list(zip(v[0::2], v[1::2]))
out = ["| dataset | sigma position [m] | sigma rotation [rad] | drift [% of path] | end error [m] | worst segment |",
       "|---|---|---|---|---|---|"]
for data in sys.argv[1:]:
    for pos, rot in sigmas:
        r = json.load(open(f"bench/out/lidar_sigma/{os.path.basename(data)}_{pos}_{rot}.json"))
        segs = r.get("segments", [])
        worst = max(segs, key=lambda s: s["translation_error_percent"], default=None)
        w = f"{worst['condition']} {worst['translation_error_percent']:.2f} %" if worst else "-"
        out.append(f"| {os.path.basename(data)} | {pos} | {rot} | {r['drift_percent']:.2f} | {r['end_error_m']:.3f} | {w} |")
open("bench/out/lidar_sigma.md", "w").write("\n".join(out) + "\n")
print("\n".join(out))
PY

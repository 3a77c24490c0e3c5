#!/usr/bin/env bash
# drover run --realtime on the simulated farm course (10 min of data: the run takes 10 min): the live system at sensor
# rate with the LIS and loop closure, as a robot would feed it. Prints report.json's "realtime" section (latency per
# output, sweeps dropped) and the loops accepted next to the deterministic replay's, for bench/RESULTS.md.
# Run it on a quiet machine: a build beside it takes the cores the LIS needs and the latencies say so.
#   bash bench/realtime.sh                      # farm course, seed 1
#   COURSE=overlap SEED=3 bash bench/realtime.sh
#   COURSE=kitti05-replay bash bench/realtime.sh  # the car (config/car_sim.yaml; needs ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
DROVER=${DROVER:-build/apps/drover/drover}
COURSE=${COURSE:-farm}
SEED=${SEED:-1}
# The car has its own platform file (the farm's sensors, LIO-SAM's outdoor map leaf); every farm course the farm's.
. scripts/sim_cache.sh
CONFIG=${CONFIG:-$(platform_config "$COURSE")}
OUT=${OUT:-bench/out/realtime}
DATA="$OUT/sim_${COURSE}_${SEED}"
mkdir -p "$OUT"
[ -f "$DATA/calibration.yaml" ] || "$DROVER" sim --scenario "$COURSE" --seed "$SEED" --config "$CONFIG" \
  --no-camera --out "$DATA" --force -q
"$DROVER" run "$DATA" --format sim --config "$CONFIG" --out "$OUT/${COURSE}_${SEED}_realtime" \
  --no-camera --realtime -q
"$DROVER" run "$DATA" --format sim --config "$CONFIG" --out "$OUT/${COURSE}_${SEED}_replay" --no-camera -q
/usr/bin/python3 - "$OUT/${COURSE}_${SEED}_realtime/report.json" "$OUT/${COURSE}_${SEED}_replay/report.json" <<'PY'
import json, sys
rt, rp = (json.load(open(p)) for p in sys.argv[1:3])
r = rt["realtime"]
lat = r["latency_ms"]
print(f"realtime: {r['sweeps_pushed']} sweeps pushed, {r['sweeps_dropped']} dropped; loops applied {r['loops_applied']}")
for k in ("sweep", "imu_rate"):
    print(f"  latency {k:8s} p50 {lat[k]['p50']:.3f}  p95 {lat[k]['p95']:.3f}  max {lat[k]['max']:.3f} ms "
          f"({lat[k]['count']} outputs)")
print(f"  first sweep {r['first_sweep_ms']:.0f} ms (IMU initialisation window); replay pushes late by at most "
      f"{r['push_late_ms_max']:.1f} ms")
def loops(rep):
    return [(e["query"], e["candidate"]) for e in rep["loops"].get("events", []) if e.get("accepted")]
a, b = loops(rp), loops(rt)
print(f"loops accepted: replay {len(a)}, realtime {len(b)}; same queries: {[q for q, _ in a] == [q for q, _ in b]}; "
      f"candidates within one keyframe: {len(a) == len(b) and all(abs(x[1] - y[1]) <= 1 for x, y in zip(a, b))}")
print(f"APE rmse: replay {rp['ape'].get('rmse', float('nan')):.3f} m, realtime {rt['ape'].get('rmse', float('nan')):.3f} m")
PY

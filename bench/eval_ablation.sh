#!/usr/bin/env bash
# The ablation of the LVI fusion (the LVI-SAM paper's Table 4 columns): rows LIS only, VIS only, the lvi-sam and
# drover presets, and drover without each of its parts in turn; columns the simulated courses (the camera on).
# Per run: the translation APE (max, min, std, median, mean, rmse; SE(3)-aligned as evo), the drift of the path's
# end (first-pose aligned, tools/course_report.py) and the end-point gap of closed courses. Writes
# bench/out/ablation/<course>/<row>.json, bench/out/ablation.md (the table) and bench/out/ablation_ape_<course>.png
# (APE over time of the two presets, as the paper's Fig. 11).
# Usage: bash bench/eval_ablation.sh            (all rows on corridor white-walls lighting farm farm-2 farm-3)
#   ABLATION_COURSES="corridor farm" ABLATION_ROWS="lis lvi-sam drover" bash bench/eval_ablation.sh
#   ABLATION_LOOPS=0: without loop closure (the default runs with it).
#   ABLATION_DROVER_EXTRA="--without superpoint": appended to the vis row and every drover row (Shi-Tomasi rows:
#   the farm course takes ~6.5 min a row instead of ~9.5). The row drover+superpoint is the whole preset regardless,
#   drover+superpoint-PART the whole preset without PART (drover+superpoint-lk-min-eigenvalue: SuperPoint's tracks at
#   the platform's LK threshold).
# Courses are generated once into $DROVER_OUT/sim/<course>-cam (<scenario>-N, e.g. farm-2: seed N; kitti05-replay
# needs ../shared/data and ~14 GB with its camera). Runs are kept in $DROVER_OUT/ablation/<course>/<row>.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/sim_cache.sh
BUILD_DIR=${DROVER_BUILD_DIR:-build}
OUT_ROOT=${DROVER_OUT:-out}
DROVER="$BUILD_DIR/apps/drover/drover"
read -r -a COURSES <<< "${ABLATION_COURSES:-corridor white-walls lighting farm farm-2 farm-3}"
read -r -a ROWS <<< "${ABLATION_ROWS:-lis vis lvi-sam drover drover-vo-factor drover-vis-guess drover-vis-gates drover-keyframe-gap-speed drover-visual-yaw-prior drover-scan-context drover-radius-search drover-four-dof drover-loop-fitness-sigma drover-vis-carried-sigma drover-depth-factor drover-superpoint drover-lk-min-eigenvalue drover-keyframe-interval drover-lidar-rotation-sigma}"
read -r -a EXTRA <<< "${ABLATION_DROVER_EXTRA:-}"
LOOP_FLAG=()
[ "${ABLATION_LOOPS:-1}" = 1 ] || LOOP_FLAG=(--no-loop)

row_flags() {  # the drover run options of a row
  case "$1" in
    lis) echo "--no-camera" ;;
    vis) echo "--no-lidar ${EXTRA[*]}" ;;  # the same front end as the drover rows
    lvi-sam) echo "--preset lvi-sam" ;;
    drover) echo "--preset drover ${EXTRA[*]}" ;;
    drover+superpoint) echo "--preset drover" ;;  # the whole preset, whatever ABLATION_DROVER_EXTRA says
    drover+superpoint-*) echo "--preset drover --without ${1#drover+superpoint-}" ;;  # the whole preset without a part
    drover-*) echo "--preset drover --without ${1#drover-} ${EXTRA[*]}" ;;
    *) echo "unknown row $1" >&2; exit 2 ;;
  esac
}

mkdir -p bench/out/ablation "$OUT_ROOT/sim"
for c in "${COURSES[@]}"; do
  scenario=$c seed=1
  case "${c##*-}" in ''|*[!0-9]*) ;; *) scenario=${c%-*} seed=${c##*-} ;; esac  # farm-2, white-walls-3: seed N
  data="$OUT_ROOT/sim/$c-cam"
  CONFIG=${ABLATION_CONFIG:-$(platform_config "$c")}
  course_is_current "$data" "$CONFIG" ||
    "$DROVER" sim --scenario "$scenario" --seed "$seed" --config "$CONFIG" --out "$data" --force -q
  mkdir -p "bench/out/ablation/$c" "$OUT_ROOT/ablation/$c"
  for row in "${ROWS[@]}"; do
    run="$OUT_ROOT/ablation/$c/$row"
    read -r -a flags <<< "$(row_flags "$row")"
    start=$(date +%s)
    if ! "$DROVER" run "$data" --format sim --config "$CONFIG" --out "$run" -q "${LOOP_FLAG[@]}" "${flags[@]}" \
        > "$OUT_ROOT/ablation/$c/$row.log" 2>&1; then
      echo "== $c $row: FAILED (see $OUT_ROOT/ablation/$c/$row.log)"
      continue
    fi
    /usr/bin/python3 tools/course_report.py "$data" "$run" --json "bench/out/ablation/$c/$row.course.json" >/dev/null
    cp "$run/report.json" "bench/out/ablation/$c/$row.report.json"
    echo "== $c $row: $(( $(date +%s) - start )) s"
  done
done
/usr/bin/python3 tools/ablation_table.py bench/out/ablation "$OUT_ROOT/sim" bench/out

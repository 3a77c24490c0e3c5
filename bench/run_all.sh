#!/usr/bin/env bash
# Runs every micro-benchmark, keeps the raw output in bench/out/ and rewrites the generated table of
# bench/RESULTS.md (the hand-written sections stay). Usage: bash bench/run_all.sh [build-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${1:-${DROVER_BUILD_DIR:-build}}
mkdir -p bench/out
for b in "$BUILD_DIR"/bench/bench_*; do
  [ -x "$b" ] || continue
  name=$(basename "$b")
  echo "== $name"
  "$b" --benchmark_min_time=0.5 --benchmark_out="bench/out/$name.json" --benchmark_out_format=json \
    | tee "bench/out/$name.txt"
done
/usr/bin/python3 bench/summarize.py bench/RESULTS.md bench/out
echo "bench/RESULTS.md updated"

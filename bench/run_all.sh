#!/usr/bin/env bash
# Runs every micro-benchmark and writes the raw output to bench/out/; copy the figures into bench/RESULTS.md
# together with this command and the machine. Usage: bash bench/run_all.sh [build-dir]
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

#!/usr/bin/env bash
# The whole test suite: installs what is missing, builds, runs every test. Non-zero exit when any test fails.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
BUILD_DIR=${DROVER_BUILD_DIR:-build}
if [ ! -d ../shared/data ]; then
  echo "NOTE: ../shared/data is absent: tests on real data will be skipped"
fi
ctest --test-dir "$BUILD_DIR" -j "$(nproc)" --output-on-failure --timeout 900

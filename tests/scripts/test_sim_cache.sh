#!/usr/bin/env bash
# scripts/sim_cache.sh's course_is_current: a cached course whose frames were rendered with other camera rays than
# the config asks for (rays a pixel, texture filter, edge rays) is stale, and a course from before a key counts as
# rendered with that key's default. Usage: test_sim_cache.sh SOURCE_DIR
set -u
. "$1/scripts/sim_cache.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
check() {  # expected(current|stale) description
  local got=stale
  course_is_current "$tmp/course" "$tmp/config.yaml" && got=current
  [ "$got" = "$1" ] || { echo "FAIL: $2: $got, expected $1"; failures=$((failures + 1)); }
}
course() {  # calibration.yaml's camera lines
  mkdir -p "$tmp/course/camera"
  echo '{}' > "$tmp/course/scenario.json"
  printf 'timestamp [ns],filename\n0,000000.png\n' > "$tmp/course/camera/timestamps.csv"
  printf 'sensors:\n  camera:\n    rate_hz: 15\n%b' "$1" > "$tmp/course/calibration.yaml"
}
config() { printf 'sim:\n  camera_rate_hz: 15\n%b' "$1" > "$tmp/config.yaml"; }

course '    pixel_samples: 2\n    texture_filter: true\n    edge_pixel_samples: 4\n'
config '  camera_pixel_samples: 2   # comment\n  camera_texture_filter: true\n  camera_edge_pixel_samples: 4\n'
check current "the same rays"
config '  camera_pixel_samples: 2\n  camera_texture_filter: true\n  camera_edge_pixel_samples: 0\n'
check stale "edge rays rendered, none asked for"
config '  camera_pixel_samples: 2\n  camera_texture_filter: true\n'
check stale "edge rays rendered, the key absent from the config (off)"
config '  camera_pixel_samples: 2\n  camera_texture_filter: false\n  camera_edge_pixel_samples: 4\n'
check stale "filtered textures rendered, unfiltered asked for"
config '  camera_pixel_samples: 3\n  camera_texture_filter: true\n  camera_edge_pixel_samples: 4\n'
check stale "2 x 2 rays rendered, 3 x 3 asked for"
course '    pixel_samples: 2\n'
config '  camera_pixel_samples: 2\n  camera_texture_filter: false\n  camera_edge_pixel_samples: 0\n'
check current "a course from before the filter and edge rays, asked for without them"
config '  camera_pixel_samples: 2\n  camera_edge_pixel_samples: 3\n'
check stale "a course from before edge rays, asked for with them"
rm "$tmp/course/scenario.json"
check stale "an unfinished course (no scenario.json)"
[ "$failures" -eq 0 ] && echo "all course cache checks passed"
exit $((failures > 0))

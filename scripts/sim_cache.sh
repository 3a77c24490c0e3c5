# Sourced by scripts/run.sh and the bench/ scripts that keep simulated courses between runs.
# course_is_current DIR CONFIG: DIR holds a whole simulated course, and its camera frames (if it has any) were
# rendered with CONFIG's rays a pixel and texture filter (sim.camera_pixel_samples, sim.camera_texture_filter; a
# course's calibration.yaml records them under sensors.camera.pixel_samples / texture_filter, and courses from before
# the keys have one ray and no filter). A stale course would silently give other figures than the README's.
course_is_current() {
  local dir=$1 config=$2 want have
  [ -f "$dir/scenario.json" ] && [ -f "$dir/calibration.yaml" ] || return 1
  [ -f "$dir/camera/timestamps.csv" ] && [ "$(wc -l < "$dir/camera/timestamps.csv")" -gt 1 ] || return 0
  want=$(sed -n 's/^ *camera_pixel_samples: *\([0-9][0-9]*\).*/\1/p' "$config")
  have=$(sed -n 's/^    pixel_samples: *\([0-9][0-9]*\).*/\1/p' "$dir/calibration.yaml")
  [ "${want:-1}" = "${have:-1}" ] || return 1
  want=$(sed -n 's/^ *camera_texture_filter: *\([a-z]*\).*/\1/p' "$config")
  have=$(sed -n 's/^    texture_filter: *\([a-z]*\).*/\1/p' "$dir/calibration.yaml")
  [ "${want:-false}" = "${have:-false}" ]
}

# platform_config COURSE: the platform file a course runs with: the car's for kitti05-replay, the farm's otherwise
# (both have the same sim: section, so either renders the same data).
platform_config() {
  if [ "$1" = kitti05-replay ]; then echo config/car_sim.yaml; else echo config/farm_sim.yaml; fi
}

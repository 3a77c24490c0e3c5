# Sourced by scripts/run.sh and the bench/ scripts that keep simulated courses between runs.
# course_is_current DIR CONFIG: DIR holds a whole simulated course, and its camera frames (if it has any) were
# rendered with CONFIG's camera rays (sim.camera_pixel_samples, sim.camera_texture_filter,
# sim.camera_edge_pixel_samples; a course's calibration.yaml records them under sensors.camera.pixel_samples /
# texture_filter / edge_pixel_samples, and courses from before a key have its default: one ray, no filter, no edge
# rays). A stale course would silently give other figures than the README's.
course_is_current() {
  local dir=$1 config=$2 key default want have
  [ -f "$dir/scenario.json" ] && [ -f "$dir/calibration.yaml" ] || return 1
  [ -f "$dir/camera/timestamps.csv" ] && [ "$(wc -l < "$dir/camera/timestamps.csv")" -gt 1 ] || return 0
  for key in pixel_samples:1 texture_filter:false edge_pixel_samples:0; do
    default=${key#*:}
    key=${key%%:*}
    want=$(sed -n "s/^ *camera_$key: *\([0-9a-z]*\).*/\1/p" "$config")
    have=$(sed -n "s/^    $key: *\([0-9a-z]*\).*/\1/p" "$dir/calibration.yaml")
    [ "${want:-$default}" = "${have:-$default}" ] || return 1
  done
}

# platform_config COURSE: the platform file a course runs with: the car's for kitti05-replay, the farm's otherwise
# (both have the same sim: section, so either renders the same data).
platform_config() {
  if [ "$1" = kitti05-replay ]; then echo config/car_sim.yaml; else echo config/farm_sim.yaml; fi
}

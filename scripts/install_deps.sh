#!/usr/bin/env bash
# Installs the Debian packages Drover needs that are missing. The one list of packages lives here.
# Why each: see README "Dependencies". Runs apt-get only when something is missing.
set -euo pipefail
PACKAGES=(
  build-essential cmake ccache pkg-config
  libeigen3-dev libceres-dev libsuitesparse-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-video-dev libopencv-features2d-dev
  libopencv-calib3d-dev libopencv-dnn-dev libopencv-imgcodecs-dev
  libtbb-dev libnanoflann-dev libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libbz2-dev liblz4-dev
  python3-matplotlib python3-numpy python3-rosbag python3-roslz4 python3-onnx
  libroscpp-dev libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev libvisualization-msgs-dev libstd-srvs-dev
  libtf2-ros-dev python3-rosmaster python3-roslaunch rosout
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"

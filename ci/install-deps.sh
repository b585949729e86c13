#!/usr/bin/env bash
# Installs the Debian packages rovo needs. Idempotent: packages that are already present are left
# alone, so a second run costs one dpkg query.
# Usage: ci/install-deps.sh [build|plots|all]   (default all)
#   build: what configuring and building rovo need (ci/demo.sh installs these before it builds). OpenCV
#          comes as the modules rovo uses (and imgcodecs, the tests' independent image codecs), not
#          libopencv-dev, which pulls every module (VTK, contrib, dnn); image files go through libpng and
#          OpenEXR; ccache is left out: a first build gains nothing from an empty cache.
#   plots: Python's matplotlib, for the plots of report.html (ci/demo.sh installs it after the table).
#   all:   build and plots, and what the tests use: ccache, lint tools,
#          Blender (exporter and Cycles cross-checks) with oiiotool (reads Cycles' EXRs), Chromium (report screenshots), Slurm (batch tests),
#          COLMAP (the third-party system of the suite tests).
set -euo pipefail
what=${1:-all}

BUILD=(
  build-essential cmake ninja-build git
  libembree-dev libtbb-dev
  libpng-dev libjpeg-dev libopenexr-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-features2d-dev libopencv-video-dev libopencv-calib3d-dev
  libopencv-imgcodecs-dev
  libeigen3-dev libceres-dev libopengv-dev
  nlohmann-json3-dev libyaml-cpp-dev libcli11-dev libfastcdr-dev zlib1g-dev libdeflate-dev
  libgtest-dev libgmock-dev libbenchmark-dev
)
PLOTS=(python3 python3-matplotlib)
case "$what" in
  build) PACKAGES=("${BUILD[@]}") ;;
  plots) PACKAGES=("${PLOTS[@]}") ;;
  all)
    PACKAGES=("${BUILD[@]}" "${PLOTS[@]}" ccache pkg-config python3-numpy python3-yaml
              clang-format clang-tidy blender openimageio-tools chromium slurm-wlm munge colmap)
    ;;
  *) echo "install-deps: unknown set '$what' (build, plots or all)" >&2; exit 2 ;;
esac

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"

#!/usr/bin/env bash
# Installs the Debian packages rovo needs. Idempotent: packages that are already present are left
# alone, so a second run costs one dpkg query.
# Usage: ci/install-deps.sh [demo|all]   (default all)
#   demo: what building rovo and running `rovo demo` need (ci/demo.sh);
#   all:  also what the tests use: lint tools, Blender (exporter and Cycles cross-checks), Chromium
#         (report screenshots), Slurm (batch tests), COLMAP (the third-party system of the suite tests).
set -euo pipefail
what=${1:-all}

PACKAGES=(
  build-essential cmake ninja-build pkg-config git ccache
  libembree-dev libtbb-dev
  libopenimageio-dev openimageio-tools
  libopencv-dev
  libeigen3-dev libceres-dev libopengv-dev
  nlohmann-json3-dev libyaml-cpp-dev libcli11-dev libfastcdr-dev zlib1g-dev libdeflate-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-matplotlib python3-numpy python3-yaml
)
case "$what" in
  demo) ;;
  all) PACKAGES+=(clang-format clang-tidy blender chromium slurm-wlm munge colmap) ;;
  *) echo "install-deps: unknown set '$what' (demo or all)" >&2; exit 2 ;;
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

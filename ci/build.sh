#!/usr/bin/env bash
# Configures and builds rovo (Release, warnings as errors) into build/. Incremental.
# Usage: ci/build.sh [TARGET...]   (default: everything; e.g. `ci/build.sh rovo` for the executable only)
# ROVO_BUILD_UNIT_TESTS=OFF leaves the unit tests and fuzz replays out (ci/test.sh runs them in its
# sanitizer build); every other call builds them again.
# ROVO_UNITY_BUILD=ON compiles each library's sources in batches of 16 (CMake's unity build): the
# headers (Eigen, OpenCV, Ceres, CLI11) are parsed, and their shared templates compiled, once per batch
# instead of once per source, which cuts the clean build of the `rovo` executable (ci/demo.sh) 2.4×
# (docs/design-notes.md, section CI time). Off by default: clang-tidy (ci/lint.sh) needs a compile
# command per source, which a unity build does not write.
set -euo pipefail
cd "$(dirname "$0")/.."
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DROVO_WERROR=ON \
  -DROVO_BUILD_UNIT_TESTS="${ROVO_BUILD_UNIT_TESTS:-ON}" -DCMAKE_UNITY_BUILD="${ROVO_UNITY_BUILD:-OFF}" \
  -DCMAKE_UNITY_BUILD_BATCH_SIZE=16 "${launcher[@]}" >/dev/null
targets=()
for target in "$@"; do targets+=(--target "$target"); done
cmake --build build -j"$(nproc)" "${targets[@]}"

#!/usr/bin/env bash
# Configures and builds rovo (Release, warnings as errors) into build/. Incremental.
# Usage: ci/build.sh [TARGET...]   (default: everything; e.g. `ci/build.sh rovo` for the executable only)
# ROVO_BUILD_UNIT_TESTS=OFF leaves the unit tests and fuzz replays out (ci/test.sh runs them in its
# sanitizer build); every other call builds them again.
set -euo pipefail
cd "$(dirname "$0")/.."
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DROVO_WERROR=ON \
  -DROVO_BUILD_UNIT_TESTS="${ROVO_BUILD_UNIT_TESTS:-ON}" "${launcher[@]}" >/dev/null
targets=()
for target in "$@"; do targets+=(--target "$target"); done
cmake --build build -j"$(nproc)" "${targets[@]}"

#!/usr/bin/env bash
# The test command: installs dependencies, builds, checks formatting and lint (ci/lint.sh), runs every ctest
# test (unit + integration),
# then rebuilds the unit tests with AddressSanitizer + UndefinedBehaviorSanitizer and runs them.
# Set ROVO_SKIP_SANITIZERS=1 to skip the sanitizer pass locally.
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
bash ci/build.sh
bash ci/lint.sh     # clang-format and clang-tidy (bugprone-*, performance-*): any finding fails
ctest --test-dir build --output-on-failure -j2 --timeout 1500

if [ "${ROVO_SKIP_SANITIZERS:-0}" != "1" ]; then
  echo "== unit tests under ASan + UBSan =="
  launcher=()
  if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DROVO_SANITIZE=ON -DROVO_WERROR=ON \
    -DROVO_BUILD_BENCHMARKS=OFF "${launcher[@]}" >/dev/null
  cmake --build build-asan -j"$(nproc)"
  ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan -L unit --output-on-failure -j2 --timeout 1500
fi

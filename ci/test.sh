#!/usr/bin/env bash
# The test command: installs dependencies, builds, checks formatting and lint (ci/lint.sh), runs the
# integration tests (and every other test not labelled unit) on the Release build, then builds the
# unit tests with AddressSanitizer + UndefinedBehaviorSanitizer (-O1, line tables) and runs them there:
# every test is built and run once, the unit tests where the sanitizers watch them.
# Set ROVO_SKIP_SANITIZERS=1 to run the unit tests on the Release build instead.
set -euo pipefail
cd "$(dirname "$0")/.."
# The demo's package set (ci/demo.sh builds with nothing else) must be enough to configure the project: on a new
# machine this configure runs before the test tools are installed.
bash ci/install-deps.sh build
rm -rf build-setup-check
cmake -S . -B build-setup-check -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
rm -rf build-setup-check
bash ci/install-deps.sh
if [ "${ROVO_SKIP_SANITIZERS:-0}" = "1" ]; then
  bash ci/build.sh
else
  ROVO_BUILD_UNIT_TESTS=OFF bash ci/build.sh   # the unit tests are built and run in build-asan below
fi
bash ci/lint.sh     # clang-format and clang-tidy (bugprone-*, performance-*): any finding fails
# ctest starts the longest tests first when it knows their times: tests/ctest-costs.txt (seconds per
# GoogleTest suite, from a run on this kind of machine) seeds its record on a fresh checkout.
for tree in build build-asan; do
  if [ ! -f $tree/Testing/Temporary/CTestCostData.txt ]; then
    mkdir -p $tree/Testing/Temporary && cp tests/ctest-costs.txt $tree/Testing/Temporary/CTestCostData.txt
  fi
done
ctest --test-dir build -LE unit --output-on-failure -j2 --timeout 1500

if [ "${ROVO_SKIP_SANITIZERS:-0}" = "1" ]; then
  ctest --test-dir build -L unit --output-on-failure -j2 --timeout 1500
  exit 0
fi

echo "== unit tests under ASan + UBSan =="
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
# -O1 -g1: the optimisation ASan's documentation recommends, with line tables for the reports; half the
# compile time of -O2 -g with both sanitizers. Warnings are errors in the Release build above; here they
# are only shown (-O1 changes which of GCC's flow-based warnings fire, not what the code does).
# The libraries and the executable are compiled as a unity build (as ci/demo.sh builds them), the tests
# one source at a time: both ways of building are checked here.
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DROVO_SANITIZE=ON -DROVO_WERROR=OFF -DROVO_BUILD_BENCHMARKS=OFF -DCMAKE_UNITY_BUILD=ON \
  -DCMAKE_UNITY_BUILD_BATCH_SIZE=16 "${launcher[@]}" >/dev/null
cmake --build build-asan -j"$(nproc)"
ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan -L unit --output-on-failure -j2 --timeout 1500

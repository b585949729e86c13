#!/usr/bin/env bash
# The main job: installs what building rovo needs (not the test tools), builds only the `rovo` executable (not
# the tests and benchmarks; a unity build, ci/build.sh), renders the small default dataset, runs GTExt,
# NoisyExt and OnlineExt on it and prints the Table-I-style table; then installs matplotlib and writes
# out/demo/report.html with its plots (the suite resumes: nothing is rendered or run again).
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh build
ROVO_UNITY_BUILD=ON bash ci/build.sh rovo
./build/eval/rovo demo --out out/demo --no-plots "$@"
for arg in "$@"; do [ "$arg" = "--no-plots" ] && exit 0; done
# Without matplotlib (no network, say) rovo writes the report without its plots.
bash ci/install-deps.sh plots || echo "demo: matplotlib not installed; the report will have no plots" >&2
./build/eval/rovo demo --out out/demo "$@" | tail -n 2   # the report: where it is (the table is above)

#!/usr/bin/env bash
# The main job: installs the dependencies it needs (not the test tools), builds only the `rovo` executable (not the tests and
# benchmarks; a unity build, ci/build.sh),
# renders the small default dataset, runs GTExt, NoisyExt and OnlineExt on it, prints the Table-I-style
# table and writes out/demo/report.html.
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh demo
ROVO_UNITY_BUILD=ON bash ci/build.sh rovo
./build/eval/rovo demo --out out/demo "$@"

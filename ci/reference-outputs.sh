#!/usr/bin/env bash
# reference-outputs.sh ROVO OUT: renders, runs, exports, scores and studies a fixed set of small cases with
# the binary ROVO into OUT, to compare two builds output for output with ci/compare-outputs.py. A change
# meant to keep behaviour (a refactoring) leaves every output equal apart from timing fields and paths.
# About 3 CPU-minutes. Each command's console output goes to OUT/<case>.log.
set -euo pipefail
if [ $# -ne 2 ]; then
  echo "usage: ci/reference-outputs.sh ROVO OUT" >&2
  exit 2
fi
rovo=$1
out=$2
mkdir -p "$out"
run() {  # run LOG ARGS...: one rovo command, its output in OUT/LOG.log
  local log=$1
  shift
  "$rovo" "$@" >"$out/$log.log" 2>&1 || { echo "reference-outputs: rovo $* failed (see $out/$log.log)" >&2; exit 1; }
}
run render_cloudy render --preset cloudy_urban --quick --frames 0:30 --depth --masks --seed 3 --out "$out/cloudy"
run render_indoor render --preset indoor_hall --quick --frames 0:3 --realistic --out "$out/indoor"
run scene scene generate --preset night_street --quick --out "$out/scene_night"
run validate dataset validate "$out/cloudy"
run info dataset info "$out/cloudy"
for format in euroc kalibr basalt; do
  run "exp_$format" dataset export "$out/cloudy" --format "$format" --out "$out/exp_$format"
done
run vo_gt vo "$out/cloudy" --extrinsics gt --threads 2 --quiet --out "$out/run_gt"
run vo_noisy vo "$out/cloudy" --extrinsics noisy --threads 2 --quiet --out "$out/run_noisy"
run vo_online vo "$out/cloudy" --extrinsics online --draw-seed 9100 --threads 2 --quiet --out "$out/run_online"
run eval eval "$out/cloudy" "$out/run_gt" "$out/run_online" --no-plots --out "$out/eval"
run study_projection study projection "$out/cloudy" --out "$out/study_projection"
run suite suite --presets cloudy_urban --quick --frames 25 --seeds 1 --vo-threads 2 --no-plots \
  --data "$out/suite_data" --out "$out/suite"
for command in vo render suite "dataset export"; do
  # shellcheck disable=SC2086
  "$rovo" $command --help >"$out/help_${command// /_}.txt"
done
echo "reference-outputs: $out"

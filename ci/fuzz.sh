#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz with clang (ASan + UBSan) into build-fuzz/ and runs each
# for a budget (docs/fuzzing.md). Not part of ci/test.sh, which replays the committed corpora only.
# Usage: ci/fuzz.sh [BUDGET] [TARGET...]
#   BUDGET: seconds per target (e.g. 600), or executions per target with a trailing r (e.g. 1000000r);
#           default 60. TARGET: names of tests/fuzz/<name>_fuzz.cc (default: all).
# New inputs go to build-fuzz/corpus/<target>/ (the committed tests/fuzz/corpus/<target>/ is read, not
# written); crashes to build-fuzz/findings/<target>/. Runs under `nice -n 10`, one target at a time.
# Exits non-zero when a target reports a finding.
set -euo pipefail
cd "$(dirname "$0")/.."
budget="${1:-60}"
shift || true

# clang and libFuzzer (libclang_rt.fuzzer-*.a) from Debian.
if ! command -v clang++ >/dev/null 2>&1 || ! clang++ -print-file-name=libclang_rt.fuzzer-x86_64.a | grep -q /; then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  echo "fuzz: installing clang and libclang-rt-dev"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends clang libclang-rt-dev >/dev/null
fi

launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_COMPILER=clang++ -DROVO_FUZZ=ON -DROVO_BUILD_TESTS=OFF -DROVO_BUILD_BENCHMARKS=OFF \
  "${launcher[@]}" >/dev/null
nice -n 10 cmake --build build-fuzz -j"$(nproc)" --target rovo_fuzz_all

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for f in tests/fuzz/*_fuzz.cc; do
    name="$(basename "$f" _fuzz.cc)"
    targets+=("$name")
  done
fi
if [[ "$budget" == *r ]]; then limit=(-runs="${budget%r}"); else limit=(-max_total_time="$budget"); fi

status=0
for t in "${targets[@]}"; do
  work="build-fuzz/corpus/$t" findings="build-fuzz/findings/$t"
  mkdir -p "$work" "$findings"
  echo "== fuzz $t (${limit[*]})"
  # -timeout: an input that takes 10 s is a hang; -rss_limit_mb also bounds single allocations.
  set +e
  ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 \
    nice -n 10 "build-fuzz/tests/fuzz/rovo_fuzz_$t" "${limit[@]}" -timeout=10 -rss_limit_mb=2048 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="$findings/" "$work" "tests/fuzz/corpus/$t" \
    >"build-fuzz/fuzz-$t.log" 2>&1
  rc=$?
  set -e
  grep -E "^(#[0-9]+ +(INITED|DONE)|stat::number_of_executed_units|stat::average_exec_per_sec|==[0-9]+==ERROR|SUMMARY|fuzz finding)" \
    "build-fuzz/fuzz-$t.log" || true
  if [ "$rc" != "0" ]; then
    echo "fuzz $t: FINDING (exit $rc; see build-fuzz/fuzz-$t.log and $findings/)"
    status=1
  fi
done
exit $status

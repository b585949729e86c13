#!/usr/bin/env bash
# Formatting and static analysis, as CI runs them (after ci/build.sh, which writes
# build/compile_commands.json):
#   clang-format: every C++ file under the parts and tests must be formatted (.clang-format);
#   clang-tidy:   bugprone-* and performance-* (.clang-tidy) on every library and application source;
#                 any finding fails. A finding that is wrong for this code is silenced where it occurs
#                 with `// NOLINT(check-name): reason`. Verdicts are cached by a hash of their whole input
#                 (ci/tidy-cache.py): a source that preprocesses to the same text as when clang-tidy last
#                 passed it (ci/tidy-clean.txt) is not checked again.
# Usage: ci/lint.sh [format|tidy]   (default: both)
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-all}

if [ "$what" = all ] || [ "$what" = format ]; then
  mapfile -t files < <(git ls-files '*.cc' '*.h')
  clang-format --dry-run -Werror "${files[@]}"
  echo "lint: clang-format: ${#files[@]} files formatted"
fi

if [ "$what" = all ] || [ "$what" = tidy ]; then
  if [ ! -f build/compile_commands.json ]; then
    echo "lint: build/compile_commands.json missing: run ci/build.sh first" >&2
    exit 2
  fi
  # Library and application sources (tests, fuzz targets and benchmarks are checked by their compilers only).
  regex="^(?!.*_benchmark\\.cc$)$(pwd)/(datasets|scenes|render|vo|eval)/.*\\.cc$"
  # Sources whose exact input clang-tidy already passed (ci/tidy-clean.txt, ci/tidy-cache.py) are not
  # checked again; every other source is.
  cache=ci/tidy-clean.txt
  mapfile -t sources < <(python3 ci/tidy-cache.py select build "$regex" "$cache" | sed '/^$/d')
  if [ ${#sources[@]} != 0 ]; then
    only=$(printf '%s\n' "${sources[@]}" | sed 's/[.[\*^$()+?{|]/\\&/g' | paste -sd'|')
    log=$(mktemp)
    # run-clang-tidy colours its output even into a file: the colour codes are removed before counting.
    run-clang-tidy -quiet -p build -j "$(nproc)" "^($only)$" 2>&1 | sed 's/\x1b\[[0-9;]*m//g' >"$log" || true
    findings=$(grep -cE "^/.*: (warning|error): " "$log" || true)
    if [ "$findings" != 0 ]; then
      grep -E -A3 "^/.*: (warning|error): " "$log"
      echo "lint: clang-tidy: $findings finding(s)" >&2
      exit 1
    fi
  fi
  python3 ci/tidy-cache.py record build "$regex" "$cache"
  echo "lint: clang-tidy: no findings"
fi

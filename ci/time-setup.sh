#!/usr/bin/env bash
# Times the README's first command on a new machine: a fresh Debian 12 (debootstrap, minbase) with what a
# new machine of CI's kind already has (compiler, CMake, git, GoogleTest, Google Benchmark, Python), a
# fresh clone of this repository's HEAD, then `bash ci/demo.sh` with every line of its output prefixed by
# the seconds since it started. Prints the seconds to the first table and to the end.
# Usage (as root, with debootstrap installed; downloads about 500 MB from Debian's mirror):
#   ci/time-setup.sh WORKDIR     WORKDIR must not exist; it holds the root file system and demo.log
set -euo pipefail
work=${1:?usage: ci/time-setup.sh WORKDIR}
repo=$(cd "$(dirname "$0")/.." && pwd)
if [ -e "$work" ]; then echo "time-setup: $work exists" >&2; exit 2; fi
command -v debootstrap >/dev/null || { echo "time-setup: needs debootstrap (apt-get install debootstrap)" >&2; exit 2; }
root="$work/root"
mkdir -p "$root"
debootstrap --variant=minbase bookworm "$root" http://deb.debian.org/debian >"$work/debootstrap.log"
cp /etc/resolv.conf "$root/etc/"
# Only /proc is mounted: the root's own /dev (debootstrap's device nodes) is enough, and no bind mount of the
# host's /dev can be left behind for a later `rm -rf WORK` to walk into. (apt says it cannot write its log
# without /dev/pts; harmless.)
mount -t proc proc "$root/proc"
trap 'umount "$root/proc" || umount -l "$root/proc"' EXIT
export DEBIAN_FRONTEND=noninteractive
chroot "$root" apt-get update -qq
chroot "$root" apt-get install -y -qq --no-install-recommends build-essential cmake git libgtest-dev libgmock-dev \
  libbenchmark-dev python3 ca-certificates >"$work/base-packages.log"
chroot "$root" apt-get clean
git clone -q "$repo" "$root/root/rovo"
# shellcheck disable=SC2016  # expanded inside the chroot
chroot "$root" bash -c 'set -o pipefail; cd /root/rovo && t0=$EPOCHREALTIME
  bash ci/demo.sh 2>&1 | while IFS= read -r line; do now=$EPOCHREALTIME
    echo "$(( (${now/./} - ${t0/./}) / 1000000 )) $line"; done' >"$work/demo.log"
first_table=$(grep -m1 '| sequence |' "$work/demo.log" | cut -d' ' -f1)
echo "time-setup: first table after ${first_table} s, demo done after $(tail -1 "$work/demo.log" | cut -d' ' -f1) s" \
  "($work/demo.log)"

#!/usr/bin/env python3
"""clang-tidy's verdicts, cached by a hash of everything a verdict depends on (ci/lint.sh).

  tidy-cache.py select BUILD_DIR REGEX CACHE   prints the sources matching REGEX whose key is not in CACHE
                                               (and keeps every key in BUILD_DIR/tidy-keys.json)
  tidy-cache.py record BUILD_DIR REGEX CACHE   writes CACHE: the keys that select kept

A source's key is the SHA-256 of clang-tidy's version, .clang-tidy, ci/lint.sh and the source as clang
preprocesses it with its compile command (BUILD_DIR/compile_commands.json), comments kept (NOLINT) and
line markers kept (NOLINTNEXTLINE), with the checkout's path replaced so that every clone of the same
commit gets the same key. clang-tidy's verdict on a source is a function of exactly these inputs, so a
source whose key was recorded after a run without findings needs no second run. `record` is called only
after a run without findings; a missing or stale CACHE only makes the next run check more sources.
"""
import concurrent.futures
import hashlib
import json
import os
import re
import shlex
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def fixed_inputs():
    """What every key shares: the tool's version, its configuration and the script that runs it."""
    h = hashlib.sha256()
    h.update(subprocess.run(["clang-tidy", "--version"], capture_output=True, check=True).stdout)
    for name in (".clang-tidy", "ci/lint.sh"):
        with open(os.path.join(ROOT, name), "rb") as f:
            h.update(f.read())
    return h.digest()


# clang's driver: the metapackage's name, else the one clang-tidy-14 brings (clang-14).
CLANG = shutil.which("clang++") or shutil.which("clang++-14")


def preprocess_command(entry):
    """The compile command turned into clang's preprocessor, comments kept, warnings off."""
    args = shlex.split(entry["command"]) if "command" in entry else list(entry["arguments"])
    out = [CLANG]
    skip = False
    for a in args[1:]:
        if skip:
            skip = False
            continue
        if a == "-o":
            skip = True
            continue
        if a in ("-c", entry["file"]):
            continue
        out.append(a)
    return out + ["-E", "-C", "-w", entry["file"]]


def key(entry, shared):
    if CLANG is None:
        return None  # no preprocessor: every source is checked
    result = subprocess.run(preprocess_command(entry), cwd=entry["directory"], capture_output=True)
    if result.returncode != 0:
        return None  # not preprocessable here: clang-tidy will say why
    text = result.stdout.replace(ROOT.encode(), b"@ROOT@")
    return hashlib.sha256(shared + text).hexdigest()


def keys(build_dir, regex):
    with open(os.path.join(build_dir, "compile_commands.json")) as f:
        all_entries = json.load(f)
    if any("/Unity/" in e["file"] for e in all_entries):
        # A unity build (ci/demo.sh) has no compile command per source: checking it would pass nothing.
        sys.exit("tidy-cache: %s is a unity build (ci/demo.sh); run ci/build.sh to configure it one source per "
                 "compile first" % build_dir)
    entries = [e for e in all_entries if re.match(regex, e["file"])]
    shared = fixed_inputs()
    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
        found = list(pool.map(lambda e: key(e, shared), entries))
    return {e["file"]: k for e, k in zip(entries, found)}


def main():
    if len(sys.argv) != 5 or sys.argv[1] not in ("select", "record"):
        sys.exit(__doc__)
    mode, build_dir, regex, cache = sys.argv[1:]
    kept = os.path.join(build_dir, "tidy-keys.json")
    if mode == "select":
        current = keys(build_dir, regex)
        with open(kept, "w") as f:
            json.dump(current, f)
        known = set()
        if os.path.exists(cache):
            with open(cache) as f:
                known = {line.split()[0] for line in f if line.strip() and not line.startswith("#")}
        todo = [path for path, k in sorted(current.items()) if k is None or k not in known]
        print(f"lint: clang-tidy: {len(current) - len(todo)} of {len(current)} sources as a clean run left them "
              f"({os.path.relpath(cache, ROOT)}), {len(todo)} to check", file=sys.stderr)
        print("\n".join(todo))
        return
    with open(kept) as f:
        current = json.load(f)
    lines = sorted(f"{k} {os.path.relpath(p, ROOT)}" for p, k in current.items() if k is not None)
    tmp = cache + ".tmp"
    with open(tmp, "w") as f:
        f.write("# clang-tidy found nothing in these sources as they were; written by ci/lint.sh (ci/tidy-cache.py)\n")
        f.write("\n".join(lines) + "\n")
    os.replace(tmp, cache)


if __name__ == "__main__":
    main()

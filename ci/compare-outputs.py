#!/usr/bin/env python3
"""compare-outputs.py BEFORE AFTER: compares two folders written by ci/reference-outputs.sh file for file.

Images and binary files must be equal byte for byte. Text files are compared with each folder's own path
replaced by ROOT and the binary's path in usage lines removed; JSON keys, CSV columns and Markdown table
columns that hold timing (seconds, ms, time, elapsed, ...) are left out. Prints each file that differs and
a count; exits 1 when any file differs or exists on one side only.
"""
import json, os, re, sys
TIMING = re.compile(r"(^|_)(seconds|ms|time|elapsed|wall|cpu|date|created|timestamp_utc|duration|fps|frames_per_s)(_|$)|ms_per_frame|per_frame_ms|_ms$|^ms_")
def strip(o):
    if isinstance(o, dict):
        return {k: strip(v) for k, v in o.items() if not TIMING.search(k)}
    if isinstance(o, list):
        return [strip(v) for v in o]
    return o
def csv_strip(text, sep):
    lines = text.split("\n")
    if not lines:
        return text
    head = [c.strip() for c in lines[0].split(sep)]
    drop = {i for i, c in enumerate(head) if TIMING.search(c) or c in ("ms/frame", "s", "seconds")}
    if not drop:
        return text
    out = [sep.join(c for i, c in enumerate(l.split(sep)) if i not in drop) for l in lines]
    return "\n".join(out)
def load(p, root):
    with open(p, "rb") as f:
        data = f.read()
    try:
        text = data.decode()
    except UnicodeDecodeError:
        return data
    text = text.replace(root, "ROOT")
    text = re.sub(r"Usage: \S+", "Usage: rovo", text)
    if p.endswith(".csv"):
        return csv_strip(text, ",")
    if p.endswith(".md"):
        blocks = []
        for line in text.split("\n"):
            blocks.append(line)
        # Markdown tables: drop timing columns of each table (header row decides).
        out, head_drop = [], set()
        for line in blocks:
            if line.startswith("|"):
                cells = line.split("|")
                if not head_drop and not set(line) <= set("|-: "):
                    head_drop = {i for i, c in enumerate(cells) if "ms/frame" in c or "ms per frame" in c or c.strip() in ("s", "time [s]")}
                out.append("|".join(c for i, c in enumerate(cells) if i not in head_drop))
            else:
                head_drop = set()
                out.append(line)
        return "\n".join(out)
    data = text.encode()
    if p.endswith(".json"):
        try:
            return json.dumps(strip(json.loads(data)), sort_keys=True)
        except Exception:
            return data
    return data
if len(sys.argv) != 3:
    sys.exit("usage: ci/compare-outputs.py BEFORE AFTER")
a, b = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
files = set()
for root in (a, b):
    for d, _, fs in os.walk(root):
        for f in fs:
            files.add(os.path.relpath(os.path.join(d, f), root))
diff = same = 0
for f in sorted(files):
    if f.endswith(".log") or f.endswith(".html"):
        continue
    pa, pb = os.path.join(a, f), os.path.join(b, f)
    if not os.path.exists(pa) or not os.path.exists(pb):
        print("only in", a if os.path.exists(pa) else b, f); diff += 1; continue
    if load(pa, a) != load(pb, b):
        print("differs", f); diff += 1
    else:
        same += 1
print(f"{same} identical, {diff} differ")
sys.exit(1 if diff else 0)

#!/usr/bin/env python3
"""Cross-checks rovo's motion blur and rolling shutter against Cycles 3.4 (plain python3).

    python3 scenes/blender/timing_cycles_check.py --rovo BUILD/rovo --out WORK [--size 200]
        [--samples 512] [--spp 64] [--threads 2]

Builds the scene of cycles_timing.py (a bright vertical bar on a dark wall, emission only, the rig
moving sideways at 20 m/s, one 180-degree equidistant fisheye looking at the wall), exports it
(export_scene.py, Blender frames 1..3) and renders Blender frame 2 (dataset frame 1) with Cycles
and with `rovo render --scene` for each case:

  sharp          no motion blur                       | no timing
  blur           shutter 0.2 frames, centred          | --shutter-ms 20
  rolling        shutter 0.5 frames, rolling TOP,     | --rolling-shutter-ms 50 (H-1)/H
                 duration 0 (rows instantaneous)      |
  rolling_blur   shutter 0.5 frames, rolling TOP,     | --shutter-ms 10 --rolling-shutter-ms 40 (H-1)/H
                 duration 0.2                         |

Cycles' rolling shutter (kernel camera_sample): a sample's time in the shutter interval is
(u - 1/2) d + y_r (1 - d) + d/2 with u uniform, d the duration and y_r the raster row fraction, so
a row is exposed for d x shutter and the rows' centres span (1 - d) x shutter; with rovo's rule
(datasets/FORMAT.md, Timing) the rows' centres agree exactly for T = d S, R = (1 - d) S (H - 1)/H.

Metrics, on the linear radiance (rovo's 8-bit sRGB decoded) of the rows within 60 px of the centre:
  * mad: mean absolute difference per pixel inside the image circle;
  * for each edge of the bar (rising = left, falling = right): its position per row (centroid of
    the signed gradient within 50 px of the centre) and its width sqrt(12 var) (for a box in time
    the blur extent, sqrt(W^2 + 1) with the 1-px pixel box), and the
    slope of position against row (the rolling-shutter shear, px per row; its sign is the row order).
A case passes when mad <= mad(sharp) + 0.01, the widths agree within 0.5 px + 5 %, and the slopes
within 0.005 px/row + 5 %. Controls that must fail: rovo with the blur's shutter doubled, with half
the readout, and with the rows in the opposite order (the rolling image flipped upside down: the
scene is symmetric about the horizon, so this is a bottom-first rolling shutter).
Prints a table and writes WORK/timing_check.json; exits 1 if a case fails or a control passes.
"""

import argparse
import json
import os
import shutil
import struct
import subprocess
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def run(cmd, log):
    with open(log, "a") as f:
        f.write("\n$ %s\n" % " ".join(cmd))
        f.flush()
        r = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT)
    if r.returncode != 0:
        sys.exit("failed (exit %d): %s\nsee %s" % (r.returncode, " ".join(cmd), log))


def read_png(path):
    """8-bit gray/RGB/RGBA non-interlaced PNG -> (width, height, channels, bytes rows)."""
    data = open(path, "rb").read()
    pos, idat, w = 8, b"", 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or interlace:
                sys.exit("%s: only 8-bit non-interlaced PNG" % path)
            ch = {0: 1, 2: 3, 6: 4, 4: 2}[ctype]
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = w * ch
    rows, prev = [], bytearray(stride)
    for y in range(h):
        ft = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - ch] if i >= ch else 0
            b = prev[i]
            c = prev[i - ch] if i >= ch else 0
            if ft == 1:
                line[i] = (line[i] + a) & 255
            elif ft == 2:
                line[i] = (line[i] + b) & 255
            elif ft == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif ft == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return w, h, ch, rows


def srgb_to_linear(v):
    v /= 255.0
    return v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4


def rovo_image(path):
    w, h, ch, rows = read_png(path)
    lut = [srgb_to_linear(float(i)) for i in range(256)]
    return w, h, [[lut[row[x * ch]] for x in range(w)] for row in rows]


def cycles_image(path):
    d = json.load(open(path))
    w, h, r = d["width"], d["height"], d["r"]
    return w, h, [r[y * w:(y + 1) * w] for y in range(h)]


def edges(img, rows):
    """Per row: (rising centroid, rising width, falling centroid, falling width) of the gradient
    within 50 px of the image centre (the bar; the image circle's rim stays outside)."""
    out = []
    for y in rows:
        line = img[y]
        x0 = len(line) // 2 - 50
        g = [0.0] * x0 + [line[x + 1] - line[x] for x in range(x0, len(line) // 2 + 50)]
        row = []
        for sign in (1.0, -1.0):
            wts = [max(0.0, sign * v) for v in g]
            s0 = sum(wts)
            m = sum(wt * (x + 0.5) for x, wt in enumerate(wts)) / s0
            var = sum(wt * (x + 0.5 - m) ** 2 for x, wt in enumerate(wts)) / s0
            row += [m, (12.0 * var) ** 0.5]
        out.append(row)
    return out


def slope(rows, values):
    n = len(rows)
    mr, mv = sum(rows) / n, sum(values) / n
    return sum((r - mr) * (v - mv) for r, v in zip(rows, values)) / sum((r - mr) ** 2 for r in rows)


def measure(img, w, h, rows):
    e = edges(img, rows)
    return {"rise_pos": sum(r[0] for r in e) / len(e), "rise_width": sum(r[1] for r in e) / len(e),
            "fall_pos": sum(r[2] for r in e) / len(e), "fall_width": sum(r[3] for r in e) / len(e),
            "rise_slope": slope(rows, [r[0] for r in e]), "fall_slope": slope(rows, [r[2] for r in e])}


def mad(a, b, w, h, rows):
    cx, cy, rad = (w - 1) / 2.0, (h - 1) / 2.0, min(w, h) / 2.0 - 1.0
    s, n = 0.0, 0
    for y in rows:
        for x in range(w):
            if (x - cx) ** 2 + (y - cy) ** 2 <= rad * rad:
                s += abs(a[y][x] - b[y][x])
                n += 1
    return s / n


def compare(name, rovo, cyc, w, h, rows, sharp_mad):
    mr, mc = measure(rovo, w, h, rows), measure(cyc, w, h, rows)
    d = mad(rovo, cyc, w, h, rows)
    ok_mad = sharp_mad is None or d <= sharp_mad + 0.01
    ok_w = all(abs(mr[k] - mc[k]) <= 0.5 + 0.05 * mc[k] for k in ("rise_width", "fall_width"))
    ok_s = all(abs(mr[k] - mc[k]) <= 0.005 + 0.05 * abs(mc[k]) for k in ("rise_slope", "fall_slope"))
    return {"case": name, "mad": d, "rovo": mr, "cycles": mc, "pass": ok_mad and ok_w and ok_s,
            "pass_mad": ok_mad, "pass_width": ok_w, "pass_slope": ok_s}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--rovo", required=True)
    p.add_argument("--out", required=True, help="work folder (replaced)")
    p.add_argument("--size", type=int, default=200)
    p.add_argument("--samples", type=int, default=512, help="Cycles samples per pixel")
    p.add_argument("--spp", type=int, default=64, help="rovo samples per pixel")
    p.add_argument("--threads", type=int, default=2)
    a = p.parse_args()
    if os.path.exists(a.out):
        shutil.rmtree(a.out)
    os.makedirs(a.out)
    log = os.path.join(a.out, "log.txt")
    blender = ["blender", "-b", "--factory-startup"]
    script = os.path.join(HERE, "cycles_timing.py")
    blend = os.path.join(a.out, "scene.blend")
    run(blender + ["--python-exit-code", "1", "--python", script, "--", "build", blend, "--size", str(a.size)], log)
    exported = os.path.join(a.out, "exported")
    run(blender + [blend, "--python-exit-code", "1", "--python", os.path.join(HERE, "export_scene.py"), "--",
                   exported, "--frames", "1:4"], log)
    h = a.size
    fps = 10.0
    cases = [
        ("sharp", [], []),
        ("blur", ["--shutter", "0.2"], ["--shutter-ms", "20"]),
        ("rolling", ["--shutter", "0.5", "--rolling", "--rolling-duration", "0"],
         ["--rolling-shutter-ms", repr(0.5 / fps * 1000.0 * (h - 1) / h)]),
        ("rolling_blur", ["--shutter", "0.5", "--rolling", "--rolling-duration", "0.2"],
         ["--shutter-ms", "10", "--rolling-shutter-ms", repr(0.8 * 0.5 / fps * 1000.0 * (h - 1) / h)]),
    ]
    controls = [  # (name, compared with the Cycles render of case, rovo arguments, flip rows)
        ("control_blur_double_shutter", "blur", ["--shutter-ms", "40"], False),
        ("control_rolling_half_readout", "rolling", ["--rolling-shutter-ms", repr(25.0 * (h - 1) / h)], False),
        ("control_rolling_bottom_first", "rolling", None, True),
    ]
    images = {}
    for name, cargs, rargs in cases:
        cj = os.path.join(a.out, "cycles_%s.json" % name)
        run(["blender", "-b", blend, "--python-exit-code", "1", "--python", script, "--", "render", cj, "--frame", "2",
             "--samples", str(a.samples), "--threads", str(a.threads)] + cargs, log)
        out = os.path.join(a.out, "rovo_%s" % name)
        run([a.rovo, "render", "--scene", exported, "--out", out, "--spp", str(a.spp), "--threads", str(a.threads),
             "--quiet"] + rargs, log)
        images[name] = (rovo_image(os.path.join(out, "cam0", "000001.png")), cycles_image(cj))
    rows = list(range(h // 2 - 60, h // 2 + 60))
    results = []
    sharp_mad = None
    for name, _, _ in cases:
        (w, hh, rimg), (_, _, cimg) = images[name]
        r = compare(name, rimg, cimg, w, hh, rows, sharp_mad)
        if name == "sharp":
            sharp_mad = r["mad"]
        results.append(r)
    for name, base, rargs, flip in controls:
        (w, hh, rimg), (_, _, cimg) = images[base]
        if flip:
            rimg = rimg[::-1]
        else:
            out = os.path.join(a.out, "rovo_%s" % name)
            run([a.rovo, "render", "--scene", exported, "--out", out, "--spp", str(a.spp), "--threads",
                 str(a.threads), "--quiet"] + rargs, log)
            rimg = rovo_image(os.path.join(out, "cam0", "000001.png"))[2]
        results.append(compare(name, rimg, cimg, w, hh, rows, sharp_mad))

    print("| case | mad | rise width rovo / Cycles px | fall width rovo / Cycles px | rise slope rovo / Cycles "
          "px/row | fall slope rovo / Cycles px/row | rise pos diff px | pass |")
    print("|---|---|---|---|---|---|---|---|")
    failed = False
    for r in results:
        ro, cy = r["rovo"], r["cycles"]
        print("| %s | %.4f | %.2f / %.2f | %.2f / %.2f | %.4f / %.4f | %.4f / %.4f | %+.2f | %s |" % (
            r["case"], r["mad"], ro["rise_width"], cy["rise_width"], ro["fall_width"], cy["fall_width"],
            ro["rise_slope"], cy["rise_slope"], ro["fall_slope"], cy["fall_slope"],
            ro["rise_pos"] - cy["rise_pos"], "yes" if r["pass"] else "no"))
        control = r["case"].startswith("control")
        failed |= r["pass"] == control
    tmp = os.path.join(a.out, "timing_check.json.tmp")
    with open(tmp, "w") as f:
        json.dump({"size": a.size, "samples": a.samples, "spp": a.spp, "rows": [rows[0], rows[-1]],
                   "results": results}, f, indent=1)
    os.replace(tmp, os.path.join(a.out, "timing_check.json"))
    print("FAILED" if failed else "OK: every case agrees with Cycles and every control is caught")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Times the same frames in Cycles and in `rovo render` (seconds per 4-view frame).

    python3 scenes/blender/time_cycles_vs_rovo.py --rovo BUILD/rovo --out WORK
        [--blend FILE.blend] [--width 1600 --height 1532] [--frames 3] [--samples 16] [--threads 2]

Without --blend it builds the round-trip test scene (tests/scenes/blender/make_roundtrip_scene.py)
at --width x --height (four 220-degree Cycles FISHEYE_EQUIDISTANT views, like a rovo4 frame),
exports it (export_scene.py), then times
  * Cycles (cycles_reference.py): --samples spp, --threads threads, direct light only (bounces 0),
    Blackman-Harris 1.5 px filter, no denoising, no depth pass; wall and CPU time of each view's
    render call (sync + BVH + tracing + EXR write), summed per frame;
  * rovo render --scene (same rig.json): at --samples spp and at its default spp, --threads, wall
    and CPU time of the whole command divided by the frame count (includes scene load, BVH build
    and PNG writing).
CPU seconds (user + system, all threads) are the fairer figure on a loaded machine.
Prints a table and writes WORK/timing.json.
"""

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.path.join(HERE, "..", ".."))


def run(cmd, log):
    """Runs cmd; returns (wall seconds, CPU seconds of the child: user + system, all threads)."""
    with open(log, "a") as f:
        f.write("\n$ %s\n" % " ".join(cmd))
        f.flush()
        t0 = time.perf_counter()
        u0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        r = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT)
        u1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        seconds = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit("failed (exit %d): %s\nsee %s" % (r.returncode, " ".join(cmd), log))
    return seconds, (u1.ru_utime - u0.ru_utime) + (u1.ru_stime - u0.ru_stime)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--rovo", required=True, help="path of the rovo executable")
    p.add_argument("--out", required=True, help="work folder (replaced)")
    p.add_argument("--blend", help="a .blend with a rig (default: build the round-trip test scene)")
    p.add_argument("--width", type=int, default=1600)
    p.add_argument("--height", type=int, default=1532)
    p.add_argument("--frames", type=int, default=3, help="frames to time (default 3)")
    p.add_argument("--samples", type=int, default=16, help="samples per pixel for both (default 16)")
    p.add_argument("--threads", type=int, default=2, help="threads for both (default 2)")
    a = p.parse_args()
    if os.path.exists(a.out):
        shutil.rmtree(a.out)
    os.makedirs(a.out)
    log = os.path.join(a.out, "log.txt")
    blender = ["blender", "-b", "--factory-startup"]
    blend = a.blend
    if blend is None:
        blend = os.path.join(a.out, "scene.blend")
        run(blender + ["--python-exit-code", "1", "--python",
                       os.path.join(SOURCE, "tests", "scenes", "blender", "make_roundtrip_scene.py"), "--", blend,
                       "--size", str(a.width), "--height", str(a.height), "--frames", str(a.frames)], log)
    frames = "1:%d" % (1 + a.frames)
    exported = os.path.join(a.out, "exported")
    run(blender + [blend, "--python-exit-code", "1", "--python", os.path.join(HERE, "export_scene.py"), "--",
                   exported, "--frames", frames], log)

    cycles = os.path.join(a.out, "cycles")
    run(blender + [blend, "--python-exit-code", "1", "--python", os.path.join(HERE, "cycles_reference.py"), "--",
                   cycles, "--frames", frames, "--samples", str(a.samples), "--threads", str(a.threads),
                   "--filter-width", "1.5", "--no-depth"], log)
    cyc = json.load(open(os.path.join(cycles, "cycles.json")))
    n_frames = len(cyc["frames"])
    cycles_s = sum(v["seconds"] for v in cyc["views"]) / n_frames
    cycles_cpu = sum(v["cpu_seconds"] for v in cyc["views"]) / n_frames
    view_s = [v["seconds"] for v in cyc["views"]]

    rows = [("Cycles %d spp, %d views" % (a.samples, len(cyc["cameras"])), cycles_s, cycles_cpu)]
    for label, spp in (("spp %d" % a.samples, a.samples), ("default spp", 0)):
        out = os.path.join(a.out, "rovo_" + label.replace(" ", "_"))
        cmd = [a.rovo, "render", "--scene", exported, "--rig", os.path.join(exported, "rig.json"), "--out", out,
               "--threads", str(a.threads), "--quiet"]
        if spp:
            cmd += ["--spp", str(spp)]
        wall, cpu = run(cmd, log)
        rows.append(("rovo render, %s (whole command)" % label, wall / a.frames, cpu / a.frames))

    load = os.getloadavg()
    print("%d x %dx%d views, %d threads, %d frames, load average now %.1f (scene: %s)" % (
        len(cyc["cameras"]), cyc["width"], cyc["height"], a.threads, a.frames, load[0], blend))
    print("| renderer | wall s/frame | CPU s/frame | Cycles CPU / this CPU |")
    print("|---|---|---|---|")
    for name, wall, cpu in rows:
        print("| %s | %.2f | %.2f | %.1f |" % (name, wall, cpu, cycles_cpu / cpu))
    print("Cycles wall s per view: min %.2f, max %.2f" % (min(view_s), max(view_s)))
    result = {"width": cyc["width"], "height": cyc["height"], "views": len(cyc["cameras"]), "threads": a.threads,
              "frames": a.frames, "samples": a.samples, "blend": blend, "load_average": load,
              "rows": [{"renderer": r[0], "wall_seconds_per_frame": r[1], "cpu_seconds_per_frame": r[2]}
                       for r in rows]}
    with open(os.path.join(a.out, "timing.json.tmp"), "w") as f:
        json.dump(result, f, indent=1)
    os.replace(os.path.join(a.out, "timing.json.tmp"), os.path.join(a.out, "timing.json"))


if __name__ == "__main__":
    main()

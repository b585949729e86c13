"""Checks an exported rig (rig.json + trajectory.tum) against Cycles' depth, with Blender's own ray
caster: independent of `rovo render`, it isolates the lens mapping, camera axes, cam_from_rig and
trajectory of export_scene.py.

    blender -b FILE.blend --python tests/scenes/blender/check_lens_raycast.py -- EXPORTED CYCLES
            [--stride N] [--min-agree 0.98]

For every export frame k, rig camera i and every N-th pixel (u, v) (rovo pixel convention) whose
Cycles depth is a hit: bearing = equidistant unprojection (k1..k4 as in rig.json),
ray = world_from_rig(k) * rig_from_cam_i, Blender scene.ray_cast at Blender frame A + k; the pixel
agrees when |d_raycast - d_cycles| <= 1% of d_cycles. Exits 1 when the agreeing fraction of pixels
hit in both is below --min-agree. Reads Cycles' EXR depth through `oiiotool --dumpdata`.
"""

import argparse
import json
import math
import os
import subprocess
import sys

import bpy
from mathutils import Quaternion, Vector


def read_depth(path, channel):
    """{(x, y): depth} of a (multilayer) EXR channel, via oiiotool."""
    info = subprocess.run(["oiiotool", "--info", "-v", path], check=True, capture_output=True, text=True).stdout
    names = next(l for l in info.splitlines() if "channel list:" in l).split(":", 1)[1].split(",")
    index = [n.strip() for n in names].index(channel)
    text = subprocess.run(["oiiotool", "--dumpdata", path], check=True, capture_output=True, text=True).stdout
    depth = {}
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("Pixel ("):
            xy, values = line[len("Pixel ("):].split("):")
            x, y = (int(s) for s in xy.split(","))
            depth[(x, y)] = float(values.split()[index])
    return depth


def unproject(params, u, v):
    fx, fy, cx, cy, k1, k2, k3, k4 = params
    mx, my = (u - cx) / fx, (v - cy) / fy
    rho = math.hypot(mx, my)
    if rho == 0.0:
        return Vector((0.0, 0.0, 1.0))
    theta = rho
    for _ in range(30):
        t2 = theta * theta
        f = theta * (1 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4)))) - rho
        df = 1 + t2 * (3 * k1 + t2 * (5 * k2 + t2 * (7 * k3 + t2 * 9 * k4)))
        theta -= f / df
    s = math.sin(theta) / rho
    return Vector((s * mx, s * my, math.cos(theta)))


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="check_lens_raycast.py")
    p.add_argument("exported")
    p.add_argument("cycles")
    p.add_argument("--stride", type=int, default=3)
    p.add_argument("--min-agree", type=float, default=0.98)
    a = p.parse_args(argv)
    rig = json.load(open(os.path.join(a.exported, "rig.json")))
    scene_json = json.load(open(os.path.join(a.exported, "scene.json")))
    cyc = json.load(open(os.path.join(a.cycles, "cycles.json")))
    poses = []
    for line in open(os.path.join(a.exported, "trajectory.tum")):
        if line.strip() and not line.startswith("#"):
            t, x, y, z, qx, qy, qz, qw = (float(s) for s in line.split())
            poses.append((Quaternion((qw, qx, qy, qz)), Vector((x, y, z))))
    frames = scene_json["blender"]["frames"]
    scene = bpy.context.scene
    both = agree = 0
    worst = 0.0
    for k, frame in enumerate(frames):
        scene.frame_set(frame)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        q_wr, t_wr = poses[k]
        for i, cam in enumerate(rig["cameras"]):
            depth = read_depth(os.path.join(a.cycles, "cam%d" % i, "%06d.exr" % k), cyc["depth_channel"])
            qx, qy, qz, qw = cam["cam_from_rig"]["rotation_xyzw"]
            q_cr = Quaternion((qw, qx, qy, qz))
            t_cr = Vector(cam["cam_from_rig"]["translation"])
            q_rc = q_cr.inverted()
            origin = q_wr @ (q_rc @ -t_cr) + t_wr  # camera centre in world
            n_both = n_agree = 0
            for v in range(0, cam["height"], a.stride):
                for u in range(0, cam["width"], a.stride):
                    d_cyc = depth[(u, v)]
                    if not (0.0 < d_cyc < 1e9):
                        continue
                    bearing = unproject(cam["params"], u, v)
                    direction = q_wr @ (q_rc @ bearing)
                    hit, loc, _, _, _, _ = scene.ray_cast(depsgraph, origin, direction)
                    if not hit:
                        continue
                    d = (loc - origin).length
                    n_both += 1
                    rel = abs(d - d_cyc) / d_cyc
                    worst = max(worst, rel)
                    if rel <= 0.01:
                        n_agree += 1
            print("frame %d cam%d: %d/%d pixels agree within 1%%" % (k, i, n_agree, n_both))
            both += n_both
            agree += n_agree
    frac = agree / max(both, 1)
    print("raycast vs cycles: %.4f of %d pixels agree within 1%% (worst %.3g)" % (frac, both, worst))
    sys.stdout.flush()
    os._exit(0 if both > 0 and frac >= a.min_agree else 1)


main()

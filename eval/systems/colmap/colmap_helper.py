#!/usr/bin/env python3
"""Helpers of run.sh (standard library only).

colmap_helper.py params SENSOR_YAML                  fx,fy,cx,cy,k1,k2,k3,k4 (COLMAP OPENCV_FISHEYE)
colmap_helper.py masks SENSOR_YAML IMAGES MASKS DEG  a COLMAP mask per image: features within DEG of the axis
colmap_helper.py tum SENSOR_YAML TEXT_MODELS         TUM lines (seconds) of world_from_rig from the model
                                                     with the most images; rig = camera * T_BS^-1
"""
import math
import os
import struct
import sys
import zlib


def read_sensor(path):
    fields = {}
    with open(path) as f:
        lines = f.read().split("\n")
    for i, line in enumerate(lines):
        key, _, value = line.partition(":")
        if key.strip() == "data" and "T_BS" not in fields:
            fields["T_BS"] = [float(v) for v in value.strip(" []").split(",")]
        elif key in ("intrinsics", "distortion_coefficients", "resolution"):
            fields[key] = [float(v) for v in value.strip(" []").split(",")]
        elif key in ("camera_model", "distortion_model"):
            fields[key] = value.strip()
    if fields.get("camera_model") != "pinhole" or fields.get("distortion_model") != "equidistant":
        sys.exit(path + ": camera_model/distortion_model: COLMAP's OPENCV_FISHEYE needs pinhole + equidistant "
                 "(export with lens: kb4)")
    return fields


def write_gray_png(path, width, height, rows):
    raw = b"".join(b"\x00" + bytes(row) for row in rows)
    chunk = lambda tag, data: (struct.pack(">I", len(data)) + tag + data +
                               struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))
    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)) +
           chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(png)


def masks(sensor_path, images, out, max_deg):
    s = read_sensor(sensor_path)
    fx, fy, cx, cy = s["intrinsics"]
    k = s["distortion_coefficients"]
    width, height = int(s["resolution"][0]), int(s["resolution"][1])
    t = math.radians(max_deg)
    radius = t * (1 + k[0] * t**2 + k[1] * t**4 + k[2] * t**6 + k[3] * t**8)  # normalised
    rows = []
    for y in range(height):
        dy = (y - cy) / fy
        rows.append([255 if ((x - cx) / fx) ** 2 + dy * dy <= radius * radius else 0 for x in range(width)])
    first = None
    for name in sorted(os.listdir(images)):
        target = os.path.join(out, name + ".png")
        if first is None:
            write_gray_png(target, width, height, rows)
            first = target
        elif not os.path.exists(target):
            os.symlink(os.path.abspath(first), target)


def quat_to_matrix(w, x, y, z):
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def matrix_to_quat(m):
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0:
        s = 2 * math.sqrt(trace + 1)
        return (0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s)
    i = max(range(3), key=lambda a: m[a][a])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2 * math.sqrt(1 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0, 0.0, 0.0, 0.0]
    q[0] = (m[k][j] - m[j][k]) / s
    q[1 + i] = 0.25 * s
    q[1 + j] = (m[j][i] + m[i][j]) / s
    q[1 + k] = (m[k][i] + m[i][k]) / s
    return tuple(q)


def matmul(a, b):
    return [[sum(a[r][i] * b[i][c] for i in range(3)) for c in range(3)] for r in range(3)]


def transpose(a):
    return [[a[c][r] for c in range(3)] for r in range(3)]


def read_images(path):
    poses = []
    with open(path) as f:
        lines = [l for l in f.read().split("\n") if l and not l.startswith("#")]
    for line in lines[0::2]:  # each image: its pose line, then its points line
        v = line.split()
        q = [float(a) for a in v[1:5]]
        t = [float(a) for a in v[5:8]]
        poses.append((int(os.path.splitext(v[9])[0]), q, t))
    return poses


def tum(sensor_path, text_models):
    tbs = read_sensor(sensor_path)["T_BS"]  # rig_from_cam, row-major 4x4
    rig_from_cam_r = [tbs[0:3], tbs[4:7], tbs[8:11]]
    rig_from_cam_t = [tbs[3], tbs[7], tbs[11]]
    models = [read_images(os.path.join(text_models, m, "images.txt")) for m in sorted(os.listdir(text_models))]
    if not models:
        sys.exit(text_models + ": COLMAP reconstructed no model")
    best = max(models, key=len)
    for stamp_ns, q, t in sorted(best):
        r_cw = quat_to_matrix(*q)  # cam_from_world
        r_wc = transpose(r_cw)
        p_wc = [-sum(r_wc[r][i] * t[i] for i in range(3)) for r in range(3)]
        # world_from_rig = world_from_cam * cam_from_rig, cam_from_rig = (rig_from_cam)^-1
        r_cr = transpose(rig_from_cam_r)
        t_cr = [-sum(r_cr[r][i] * rig_from_cam_t[i] for i in range(3)) for r in range(3)]
        r_wr = matmul(r_wc, r_cr)
        p_wr = [p_wc[r] + sum(r_wc[r][i] * t_cr[i] for i in range(3)) for r in range(3)]
        w, x, y, z = matrix_to_quat(r_wr)
        print("%.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f" % (stamp_ns * 1e-9, p_wr[0], p_wr[1], p_wr[2], x, y, z, w))


def main():
    if sys.argv[1] == "params":
        s = read_sensor(sys.argv[2])
        print(",".join(repr(v) for v in s["intrinsics"] + s["distortion_coefficients"]))
    elif sys.argv[1] == "masks":
        masks(sys.argv[2], sys.argv[3], sys.argv[4], float(sys.argv[5]))
    elif sys.argv[1] == "tum":
        tum(sys.argv[2], sys.argv[3])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()

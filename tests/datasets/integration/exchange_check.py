#!/usr/bin/env python3
"""Independent check of a `rovo dataset export` folder against the rovo dataset it came from.

Written from the formats' documentation, not from rovo's C++ code:
- ocam projection from datasets/FORMAT.md (Scaramuzza's inverse polynomial in the elevation angle);
- double sphere from Usenko, Demmel, Cremers, "The Double Sphere Camera Model" (3DV 2018), eq. 40-45;
  extended unified from Khomutenko et al. (RA-L 2016); Kannala-Brandt on the angle (Basalt's kb4);
  unified + radial-tangential as Kalibr's omni/radtan;
- EuRoC ground-truth columns from the EuRoC MAV dataset's documentation (timestamp [ns], p_RS_R xyz,
  q_RS wxyz, v_RS_R xyz, b_w_RS_S xyz, b_a_RS_S xyz);
- Kalibr camchain (T_cn_cnm1, T_cam_imu) and Basalt calibration (value0/T_imu_cam) layouts.
- PNG decoding from the PNG specification (grey exports: the Rec. 709 luminance of the sRGB images);
Usage: exchange_check.py EXPORT_DIR DATASET_DIR FORMAT   (exit 1 with a message on any mismatch)
"""
import csv
import json
import math
import os
import sys
import zlib

import numpy as np
import yaml


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def quat_to_matrix(w, x, y, z):
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def transform(rotation, translation):
    t = np.eye(4)
    t[:3, :3] = rotation
    t[:3, 3] = translation
    return t


def project_ocam(p, point):
    """FORMAT.md: theta = atan2(-z, |(x,y)|), rho = sum b_i theta^i, (x,y) = rho (X,Y)/|(X,Y)|, affine."""
    cx, cy, c, d, e = p[0:5]
    b = p[10:]
    r = math.hypot(point[0], point[1])
    theta = math.atan2(-point[2], r)
    rho = sum(bi * theta ** i for i, bi in enumerate(b))
    x, y = rho * point[0] / r, rho * point[1] / r
    return np.array([c * x + d * y + cx, e * x + y + cy])


def project_ds(fx, fy, cx, cy, xi, alpha, point):
    """Usenko et al. 2018: d1 = |p|, d2 = |(x, y, xi d1 + z)|, pi = (fx x, fy y) / (alpha d2 + (1-alpha)(xi d1 + z)) + c."""
    x, y, z = point
    d1 = math.sqrt(x * x + y * y + z * z)
    w1 = alpha / (1 - alpha) if alpha <= 0.5 else (1 - alpha) / alpha
    w2 = (w1 + xi) / math.sqrt(2 * w1 * xi + xi * xi + 1)
    if z <= -w2 * d1:
        return None
    k = xi * d1 + z
    d2 = math.sqrt(x * x + y * y + k * k)
    s = alpha * d2 + (1 - alpha) * k
    return np.array([fx * x / s + cx, fy * y / s + cy])


def project_eucm(fx, fy, cx, cy, alpha, beta, point):
    x, y, z = point
    d = math.sqrt(beta * (x * x + y * y) + z * z)
    w = alpha / (1 - alpha) if alpha <= 0.5 else (1 - alpha) / alpha
    if z <= -w * d:
        return None
    s = alpha * d + (1 - alpha) * z
    return np.array([fx * x / s + cx, fy * y / s + cy])


def project_kb4(fx, fy, cx, cy, k1, k2, k3, k4, point):
    x, y, z = point
    r = math.hypot(x, y)
    theta = math.atan2(r, z)
    rt = theta * (1 + k1 * theta ** 2 + k2 * theta ** 4 + k3 * theta ** 6 + k4 * theta ** 8)
    return np.array([fx * rt * x / r + cx, fy * rt * y / r + cy])


def project_omni(xi, fx, fy, cx, cy, k1, k2, p1, p2, point):
    x, y, z = point
    n = math.sqrt(x * x + y * y + z * z)
    if z <= -(1 / xi if xi > 1 else xi) * n:
        return None
    s = z + xi * n
    mx, my = x / s, y / s
    r2 = mx * mx + my * my
    radial = 1 + k1 * r2 + k2 * r2 * r2
    dx = mx * radial + 2 * p1 * mx * my + p2 * (r2 + 2 * mx * mx)
    dy = my * radial + p1 * (r2 + 2 * my * my) + 2 * p2 * mx * my
    return np.array([fx * dx + cx, fy * dy + cy])


def kalibr_projector(camera_model, intrinsics, distortion_model, coeffs):
    """Kalibr's parameter order: ds [xi, alpha, fu, fv, pu, pv], eucm [alpha, beta, fu, fv, pu, pv],
    omni [xi, fu, fv, pu, pv] + radtan [k1, k2, r1, r2], pinhole [fu, fv, pu, pv] + equidistant [k1..k4]."""
    i = intrinsics
    if camera_model == "ds":
        return lambda p: project_ds(i[2], i[3], i[4], i[5], i[0], i[1], p)
    if camera_model == "eucm":
        return lambda p: project_eucm(i[2], i[3], i[4], i[5], i[0], i[1], p)
    if camera_model == "omni":
        return lambda p: project_omni(i[0], i[1], i[2], i[3], i[4], *coeffs, p)
    if camera_model == "pinhole" and distortion_model == "equidistant":
        return lambda p: project_kb4(*i, *coeffs, p)
    fail("unexpected camera model " + camera_model)


def basalt_projector(entry):
    k = entry["intrinsics"]
    t = entry["camera_type"]
    if t == "ds":
        return lambda p: project_ds(k["fx"], k["fy"], k["cx"], k["cy"], k["xi"], k["alpha"], p)
    if t == "eucm":
        return lambda p: project_eucm(k["fx"], k["fy"], k["cx"], k["cy"], k["alpha"], k["beta"], p)
    if t == "kb4":
        return lambda p: project_kb4(k["fx"], k["fy"], k["cx"], k["cy"], k["k1"], k["k2"], k["k3"], k["k4"], p)
    fail("unexpected Basalt camera_type " + t)


def read_calibration(export_dir, fmt, n):
    """Per camera: (projector, cam_from_rig 4x4, resolution) as the exported files say."""
    out = []
    if fmt == "kalibr":
        chain = yaml.safe_load(open(os.path.join(export_dir, "camchain.yaml")))
        for k in range(n):
            c = chain["cam%d" % k]
            cam_from_rig = np.array(c["T_cam_imu"], dtype=float)
            if k > 0:  # T_cn_cnm1 must agree with T_cam_imu
                expected = cam_from_rig @ np.linalg.inv(np.array(chain["cam%d" % (k - 1)]["T_cam_imu"], dtype=float))
                if np.abs(np.array(c["T_cn_cnm1"], dtype=float) - expected).max() > 1e-9:
                    fail("cam%d: T_cn_cnm1 disagrees with T_cam_imu" % k)
            proj = kalibr_projector(c["camera_model"], c["intrinsics"], c["distortion_model"], c["distortion_coeffs"])
            out.append((proj, cam_from_rig, c["resolution"]))
    elif fmt == "basalt":
        value = json.load(open(os.path.join(export_dir, "calibration.json")))["value0"]
        for key in ["calib_accel_bias", "calib_gyro_bias", "imu_update_rate", "accel_noise_std", "gyro_noise_std",
                    "accel_bias_std", "gyro_bias_std", "cam_time_offset_ns", "vignette"]:
            if key not in value:
                fail("calibration.json: value0/%s missing" % key)
        if len(value["calib_accel_bias"]) != 9 or len(value["calib_gyro_bias"]) != 12:
            fail("calibration.json: bias lengths")
        if not isinstance(value["cam_time_offset_ns"], int):
            fail("calibration.json: cam_time_offset_ns is not an integer")
        for k in range(n):
            t = value["T_imu_cam"][k]
            q = (t["qw"], t["qx"], t["qy"], t["qz"])
            if abs(math.sqrt(sum(v * v for v in q)) - 1) > 1e-9:
                fail("calibration.json: T_imu_cam/%d quaternion not normalised" % k)
            rig_from_cam = transform(quat_to_matrix(*q), [t["px"], t["py"], t["pz"]])
            res = value["resolution"][k]
            if not all(isinstance(v, int) for v in res):
                fail("calibration.json: resolution entries must be integers")
            out.append((basalt_projector(value["intrinsics"][k]), np.linalg.inv(rig_from_cam), res))
    else:
        for k in range(n):
            s = yaml.safe_load(open(os.path.join(export_dir, "mav0", "cam%d" % k, "sensor.yaml")))
            body_from_sensor = np.array(s["T_BS"]["data"], dtype=float).reshape(4, 4)
            proj = kalibr_projector(s["camera_model"], s["intrinsics"], s["distortion_model"],
                                    s["distortion_coefficients"])
            out.append((proj, np.linalg.inv(body_from_sensor), s["resolution"]))
    return out


def check_lenses(export_dir, dataset, fmt):
    report = json.load(open(os.path.join(export_dir, "rovo_export.json")))
    cameras = dataset["rig"]["cameras"]
    exported = read_calibration(export_dir, fmt, len(cameras))
    rng = np.random.default_rng(7)
    # Rig-frame points: directions over the whole sphere at 0.5 .. 30 m from the rig origin.
    dirs = rng.normal(size=(6000, 3))
    points = dirs / np.linalg.norm(dirs, axis=1)[:, None] * rng.uniform(0.5, 30, size=(6000, 1))
    for k, cam in enumerate(cameras):
        q = cam["cam_from_rig"]["rotation_xyzw"]
        truth = transform(quat_to_matrix(q[3], q[0], q[1], q[2]), cam["cam_from_rig"]["translation"])
        proj, cam_from_rig, res = exported[k]
        if res != [cam["width"], cam["height"]]:
            fail("cam%d: resolution %s, dataset %dx%d" % (k, res, cam["width"], cam["height"]))
        roll = math.radians(report["fits"][k].get("roll_deg", 0.0))
        rz = np.array([[math.cos(roll), -math.sin(roll), 0], [math.sin(roll), math.cos(roll), 0], [0, 0, 1]])
        if np.abs(cam_from_rig - transform(rz, [0, 0, 0]) @ truth).max() > 1e-9:
            fail("cam%d: exported extrinsics differ from dataset.json (turned by roll_deg)" % k)
        bound = report["fits"][k]["max_error_px"]
        if bound > report["max_fit_error_px"]:
            fail("cam%d: reported fit error above the stated bound" % k)
        worst, count = 0.0, 0
        for p in points:
            pc = truth[:3, :3] @ p + truth[:3, 3]
            angle = math.degrees(math.atan2(math.hypot(pc[0], pc[1]), pc[2]))
            if angle > cam["max_fov_deg"] / 2 or math.hypot(pc[0], pc[1]) == 0:
                continue
            if cam["model"] == "ocam":
                uv_true = project_ocam(cam["params"], pc)
            elif cam["model"] == "equidistant":  # FORMAT.md: fx fy cx cy k1..k4, Kannala-Brandt on the angle
                uv_true = project_kb4(*cam["params"][:8], pc)
            else:
                fail("this check needs ocam or equidistant lenses, not %s" % cam["model"])
            if not (-0.5 <= uv_true[0] < cam["width"] - 0.5 and -0.5 <= uv_true[1] < cam["height"] - 0.5):
                continue
            pe = cam_from_rig[:3, :3] @ p + cam_from_rig[:3, 3]
            uv = proj(pe)
            if uv is None:
                fail("cam%d: exported lens cannot project a point the rovo lens sees (%.1f deg)" % (k, angle))
            worst = max(worst, float(np.linalg.norm(uv - uv_true)))
            count += 1
        # The fit error is measured on a bearing grid; random points fall between grid nodes.
        if count < 500 or worst > bound * 1.05 + 1e-3:
            fail("cam%d: %d points, worst %.4f px, reported %.4f px" % (k, count, worst, bound))
        print("cam%d: %d rig points project within %.4f px (reported max %.4f px)" % (k, count, worst, bound))


def check_ground_truth(export_dir, dataset_dir):
    tum = np.loadtxt(os.path.join(dataset_dir, "groundtruth.tum"), comments="#")
    rows = []
    with open(os.path.join(export_dir, "mav0", "state_groundtruth_estimate0", "data.csv")) as f:
        for row in csv.reader(f):
            if row and not row[0].startswith("#"):
                rows.append(row)
    if len(rows) != len(tum):
        fail("ground truth: %d rows, groundtruth.tum %d" % (len(rows), len(tum)))
    for row, ref in zip(rows, tum):
        if len(row) != 17:
            fail("ground truth row with %d columns, EuRoC has 17" % len(row))
        stamp_ns = int(row[0])
        if stamp_ns != round(ref[0] * 1e9):
            fail("ground truth timestamp %d vs %.9f s" % (stamp_ns, ref[0]))
        p = np.array([float(v) for v in row[1:4]])
        if np.abs(p - ref[1:4]).max() > 1e-9:
            fail("ground truth position at %d" % stamp_ns)
        qw, qx, qy, qz = (float(v) for v in row[4:8])
        r = quat_to_matrix(qw, qx, qy, qz)
        r_ref = quat_to_matrix(ref[7], ref[4], ref[5], ref[6])
        angle = math.acos(max(-1.0, min(1.0, (np.trace(r.T @ r_ref) - 1) / 2)))
        if angle > 1e-7:
            fail("ground truth orientation at %d off by %g rad" % (stamp_ns, angle))
        if any(float(v) != 0.0 for v in row[11:17]):
            fail("biases must be zero")
    # Velocity: central difference of the positions.
    if len(tum) >= 3:
        v = (tum[2, 1:4] - tum[0, 1:4]) / (tum[2, 0] - tum[0, 0])
        if np.abs(np.array([float(x) for x in rows[1][8:11]]) - v).max() > 1e-6:
            fail("velocity is not the central difference")
    print("ground truth: %d poses match groundtruth.tum" % len(rows))


def read_png(path):
    """8-bit, non-interlaced PNG (grey, grey+alpha, RGB, RGBA) from the PNG specification (ISO/IEC 15948):
    IHDR, the concatenated IDAT zlib stream, per-row filters None/Sub/Up/Average/Paeth."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail("%s: not a PNG" % path)
    pos, idat = 8, b""
    while pos < len(data):
        length = int.from_bytes(data[pos:pos + 4], "big")
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height = int.from_bytes(body[0:4], "big"), int.from_bytes(body[4:8], "big")
            depth, color, interlace = body[8], body[9], body[12]
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    if depth != 8 or interlace != 0 or color not in (0, 2, 4, 6):
        fail("%s: unsupported PNG (depth %d, colour type %d)" % (path, depth, color))
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[color]
    raw = zlib.decompress(idat)
    stride = width * channels
    out = np.zeros((height, stride), dtype=np.int64)
    prev = np.zeros(stride, dtype=np.int64)
    for y in range(height):
        row = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * (stride + 1) + 1).astype(np.int64)
        kind = raw[y * (stride + 1)]
        if kind == 0:
            cur = row
        elif kind == 2:
            cur = (row + prev) % 256
        else:  # Sub, Average, Paeth depend on the left neighbour: byte by byte
            cur = np.zeros(stride, dtype=np.int64)
            for x in range(stride):
                a = cur[x - channels] if x >= channels else 0
                b = prev[x]
                c = prev[x - channels] if x >= channels else 0
                if kind == 1:
                    pred = a
                elif kind == 3:
                    pred = (a + b) // 2
                else:
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                cur[x] = (row[x] + pred) % 256
        out[y] = cur
        prev = cur
    return out.reshape(height, width, channels)


def srgb_to_linear(v):
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def linear_to_srgb(v):
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)


def expected_grey(rgb):
    """Relative luminance (Rec. 709 / sRGB primaries) of the linearised sRGB values, sRGB-encoded."""
    lin = srgb_to_linear(rgb[:, :, :3] / 255.0)
    y = 0.2126 * lin[:, :, 0] + 0.7152 * lin[:, :, 1] + 0.0722 * lin[:, :, 2]
    return np.rint(255.0 * linear_to_srgb(np.clip(y, 0.0, 1.0)))


def check_images(export_dir, dataset_dir, dataset):
    tum = np.loadtxt(os.path.join(dataset_dir, "groundtruth.tum"), comments="#")
    grey = json.load(open(os.path.join(export_dir, "rovo_export.json"))).get("images", "").startswith("8-bit grey")
    for cam in dataset["rig"]["cameras"]:
        k = dataset["rig"]["cameras"].index(cam)
        with open(os.path.join(export_dir, "mav0", "cam%d" % k, "data.csv")) as f:
            rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
        if len(rows) != dataset["frame_count"]:
            fail("cam%d: %d images listed" % (k, len(rows)))
        for i, (stamp, name) in enumerate(rows):
            if int(stamp) != round(tum[i, 0] * 1e9) or name != stamp + ".png":
                fail("cam%d: row %d: %s,%s" % (k, i, stamp, name))
            exported = os.path.join(export_dir, "mav0", "cam%d" % k, "data", name)
            source = os.path.join(dataset_dir, cam["name"], "%06d.png" % i)
            if grey:
                a, b = read_png(exported), read_png(source)
                if a.shape != (b.shape[0], b.shape[1], 1):
                    fail("cam%d: image %s is not one grey channel of the source's size: %s" % (k, name, a.shape))
                diff = np.abs(a[:, :, 0] - expected_grey(b))
                if diff.max() > 1 or np.count_nonzero(diff) > 1e-4 * diff.size:
                    fail("cam%d: image %s: grey values differ from the luminance by up to %d" % (k, name, diff.max()))
            elif open(exported, "rb").read() != open(source, "rb").read():
                fail("cam%d: image %s differs from the dataset's frame %d" % (k, name, i))
    print("images: %s, named by their timestamps" % ("grey luminance of the dataset's" if grey else "identical"))


def main():
    export_dir, dataset_dir, fmt = sys.argv[1:4]
    dataset = json.load(open(os.path.join(dataset_dir, "dataset.json")))
    # A camera subset (--cameras): exported camK is the dataset camera rovo_export.json cameras[K] names.
    mapping = json.load(open(os.path.join(export_dir, "rovo_export.json"))).get("cameras")
    if mapping is not None:
        source = dataset["rig"]["cameras"]
        for k, entry in enumerate(mapping):
            if entry["name"] != "cam%d" % k or source[entry["source_index"]]["name"] != entry["source_name"]:
                fail("rovo_export.json: cameras[%d] = %s" % (k, entry))
        dataset["rig"]["cameras"] = [source[e["source_index"]] for e in mapping]
        for k in range(len(mapping), len(source) + 1):
            if os.path.exists(os.path.join(export_dir, "mav0", "cam%d" % k)):
                fail("cam%d exported, but rovo_export.json lists %d cameras" % (k, len(mapping)))
    check_lenses(export_dir, dataset, fmt)
    check_ground_truth(export_dir, dataset_dir)
    check_images(export_dir, dataset_dir, dataset)
    readme = open(os.path.join(export_dir, "README.md")).read()
    if "max error" not in readme or "T_BS" not in readme:
        fail("README lacks the fit table or the frame conventions")
    print("OK")


if __name__ == "__main__":
    main()

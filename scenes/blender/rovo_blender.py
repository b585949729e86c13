"""Shared helpers of the rovo Blender scripts (run inside `blender -b`, Blender 3.4, no numpy).

Frames
  Blender world: right-handed, z up, metres. rovo world: REP-103 (x forward, y left, z up). Both
  are z-up right-handed, so Blender world coordinates are used as rovo world coordinates unchanged.
  Blender camera: looks down its local -z, +y up, +x right. rovo camera: OpenCV (x right, y down,
  z forward):  point_in_cam_opencv = diag(1, -1, -1) * point_in_cam_blender.

Lens (Cycles 3.4, kernel/camera/projection.h, fisheye_to_direction, panorama type
FISHEYE_EQUIDISTANT with field of view `fov`): a raster position (x, y) in [0, W] x [0, H]
(pixel i covers [i, i + 1], y up) is normalised per axis, a = 2x/W - 1, b = 2y/H - 1; the ray
leaves at theta = sqrt(a^2 + b^2) * fov / 2 from the optical axis with azimuth atan2(b, a);
r > 1 casts no ray. In rovo's pixel convention (centre of the top-left pixel at (0, 0), v down)
this is exactly the equidistant model with
    fx = W / fov,  fy = H / fov,  cx = W / 2 - 0.5,  cy = H / 2 - 0.5,  k1..k4 = 0,
    max_fov_deg = degrees(fov)
(fx != fy for a non-square image: Cycles' image circle is then an ellipse, and so is ours).
The valid image area is the inscribed circle (ellipse) of the image.
"""

import math
import os
import re
import sys
import tempfile

import bpy
from mathutils import Matrix

# diag(1, -1, -1): Blender camera axes -> OpenCV camera axes (it is its own inverse).
BLENDER_CAM_TO_OPENCV = Matrix(((1.0, 0.0, 0.0, 0.0), (0.0, -1.0, 0.0, 0.0),
                                (0.0, 0.0, -1.0, 0.0), (0.0, 0.0, 0.0, 1.0)))


class ExportError(RuntimeError):
    """Bad input (.blend content or arguments); the message names the object and the field."""


def script_args(argv=None):
    """Arguments after `--` on the Blender command line."""
    argv = sys.argv if argv is None else argv
    return argv[argv.index("--") + 1:] if "--" in argv else []


def parse_frames(text, scene):
    """'A:B' -> Blender frames A..B-1 (half-open, like `rovo render --frames`); None -> the
    scene's frame_start..frame_end inclusive."""
    if text is None:
        return list(range(scene.frame_start, scene.frame_end + 1))
    m = re.fullmatch(r"\s*(-?\d+)\s*:\s*(-?\d+)\s*", text)
    if not m:
        raise ExportError("--frames: expected A:B (Blender frame numbers, B exclusive), got '%s'" % text)
    a, b = int(m.group(1)), int(m.group(2))
    if b <= a:
        raise ExportError("--frames %s: empty range (B must be greater than A)" % text)
    return list(range(a, b))


def rigid_from_matrix(m):
    """World matrix (possibly scaled) -> (rotation quaternion wxyz, translation, scale vector)."""
    loc, rot, scale = m.decompose()
    return rot.normalized(), loc, scale


def rigid_matrix(m):
    """The rigid part (rotation and translation) of a world matrix, scale removed."""
    rot, loc, _ = rigid_from_matrix(m)
    r = rot.to_matrix().to_4x4()
    r.translation = loc
    return r


def transform_json(m):
    """Rigid 4x4 -> {"rotation_xyzw", "translation"} (rovo JSON transform)."""
    q = m.to_quaternion().normalized()
    t = m.translation
    return {"rotation_xyzw": [q.x, q.y, q.z, q.w], "translation": [t.x, t.y, t.z]}


def find_rig(scene, name=None):
    """The rig Empty: `name` if given, else the first Empty called 'rig' or 'rig.*'/'rig_*'
    (case-insensitive) with camera children. Returns (rig object, [camera objects sorted by name]),
    or (None, []) when the file has no rig and no name was asked for."""
    if name is not None:
        rig = scene.objects.get(name)
        if rig is None:
            raise ExportError("--rig %s: no such object in scene '%s'" % (name, scene.name))
        cams = sorted((c for c in rig.children if c.type == "CAMERA"), key=lambda c: c.name)
        if not cams:
            raise ExportError("rig '%s': has no camera children" % name)
        return rig, cams
    for ob in sorted(scene.objects, key=lambda o: o.name):
        if ob.type != "EMPTY" or not re.fullmatch(r"rig([._\-].*)?", ob.name, re.IGNORECASE):
            continue
        cams = sorted((c for c in ob.children if c.type == "CAMERA"), key=lambda c: c.name)
        if cams:
            return ob, cams
    return None, []


def render_size(scene):
    pct = scene.render.resolution_percentage / 100.0
    return (int(round(scene.render.resolution_x * pct)), int(round(scene.render.resolution_y * pct)))


def equidistant_camera(cam_ob, scene):
    """rovo camera JSON fields (without name/cam_from_rig) of a Cycles FISHEYE_EQUIDISTANT camera.
    Raises ExportError for any other lens (rovo has no exact equivalent)."""
    data = cam_ob.data
    if data.type != "PANO":
        raise ExportError("camera '%s': type is %s, expected PANO (Cycles panoramic) with "
                          "panorama_type FISHEYE_EQUIDISTANT" % (cam_ob.name, data.type))
    ptype = data.cycles.panorama_type
    if ptype != "FISHEYE_EQUIDISTANT":
        raise ExportError("camera '%s': cycles.panorama_type is %s; only FISHEYE_EQUIDISTANT maps "
                          "exactly to rovo's equidistant model" % (cam_ob.name, ptype))
    if abs(scene.render.pixel_aspect_x - scene.render.pixel_aspect_y) > 1e-9:
        raise ExportError("scene '%s': render.pixel_aspect_x/y must be equal" % scene.name)
    fov = float(data.cycles.fisheye_fov)
    if not (0.0 < fov <= 2.0 * math.pi):
        raise ExportError("camera '%s': cycles.fisheye_fov %.6g rad out of range" % (cam_ob.name, fov))
    width, height = render_size(scene)
    return {
        "model": "equidistant",
        "width": width,
        "height": height,
        "params": [width / fov, height / fov, width / 2.0 - 0.5, height / 2.0 - 0.5, 0.0, 0.0, 0.0, 0.0],
        "max_fov_deg": math.degrees(fov),
    }


def cam_from_rig_matrix(cam_ob, rig_ob):
    """cam_from_rig (OpenCV camera) = (world_from_cam_blender * diag(1,-1,-1))^-1 * world_from_rig,
    both world matrices with their scale removed."""
    world_from_cam = rigid_matrix(cam_ob.matrix_world) @ BLENDER_CAM_TO_OPENCV
    return world_from_cam.inverted() @ rigid_matrix(rig_ob.matrix_world)


def atomic_path(path):
    """Temporary sibling of `path` (same folder, so os.replace is atomic)."""
    d = os.path.dirname(os.path.abspath(path))
    os.makedirs(d, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".%s." % os.path.basename(path), suffix=".tmp", dir=d)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the file ordinary permissions
    return tmp


def write_bytes_atomic(path, data):
    tmp = atomic_path(path)
    try:
        with open(tmp, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def rovo_version():
    """Version from the top-level CMakeLists.txt (project(rovo VERSION x.y.z)), or 'unknown'."""
    here = os.path.dirname(os.path.abspath(__file__))
    try:
        with open(os.path.join(here, "..", "..", "CMakeLists.txt")) as f:
            m = re.search(r"project\(\s*rovo\s+VERSION\s+([0-9.]+)", f.read())
            return m.group(1) if m else "unknown"
    except OSError:
        return "unknown"


def fail(message):
    """Print a message for the user and exit non-zero (Blender itself would exit 0)."""
    sys.stderr.write("error: %s\n" % message)
    sys.stderr.flush()
    os._exit(1)

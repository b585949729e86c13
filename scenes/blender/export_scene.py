"""Export a Blender scene to the rovo scene format (scenes/FORMAT.md).

    blender -b FILE.blend --python scenes/blender/export_scene.py -- OUT [--frames A:B] [--rig NAME]
                                                                        [--seed S]

Writes OUT/scene.json, OUT/geometry.bin, OUT/motion.bin, OUT/textures/*.png, OUT/trajectory.tum and,
when the file has a rig, OUT/rig.json (datasets/FORMAT.md rig JSON); every file atomically.

What is exported (depsgraph-evaluated, i.e. with modifiers applied at their viewport settings,
since a background Blender evaluates a viewport depsgraph; at the first exported frame):
  * every visible, render-enabled mesh-like object (mesh, curve, surface, text, metaball) and every
    instance (collection instances, particles, geometry-node instances): triangulated with
    loop_triangles; vertices are split where UVs differ (one rovo vertex per distinct
    (vertex, uv) pair of the active render UV map); instances of one source share a mesh.
  * object scale/shear is baked into the mesh (rovo transforms are rigid); a negative determinant
    flips the triangle winding so faces stay counter-clockwise.
  * objects whose world matrix changes over the frames are dynamic (ids 1..N, per-frame
    world_from_object in motion.bin); their mesh is the one of the first frame (rigid motion
    only: deformation is not exported). Instances are static.
  * materials: Principled BSDF (or Diffuse BSDF) Base Color: its value, or the first Image Texture
    found upstream of it (then base_color = 1, or the constant colour of a Multiply MixRGB node
    between them). Images are written as 8-bit sRGB PNG, top row first; UV v is flipped (rovo: v
    down from the top-left corner, Blender: v up from bottom-left). Emission: Principled Emission x
    Emission Strength (or an Emission shader). Blinn-Phong highlight: the custom properties
    rovo_specular and rovo_shininess (import_scene.py writes them).
  * objects that share a mesh datablock (and have no modifiers) share one rovo mesh; objects with
    the custom properties rovo_name / rovo_index (import_scene.py) keep that name and order.
  * lighting: the first render-enabled Sun lamp: direction_to_sun = its local +z,
    sun_radiance = colour * strength (irradiance; the renderer shades albedo * sun_radiance * cos / pi,
    the radiance Cycles computes for a Lambertian surface), angular diameter = its angle; world Background
    colour * strength -> uniform sky (zenith = horizon) with ambient 1, or the World's custom
    properties rovo_sky_zenith, rovo_sky_horizon, rovo_ground_albedo, rovo_ambient and
    rovo_lighting_preset when present; exposure from the film and view transform exposure.
  * point and spot lamps -> lights: intensity = colour * power / (4 pi) (Cycles' radiant intensity),
    range = the lamp's custom distance (Eevee's cutoff) when enabled, else 0; spot angle and blend;
    a lamp parented to an exported object rides on it. Area lamps are reported and ignored.
  * rig: an Empty named 'rig' (or --rig NAME) whose children are Cycles FISHEYE_EQUIDISTANT
    cameras: rig.json with one equidistant camera per child (sorted by name -> cam0, cam1, ...;
    lens mapping in rovo_blender.py) and cam_from_rig from the first frame; the trajectory is the
    Empty's world matrix (scale removed) per frame. Frame k of the export is Blender frame A + k,
    at timestamp k / fps. Without a rig the trajectory is identity at every frame.
Frames: --frames A:B exports Blender frames A..B-1; default: the scene's frame range (inclusive).
"""

import argparse
import json
import math
import os
import struct
import sys
import time
import zlib
from array import array

import bpy
from mathutils import Matrix, Vector

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rovo_blender as rb  # noqa: E402

MESH_TYPES = {"MESH", "CURVE", "SURFACE", "FONT", "META"}


def _le(arr):
    """Bytes of an array in little-endian order."""
    if sys.byteorder != "little":
        arr = array(arr.typecode, arr)
        arr.byteswap()
    return arr.tobytes()


# --------------------------------------------------------------------------------------------
# PNG writer (zlib + struct only): 8-bit RGB, no interlace, filter 0 on every row.

def _png_chunk(tag, data):
    return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)


def encode_png_rgb(width, height, rows_rgb):
    """rows_rgb: bytes of height rows (top first), each width*3 bytes."""
    stride = width * 3
    raw = bytearray()
    for y in range(height):
        raw.append(0)
        raw += rows_rgb[y * stride:(y + 1) * stride]
    return (b"\x89PNG\r\n\x1a\n" + _png_chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            _png_chunk(b"IDAT", zlib.compress(bytes(raw), 6)) + _png_chunk(b"IEND", b""))


def _srgb_encode(x):
    if x <= 0.0031308:
        return 12.92 * max(x, 0.0)
    return 1.055 * (x ** (1.0 / 2.4)) - 0.055


def image_to_srgb_rows(img):
    """Blender image -> (width, height, RGB bytes top row first, 8-bit sRGB)."""
    width, height = img.size
    if width == 0 or height == 0:
        raise rb.ExportError("image '%s': cannot be loaded (size 0; missing file %s?)" % (img.name, img.filepath))
    ch = img.channels
    px = array("f", [0.0]) * (width * height * ch)
    img.pixels.foreach_get(px)
    # Byte images hold their encoded values (pixels = byte / 255) and are copied; float images hold
    # scene-linear values and are sRGB-encoded (non-colour data is copied as it is).
    encode = img.is_float and img.colorspace_settings.name not in ("Non-Color", "Raw")
    if encode:
        px = array("f", (_srgb_encode(v) for v in px))
    vals = bytes(0 if v <= 0.0 else 255 if v >= 1.0 else int(v * 255.0 + 0.5) for v in px)
    out = bytearray(width * height * 3)
    row = width * ch
    for y in range(height):
        src = vals[(height - 1 - y) * row:(height - y) * row]  # Blender rows are bottom first
        d = y * width * 3
        for c in range(3):
            out[d + c:d + width * 3:3] = src[min(c, ch - 1)::ch] if ch >= 3 else src[0::ch]
    return width, height, bytes(out)


# --------------------------------------------------------------------------------------------
# Materials and textures.

def _upstream_image(socket, depth=0):
    """First Image Texture node feeding `socket` (depth-first through any node)."""
    if depth > 16 or not socket.is_linked:
        return None
    node = socket.links[0].from_node
    if node.type == "TEX_IMAGE" and node.image is not None:
        return node.image
    for inp in node.inputs:
        img = _upstream_image(inp, depth + 1)
        if img is not None:
            return img
    return None


def _multiply_tint(socket):
    """The constant colour of a Multiply MixRGB node (factor 1) feeding `socket` whose other colour
    input is linked (an image times a tint, as import_scene.py builds it), else None."""
    if not socket.is_linked:
        return None
    node = socket.links[0].from_node
    if node.type != "MIX_RGB" or node.blend_type != "MULTIPLY" or node.inputs["Fac"].is_linked or \
            abs(node.inputs["Fac"].default_value - 1.0) > 1e-9:
        return None
    a, b = node.inputs["Color1"], node.inputs["Color2"]
    const = b if a.is_linked and not b.is_linked else a if b.is_linked and not a.is_linked else None
    if const is None:
        return None
    v = const.default_value
    return float(v[0]), float(v[1]), float(v[2])


def material_albedo(mat):
    """(linear RGB base colour, image or None) of a Blender material."""
    if mat is None:
        return (0.8, 0.8, 0.8), None
    if mat.use_nodes and mat.node_tree is not None:
        for node in mat.node_tree.nodes:
            if node.type in ("BSDF_PRINCIPLED", "BSDF_DIFFUSE"):
                sock = node.inputs.get("Base Color") or node.inputs.get("Color")
                if sock is None:
                    break
                img = _upstream_image(sock)
                if img is not None:
                    return _multiply_tint(sock) or (1.0, 1.0, 1.0), img
                v = sock.default_value
                return (float(v[0]), float(v[1]), float(v[2])), None
    c = mat.diffuse_color
    return (float(c[0]), float(c[1]), float(c[2])), None


def material_extras(mat):
    """Optional rovo material fields: emission (Principled Emission x Emission Strength, or an
    Emission shader's Color x Strength) and the Blinn-Phong highlight (custom properties
    rovo_specular and rovo_shininess)."""
    extras = {}
    if mat is None:
        return extras
    if mat.use_nodes and mat.node_tree is not None:
        for node in mat.node_tree.nodes:
            if node.type == "BSDF_PRINCIPLED":
                c, k = node.inputs["Emission"].default_value, node.inputs["Emission Strength"].default_value
            elif node.type == "EMISSION":
                c, k = node.inputs["Color"].default_value, node.inputs["Strength"].default_value
            else:
                continue
            e = [float(c[0] * k), float(c[1] * k), float(c[2] * k)]
            if max(e) > 0.0:
                extras["emission"] = e
                break
    if float(mat.get("rovo_specular", 0.0)) > 0.0:
        extras["specular"] = float(mat["rovo_specular"])
        extras["shininess"] = float(mat.get("rovo_shininess", 0.0))
    return extras


class Exporter:
    def __init__(self, scene, out_dir, frames, rig_name=None, seed=0):
        self.scene = scene
        self.out = out_dir
        self.frames = frames
        self.seed = seed
        self.rig, self.rig_cams = rb.find_rig(scene, rig_name)
        self.textures = []       # scene.json entries
        self.texture_index = {}  # image name -> index
        self.materials = []
        self.material_index = {}
        self.meshes = []         # scene.json entries
        self.mesh_index = {}     # key -> index
        self.geometry = bytearray()
        self.objects = []        # dicts: name, mesh, matrix (rigid), source object name or None
        self.warnings = []
        self.instance_names = {}  # instance name -> count, for unique names

    def warn(self, text):
        self.warnings.append(text)
        print("warning: " + text)

    # ---- materials -------------------------------------------------------------------------
    def texture_for(self, img):
        if img.name in self.texture_index:
            return self.texture_index[img.name]
        width, height, rows = image_to_srgb_rows(img)
        index = len(self.textures)
        rel = "textures/%03d.png" % index
        rb.write_bytes_atomic(os.path.join(self.out, rel), encode_png_rgb(width, height, rows))
        self.textures.append({"name": img.name, "file": rel, "width": width, "height": height})
        self.texture_index[img.name] = index
        return index

    def material_for(self, mat):
        key = mat.name if mat is not None else ""
        if key in self.material_index:
            return self.material_index[key]
        color, img = material_albedo(mat)
        entry = {"name": key or "default", "base_color": list(color),
                 "texture": self.texture_for(img) if img is not None else -1}
        entry.update(material_extras(mat))
        self.material_index[key] = len(self.materials)
        self.materials.append(entry)
        return self.material_index[key]

    # ---- geometry --------------------------------------------------------------------------
    def add_mesh(self, name, ob_eval, linear):
        """Triangulated mesh of an evaluated object with `linear` (3x3, object scale/shear) baked
        in. Returns the mesh index, or None for an empty mesh."""
        me = ob_eval.to_mesh()
        try:
            me.calc_loop_triangles()
            nt = len(me.loop_triangles)
            if nt == 0:
                return None
            nv, nl = len(me.vertices), len(me.loops)
            co = array("f", [0.0]) * (nv * 3)
            me.vertices.foreach_get("co", co)
            tri_loops = array("i", [0]) * (nt * 3)
            me.loop_triangles.foreach_get("loops", tri_loops)
            tri_mat_slot = array("i", [0]) * nt
            me.loop_triangles.foreach_get("material_index", tri_mat_slot)
            loop_vertex = array("i", [0]) * nl
            me.loops.foreach_get("vertex_index", loop_vertex)
            uv_layer = None
            for layer in me.uv_layers:
                if layer.active_render:
                    uv_layer = layer
            if uv_layer is None and len(me.uv_layers):
                uv_layer = me.uv_layers.active
            positions = array("f")
            uvs = array("f")
            triangles = array("i", [0]) * (nt * 3)
            if uv_layer is not None:
                loop_uv = array("f", [0.0]) * (nl * 2)
                uv_layer.data.foreach_get("uv", loop_uv)
                remap = {}
                for i in range(nt * 3):
                    li = tri_loops[i]
                    vi = loop_vertex[li]
                    u, v = loop_uv[2 * li], loop_uv[2 * li + 1]
                    key = (vi, u, v)
                    idx = remap.get(key)
                    if idx is None:
                        idx = len(remap)
                        remap[key] = idx
                        positions.extend(co[3 * vi:3 * vi + 3])
                        uvs.append(u)
                        uvs.append(1.0 - v)  # Blender v up from the bottom -> rovo v down from the top
                    triangles[i] = idx
            else:
                positions = co
                for i in range(nt * 3):
                    triangles[i] = loop_vertex[tri_loops[i]]
            # Per-triangle materials through the object's material slots.
            slots = [s.material for s in ob_eval.material_slots]
            slot_to_material = [self.material_for(m) for m in slots] or [self.material_for(None)]
            tri_mats = array("i", (slot_to_material[min(max(s, 0), len(slot_to_material) - 1)] for s in tri_mat_slot))
        finally:
            ob_eval.to_mesh_clear()

        if linear is not None:
            a = [[linear[r][c] for c in range(3)] for r in range(3)]
            for i in range(0, len(positions), 3):
                x, y, z = positions[i], positions[i + 1], positions[i + 2]
                positions[i] = a[0][0] * x + a[0][1] * y + a[0][2] * z
                positions[i + 1] = a[1][0] * x + a[1][1] * y + a[1][2] * z
                positions[i + 2] = a[2][0] * x + a[2][1] * y + a[2][2] * z
            if linear.determinant() < 0.0:
                for i in range(0, len(triangles), 3):
                    triangles[i + 1], triangles[i + 2] = triangles[i + 2], triangles[i + 1]

        vcount = len(positions) // 3
        entry = {"name": name, "material": tri_mats[0], "buffer": "geometry.bin",
                 "vertex_count": vcount, "triangle_count": nt}
        entry["positions_offset"] = len(self.geometry)
        self.geometry += _le(positions)
        if len(uvs):
            entry["uvs_offset"] = len(self.geometry)
            self.geometry += _le(uvs)
        else:
            entry["uvs_offset"] = -1
        entry["triangles_offset"] = len(self.geometry)
        self.geometry += _le(triangles)
        if min(tri_mats) != max(tri_mats):
            entry["triangle_materials_offset"] = len(self.geometry)
            self.geometry += _le(tri_mats)
        else:
            entry["triangle_materials_offset"] = -1
        self.meshes.append(entry)
        return len(self.meshes) - 1

    @staticmethod
    def split_matrix(m):
        """world matrix -> (rigid world_from_object 4x4, object-frame linear part 3x3 or None)."""
        rigid = rb.rigid_matrix(m)
        linear = rigid.to_3x3().transposed() @ m.to_3x3()
        # 1e-6: float32 rotations of unscaled objects deviate from orthonormal by about 1e-7.
        ident = all(abs(linear[r][c] - (1.0 if r == c else 0.0)) < 1e-6 for r in range(3) for c in range(3))
        return rigid, (None if ident else linear)

    def collect_geometry(self):
        depsgraph = bpy.context.evaluated_depsgraph_get()
        skip = set([self.rig.name] if self.rig else []) | set(c.name for c in self.rig_cams)
        for inst in depsgraph.object_instances:
            ob = inst.object
            if ob.type not in MESH_TYPES or ob.original.name in skip:
                continue
            if inst.is_instance:
                parent = inst.parent  # the instancer
                if parent is not None and (parent.original.hide_render or parent.original == ob.original):
                    # Hidden instancer, or an object's own evaluated geometry (curves and text are
                    # also listed as an instance of themselves): exported once, as the object.
                    continue
            elif ob.original.hide_render:
                continue
            rigid, linear = self.split_matrix(inst.matrix_world.copy())
            src = ob.original.name
            key = ("instance:" if inst.is_instance else "object:") + src
            if not inst.is_instance and ob.original.type == "MESH" and not ob.original.modifiers:
                key = "data:" + ob.original.data.name  # objects sharing a mesh datablock share the mesh
            if linear is not None:
                key += ":" + ",".join("%.7g" % linear[r][c] for r in range(3) for c in range(3))
            if key not in self.mesh_index:
                mesh_name = ob.original.data.name if key.startswith("data:") else src
                self.mesh_index[key] = self.add_mesh(mesh_name, ob, linear)
            mesh = self.mesh_index[key]
            if mesh is None:
                continue
            name = ob.original.get("rovo_name", src) if not inst.is_instance else src
            if inst.is_instance:
                name = "%s[%s]" % (src, inst.parent.original.name if inst.parent is not None else "")
                self.instance_names[name] = self.instance_names.get(name, 0) + 1
                if self.instance_names[name] > 1:
                    name += "#%d" % (self.instance_names[name] - 1)
            self.objects.append({"name": name, "mesh": mesh, "matrix": rigid,
                                 "source": None if inst.is_instance else src, "linear": linear,
                                 "order": ob.original.get("rovo_index", -1) if not inst.is_instance else -1})
        # Objects made by import_scene.py keep their rovo order (the others follow, as listed).
        if any(o["order"] >= 0 for o in self.objects):
            big = len(self.objects) + 1
            self.objects = [o for _, o in sorted(enumerate(self.objects), key=lambda io: (
                io[1]["order"] if io[1]["order"] >= 0 else big + io[0]))]

    # ---- lighting --------------------------------------------------------------------------
    def lighting(self):
        scene = self.scene
        light = {"preset": "blender", "direction_to_sun": [0.0, 0.0, 1.0], "sun_radiance": [0.0, 0.0, 0.0],
                 "sun_angular_diameter_deg": 0.53, "sky_zenith": [0.0, 0.0, 0.0], "sky_horizon": [0.0, 0.0, 0.0],
                 "ground_albedo": [0.3, 0.3, 0.3], "ambient": 1.0, "exposure": 1.0}
        suns = [o for o in sorted(scene.objects, key=lambda o: o.name)
                if o.type == "LIGHT" and o.data.type == "SUN" and not o.hide_render]
        if suns:
            sun = suns[0]
            if len(suns) > 1:
                self.warn("%d sun lamps; exporting '%s' only" % (len(suns), sun.name))
            z = sun.matrix_world.to_3x3().normalized().col[2]
            light["direction_to_sun"] = [z.x, z.y, z.z]
            k = sun.data.energy  # W/m^2 irradiance; the renderer divides by pi (Lambertian)
            light["sun_radiance"] = [sun.data.color[0] * k, sun.data.color[1] * k, sun.data.color[2] * k]
            light["sun_angular_diameter_deg"] = math.degrees(sun.data.angle)
        others = [o.name for o in scene.objects
                  if o.type == "LIGHT" and o.data.type not in ("SUN", "POINT", "SPOT") and not o.hide_render]
        if others:
            self.warn("area lights are not exported: %s" % ", ".join(sorted(others)))
        world = scene.world
        if world is not None:
            color, strength = (world.color[0], world.color[1], world.color[2]), 1.0
            if world.use_nodes and world.node_tree is not None:
                bg = next((n for n in world.node_tree.nodes if n.type == "BACKGROUND"), None)
                if bg is not None:
                    c = bg.inputs["Color"]
                    if c.is_linked:
                        self.warn("world '%s': Background colour is linked to nodes; using its default value" %
                                  world.name)
                    color = (c.default_value[0], c.default_value[1], c.default_value[2])
                    strength = bg.inputs["Strength"].default_value
            sky = [float(v * strength) for v in color]
            light["sky_zenith"] = sky
            light["sky_horizon"] = list(sky)
            if "rovo_sky_zenith" in world:  # written by import_scene.py: rovo's sky model exactly
                light["preset"] = str(world.get("rovo_lighting_preset", "blender"))
                light["sky_zenith"] = [float(v) for v in world["rovo_sky_zenith"]]
                light["sky_horizon"] = [float(v) for v in world["rovo_sky_horizon"]]
                light["ground_albedo"] = [float(v) for v in world["rovo_ground_albedo"]]
                light["ambient"] = float(world["rovo_ambient"])
        light["exposure"] = float(scene.cycles.film_exposure) * 2.0 ** float(scene.view_settings.exposure)
        return light

    def point_lights(self):
        """Point and spot lamps (at the first exported frame) -> rovo lights. A lamp whose parent is
        an exported object rides on it (position and spot axis in the parent's rigid frame);
        otherwise it is fixed in the world. Radius (soft shadows) is ignored: rovo lights are points."""
        exported = {o["source"]: i for i, o in enumerate(self.objects) if o["source"] is not None}
        lights = []
        soft = []
        for ob in sorted(self.scene.objects, key=lambda o: o.name):
            if ob.type != "LIGHT" or ob.data.type not in ("POINT", "SPOT") or ob.hide_render:
                continue
            d = ob.data
            if d.shadow_soft_size > 0.0:
                soft.append(ob.name)
            frame = Matrix.Identity(4)
            index = -1
            if ob.parent is not None and ob.parent.name in exported:
                index = exported[ob.parent.name]
                frame = rb.rigid_matrix(ob.parent.matrix_world).inverted()
            m = frame @ rb.rigid_matrix(ob.matrix_world)
            k = d.energy / (4.0 * math.pi)  # Cycles: radiant intensity = power / (4 pi)
            entry = {"name": ob.get("rovo_name", ob.name), "position": list(m.translation),
                     "intensity": [d.color[0] * k, d.color[1] * k, d.color[2] * k],
                     "range": float(d.cutoff_distance) if d.use_custom_distance else 0.0, "object": index}
            if d.type == "SPOT":
                axis = m.to_3x3() @ Vector((0.0, 0.0, -1.0))  # a spot shines along its local -z
                entry["spot"] = {"direction": list(axis), "angle_deg": min(180.0, math.degrees(d.spot_size)),
                                 "blend": float(d.spot_blend)}
            lights.append(entry)
        if soft:
            self.warn("%d point/spot lamps have a radius > 0 (soft shadows); exported as points" % len(soft))
        return lights

    # ---- animation -------------------------------------------------------------------------
    def sample_animation(self):
        """Per exported frame: world_from_rig and the world matrix of every non-instance object."""
        scene = self.scene
        tracked = sorted(set(o["source"] for o in self.objects if o["source"] is not None))
        rig_poses, object_poses = [], {name: [] for name in tracked}
        cam_from_rig = None
        for k, frame in enumerate(self.frames):
            scene.frame_set(frame)
            if self.rig is not None:
                rig_poses.append(rb.rigid_matrix(self.rig.matrix_world))
                now = [rb.cam_from_rig_matrix(c, self.rig) for c in self.rig_cams]
                if cam_from_rig is None:
                    cam_from_rig = now
                else:
                    # Blender composes parent and child in float32: allow its rounding at the
                    # rig's distance from the origin (1e-5 in rotation, 1e-6 relative in position).
                    far = 1.0 + self.rig.matrix_world.translation.length
                    for c, a, b in zip(self.rig_cams, cam_from_rig, now):
                        if max(abs(a[r][s] - b[r][s]) for r in range(3) for s in range(3)) > 1e-5 or \
                                max(abs(a[r][3] - b[r][3]) for r in range(3)) > 1e-5 + 1e-6 * far:
                            self.warn("camera '%s' moves relative to the rig at frame %d; cam_from_rig is "
                                      "the one of frame %d" % (c.name, frame, self.frames[0]))
            for name in tracked:
                object_poses[name].append(scene.objects[name].matrix_world.copy())
        scene.frame_set(self.frames[0])
        return rig_poses, object_poses, cam_from_rig

    # ---- output ----------------------------------------------------------------------------
    def run(self):
        t0 = time.perf_counter()
        scene = self.scene
        os.makedirs(self.out, exist_ok=True)
        scene.frame_set(self.frames[0])
        rig_json = None
        if self.rig is not None:
            cams = []
            for i, c in enumerate(self.rig_cams):
                cam = {"name": "cam%d" % i}
                cam.update(rb.equidistant_camera(c, scene))
                cams.append(cam)
        else:
            self.warn("no rig (an Empty named 'rig' with camera children): trajectory is identity")
        self.collect_geometry()
        rig_poses, object_poses, cam_from_rig = self.sample_animation()
        if self.rig is not None:
            for cam, m in zip(cams, cam_from_rig):
                cam["cam_from_rig"] = rb.transform_json(m)
            rig_json = {"schema_version": 1,
                        "source": "blender %s: rig '%s' (cameras %s)" % (
                            os.path.basename(bpy.data.filepath), self.rig.name,
                            ", ".join(c.name for c in self.rig_cams)),
                        "cameras": cams}

        fps = scene.render.fps / scene.render.fps_base
        n = len(self.frames)
        motion = bytearray()
        objects_json = []
        next_id = 1
        for o in self.objects:
            entry = {"name": o["name"], "mesh": o["mesh"], "id": 0}
            poses = object_poses.get(o["source"]) if o["source"] is not None else None
            first = o["matrix"]
            dynamic = poses is not None and any(
                max(abs(p[r][s] - poses[0][r][s]) for r in range(4) for s in range(4)) > 1e-9 for p in poses)
            if dynamic:
                entry["id"] = next_id
                next_id += 1
                entry["motion"] = {"buffer": "motion.bin", "offset": len(motion), "frames": n}
                records = array("d")
                for p in poses:
                    rigid, linear = self.split_matrix(p)
                    if (linear is None) != (o["linear"] is None) or (
                            linear is not None and max(abs(linear[r][c] - o["linear"][r][c])
                                                       for r in range(3) for c in range(3)) > 1e-6):
                        self.warn("object '%s': scale changes over the frames; exported with the first "
                                  "frame's scale" % o["name"])
                    q, t = rigid.to_quaternion().normalized(), rigid.translation
                    records.extend((q.x, q.y, q.z, q.w, t.x, t.y, t.z))
                motion += _le(records)
            else:
                entry["world_from_object"] = rb.transform_json(first)
            objects_json.append(entry)
        if next_id > 65536:
            raise rb.ExportError("more than 65535 dynamic objects")

        traj_lines = ["# world_from_rig exported from %s, Blender frames %d..%d at %.9g fps" % (
            os.path.basename(bpy.data.filepath) or "(unsaved)", self.frames[0], self.frames[-1], fps),
            "# timestamp tx ty tz qx qy qz qw"]
        for k in range(n):
            if rig_poses:
                m = rig_poses[k]
                q, t = m.to_quaternion().normalized(), m.translation
                vals = (t.x, t.y, t.z, q.x, q.y, q.z, q.w)
            else:
                vals = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
            traj_lines.append(" ".join(["%.17g" % (k / fps)] + ["%.17g" % v for v in vals]))

        if not self.materials:
            self.material_for(None)
        scene_json = {
            "format": "rovo-scene",
            "format_version": 1,
            "metadata": {"generator": "rovo-blender-export", "generator_version": rb.rovo_version(),
                         "preset": "blender", "seed": self.seed,
                         "source": "%s (Blender %s, scene '%s', frames %d..%d)" % (
                             bpy.data.filepath, bpy.app.version_string, scene.name, self.frames[0],
                             self.frames[-1])},
            "frame_rate": fps,
            "rig_preset": "",
            "trajectory": "trajectory.tum",
            "lighting": self.lighting(),
            "textures": self.textures,
            "materials": self.materials,
            "meshes": self.meshes,
            "objects": objects_json,
            "lights": self.point_lights(),
            "blender": {"frames": self.frames, "rig": self.rig.name if self.rig else None,
                        "rig_cameras": [c.name for c in self.rig_cams], "warnings": self.warnings},
        }
        rb.write_bytes_atomic(os.path.join(self.out, "geometry.bin"), bytes(self.geometry))
        rb.write_bytes_atomic(os.path.join(self.out, "motion.bin"), bytes(motion))
        rb.write_bytes_atomic(os.path.join(self.out, "trajectory.tum"), ("\n".join(traj_lines) + "\n").encode())
        if rig_json is not None:
            rb.write_bytes_atomic(os.path.join(self.out, "rig.json"), (json.dumps(rig_json, indent=2) + "\n").encode())
        # scene.json last: a folder with scene.json is complete.
        rb.write_bytes_atomic(os.path.join(self.out, "scene.json"), (json.dumps(scene_json, indent=1) + "\n").encode())
        tris = sum(m["triangle_count"] for m in self.meshes)
        print("exported %s: %d objects (%d dynamic), %d meshes, %d triangles, %d materials, %d textures, "
              "%d frames, rig %s, %.2f s" % (
                  self.out, len(objects_json), next_id - 1, len(self.meshes), tris, len(self.materials),
                  len(self.textures), n, ("%d cameras" % len(self.rig_cams)) if self.rig else "none",
                  time.perf_counter() - t0))


def main():
    parser = argparse.ArgumentParser(
        prog="blender -b FILE.blend --python export_scene.py --",
        description="Export the open Blender scene to a rovo scene folder (scenes/FORMAT.md).")
    parser.add_argument("out", help="output scene folder (created)")
    parser.add_argument("--frames", help="Blender frames A:B (B exclusive); default: the scene's frame range")
    parser.add_argument("--rig", help="name of the rig Empty (default: an Empty named 'rig' with camera children)")
    parser.add_argument("--seed", type=int, default=0, help="seed recorded in the metadata (default 0)")
    args = parser.parse_args(rb.script_args())
    try:
        scene = bpy.context.scene
        Exporter(scene, args.out, rb.parse_frames(args.frames, scene), args.rig, args.seed).run()
    except rb.ExportError as e:
        rb.fail(str(e))


if __name__ == "__main__":
    main()

"""Import a rovo scene folder (scenes/FORMAT.md) into Blender and save it as a .blend.

    blender -b --factory-startup --python scenes/blender/import_scene.py -- SCENE OUT.blend
        [--rig RIG.json] [--frames A:B]

The inverse of export_scene.py: exporting the saved .blend gives back the scene (same objects,
meshes, materials, textures, lights, lighting and trajectory, up to float32 rounding of Blender's
transforms and of 1 - (1 - v) in the UVs), so procedural presets can be edited in Blender, rendered
in Cycles and round-tripped. What is created:
  * one mesh datablock per rovo mesh (objects that share a rovo mesh share it), one object per rovo
    object (custom properties rovo_name and rovo_index keep its name, which Blender makes unique,
    and its place in the list); dynamic objects get a keyframe per frame (location + quaternion,
    linear);
  * materials: a Diffuse BSDF at roughness 0 (Lambertian, as rovo shades) whose colour is
    base_color, or an Image Texture (packed into the .blend) times base_color through a Multiply
    MixRGB node; emission: an Emission shader added to it for camera rays only (Light Path "Is
    Camera Ray"; in rovo an emissive surface is seen but lights nothing); a material with a highlight gets a
    Principled BSDF instead, whose Specular/Roughness approximate it for Cycles, and the custom
    properties `rovo_specular` and `rovo_shininess` keep the exact values for the exporter;
  * lights: point -> POINT lamp, spot -> SPOT lamp (radius 0, power = 4 pi max(intensity), colour
    = intensity / max, spot_size = angle, spot_blend = blend, cutoff_distance = range with
    use_custom_distance when range > 0); a light on an object is parented to that object;
  * the sun -> a SUN lamp (strength = max(sun_radiance), local +z = direction_to_sun); the sky ->
    the World background (mean of zenith and horizon times ambient, for Cycles) plus the custom
    properties rovo_sky_zenith, rovo_sky_horizon, rovo_ground_albedo, rovo_ambient and
    rovo_lighting_preset, which the exporter reads back; exposure -> film exposure x 2^(view
    exposure), the film exposure at most 10 (Blender's limit);
  * the trajectory -> an Empty 'rig' keyframed per frame; with --rig, its cameras (equidistant only,
    in Cycles' exact mapping, see rovo_blender.py) as FISHEYE_EQUIDISTANT children cam0, cam1, ...
Frames: scene frame k is Blender frame 1 + k - A (--frames A:B imports frames A..B-1; default all).
"""

import argparse
import json
import math
import os
import struct
import sys
from array import array

import bpy
from mathutils import Matrix, Quaternion, Vector

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rovo_blender as rb  # noqa: E402


def read_array(buffers, folder, name, offset, count, typecode):
    """`count` little-endian values of `typecode` ('f', 'i', 'd') from buffer file `name`."""
    if name not in buffers:
        with open(os.path.join(folder, name), "rb") as f:
            buffers[name] = f.read()
    a = array(typecode)
    size = a.itemsize * count
    data = buffers[name][offset:offset + size]
    if len(data) != size:
        raise rb.ExportError("%s: range [%d, %d) outside the buffer" % (name, offset, offset + size))
    a.frombytes(data)
    if sys.byteorder != "little":
        a.byteswap()
    return a


def matrix_from_rigid(q_xyzw, t):
    m = Quaternion((q_xyzw[3], q_xyzw[0], q_xyzw[1], q_xyzw[2])).to_matrix().to_4x4()
    m.translation = Vector(t)
    return m


def read_tum(path):
    poses = []
    with open(path) as f:
        for line in f:
            s = line.strip()
            if not s or s.startswith("#"):
                continue
            v = [float(x) for x in s.split()]
            poses.append((v[0], matrix_from_rigid(v[4:8], v[1:4])))
    return poses


class Importer:
    def __init__(self, folder, rig_json, frames_arg):
        self.folder = folder
        self.scene_json = json.load(open(os.path.join(folder, "scene.json")))
        self.rig_json = rig_json
        self.trajectory = read_tum(os.path.join(folder, self.scene_json["trajectory"]))
        n = len(self.trajectory)
        self.first, self.last = 0, n
        if frames_arg:
            a, b = (int(x) for x in frames_arg.split(":"))
            if not (0 <= a < b <= n):
                raise rb.ExportError("--frames %s: outside the scene's %d frames" % (frames_arg, n))
            self.first, self.last = a, b
        self.buffers = {}
        self.images, self.materials, self.meshes, self.objects = [], [], [], []

    # ---- materials -------------------------------------------------------------------------
    def make_images(self):
        for t in self.scene_json["textures"]:
            img = bpy.data.images.load(os.path.abspath(os.path.join(self.folder, t["file"])))
            img.name = t["name"]
            img.colorspace_settings.name = "sRGB"
            img.pack()
            self.images.append(img)

    def make_material(self, m):
        """Matte: a Diffuse BSDF (Lambertian at roughness 0, like rovo); with a highlight: a
        Principled BSDF whose Specular/Roughness approximate it; emission: an Emission shader added."""
        mat = bpy.data.materials.new(m["name"])
        mat.use_nodes = True
        nt = mat.node_tree
        nt.nodes.clear()
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        specular = m.get("specular", 0.0)
        if specular > 0.0:
            bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
            colour = bsdf.inputs["Base Color"]
            mat["rovo_specular"] = specular
            mat["rovo_shininess"] = m["shininess"]
            bsdf.inputs["Specular"].default_value = min(1.0, specular / 0.08)
            bsdf.inputs["Roughness"].default_value = (2.0 / (m["shininess"] + 2.0)) ** 0.25
        else:
            bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
            colour = bsdf.inputs["Color"]
            bsdf.inputs["Roughness"].default_value = 0.0
        base = m["base_color"]
        if m["texture"] >= 0:
            tex = nt.nodes.new("ShaderNodeTexImage")
            tex.image = self.images[m["texture"]]
            tex.interpolation = "Linear"
            mix = nt.nodes.new("ShaderNodeMixRGB")
            mix.blend_type = "MULTIPLY"
            mix.inputs["Fac"].default_value = 1.0
            nt.links.new(tex.outputs["Color"], mix.inputs["Color1"])
            mix.inputs["Color2"].default_value = (base[0], base[1], base[2], 1.0)
            nt.links.new(mix.outputs["Color"], colour)
        else:
            colour.default_value = (base[0], base[1], base[2], 1.0)
        shader = bsdf.outputs[0]
        emission = m.get("emission", [0.0, 0.0, 0.0])
        strength = max(emission)
        if strength > 0.0:
            em = nt.nodes.new("ShaderNodeEmission")
            em.inputs["Color"].default_value = (emission[0] / strength, emission[1] / strength,
                                                emission[2] / strength, 1.0)
            em.inputs["Strength"].default_value = strength
            # Seen by camera rays only: rovo's emission lights nothing (the scene's lights do).
            path = nt.nodes.new("ShaderNodeLightPath")
            camera_only = nt.nodes.new("ShaderNodeMixShader")
            nt.links.new(path.outputs["Is Camera Ray"], camera_only.inputs["Fac"])
            nt.links.new(em.outputs[0], camera_only.inputs[2])
            add = nt.nodes.new("ShaderNodeAddShader")
            nt.links.new(shader, add.inputs[0])
            nt.links.new(camera_only.outputs[0], add.inputs[1])
            shader = add.outputs[0]
            mat.cycles.sample_as_light = False
        nt.links.new(shader, out.inputs["Surface"])
        return mat

    # ---- geometry --------------------------------------------------------------------------
    def make_mesh(self, j):
        nv, nt = j["vertex_count"], j["triangle_count"]
        buf = j["buffer"]
        pos = read_array(self.buffers, self.folder, buf, j["positions_offset"], nv * 3, "f")
        tris = read_array(self.buffers, self.folder, buf, j["triangles_offset"], nt * 3, "i")
        me = bpy.data.meshes.new(j["name"])
        me.vertices.add(nv)
        me.vertices.foreach_set("co", pos)
        me.loops.add(nt * 3)
        me.loops.foreach_set("vertex_index", tris)
        me.polygons.add(nt)
        me.polygons.foreach_set("loop_start", array("i", range(0, nt * 3, 3)))
        me.polygons.foreach_set("loop_total", array("i", [3]) * nt)
        if j["uvs_offset"] >= 0:
            uv = read_array(self.buffers, self.folder, buf, j["uvs_offset"], nv * 2, "f")
            loop_uv = array("f", [0.0]) * (nt * 6)
            for k in range(nt * 3):
                v = tris[k]
                loop_uv[2 * k] = uv[2 * v]
                loop_uv[2 * k + 1] = 1.0 - uv[2 * v + 1]  # rovo v down from the top -> Blender v up
            me.uv_layers.new(name="UVMap").data.foreach_set("uv", loop_uv)
        if j["triangle_materials_offset"] >= 0:
            tri_mats = read_array(self.buffers, self.folder, buf, j["triangle_materials_offset"], nt, "i")
        else:
            tri_mats = array("i", [j["material"]]) * nt
        slots = sorted(set(tri_mats), key=lambda m: (m != j["material"], m))  # the mesh material first
        slot_of = {m: i for i, m in enumerate(slots)}
        for m in slots:
            me.materials.append(self.materials[m])
        me.polygons.foreach_set("material_index", array("i", (slot_of[m] for m in tri_mats)))
        me.update(calc_edges=True)
        me.validate(clean_customdata=False)
        return me

    def make_objects(self, scene):
        coll = scene.collection
        n = self.last - self.first
        for index, j in enumerate(self.scene_json["objects"]):
            ob = bpy.data.objects.new(j["name"], self.meshes[j["mesh"]])
            coll.objects.link(ob)
            # Blender makes names unique ('parked_car.001'); the exporter restores name and order.
            ob["rovo_name"] = j["name"]
            ob["rovo_index"] = index
            ob.rotation_mode = "QUATERNION"
            if "world_from_object" in j:
                w = j["world_from_object"]
                ob.matrix_world = matrix_from_rigid(w["rotation_xyzw"], w["translation"])
            else:
                mo = j["motion"]
                rec = read_array(self.buffers, self.folder, mo["buffer"], mo["offset"] + 56 * self.first, 7 * n, "d")
                for k in range(n):
                    r = rec[7 * k:7 * k + 7]
                    ob.matrix_world = matrix_from_rigid(r[0:4], r[4:7])
                    ob.keyframe_insert("location", frame=1 + k)
                    ob.keyframe_insert("rotation_quaternion", frame=1 + k)
                set_linear(ob)
            self.objects.append(ob)

    # ---- lights, lighting, rig ---------------------------------------------------------------
    def make_lights(self, scene):
        for j in self.scene_json.get("lights", []):
            spot = j.get("spot")
            data = bpy.data.lights.new(j["name"], "SPOT" if spot else "POINT")
            inten = j["intensity"]
            peak = max(inten)
            data.color = [c / peak for c in inten] if peak > 0 else [1.0, 1.0, 1.0]
            data.energy = 4.0 * math.pi * peak  # Cycles: radiant intensity = power / (4 pi)
            data.shadow_soft_size = 0.0
            if j["range"] > 0:
                data.use_custom_distance = True
                data.cutoff_distance = j["range"]
            ob = bpy.data.objects.new(j["name"], data)
            scene.collection.objects.link(ob)
            ob["rovo_name"] = j["name"]
            local = Matrix.Translation(Vector(j["position"]))
            if spot:
                data.spot_size = math.radians(spot["angle_deg"])
                data.spot_blend = spot["blend"]
                # A Blender spot shines along its local -z.
                rot = Vector(spot["direction"]).normalized().to_track_quat("-Z", "Y").to_matrix().to_4x4()
                local = local @ rot
            if j["object"] >= 0:
                ob.parent = self.objects[j["object"]]
                ob.matrix_parent_inverse = Matrix.Identity(4)
                ob.matrix_basis = local
            else:
                ob.matrix_world = local

    def make_lighting(self, scene):
        lj = self.scene_json["lighting"]
        sun = lj["sun_radiance"]
        if max(sun) > 0:
            data = bpy.data.lights.new("sun", "SUN")
            data.energy = max(sun)
            data.color = [c / max(sun) for c in sun]
            data.angle = math.radians(lj["sun_angular_diameter_deg"])
            ob = bpy.data.objects.new("sun", data)
            scene.collection.objects.link(ob)
            ob.matrix_world = Vector(lj["direction_to_sun"]).normalized().to_track_quat("Z", "Y").to_matrix().to_4x4()
        world = bpy.data.worlds.new("rovo_sky")
        scene.world = world
        world.use_nodes = True
        bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
        mean = [0.5 * (a + b) * lj["ambient"] for a, b in zip(lj["sky_zenith"], lj["sky_horizon"])]
        bg.inputs["Color"].default_value = (mean[0], mean[1], mean[2], 1.0)
        bg.inputs["Strength"].default_value = 1.0
        world["rovo_sky_zenith"] = lj["sky_zenith"]
        world["rovo_sky_horizon"] = lj["sky_horizon"]
        world["rovo_ground_albedo"] = lj["ground_albedo"]
        world["rovo_ambient"] = lj["ambient"]
        world["rovo_lighting_preset"] = lj["preset"]
        # Blender caps the film exposure at 10: the rest goes to the view exposure (stops), and the
        # exporter reads exposure = film * 2^view back exactly (both factors are exact in float32).
        stops = max(0, math.ceil(math.log2(lj["exposure"] / 10.0))) if lj["exposure"] > 10.0 else 0
        scene.cycles.film_exposure = lj["exposure"] / 2.0 ** stops
        scene.view_settings.view_transform = "Standard"
        scene.view_settings.exposure = stops

    def make_rig(self, scene):
        rig = bpy.data.objects.new("rig", None)
        scene.collection.objects.link(rig)
        rig.rotation_mode = "QUATERNION"
        for k, (_, m) in enumerate(self.trajectory[self.first:self.last]):
            rig.matrix_world = m
            rig.keyframe_insert("location", frame=1 + k)
            rig.keyframe_insert("rotation_quaternion", frame=1 + k)
        set_linear(rig)
        if not self.rig_json:
            return
        cams = json.load(open(self.rig_json))["cameras"]
        for i, c in enumerate(cams):
            add_fisheye_camera(scene, rig, i, c, self.rig_json)

    def run(self, out):
        scene = bpy.context.scene
        fps = float(self.scene_json["frame_rate"])
        scene.render.fps = max(1, int(round(fps)))
        scene.render.fps_base = scene.render.fps / fps
        scene.frame_start, scene.frame_end = 1, self.last - self.first
        self.make_images()
        self.materials = [self.make_material(m) for m in self.scene_json["materials"]]
        self.meshes = [self.make_mesh(j) for j in self.scene_json["meshes"]]
        self.make_objects(scene)
        self.make_lights(scene)
        self.make_lighting(scene)
        self.make_rig(scene)
        scene.frame_set(1)
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(out), compress=True)
        print("imported %s -> %s: %d objects, %d meshes, %d materials, %d textures, %d lights, frames %d..%d" % (
            self.folder, out, len(self.objects), len(self.meshes), len(self.materials), len(self.images),
            len(self.scene_json.get("lights", [])), self.first, self.last - 1))


def set_linear(ob):
    if ob.animation_data and ob.animation_data.action:
        for fc in ob.animation_data.action.fcurves:
            for kp in fc.keyframe_points:
                kp.interpolation = "LINEAR"


def add_fisheye_camera(scene, rig, i, c, path):
    """Camera i of a rig.json as a Cycles FISHEYE_EQUIDISTANT child of the rig Empty."""
    if c["model"] != "equidistant" or any(abs(k) > 0 for k in c["params"][4:8]):
        raise rb.ExportError("%s: camera %d: only equidistant cameras without k1..k4 exist in Cycles" % (path, i))
    w, h = c["width"], c["height"]
    fov = math.radians(c["max_fov_deg"])
    want = [w / fov, h / fov, w / 2.0 - 0.5, h / 2.0 - 0.5]
    if any(abs(a - b) > 1e-6 * max(1.0, abs(b)) for a, b in zip(c["params"][:4], want)):
        raise rb.ExportError("%s: camera %d: params %s are not Cycles' fisheye mapping %s (fx = W/fov, cx = W/2 - 0.5)"
                             % (path, i, c["params"][:4], want))
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.resolution_percentage = 100
    data = bpy.data.cameras.new("cam%d" % i)
    data.type = "PANO"
    data.cycles.panorama_type = "FISHEYE_EQUIDISTANT"
    data.cycles.fisheye_fov = fov
    ob = bpy.data.objects.new("cam%d" % i, data)
    scene.collection.objects.link(ob)
    t = c["cam_from_rig"]
    cam_from_rig = matrix_from_rigid(t["rotation_xyzw"], t["translation"])
    ob.parent = rig
    ob.matrix_parent_inverse = Matrix.Identity(4)
    ob.matrix_basis = cam_from_rig.inverted() @ rb.BLENDER_CAM_TO_OPENCV
    if i == 0:
        scene.camera = ob


def main():
    parser = argparse.ArgumentParser(prog="blender -b --python import_scene.py --",
                                     description="Import a rovo scene folder into Blender and save a .blend.")
    parser.add_argument("scene", help="rovo scene folder (scenes/FORMAT.md)")
    parser.add_argument("out", help="output .blend")
    parser.add_argument("--rig", help="rig.json with equidistant cameras to add under the rig Empty")
    parser.add_argument("--frames", help="scene frames A:B (B exclusive) to import; default all")
    args = parser.parse_args(rb.script_args())
    try:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        Importer(args.scene, args.rig, args.frames).run(args.out)
    except (rb.ExportError, OSError, KeyError, ValueError) as e:
        rb.fail(str(e))


if __name__ == "__main__":
    main()

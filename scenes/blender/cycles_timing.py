"""Scene and Cycles renders of the timing cross-check (timing_cycles_check.py drives it).

    blender -b --factory-startup --python-exit-code 1 --python cycles_timing.py -- build OUT.blend [--size N]
    blender -b SCENE.blend --python-exit-code 1 --python cycles_timing.py -- render OUT.json --frame F
        [--shutter FRAMES] [--rolling] [--rolling-duration D] [--samples N] [--threads N]

build: a dark emissive wall (radiance 0.1) at x = 4 m with a bright emissive bar (radiance 1, y in
[1, 3] m, vertical) in front of it, a black world, 10 frames/s, and an Empty 'rig' moving along +y
at 20 m/s (y = 2 (frame - 1) m, linear keys) carrying one Cycles FISHEYE_EQUIDISTANT 180-degree
camera looking along +x. Emission only (base colour black, bounces 0): both renderers see exactly
the emitted radiance, so every difference is geometry or time.

render: Blender frame F of the camera in Cycles, box filter of 1 px, no denoising, with motion blur
over `--shutter` frames centred on the frame (motion_blur_position CENTER) and, with --rolling,
Cycles' rolling shutter (type TOP, rolling_shutter_duration D); writes the R channel as floats,
top row first, in OUT.json ({"width", "height", "r": [...]}).
"""

import argparse
import json
import math
import os
import sys

import bpy


def emissive(name, radiance):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    bsdf.inputs["Specular"].default_value = 0.0
    bsdf.inputs["Emission"].default_value = (1.0, 1.0, 1.0, 1.0)
    bsdf.inputs["Emission Strength"].default_value = radiance
    return mat


def quad(name, mat, x, y0, y1, z0, z1):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(x, y0, z0), (x, y1, z0), (x, y1, z1), (x, y0, z1)], [], [(0, 1, 2, 3)])
    mesh.materials.append(mat)
    ob = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def build(a):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 10
    scene.render.fps_base = 1.0
    scene.frame_start, scene.frame_end = 1, 3
    scene.render.resolution_x = scene.render.resolution_y = a.size
    scene.render.resolution_percentage = 100
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    quad("wall", emissive("wall", 0.1), 4.0, -30.0, 30.0, -20.0, 20.0)
    quad("bar", emissive("bar", 1.0), 3.9, 1.0, 3.0, -20.0, 20.0)
    rig = bpy.data.objects.new("rig", None)
    scene.collection.objects.link(rig)
    for frame in (1, 3):
        rig.location = (0.0, 2.0 * (frame - 1), 0.0)
        rig.keyframe_insert("location", frame=frame)
    for fc in rig.animation_data.action.fcurves:
        for kp in fc.keyframe_points:
            kp.interpolation = "LINEAR"
    data = bpy.data.cameras.new("cam0")
    data.type = "PANO"
    data.cycles.panorama_type = "FISHEYE_EQUIDISTANT"
    data.cycles.fisheye_fov = math.pi
    data.clip_start = 0.01
    data.clip_end = 1000.0
    cam = bpy.data.objects.new("cam0", data)
    scene.collection.objects.link(cam)
    cam.parent = rig
    cam.rotation_euler = (math.pi / 2, 0.0, -math.pi / 2)  # optical axis (-z) along +x, +y up
    scene.camera = cam
    scene.frame_set(1)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(a.out))


def render(a):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = a.samples
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.seed = 0
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.max_bounces = cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = 0
    scene.render.threads_mode = "FIXED"
    scene.render.threads = a.threads
    scene.render.use_motion_blur = a.shutter > 0.0
    scene.render.motion_blur_shutter = max(a.shutter, 0.01)
    cy.motion_blur_position = "CENTER"
    cy.rolling_shutter_type = "TOP" if a.rolling else "NONE"
    cy.rolling_shutter_duration = a.rolling_duration
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    img = scene.render.image_settings
    img.file_format = "OPEN_EXR"
    img.color_depth = "32"
    scene.frame_set(a.frame)
    exr = os.path.abspath(a.out) + ".exr"
    scene.render.filepath = exr
    scene.render.use_file_extension = False
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(exr)
    w, h = image.size
    px = list(image.pixels)  # RGBA, bottom row first
    r = [px[4 * ((h - 1 - y) * w + x)] for y in range(h) for x in range(w)]
    tmp = os.path.abspath(a.out) + ".tmp"
    with open(tmp, "w") as f:
        json.dump({"width": w, "height": h, "r": r}, f)
    os.replace(tmp, os.path.abspath(a.out))
    os.remove(exr)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="cycles_timing.py")
    p.add_argument("mode", choices=["build", "render"])
    p.add_argument("out")
    p.add_argument("--size", type=int, default=200)
    p.add_argument("--frame", type=int, default=2)
    p.add_argument("--shutter", type=float, default=0.0, help="motion blur shutter in frames (0: off)")
    p.add_argument("--rolling", action="store_true")
    p.add_argument("--rolling-duration", type=float, default=0.0)
    p.add_argument("--samples", type=int, default=256)
    p.add_argument("--threads", type=int, default=2)
    a = p.parse_args(argv)
    build(a) if a.mode == "build" else render(a)


main()

"""Builds the small Blender scene of the Blender round-trip test and saves it as a .blend.

    blender -b --factory-startup --python tests/scenes/blender/make_roundtrip_scene.py -- OUT.blend
            [--size N] [--height N] [--frames N]

Contents (chosen to exercise every exporter path): a textured open-top room (a cube scaled
non-uniformly: scale baking, two material slots), textured and plain boxes (rotated, one with a negative scale), a
UV sphere, a collection instance (instances), one animated box (dynamic object), a sun and a
world colour (lighting), and a rig: an Empty 'rig' that moves and turns, with four Cycles
FISHEYE_EQUIDISTANT 220-degree cameras as children looking diagonally like the paper's rig.
Blender frames 1..--frames. Images are generated and packed into the .blend.
"""

import argparse
import math
import os
import sys

import bmesh
import bpy


def args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="make_roundtrip_scene.py")
    p.add_argument("out")
    p.add_argument("--size", type=int, default=192, help="image width of each camera (square by default)")
    p.add_argument("--height", type=int, default=0, help="image height (default: --size)")
    p.add_argument("--frames", type=int, default=2, help="number of frames (Blender 1..N)")
    return p.parse_args(argv)


def checker_image(name, n, cells, c0, c1):
    img = bpy.data.images.new(name, n, n, alpha=False)
    px = []
    for y in range(n):
        for x in range(n):
            a = ((x * cells // n) + (y * cells // n)) % 2
            c = c0 if a else c1
            # a gradient inside each cell so the texture is not symmetric
            g = 0.25 * (x % (n // cells)) / (n // cells)
            px.extend((min(1.0, c[0] + g), c[1], c[2], 1.0))
    img.pixels.foreach_set(px)
    img.pack()
    return img


def material(name, color=None, image=None):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Roughness"].default_value = 1.0
    bsdf.inputs["Specular"].default_value = 0.0
    if image is not None:
        tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
        tex.image = image
        mat.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    else:
        bsdf.inputs["Base Color"].default_value = (color[0], color[1], color[2], 1.0)
    return mat


def add(op, name, mat, location, rotation_deg=(0, 0, 0), scale=(1, 1, 1), **kw):
    op(location=location, **kw)
    ob = bpy.context.active_object
    ob.name = name
    ob.rotation_euler = tuple(math.radians(a) for a in rotation_deg)
    ob.scale = scale
    ob.data.materials.append(mat)
    return ob


def linear_keys(ob):
    for fc in ob.animation_data.action.fcurves:
        for kp in fc.keyframe_points:
            kp.interpolation = "LINEAR"


def main():
    a = args()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, a.frames
    scene.render.fps, scene.render.fps_base = 10, 1.0
    scene.render.resolution_x = a.size
    scene.render.resolution_y = a.height or a.size
    scene.render.resolution_percentage = 100
    scene.render.engine = "CYCLES"

    wall = material("wall", image=checker_image("wall_checker", 64, 8, (0.8, 0.3, 0.2), (0.9, 0.9, 0.85)))
    floor = material("floor", image=checker_image("floor_checker", 64, 16, (0.2, 0.2, 0.2), (0.7, 0.7, 0.6)))
    blue = material("blue", color=(0.1, 0.2, 0.8))
    green = material("green", color=(0.2, 0.7, 0.2))
    yellow = material("yellow", color=(0.9, 0.8, 0.1))

    # Room 24 x 18 x 7 m: a 2 m cube scaled non-uniformly (the exporter bakes the scale).
    room = add(bpy.ops.mesh.primitive_cube_add, "room", wall, (1.0, -0.5, 3.0), scale=(12.0, 9.0, 3.5))
    room.data.materials.append(floor)
    # No ceiling (so sky light comes in); the floor (normal -z) uses the second material slot.
    bm = bmesh.new()
    bm.from_mesh(room.data)
    bmesh.ops.delete(bm, geom=[f for f in bm.faces if f.normal.z > 0.5], context="FACES_ONLY")
    for f in bm.faces:
        if f.normal.z < -0.5:
            f.material_index = 1
    bm.to_mesh(room.data)
    bm.free()

    add(bpy.ops.mesh.primitive_cube_add, "box_a", wall, (5.0, 2.0, 1.0), (0, 0, 30), (1.0, 1.5, 1.0))
    add(bpy.ops.mesh.primitive_cube_add, "box_b", blue, (-4.0, 3.0, 0.75), (0, 0, -15), (0.75, 0.75, 0.75))
    add(bpy.ops.mesh.primitive_cube_add, "box_mirrored", green, (-3.0, -4.0, 1.5), (10, 20, 5), (-1.0, 0.6, 1.5))
    add(bpy.ops.mesh.primitive_uv_sphere_add, "sphere", yellow, (2.0, -3.5, 1.2), radius=1.2, segments=24,
        ring_count=12)
    add(bpy.ops.mesh.primitive_plane_add, "panel", floor, (0.0, 6.5, 2.5), (90, 0, 0), (3.0, 1.5, 1.0))

    # A collection instanced twice (not linked to the scene itself).
    props = bpy.data.collections.new("props")
    bpy.ops.mesh.primitive_cone_add(location=(0, 0, 0.75), radius1=0.6, depth=1.5, vertices=12)
    cone = bpy.context.active_object
    cone.name = "cone"
    cone.data.materials.append(yellow)
    for coll in cone.users_collection:
        coll.objects.unlink(cone)
    props.objects.link(cone)
    for i, loc in enumerate(((7.0, -5.0, 0.0), (-7.0, 5.5, 0.0))):
        inst = bpy.data.objects.new("props_instance_%d" % i, None)
        inst.instance_type = "COLLECTION"
        inst.instance_collection = props
        inst.location = loc
        scene.collection.objects.link(inst)

    # The moving object: a box crossing in front of the rig.
    mover = add(bpy.ops.mesh.primitive_cube_add, "mover", blue, (3.0, -1.5, 0.8), (0, 0, 0), (0.8, 0.5, 0.8))
    mover.keyframe_insert("location", frame=1)
    mover.keyframe_insert("rotation_euler", frame=1)
    mover.location = (3.0, 1.5, 0.8)
    mover.rotation_euler = (0.0, 0.0, math.radians(25.0))
    mover.keyframe_insert("location", frame=3)
    mover.keyframe_insert("rotation_euler", frame=3)
    linear_keys(mover)

    # Lighting.
    sun_data = bpy.data.lights.new("sun", type="SUN")
    sun_data.energy = 3.0
    sun_data.angle = math.radians(0.53)
    sun = bpy.data.objects.new("sun", sun_data)
    sun.rotation_euler = (math.radians(40), 0.0, math.radians(30))
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.4, 0.5, 0.7, 1.0)
    scene.world = world

    # The rig: an Empty that moves forward and turns; four fisheye cameras as children.
    rig = bpy.data.objects.new("rig", None)
    scene.collection.objects.link(rig)
    rig.location = (0.0, 0.0, 1.8)
    rig.rotation_euler = (0.0, 0.0, math.radians(10.0))
    rig.keyframe_insert("location", frame=1)
    rig.keyframe_insert("rotation_euler", frame=1)
    rig.location = (1.2, 0.3, 1.85)
    rig.rotation_euler = (math.radians(2.0), math.radians(-1.0), math.radians(25.0))
    rig.keyframe_insert("location", frame=3)
    rig.keyframe_insert("rotation_euler", frame=3)
    linear_keys(rig)
    for i, yaw in enumerate((45.0, 135.0, -135.0, -45.0)):
        data = bpy.data.cameras.new("cam%d" % i)
        data.type = "PANO"
        data.cycles.panorama_type = "FISHEYE_EQUIDISTANT"
        data.cycles.fisheye_fov = math.radians(220.0)
        data.clip_start = 0.01
        data.clip_end = 1000.0
        cam = bpy.data.objects.new("cam%d" % i, data)
        scene.collection.objects.link(cam)
        cam.parent = rig
        y = math.radians(yaw)
        cam.location = (0.2 * math.cos(y), 0.2 * math.sin(y), 0.05 * (i % 2))
        # Optical axis (-z of the Blender camera) at `yaw` in the rig's xy plane, tilted 5 degrees up.
        cam.rotation_euler = (math.radians(95.0), 0.0, y - math.pi / 2)
    scene.camera = scene.objects["cam0"]

    scene.frame_set(1)
    out = os.path.abspath(a.out)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=out)
    print("saved %s" % out)


main()

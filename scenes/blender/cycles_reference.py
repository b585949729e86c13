"""Render the rig cameras of a Blender scene in Cycles, as a reference for `rovo render`.

    blender -b FILE.blend --python scenes/blender/cycles_reference.py -- OUT [--frames A:B] [--rig NAME]
        [--samples N] [--threads N] [--filter-width PX] [--bounces N] [--seed S] [--no-depth]

For export frame k (Blender frame A + k, the same numbering as export_scene.py) and rig camera i
(children of the rig Empty sorted by name, as in rig.json) it writes OUT/cam<i>/<k:06d>.exr, a
multilayer OpenEXR (float32) with the passes of view layer 'ViewLayer':
  ViewLayer.Combined.{R,G,B,A}  scene-linear colour
  ViewLayer.Depth.Z             ray length in metres (see below); 1e10 where no surface was hit
and OUT/cycles.json with the settings and the seconds of every view (wall and CPU time of the whole
render call: scene sync, BVH build, path tracing and writing).

Depth: for panoramic cameras Cycles' Depth pass is the distance from the camera position to the
hit point, |P - camera_position| (kernel/camera/camera.h, camera_z_depth), i.e. exactly rovo's
ray length; it is written from the first sample only (kernel/film/data_passes.h), so the default
box filter of width 0.01 px makes that sample go through the pixel centre (rovo's depth rays do).
Pixels outside the lens circle cast no ray and read 1e10, like background pixels.
The lens must be FISHEYE_EQUIDISTANT; its exact rovo equivalent is in rovo_blender.py.
"""

import argparse
import json
import os
import sys
import time

import bpy

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rovo_blender as rb  # noqa: E402


def configure(scene, args):
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = args.samples
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.seed = args.seed
    cy.use_animated_seed = False
    cy.pixel_filter_type = "BOX" if args.filter_width < 1.0 else "BLACKMAN_HARRIS"
    cy.filter_width = args.filter_width
    cy.max_bounces = args.bounces
    cy.diffuse_bounces = args.bounces
    cy.glossy_bounces = args.bounces
    cy.transmission_bounces = args.bounces
    cy.transparent_max_bounces = max(args.bounces, 1)
    scene.render.threads_mode = "FIXED" if args.threads > 0 else "AUTO"
    if args.threads > 0:
        scene.render.threads = args.threads
    scene.render.use_persistent_data = args.persistent_data
    scene.render.film_transparent = False
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    scene.render.use_file_extension = False
    scene.render.use_motion_blur = False
    img = scene.render.image_settings
    img.file_format = "OPEN_EXR_MULTILAYER"
    img.color_depth = "32"
    img.exr_codec = "ZIP"
    for layer in scene.view_layers:
        layer.use = layer == scene.view_layers[0]
    layer = scene.view_layers[0]
    layer.use_pass_combined = True
    layer.use_pass_z = not args.no_depth
    return layer.name


def main():
    parser = argparse.ArgumentParser(
        prog="blender -b FILE.blend --python cycles_reference.py --",
        description="Render every rig camera in Cycles (multilayer EXR with a ray-length depth pass).")
    parser.add_argument("out", help="output folder")
    parser.add_argument("--frames", help="Blender frames A:B (B exclusive); default: the scene's frame range")
    parser.add_argument("--rig", help="name of the rig Empty (default: an Empty named 'rig' with camera children)")
    parser.add_argument("--samples", type=int, default=1, help="samples per pixel (default 1)")
    parser.add_argument("--threads", type=int, default=2, help="render threads, 0 = all cores (default 2)")
    parser.add_argument("--filter-width", type=float, default=0.01,
                        help="pixel filter width in pixels; < 1 uses a box filter (default 0.01: samples "
                             "through pixel centres), >= 1 Blackman-Harris (Blender's default is 1.5)")
    parser.add_argument("--bounces", type=int, default=0,
                        help="max light bounces (default 0: direct sun and sky light only, like rovo)")
    parser.add_argument("--seed", type=int, default=0, help="Cycles sampling seed (default 0)")
    parser.add_argument("--persistent-data", action="store_true",
                        help="keep scene data between renders (faster repeated renders)")
    parser.add_argument("--no-depth", action="store_true", help="do not write the depth pass")
    args = parser.parse_args(rb.script_args())
    try:
        if args.samples < 1:
            raise rb.ExportError("--samples must be >= 1")
        if args.filter_width < 0.01:
            raise rb.ExportError("--filter-width must be >= 0.01 (Blender's minimum)")
        scene = bpy.context.scene
        frames = rb.parse_frames(args.frames, scene)
        rig, cams = rb.find_rig(scene, args.rig)
        if rig is None:
            raise rb.ExportError("no rig: an Empty named 'rig' (or --rig NAME) with camera children")
        lenses = [rb.equidistant_camera(c, scene) for c in cams]  # checks every lens
        layer = configure(scene, args)
        os.makedirs(args.out, exist_ok=True)
        views = []
        t_all = time.perf_counter()
        for k, frame in enumerate(frames):
            scene.frame_set(frame)
            for i, cam in enumerate(cams):
                scene.camera = cam
                path = os.path.join(args.out, "cam%d" % i, "%06d.exr" % k)
                tmp = rb.atomic_path(path) + ".exr"
                scene.render.filepath = tmp
                t0, c0 = time.perf_counter(), time.process_time()
                bpy.ops.render.render(write_still=True)
                seconds, cpu_seconds = time.perf_counter() - t0, time.process_time() - c0
                if not os.path.exists(tmp):
                    raise rb.ExportError("Cycles wrote no image for camera '%s' frame %d" % (cam.name, frame))
                os.replace(tmp, path)
                if os.path.exists(tmp[:-4]):
                    os.remove(tmp[:-4])
                views.append({"frame": k, "blender_frame": frame, "camera": i, "blender_camera": cam.name,
                              "seconds": seconds, "cpu_seconds": cpu_seconds})
                print("cycles: frame %d camera %d: %.2f s (%.2f CPU s)" % (frame, i, seconds, cpu_seconds), flush=True)
        total = time.perf_counter() - t_all
        summary = {
            "generator": "rovo scenes/blender/cycles_reference.py",
            "blender_version": bpy.app.version_string,
            "source": bpy.data.filepath,
            "view_layer": layer,
            "depth_channel": None if args.no_depth else "%s.Depth.Z" % layer,
            "frames": frames, "rig": rig.name, "cameras": [c.name for c in cams],
            "width": lenses[0]["width"], "height": lenses[0]["height"],
            "samples": args.samples, "threads": args.threads, "filter_width": args.filter_width,
            "bounces": args.bounces, "seed": args.seed, "persistent_data": args.persistent_data,
            "views": views, "seconds_total": total,
            "seconds_per_frame": total / len(frames),
        }
        rb.write_bytes_atomic(os.path.join(args.out, "cycles.json"), (json.dumps(summary, indent=1) + "\n").encode())
        print("cycles: %d frames x %d views, %d spp, %d threads: %.2f s/frame" % (
            len(frames), len(cams), args.samples, args.threads, total / len(frames)))
    except rb.ExportError as e:
        rb.fail(str(e))


if __name__ == "__main__":
    main()

"""Blender Cycles with OpenImageDenoise on a glTF scene: the peer issue 47 weighs shine's
one-sample frames against. One bounce (as `shine reference --bounces 1`), CPU, the pixel
filter narrowed to the pixel centre (as `--no-jitter`), OIDN with the FAST prefilter, at each
sample count; the first render is a warm-up. Prints one JSON line per render (spp, seconds)
and writes OUT_DIR/cycles_SPP.exr (linear, Cycles' units: the glTF importer converts the
lights' candela to watts, so compare after fitting one scale, docs/quality.md).

Usage: python3 scripts/cycles_oidn.py SCENE.glb WIDTH HEIGHT OUT_DIR SPP [SPP ...]
(pip install bpy; e.g. assets/metals.glb 128 128 out/cycles 1 2 4 8 16).
"""

import json
import sys
import time

import bpy


def main():
    scene_path, width, height, out_dir = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    counts = [int(a) for a in sys.argv[5:]]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    s = bpy.context.scene
    s.render.engine = "CYCLES"
    s.cycles.device = "CPU"
    bpy.ops.import_scene.gltf(filepath=scene_path)
    s.camera = next(o for o in bpy.data.objects if o.type == "CAMERA")
    s.render.resolution_x, s.render.resolution_y = width, height
    s.render.resolution_percentage = 100
    s.cycles.max_bounces = 1
    s.cycles.diffuse_bounces = 1
    s.cycles.glossy_bounces = 1
    s.cycles.transmission_bounces = 0
    s.cycles.transparent_max_bounces = 0
    s.cycles.filter_width = 0.01
    s.cycles.use_adaptive_sampling = False
    s.cycles.use_denoising = True
    s.cycles.denoiser = "OPENIMAGEDENOISE"
    s.cycles.denoising_prefilter = "FAST"
    s.view_settings.view_transform = "Standard"
    s.render.image_settings.file_format = "OPEN_EXR"
    s.render.image_settings.color_depth = "32"
    for i, spp in enumerate([counts[0]] + counts):
        s.cycles.samples = spp
        s.render.filepath = f"{out_dir}/cycles_{spp}.exr"
        start = time.time()
        bpy.ops.render.render(write_still=True)
        if i > 0:
            print(json.dumps({"spp": spp, "seconds": time.time() - start}), flush=True)


if __name__ == "__main__":
    main()

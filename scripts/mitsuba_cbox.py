"""Mitsuba 3's Cornell box at the size and depth of shine's path-tracer benchmark
(scripts/bench.sh): samples per second of one variant, printed as JSON.

Usage: python3 scripts/mitsuba_cbox.py VARIANT WIDTH HEIGHT SPP MAX_DEPTH
(VARIANT: scalar_rgb or llvm_ad_rgb). The first render, at the same sample count, is a
warm-up (the LLVM variant compiles its kernels then); the second is timed.
"""

import json
import sys
import time

import drjit as dr
import mitsuba as mi


def main():
    variant, width, height, spp, depth = sys.argv[1], *map(int, sys.argv[2:6])
    mi.set_variant(variant)
    scene_dict = mi.cornell_box()
    scene_dict["sensor"]["film"]["width"] = width
    scene_dict["sensor"]["film"]["height"] = height
    scene_dict["integrator"] = {"type": "path", "max_depth": depth}
    scene = mi.load_dict(scene_dict)
    mi.render(scene, spp=spp)
    start = time.perf_counter()
    image = mi.render(scene, spp=spp)
    # Dr.Jit evaluates lazily: wait for the render to finish.
    dr.eval(image)
    dr.sync_thread()
    seconds = time.perf_counter() - start
    print(json.dumps({
        "variant": variant,
        "version": mi.__version__,
        "seconds": seconds,
        "samples_per_second": width * height * spp / seconds,
    }))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Render the material reference scenes with Mitsuba 3 for Radiant's tests.

Each scene is Mitsuba's ``mi.cornell_box()`` with the two boxes replaced by
two spheres of the material under test, at 64x64, max_depth 16; the
Radiant scenes ``scenes/glass.yaml``, ``scenes/rough-metal.yaml`` and
``scenes/plastic.yaml`` describe exactly the same. Output is half-float RGB
OpenEXR in ``tests/data/<name>-mitsuba.exr``.

    pip install mitsuba numpy
    apt-get install -y libllvm19
    nice -n 10 python3 tests/reference/render_materials.py --spp 8192

``--variant scalar_rgb`` avoids the LLVM dependency (much slower).
"""
import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from render_mitsuba import setup_variant  # noqa: E402

SIZE = 64
MAX_DEPTH = 16
LEFT = [-0.45, -0.6, -0.2]
RIGHT = [0.45, -0.6, 0.25]
RADIUS = 0.38


def materials():
    """Mitsuba BSDFs of the left and right sphere, per scene."""
    return {
        "glass": (
            {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0},
            {"type": "roughdielectric", "distribution": "ggx", "alpha": 0.15,
             "int_ior": 1.5, "ext_ior": 1.0},
        ),
        "rough-metal": (
            {"type": "roughconductor", "distribution": "ggx", "alpha": 0.1,
             "material": "Au"},
            {"type": "roughconductor", "distribution": "ggx", "alpha": 0.3,
             "material": "Al"},
        ),
        "plastic": (
            {"type": "plastic", "int_ior": 1.5, "ext_ior": 1.0,
             "diffuse_reflectance": {"type": "rgb", "value": [0.7, 0.2, 0.1]}},
            {"type": "roughplastic", "distribution": "ggx", "alpha": 0.1,
             "int_ior": 1.5, "ext_ior": 1.0,
             "diffuse_reflectance": {"type": "rgb", "value": [0.1, 0.3, 0.6]}},
        ),
    }


def scene_dict(mi, left, right):
    desc = mi.cornell_box()
    del desc["small-box"], desc["large-box"]
    desc["integrator"]["max_depth"] = MAX_DEPTH
    desc["sensor"]["film"]["width"] = SIZE
    desc["sensor"]["film"]["height"] = SIZE
    desc["left"] = {"type": "sphere", "center": LEFT, "radius": RADIUS, "bsdf": left}
    desc["right"] = {"type": "sphere", "center": RIGHT, "radius": RADIUS, "bsdf": right}
    return desc


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--spp", type=int, default=8192)
    ap.add_argument("--pass-spp", type=int, default=1024)
    ap.add_argument("--only", help="render only this scene")
    ap.add_argument("--out-dir", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "data"))
    args = ap.parse_args()
    mi = setup_variant(args.variant)
    import numpy as np

    for name, (left, right) in materials().items():
        if args.only and name != args.only:
            continue
        t0 = time.time()
        scene = mi.load_dict(scene_dict(mi, left, right))
        accum = np.zeros((SIZE, SIZE, 3), dtype=np.float64)
        done = 0
        i = 0
        while done < args.spp:
            n = min(args.pass_spp, args.spp - done)
            img = mi.render(scene, spp=n, seed=1_000_003 * (i + 1))
            accum += np.array(img, dtype=np.float64)[..., :3] * n
            done += n
            i += 1
        img = (accum / done).astype(np.float32)
        out = os.path.join(args.out_dir, f"{name}-mitsuba.exr")
        bmp = mi.Bitmap(img, pixel_format=mi.Bitmap.PixelFormat.RGB)
        bmp = bmp.convert(component_format=mi.Struct.Type.Float16)
        bmp.write(out)
        mean = img.reshape(-1, 3).mean(axis=0)
        print(f"{name}: {done} spp in {time.time() - t0:.1f} s, mean RGB "
              f"{mean[0]:.5f} {mean[1]:.5f} {mean[2]:.5f} -> {out}",
              file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()

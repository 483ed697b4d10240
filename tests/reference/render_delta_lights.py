#!/usr/bin/env python3
"""Render scenes/spot-directional.yaml's scene in Mitsuba 3 (spot and
directional lights) and write tests/data/spot-directional-mitsuba.exr.

    pip install mitsuba numpy
    apt-get install -y libllvm19
    nice -n 10 python3 tests/reference/render_delta_lights.py --spp 4096

The scene here must stay identical to scenes/spot-directional.yaml.
"""
import argparse
import os
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
OUT = os.path.join(ROOT, "tests", "data", "spot-directional-mitsuba.exr")
SIZE = 128


def scene_dict(mi, spp):
    T = mi.ScalarTransform4f

    def diffuse(rgb):
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}}

    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 4},
        "sensor": {
            "type": "perspective", "fov": 45.0, "fov_axis": "x",
            "to_world": T().look_at(origin=[0, 2, 4], target=[0, 0.3, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE,
                     "rfilter": {"type": "gaussian"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "ground": {"type": "rectangle", "to_world": T().rotate([1, 0, 0], -90).scale(3.0),
                   "bsdf": diffuse([0.6, 0.6, 0.6])},
        "ball": {"type": "sphere", "center": [0.3, 0.5, 0], "radius": 0.5,
                 "bsdf": diffuse([0.8, 0.6, 0.4])},
        "box": {"type": "cube",
                "to_world": T().translate([-1, 0.3, 0.3]).rotate([0, 1, 0], 30).scale(0.3),
                "bsdf": diffuse([0.2, 0.5, 0.3])},
        "spot": {"type": "spot",
                 "to_world": T().look_at(origin=[-1.5, 2.5, 1.5], target=[0, 0, 0], up=[0, 1, 0]),
                 "intensity": {"type": "rgb", "value": [30, 25, 20]},
                 "cutoff_angle": 30.0, "beam_width": 15.0},
        "sun": {"type": "directional", "direction": [1, -0.5, -0.3],
                "irradiance": {"type": "rgb", "value": [0.6, 0.7, 0.9]}},
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=4096)
    args = ap.parse_args()
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        os.environ["DRJIT_LIBLLVM_PATH"] = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
    import numpy as np
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    scene = mi.load_dict(scene_dict(mi, 1024))
    passes = max(1, args.spp // 1024)
    acc = np.zeros((SIZE, SIZE, 3))
    for i in range(passes):
        acc += np.array(mi.render(scene, spp=1024, seed=2000 + i), dtype=np.float64)[..., :3]
        print(f"pass {i + 1}/{passes}", file=sys.stderr, flush=True)
    img = (acc / passes).astype(np.float32)
    mi.Bitmap(img, pixel_format=mi.Bitmap.PixelFormat.RGB).write(OUT)
    print(f"wrote {OUT}: mean RGB {img.reshape(-1, 3).mean(axis=0)}", file=sys.stderr)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Make the environment-light references for Radiant with Mitsuba 3.

1. Generates the procedural 64x32 equirectangular map
   ``scenes/environment-sky.exr`` (half float): a sky gradient, a dark
   ground, a red patch on the horizon and a small bright sun.
2. Evaluates Mitsuba's ``envmap`` emitter on that map (rotated like the scene)
   in 256 fixed directions and writes them to
   ``tests/data/environment-eval-mitsuba.txt`` ("dx dy dz r g b" per line),
   so Radiant's lookup convention is checked texel by texel.
3. Renders ``scenes/environment.yaml``'s scene in Mitsuba (``path``
   integrator, gaussian filter) and writes ``tests/data/environment-mitsuba.exr``.

The committed files were made with:

    pip install mitsuba numpy
    apt-get install -y libllvm19
    nice -n 10 python3 tests/reference/render_environment.py --spp 16384

The scene here must stay identical to ``scenes/environment.yaml``.
"""
import argparse
import math
import os
import sys
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
SKY = os.path.join(ROOT, "scenes", "environment-sky.exr")
EVAL = os.path.join(ROOT, "tests", "data", "environment-eval-mitsuba.txt")
OUT = os.path.join(ROOT, "tests", "data", "environment-mitsuba.exr")
ROTATE_Y = 60.0  # degrees, the light's transform in the scene
SIZE = 128


def make_sky(np, width=64, height=32):
    """The procedural sky: pixel (x, y) sits at u = x/W, v = y/(H-1)."""
    img = np.zeros((height, width, 3), dtype=np.float64)
    for y in range(height):
        theta = math.pi * y / (height - 1)
        for x in range(width):
            phi = 2 * math.pi * x / width
            up = math.cos(theta)
            if up > 0:  # sky: blue at the zenith, pale at the horizon
                c = np.array([0.35, 0.55, 1.0]) * up + np.array([1.0, 0.9, 0.75]) * (1 - up)
            else:  # ground: dark brown
                c = np.array([0.12, 0.09, 0.06]) * (1 + up * 0.5)
            # A red patch on the horizon around phi = 90 degrees.
            if abs(phi - math.pi / 2) < 0.5 and abs(theta - math.pi / 2) < 0.25:
                c = np.array([2.0, 0.2, 0.1])
            img[y, x] = c
    # The sun: a gaussian blob of about two pixels at u = 0.3, v = 0.3.
    for y in range(height):
        for x in range(width):
            du = min(abs(x - 0.3 * width), width - abs(x - 0.3 * width))
            dv = y - 0.3 * (height - 1)
            img[y, x] += np.array([60.0, 50.0, 35.0]) * math.exp(-(du * du + dv * dv) / 2.0)
    return img.astype(np.float16).astype(np.float32)


def scene_dict(mi, spp, max_depth):
    T = mi.ScalarTransform4f
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth},
        "sensor": {
            "type": "perspective",
            "fov": 40.0,
            "fov_axis": "x",
            "to_world": T().look_at(origin=[0, 1.2, 4.0], target=[0, 0.4, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE,
                     "rfilter": {"type": "gaussian"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "sky": {"type": "envmap", "filename": SKY,
                "to_world": T().rotate([0, 1, 0], ROTATE_Y)},
        "ground": {
            "type": "rectangle",
            "to_world": T().rotate([1, 0, 0], -90).scale(3.0),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.5, 0.5, 0.5]}},
        },
        "ball": {
            "type": "sphere", "center": [0, 0.6, 0], "radius": 0.6,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.8, 0.6, 0.4]}},
        },
        "box": {
            "type": "cube",
            "to_world": T().translate([-1.1, 0.3, 0.4]).rotate([0, 1, 0], 30).scale(0.3),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.2, 0.5, 0.3]}},
        },
    }


def eval_directions():
    """256 fixed directions: a spiral over the sphere plus the poles."""
    dirs = [(0.0, 1.0, 0.0), (0.0, -1.0, 0.0)]
    n = 254
    for i in range(n):
        z = 1 - 2 * (i + 0.5) / n
        r = math.sqrt(1 - z * z)
        phi = i * math.pi * (3 - math.sqrt(5))
        dirs.append((r * math.cos(phi), z, r * math.sin(phi)))
    return dirs


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--max-depth", type=int, default=6)
    ap.add_argument("--pass-spp", type=int, default=1024)
    args = ap.parse_args()
    if "DRJIT_LIBLLVM_PATH" not in os.environ:
        os.environ["DRJIT_LIBLLVM_PATH"] = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
    import numpy as np
    import mitsuba as mi
    t0 = time.time()

    def log(msg):
        print(f"[{time.time() - t0:7.1f} s] {msg}", file=sys.stderr, flush=True)

    mi.set_variant("scalar_rgb")
    sky = make_sky(np)
    mi.Bitmap(sky.astype(np.float16), pixel_format=mi.Bitmap.PixelFormat.RGB).write(SKY)
    log(f"wrote {SKY}")

    emitter = mi.load_dict({"type": "envmap", "filename": SKY,
                            "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], ROTATE_Y)})
    with open(EVAL, "w") as f:
        f.write("# Mitsuba 3 envmap radiance of scenes/environment-sky.exr rotated 60 deg about +y:\n")
        f.write("# dx dy dz (direction towards the sky) r g b\n")
        for d in eval_directions():
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(-d[0], -d[1], -d[2])
            v = emitter.eval(si)
            f.write(f"{d[0]:.7f} {d[1]:.7f} {d[2]:.7f} {v[0]:.6e} {v[1]:.6e} {v[2]:.6e}\n")
    log(f"wrote {EVAL}")

    mi.set_variant("llvm_ad_rgb")
    scene = mi.load_dict(scene_dict(mi, args.pass_spp, args.max_depth))
    passes = max(1, -(-args.spp // args.pass_spp))
    acc = np.zeros((SIZE, SIZE, 3))
    for i in range(passes):
        acc += np.array(mi.render(scene, spp=args.pass_spp, seed=1000 + i), dtype=np.float64)[..., :3]
        log(f"pass {i + 1}/{passes}")
    img = (acc / passes).astype(np.float32)
    mi.Bitmap(img, pixel_format=mi.Bitmap.PixelFormat.RGB).write(OUT)
    log(f"wrote {OUT} ({passes * args.pass_spp} spp, max_depth {args.max_depth}); "
        f"mean RGB = {img.reshape(-1, 3).mean(axis=0)}")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Render Mitsuba 3 `volpath` references for Radiant's participating-media tests.

``--scene smoke``: Mitsuba's ``mi.cornell_box()`` at 64x64 with a sphere of chromatic
homogeneous smoke (Henyey-Greenstein g = 0.3) behind a ``null`` boundary,
the scene ``scenes/media/cornell-smoke.yaml`` writes for Radiant
(``tests/media.rs`` compares the two). The integrator is ``volpath`` with
unlimited depth (Russian roulette from depth 5, as Radiant's default), and
the image is written as linear float32 RGB OpenEXR.

``--scene dark``: ``scenes/media/smoke-dark.yaml``, a grey smoke sphere lit
by a small spherical area light with nothing behind it, so that the image
is in-scattered light alone (it moves with sigma_s: the test's power).

The committed reference ``tests/data/media-smoke-mitsuba.exr`` was made with
(Mitsuba 3.9.1, scalar_rgb; no LLVM needed)::

    nice -n 10 python3 tests/reference/render_media.py --spp 32768 \\
        --pass-spp 4096 --out tests/data/media-smoke-mitsuba.exr
    nice -n 10 python3 tests/reference/render_media.py --scene dark \\
        --spp 65536 --pass-spp 8192 --out tests/data/media-dark-mitsuba.exr
"""
import argparse
import sys
import time

# The smoke of scenes/media/cornell-smoke.yaml.
SIGMA_S = [2.0, 3.5, 5.0]
SIGMA_A = [0.3, 0.2, 0.1]
G = 0.3
CENTER = [0.3, 0.45, 0.3]
RADIUS = 0.38
SIZE = 64


def smoke_scene(mi):
    """mi.cornell_box() at SIZE x SIZE with the smoke sphere and volpath."""
    desc = mi.cornell_box()
    desc["integrator"] = {"type": "volpath", "max_depth": -1, "rr_depth": 5}
    film = desc["sensor"]["film"]
    film["width"] = SIZE
    film["height"] = SIZE
    sigma_t = [s + a for s, a in zip(SIGMA_S, SIGMA_A)]
    albedo = [s / t for s, t in zip(SIGMA_S, sigma_t)]
    # RGB values must lie in [0, 1] (Mitsuba reads them as reflectances):
    # sigma_t is given relative to its largest channel, times `scale`.
    top = max(sigma_t)
    desc["smoke"] = {
        "type": "sphere",
        "center": CENTER,
        "radius": RADIUS,
        "bsdf": {"type": "null"},
        "interior": {
            "type": "homogeneous",
            "sigma_t": {"type": "rgb", "value": [t / top for t in sigma_t]},
            "scale": top,
            "albedo": {"type": "rgb", "value": albedo},
            "phase": {"type": "hg", "g": G},
        },
    }
    return mi.load_dict(desc)


def dark_scene(mi):
    """A grey HG smoke sphere and a spherical light, no other geometry."""
    T = mi.ScalarTransform4f
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": -1, "rr_depth": 5},
        "sensor": {
            "type": "perspective",
            "fov": 30,
            "to_world": T().look_at(origin=[0, 0, 4], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE,
                     "rfilter": {"type": "gaussian", "stddev": 0.5}},
        },
        "smoke": {
            "type": "sphere",
            "radius": 0.6,
            "bsdf": {"type": "null"},
            "interior": {
                "type": "homogeneous",
                "sigma_t": 1.2,
                "albedo": 0.9,
                "phase": {"type": "hg", "g": 0.5},
            },
        },
        "light": {
            "type": "sphere",
            "center": [1.2, 1.2, 0.6],
            "radius": 0.2,
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [100, 100, 100]}},
        },
    })


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", choices=["smoke", "dark"], default="smoke")
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--pass-spp", type=int, default=1024)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", required=True, help="output .exr file")
    args = ap.parse_args()

    import mitsuba as mi
    import numpy as np

    mi.set_variant(args.variant)
    t0 = time.time()
    scene = smoke_scene(mi) if args.scene == "smoke" else dark_scene(mi)
    accum = np.zeros((SIZE, SIZE, 3), dtype=np.float64)
    done = 0
    i = 0
    while done < args.spp:
        n = min(args.pass_spp, args.spp - done)
        img = mi.render(scene, spp=n, seed=args.seed * 1_000_003 + i)
        accum += np.array(img, dtype=np.float64)[..., :3] * n
        done += n
        i += 1
        print(f"[{time.time() - t0:7.1f} s] {done}/{args.spp} spp",
              file=sys.stderr, flush=True)
    img = (accum / done).astype(np.float32)
    mi.Bitmap(img, pixel_format=mi.Bitmap.PixelFormat.RGB).write(args.out)
    mean = img.reshape(-1, 3).mean(axis=0)
    print(f"wrote {args.out} ({args.variant}, {args.spp} spp, {time.time() - t0:.1f} s); "
          f"mean RGB = {mean[0]:.6f} {mean[1]:.6f} {mean[2]:.6f}", file=sys.stderr)


if __name__ == "__main__":
    main()

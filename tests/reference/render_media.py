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

``--scene beam``: ``scenes/media/fog-beam.yaml``, a spot light's visible
beam in a global homogeneous fog the camera sits in (the sensor's
``medium``; Mitsuba has no height fog, so the beam is referenced with a
homogeneous atmosphere and ``height_fog`` is tested against closed forms).

``--scene cloud``: ``scenes/media/cloud.yaml``, a heterogeneous cloud on the
32^3 grid ``scenes/media/cloud.vol`` (Mitsuba's ``heterogeneous`` medium
with a ``gridvolume``; the same file feeds Radiant's ``grid`` medium) inside
a ``null`` cube, lit by a sun (``directional``) and a constant environment.
``--write-grid`` (re)writes ``cloud.vol`` from the procedural density
below (deterministic) before rendering.

The committed reference ``tests/data/media-smoke-mitsuba.exr`` was made with
(Mitsuba 3.9.1, scalar_rgb; no LLVM needed)::

    nice -n 10 python3 tests/reference/render_media.py --spp 32768 \\
        --pass-spp 4096 --out tests/data/media-smoke-mitsuba.exr
    nice -n 10 python3 tests/reference/render_media.py --scene dark \\
        --spp 65536 --pass-spp 8192 --out tests/data/media-dark-mitsuba.exr
    nice -n 10 python3 tests/reference/render_media.py --scene beam \\
        --spp 8192 --pass-spp 1024 --out tests/data/media-beam-mitsuba.exr
    nice -n 10 python3 tests/reference/render_media.py --scene cloud --write-grid \\
        --spp 8192 --pass-spp 1024 --out tests/data/media-cloud-mitsuba.exr
    nice -n 10 python3 tests/reference/render_media.py --scene jade \\
        --spp 4096 --pass-spp 512 --out tests/data/media-jade-mitsuba.exr
    nice -n 10 python3 tests/reference/render_media.py --scene cloud --max-depth 2 \\
        --spp 8192 --pass-spp 1024 --out tests/data/media-cloud-depth2-mitsuba.exr

``--scene jade``: ``scenes/media/jade.yaml``, random-walk subsurface
scattering: a dielectric sphere around a dense scattering medium, under a
constant sky and a spherical light.
"""
import argparse
import os
import sys
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
CLOUD_VOL = os.path.join(ROOT, "scenes", "media", "cloud.vol")

# The smoke of scenes/media/cornell-smoke.yaml.
SIGMA_S = [2.0, 3.5, 5.0]
SIGMA_A = [0.3, 0.2, 0.1]
G = 0.3
CENTER = [0.3, 0.45, 0.3]
RADIUS = 0.38
SIZE = 64


def smoke_scene(mi, max_depth=-1):
    """mi.cornell_box() at SIZE x SIZE with the smoke sphere and volpath."""
    desc = mi.cornell_box()
    desc["integrator"] = {"type": "volpath", "max_depth": max_depth, "rr_depth": 5}
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


def dark_scene(mi, max_depth=-1):
    """A grey HG smoke sphere and a spherical light, no other geometry."""
    T = mi.ScalarTransform4f
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": max_depth, "rr_depth": 5},
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


def beam_scene(mi, max_depth=-1):
    """scenes/media/fog-beam.yaml: a spot light's beam in a global fog."""
    T = mi.ScalarTransform4f
    fog = {
        "type": "homogeneous",
        "sigma_t": 0.3,
        "albedo": 0.25 / 0.3,
        "phase": {"type": "hg", "g": 0.3},
    }
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": max_depth, "rr_depth": 5},
        "sensor": {
            "type": "perspective",
            "fov": 50,
            "to_world": T().look_at(origin=[0, 1.2, 4.5], target=[0, 0.8, 0], up=[0, 1, 0]),
            "medium": fog,
            "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE,
                     "rfilter": {"type": "gaussian", "stddev": 0.5}},
        },
        "ground": {"type": "rectangle",
                   "to_world": T().rotate([1, 0, 0], -90).scale(3.0),
                   "bsdf": {"type": "diffuse", "reflectance": 0.5}},
        "ball": {"type": "sphere", "center": [0.2, 1.0, 0], "radius": 0.3,
                 "bsdf": {"type": "diffuse",
                          "reflectance": {"type": "rgb", "value": [0.7, 0.5, 0.3]}}},
        "bubble": {"type": "sphere", "center": [-0.5, 5, -0.5], "radius": 0.5,
                   "bsdf": {"type": "null"}, "exterior": fog},
        "spot": {"type": "spot",
                 "to_world": T().look_at(origin=[-0.5, 5, -0.5], target=[0.3, 0, 0.2],
                                         up=[0, 1, 0]),
                 "intensity": {"type": "rgb", "value": [100, 90, 75]},
                 "cutoff_angle": 18.0, "beam_width": 12.0},
    })


# The cloud of scenes/media/cloud.yaml.
CLOUD_N = 32
CLOUD_SIGMA_S = 3.6
CLOUD_SIGMA_A = 0.4
CLOUD_G = 0.3


def cloud_density(np):
    """A deterministic lumpy cloud on CLOUD_N^3 voxels over [-1, 1]^3: a few
    Gaussian blobs, modulated by sines, zero at the box's faces."""
    n = CLOUD_N
    c = (np.arange(n) + 0.5) / n * 2 - 1  # voxel centres
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    rng = np.random.default_rng(2026)
    d = np.zeros((n, n, n))
    for _ in range(7):
        cx, cy, cz = rng.uniform(-0.45, 0.45, 3) * [1.0, 0.6, 1.0]
        r = rng.uniform(0.22, 0.4)
        d += np.exp(-((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / (2 * r * r))
    d *= 1 + 0.4 * np.sin(7 * x + 1) * np.sin(6 * y + 2) * np.sin(8 * z)
    edge = np.clip((1 - np.maximum(np.maximum(abs(x), abs(y)), abs(z))) * 5, 0, 1)
    return np.clip(d * edge, 0, None).astype(np.float32)  # [z, y, x]


def write_cloud(np):
    """Writes CLOUD_VOL (Mitsuba .vol: header, then x fastest)."""
    d = cloud_density(np)
    n = CLOUD_N
    header = b"VOL" + bytes([3]) + np.array([1, n, n, n, 1], "<i4").tobytes()
    header += np.array([-1, -1, -1, 1, 1, 1], "<f4").tobytes()
    with open(CLOUD_VOL, "wb") as f:
        f.write(header + d.astype("<f4").tobytes())
    print(f"wrote {CLOUD_VOL}: max {d.max():.3f}, mean {d.mean():.3f}", file=sys.stderr)


def cloud_scene(mi, max_depth=-1):
    """scenes/media/cloud.yaml: the grid cloud, a sun and a sky."""
    T = mi.ScalarTransform4f
    top = CLOUD_SIGMA_S + CLOUD_SIGMA_A
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": max_depth, "rr_depth": 5},
        "sensor": {
            "type": "perspective",
            "fov": 45,
            "to_world": T().look_at(origin=[0, 0.3, 2.7], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE,
                     "rfilter": {"type": "gaussian", "stddev": 0.5}},
        },
        "cloud": {
            "type": "cube",
            "bsdf": {"type": "null"},
            "interior": {
                "type": "heterogeneous",
                "sigma_t": {"type": "gridvolume", "filename": CLOUD_VOL,
                            "to_world": T().translate([-1, -1, -1]).scale(2.0)},
                "albedo": CLOUD_SIGMA_S / top,
                "scale": top,
                "phase": {"type": "hg", "g": CLOUD_G},
            },
        },
        "sun": {"type": "directional", "direction": [-0.5, -1.0, -0.3],
                "irradiance": {"type": "rgb", "value": [8.0, 7.5, 6.5]}},
        "sky": {"type": "constant",
                "radiance": {"type": "rgb", "value": [0.15, 0.2, 0.3]}},
    })


def jade_scene(mi, max_depth=-1):
    """scenes/media/jade.yaml: random-walk subsurface scattering in a
    dielectric sphere."""
    T = mi.ScalarTransform4f
    sigma_s, sigma_a = [6.0, 9.0, 7.0], [0.6, 0.1, 0.4]
    sigma_t = [s + a for s, a in zip(sigma_s, sigma_a)]
    top = max(sigma_t)
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": max_depth, "rr_depth": 5},
        "sensor": {
            "type": "perspective",
            "fov": 30,
            "to_world": T().look_at(origin=[0, 0.5, 3], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE,
                     "rfilter": {"type": "gaussian", "stddev": 0.5}},
        },
        "jade": {
            "type": "sphere", "radius": 0.6,
            "bsdf": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0},
            "interior": {
                "type": "homogeneous",
                "sigma_t": {"type": "rgb", "value": [t / top for t in sigma_t]},
                "scale": top,
                "albedo": {"type": "rgb", "value": [s / t for s, t in zip(sigma_s, sigma_t)]},
                "phase": {"type": "hg", "g": 0.2},
            },
        },
        "light": {"type": "sphere", "center": [1.5, 1.8, 1.0], "radius": 0.5,
                  "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [6, 6, 6]}}},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [0.3, 0.35, 0.45]}},
    })


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", choices=["smoke", "dark", "beam", "cloud", "jade"], default="smoke")
    ap.add_argument("--write-grid", action="store_true",
                    help="write scenes/media/cloud.vol from the procedural density first")
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--pass-spp", type=int, default=1024)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--max-depth", type=int, default=-1,
                    help="volpath's max_depth (-1: unlimited); null crossings do not count")
    ap.add_argument("--out", required=True, help="output .exr file")
    args = ap.parse_args()

    import mitsuba as mi
    import numpy as np

    mi.set_variant(args.variant)
    t0 = time.time()
    if args.write_grid:
        write_cloud(np)
    scenes = {"smoke": smoke_scene, "dark": dark_scene, "beam": beam_scene, "cloud": cloud_scene,
              "jade": jade_scene}
    scene = scenes[args.scene](mi, args.max_depth)
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

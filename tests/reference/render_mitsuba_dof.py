#!/usr/bin/env python3
"""Render the depth-of-field reference for Radiant with Mitsuba 3.

The scene is Mitsuba's ``mi.cornell_box()`` seen through a ``thinlens``
sensor (aperture radius 0.2, focused 3.3 units ahead, on the front of the
small box) at 128x128, exactly as ``scenes/depth-of-field.yaml`` describes
it. Writes a linear float32 RGB OpenEXR. The committed
``tests/data/depth-of-field-mitsuba.exr`` was made with:

    nice -n 10 python3 tests/reference/render_mitsuba_dof.py \\
        --variant scalar_rgb --spp 2048 --out tests/data/depth-of-field-mitsuba.exr

It reuses the variant set-up and pass averaging of render_mitsuba.py.
"""
import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from render_mitsuba import setup_variant  # noqa: E402

SIZE = 128
APERTURE_RADIUS = 0.2
FOCUS_DISTANCE = 3.3


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--pass-spp", type=int, default=1024)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    mi = setup_variant(args.variant)
    import numpy as np

    desc = mi.cornell_box()
    desc["integrator"]["max_depth"] = args.max_depth
    sensor = desc["sensor"]
    sensor["type"] = "thinlens"
    sensor["aperture_radius"] = APERTURE_RADIUS
    sensor["focus_distance"] = FOCUS_DISTANCE
    sensor.pop("near_clip", None)
    sensor.pop("far_clip", None)
    sensor["film"]["width"] = SIZE
    sensor["film"]["height"] = SIZE
    scene = mi.load_dict(desc)

    t0 = time.time()
    accum = np.zeros((SIZE, SIZE, 3), dtype=np.float64)
    done, i = 0, 0
    while done < args.spp:
        n = min(args.pass_spp, args.spp - done)
        img = mi.render(scene, spp=n, seed=1_000_003 * 7 + i)
        accum += np.array(img, dtype=np.float64)[..., :3] * n
        done += n
        i += 1
        print(f"[{time.time() - t0:7.1f} s] {done}/{args.spp} spp", file=sys.stderr, flush=True)
    img = (accum / done).astype(np.float32)
    mi.Bitmap(img, pixel_format=mi.Bitmap.PixelFormat.RGB).write(args.out)
    print(f"wrote {args.out}; mean RGB = {img.reshape(-1, 3).mean(axis=0)}", file=sys.stderr)


if __name__ == "__main__":
    main()

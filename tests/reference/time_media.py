#!/usr/bin/env python3
"""Times Mitsuba 3 on the grid cloud (scenes/media/cloud.yaml) and prints
its MSE against the committed reference, for an equal-time comparison with
`radiant render scenes/media/cloud.yaml --spp N --seed 11 -o OUT.exr`
(whose MSE the same script prints with ``--radiant OUT.exr``).

    python3 tests/reference/time_media.py --variant llvm_ad_rgb --spp 64 256
    radiant render scenes/media/cloud.yaml --spp 256 --seed 11 -o /tmp/cloud.exr
    python3 tests/reference/time_media.py --radiant /tmp/cloud.exr
"""
import argparse
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REFERENCE = os.path.join(HERE, "..", "data", "media-cloud-mitsuba.exr")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--spp", type=int, nargs="*", default=[64, 256])
    ap.add_argument("--radiant", help="a Radiant render of the cloud: print its MSE only")
    args = ap.parse_args()
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
    sys.path.insert(0, HERE)
    import numpy as np
    import mitsuba as mi
    mi.set_variant("scalar_rgb" if args.radiant else args.variant)
    ref = np.array(mi.Bitmap(REFERENCE))[..., :3]
    if args.radiant:
        img = np.array(mi.Bitmap(args.radiant))[..., :3]
        print(f"{args.radiant}: MSE {np.mean((img - ref) ** 2):.4e}")
        return
    import render_media
    scene = render_media.cloud_scene(mi)
    mi.render(scene, spp=4)  # compiles the kernels outside the timing
    for spp in args.spp:
        t = time.time()
        img = np.array(mi.render(scene, spp=spp, seed=11))[..., :3]
        print(f"{args.variant} {spp} spp: {time.time() - t:.2f} s, "
              f"MSE {np.mean((img - ref) ** 2):.4e}")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Render the Mitsuba 3 Cornell box as an independent reference image for Radiant.

Renders Mitsuba's built-in ``mi.cornell_box()`` scene (256x256, gaussian
reconstruction filter, ``path`` integrator) and writes a linear float32 RGB
OpenEXR (channels R, G, B; no alpha). High sample counts are rendered in passes
with distinct seeds and averaged, to bound memory use.

The committed reference ``tests/data/cornell-box-mitsuba.exr`` was made with:

    pip install mitsuba numpy
    apt-get install -y libllvm19   # llvm_* variants need libLLVM >= 16
    nice -n 10 python3 tests/reference/render_mitsuba.py \\
        --spp 8192 --max-depth 8 --out tests/data/cornell-box-mitsuba.exr

``DRJIT_LIBLLVM_PATH`` is set automatically if unset and a libLLVM is found in
a common location. Use ``--variant scalar_rgb`` to avoid the LLVM dependency.
"""
import argparse
import glob
import os
import sys
import time

LLVM_CANDIDATES = [
    "/usr/lib/x86_64-linux-gnu/libLLVM-2[0-9].so",
    "/usr/lib/x86_64-linux-gnu/libLLVM-1[6-9].so",
    "/usr/lib/llvm-*/lib/libLLVM.so",
    "/usr/lib/llvm-*/lib/libLLVM-*.so",
    "/usr/local/lib/libLLVM*.so",
    "/opt/homebrew/opt/llvm/lib/libLLVM.dylib",
    "/usr/local/opt/llvm/lib/libLLVM.dylib",
]


def find_libllvm():
    """Return the newest libLLVM shared library found in a common location."""
    for pattern in LLVM_CANDIDATES:
        hits = sorted(glob.glob(pattern))
        if hits:
            return hits[-1]
    return None


def setup_variant(variant):
    """Select the Mitsuba variant, pointing Dr.Jit at libLLVM if needed."""
    if variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ:
        lib = find_libllvm()
        if lib:
            os.environ["DRJIT_LIBLLVM_PATH"] = lib
    import mitsuba as mi

    mi.set_variant(variant)
    return mi


def render_cornell_box(mi, spp, max_depth, seed, pass_spp=1024, log=None):
    """Render mi.cornell_box() and return a float32 (256, 256, 3) numpy array."""
    import numpy as np

    desc = mi.cornell_box()
    desc["integrator"]["max_depth"] = max_depth
    scene = mi.load_dict(desc)
    passes = max(1, -(-spp // pass_spp))
    accum = np.zeros((256, 256, 3), dtype=np.float64)
    done = 0
    for i in range(passes):
        n = min(pass_spp, spp - done)
        img = mi.render(scene, spp=n, seed=seed * 1_000_003 + i)
        accum += np.array(img, dtype=np.float64)[..., :3] * n
        done += n
        if log:
            log(f"pass {i + 1}/{passes}: {done}/{spp} spp")
    return (accum / done).astype(np.float32)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--pass-spp", type=int, default=1024,
                    help="samples per pass (bounds memory)")
    ap.add_argument("--out", required=True, help="output .exr file")
    args = ap.parse_args()

    mi = setup_variant(args.variant)
    t0 = time.time()

    def log(msg):
        print(f"[{time.time() - t0:7.1f} s] {msg}", file=sys.stderr, flush=True)

    img = render_cornell_box(mi, args.spp, args.max_depth, args.seed,
                             args.pass_spp, log)
    bmp = mi.Bitmap(img, pixel_format=mi.Bitmap.PixelFormat.RGB)
    bmp.write(args.out)
    mean = img.reshape(-1, 3).mean(axis=0)
    log(f"wrote {args.out} ({args.variant}, {args.spp} spp, max_depth "
        f"{args.max_depth}); mean RGB = {mean[0]:.6f} {mean[1]:.6f} {mean[2]:.6f}")


if __name__ == "__main__":
    main()

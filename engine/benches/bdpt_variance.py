#!/usr/bin/env python3
"""Variance per sample of unbiased renders, from pairs of independent seeds
(engine/benches/BDPT.md's method).

For each scene file and seed s, renders with seeds s and s + 1 at --spp and
takes V = mean over pixels and channels of (a - b)^2 / 2 x spp: the variance
of one sample, which does not depend on the machine's load (the time per
sample is measured separately, by callgrind or wall clock). With --where,
also prints where the first scene's variance lies against the second's: the
pixels whose variance ratio exceeds a threshold and their share of each
scene's total.

    engine/benches/bdpt_variance.py --radiant target/release/radiant --spp 1024 \
        --seeds 1 3 5 7 caustic-bdpt.yaml
    engine/benches/bdpt_variance.py --spp 1024 --where caustic-bdpt.yaml caustic-path.yaml

(--where compares per-sample variances, so the scenes may use different
spp only through --spp-of FILE=N.)

Reads the scanline EXR files Radiant writes (float or half, no or ZIP
compression) with numpy alone.
"""

import argparse
import struct
import subprocess
import sys
import tempfile
import zlib
from pathlib import Path

import numpy as np


def read_exr(path):
    """RGB of an EXR file as an (h, w, 3) float32 array."""
    d = Path(path).read_bytes()
    p, attrs = 8, {}
    while d[p] != 0:
        e = d.index(b"\0", p)
        name, p = d[p:e].decode(), e + 1
        e = d.index(b"\0", p)
        p = e + 1
        size = struct.unpack("<i", d[p : p + 4])[0]
        attrs[name], p = d[p + 4 : p + 4 + size], p + 4 + size
    p += 1
    chans, ch, q = [], attrs["channels"], 0
    while ch[q] != 0:
        e = ch.index(b"\0", q)
        chans.append((ch[q:e].decode(), struct.unpack("<i", ch[e + 1 : e + 5])[0]))
        q = e + 17
    x0, y0, x1, y1 = struct.unpack("<4i", attrs["dataWindow"])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    comp = attrs["compression"][0]
    if comp not in (0, 2, 3):
        sys.exit(f"{path}: EXR compression {comp} not supported")
    lines = 16 if comp == 3 else 1
    blocks = (h + lines - 1) // lines
    out = {name: np.zeros((h, w), np.float32) for name, _ in chans}
    for o in struct.unpack(f"<{blocks}Q", d[p : p + 8 * blocks]):
        y, size = struct.unpack("<ii", d[o : o + 8])
        raw, n = d[o + 8 : o + 8 + size], min(lines, y1 - y + 1)
        full = sum(w * (4 if t == 2 else 2) for _, t in chans) * n
        if comp and size < full:
            t = np.frombuffer(zlib.decompress(raw), np.uint8).astype(np.int32)
            t = (np.cumsum(np.concatenate([[t[0]], t[1:] - 128])) & 0xFF).astype(np.uint8)
            half, r = (len(t) + 1) // 2, np.empty_like(t)
            r[0::2], r[1::2] = t[:half], t[half:]
            raw = r.tobytes()
        q = 0
        for row in range(n):
            for name, t in chans:
                k = 4 if t == 2 else 2
                a = np.frombuffer(raw[q : q + w * k], np.float32 if t == 2 else np.float16)
                out[name][y - y0 + row], q = a, q + w * k
    return np.stack([out["R"], out["G"], out["B"]], -1)


def pixel_variance(radiant, scene, spp, seed, tmp):
    """Per-pixel variance of one sample of `scene` from seeds `seed`, `seed + 1`."""
    images = []
    for s in (seed, seed + 1):
        out = Path(tmp) / f"{Path(scene).stem}-{s}.exr"
        cmd = [radiant, "render", scene, "-o", str(out), "--spp", str(spp), "--seed", str(s)]
        subprocess.run(cmd + ["--backend", "cpu"], check=True, capture_output=True)
        images.append(read_exr(out))
    return ((images[0] - images[1]) ** 2).mean(-1) / 2 * spp


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--radiant", default="target/release/radiant")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--spp-of", action="append", default=[], metavar="FILE=N")
    ap.add_argument("--seeds", type=int, nargs="+", default=[1])
    ap.add_argument("--where", action="store_true")
    args = ap.parse_args()
    spp_of = dict(x.split("=") for x in args.spp_of)
    maps = {}
    with tempfile.TemporaryDirectory() as tmp:
        for scene in args.scenes:
            spp = int(spp_of.get(scene, args.spp))
            per_pair = [pixel_variance(args.radiant, scene, spp, s, tmp) for s in args.seeds]
            totals = " ".join(f"{v.mean():.4g}" for v in per_pair)
            maps[scene] = np.mean(per_pair, 0)
            print(f"{scene}: spp {spp}, V per seed pair {totals}, mean {maps[scene].mean():.4g}")
    if args.where and len(args.scenes) == 2:
        a, b = (maps[s] for s in args.scenes)
        ratio = a / np.maximum(b, 1e-30)
        for threshold in (0.1, 0.5, 1.0):
            sel = ratio > threshold
            print(
                f"pixels with V ratio > {threshold}: {sel.sum()} of {sel.size}, "
                f"{a[sel].sum() / a.sum():.2f} of the first's V, {b[sel].sum() / b.sum():.2f} "
                "of the second's"
            )


if __name__ == "__main__":
    main()

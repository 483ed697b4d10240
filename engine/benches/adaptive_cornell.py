#!/usr/bin/env python3
"""Adaptive sampling against fixed spp on a scene at equal error.

Renders the scene at a fixed spp and with each adaptive variant given on
the command line (the value of the sampler's `adaptive` key), interleaved
round by round (fixed, variant 1, …; each round its own seed), and prints
per variant the median render time Radiant reports, the MSE against a
converged reference (less the reference's own variance, estimated from
its two halves' difference) and T·MSE. For unbiased estimators MSE falls
as 1/time, so (T·MSE of a variant) / (T·MSE of fixed) is the variant's
time to fixed spp's error as a fraction of fixed spp's time.

    python3 engine/benches/adaptive_cornell.py --spp 64 --rounds 6 \
        "{error: mse}" "{error: mse, min_spp: 4}" "true"

The reference defaults to the speed suite's Mitsuba reference of the
Cornell box (`python3 engine/benches/suite.py references`).
"""
import argparse, os, re, statistics, subprocess, sys
import numpy as np
import mitsuba as mi

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CACHE = os.path.expanduser("~/.cache/radiant-bench")


def read(path):
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def main():
    mi.set_variant("scalar_rgb")
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("variants", nargs="*", help="values of the sampler's `adaptive` key")
    ap.add_argument("--scene", default=os.path.join(ROOT, "scenes", "cornell-box.yaml"))
    ap.add_argument("--reference", default=os.path.join(CACHE, "cornell-box.exr"))
    ap.add_argument("--radiant", default=os.path.join(ROOT, "target", "release", "radiant"))
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--rounds", type=int, default=6)
    args = ap.parse_args()
    ref = read(args.reference)
    halves = args.reference.replace(".exr", ".halfdiff.exr")
    ref_var = float(np.mean(read(halves) ** 2)) if os.path.exists(halves) else 0.0
    text = open(args.scene).read()
    scenes = {"fixed": args.scene}
    for v in args.variants:
        edited, n = re.subn(r"^(sampler:\n(?:  .*\n)*)", lambda m: m.group(1) + f"  adaptive: {v}\n",
                            text, count=1, flags=re.M)
        if n != 1:
            sys.exit(f"no block-form `sampler:` in {args.scene}")
        path = os.path.join(os.path.dirname(args.scene), f".adaptive-bench-{len(scenes)}.yaml")
        with open(path, "w") as f:
            f.write(edited)
        scenes[v] = path
    times = {k: [] for k in scenes}
    errors = {k: [] for k in scenes}
    out = f"/tmp/adaptive-bench-{os.getpid()}.exr"
    try:
        for r in range(args.rounds):
            for name, path in scenes.items():
                p = subprocess.run([args.radiant, "render", path, "--spp", str(args.spp),
                                    "--seed", str(r + 1), "-o", out], capture_output=True, text=True)
                m = re.search(r"spp in ([\d.]+) s", p.stderr)
                if p.returncode != 0 or not m:
                    sys.exit(p.stderr)
                times[name].append(float(m.group(1)))
                errors[name].append(float(np.mean((read(out) - ref) ** 2)))
    finally:
        for name, path in scenes.items():
            if name != "fixed":
                os.remove(path)
    base = None
    print(f"{os.path.basename(args.scene)}, spp {args.spp}, {args.rounds} interleaved rounds, "
          f"reference variance {ref_var:.2e}")
    print("| sampling | time (median) | MSE | T·MSE | time to fixed's error |")
    print("|---|---|---|---|---|")
    for name in scenes:
        t = statistics.median(times[name])
        e = max(statistics.mean(errors[name]) - ref_var, 1e-30)
        base = base or t * e
        label = "fixed spp" if name == "fixed" else f"`adaptive: {name}`"
        print(f"| {label} | {t:.2f} s | {e:.3e} | {t * e:.3e} | {t * e / base:.2f}× |")


if __name__ == "__main__":
    main()

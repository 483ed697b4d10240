#!/usr/bin/env python3
"""Peer speed benchmark: Radiant vs Mitsuba 3 on the Cornell box.

Times Mitsuba 3 rendering its built-in ``mi.cornell_box()`` (256x256, 64 spp,
path integrator, max_depth 8) with the ``llvm_ad_rgb`` variant (best of 3 after
a JIT warm-up render) and ``scalar_rgb`` (one render), then runs
``radiant render SCENE --spp 64`` three times and takes the best Msamples/s it
reports on its last stderr line. Prints the CPU (Mitsuba's JIT compiles for
the host's widest vector unit: 16 lanes with AVX-512, 8 with AVX2, so the
peer's speed depends on it), a table and the speed ratios. ``--threads N``
runs both renderers on N threads (default: all).

    pip install mitsuba numpy && apt-get install -y libllvm19
    python3 engine/benches/mitsuba_peer.py --radiant target/release/radiant

``DRJIT_LIBLLVM_PATH`` is set automatically if unset and a libLLVM is found.
"""
import argparse
import glob
import os
import re
import subprocess
import sys
import time

W = H = 256
SPP = 64
MAX_DEPTH = 8
SAMPLES = W * H * SPP
RADIANT_RE = re.compile(r"rendered (\d+)x(\d+), (\d+) spp in ([\d.]+) s "
                        r"\(([\d.]+) Msamples/s, ([\d.]+) Mrays/s\)")


def find_libllvm():
    for pattern in ["/usr/lib/x86_64-linux-gnu/libLLVM-2[0-9].so",
                    "/usr/lib/x86_64-linux-gnu/libLLVM-1[6-9].so",
                    "/usr/lib/llvm-*/lib/libLLVM.so",
                    "/usr/local/lib/libLLVM*.so",
                    "/opt/homebrew/opt/llvm/lib/libLLVM.dylib"]:
        hits = sorted(glob.glob(pattern))
        if hits:
            return hits[-1]
    return None


def cpu_summary():
    """The CPU's model, its logical cores and its widest vector unit."""
    model, flags = "unknown CPU", set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() == "model name" and model == "unknown CPU":
                    model = value.strip()
                elif key.strip() == "flags" and not flags:
                    flags = set(value.split())
    except OSError:
        pass
    vector = ("AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags
              else "SSE/other")
    return f"{model}, {os.cpu_count()} logical cores, {vector}"


def time_mitsuba(mi, variant, runs, warmup):
    """Best wall time (s) of `runs` renders of the Cornell box, or None."""
    try:
        mi.set_variant(variant)
    except Exception as e:  # e.g. libLLVM missing
        print(f"mitsuba {variant}: unavailable ({e})", file=sys.stderr)
        return None
    import drjit as dr
    import numpy as np

    desc = mi.cornell_box()
    desc["integrator"]["max_depth"] = MAX_DEPTH
    scene = mi.load_dict(desc)
    best = float("inf")
    for i in range(warmup + runs):
        t0 = time.perf_counter()
        img = mi.render(scene, spp=SPP, seed=i)
        dr.eval(img)
        np.array(img)  # force evaluation and readback
        dt = time.perf_counter() - t0
        if i >= warmup:
            best = min(best, dt)
        print(f"  mitsuba {variant} run {i + 1}{' (warm-up)' if i < warmup else ''}:"
              f" {dt:.3f} s", file=sys.stderr)
    return best


def time_radiant(binary, scene, runs, threads):
    """Best Msamples/s reported by `radiant render`, or None."""
    if not os.path.exists(binary):
        print(f"radiant binary {binary} not found; skipping", file=sys.stderr)
        return None
    best = None
    for i in range(runs):
        cmd = [binary, "render", scene, "--spp", str(SPP), "-o", "/tmp/radiant_peer.exr"]
        if threads:
            cmd += ["--threads", str(threads)]
        p = subprocess.run(cmd, capture_output=True, text=True)
        lines = p.stderr.strip().splitlines()
        m = RADIANT_RE.search(lines[-1]) if lines else None
        if p.returncode != 0 or not m:
            print(f"radiant run failed (rc={p.returncode}):\n{p.stderr}", file=sys.stderr)
            return best
        msps = float(m.group(5))
        print(f"  radiant run {i + 1}: {m.group(0)}", file=sys.stderr)
        best = msps if best is None else max(best, msps)
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--radiant", default="target/release/radiant",
                    help="path to the radiant binary")
    ap.add_argument("--scene", default="scenes/cornell-box.yaml")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--threads", type=int, default=0,
                    help="threads for both renderers (default: all cores)")
    args = ap.parse_args()

    if "DRJIT_LIBLLVM_PATH" not in os.environ and find_libllvm():
        os.environ["DRJIT_LIBLLVM_PATH"] = find_libllvm()
    try:
        import mitsuba as mi
    except ImportError:
        print("mitsuba is not installed: run `pip install mitsuba numpy` "
              "(and `apt-get install libllvm19` for the llvm variant).")
        return 0
    if args.threads:
        import drjit as dr
        dr.set_thread_count(args.threads)

    def msps(t):
        return SAMPLES / t / 1e6 if t else None

    results = {
        "mitsuba llvm_ad_rgb": msps(time_mitsuba(mi, "llvm_ad_rgb", args.runs, 1)),
        "mitsuba scalar_rgb": msps(time_mitsuba(mi, "scalar_rgb", 1, 0)),
        "radiant": time_radiant(args.radiant, args.scene, args.runs, args.threads),
    }

    threads = args.threads or "all"
    print(f"\nCornell box {W}x{H}, {SPP} spp, max_depth {MAX_DEPTH}, {threads} threads")
    print(f"CPU: {cpu_summary()}")
    print(f"{'renderer':<22}{'Msamples/s':>12}")
    for name, v in results.items():
        print(f"{name:<22}{(f'{v:.3f}' if v else 'n/a'):>12}")
    r = results["radiant"]
    for name in ("mitsuba llvm_ad_rgb", "mitsuba scalar_rgb"):
        m = results[name]
        if r and m:
            print(f"radiant / {name[8:]:<13}{r / m:>11.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())

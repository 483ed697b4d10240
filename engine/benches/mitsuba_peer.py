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

Samples per second reward cheap samples, so the script also compares what
users wait for: every timed render (each with its own seed) is compared with
the converged Mitsuba reference ``tests/data/cornell-box-mitsuba.exr``
(8192 spp). Its mean squared error over all pixels and channels falls as
1/spp for both unbiased renderers, so the time to reach any given error is
T(e) = T64 * MSE64 / e^2 and the *equal-error speed ratio* is
(T_mitsuba * MSE_mitsuba) / (T_radiant * MSE_radiant). The reference's own
noise (1/128 of a 64-spp render's) is in both MSEs and pulls that ratio
slightly towards 1.

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


def read_rgb(mi, path):
    """An EXR's RGB channels as a float64 (H, W, 3) array."""
    import drjit as dr
    import numpy as np
    # Bitmap's EXR reader waits on Dr.Jit's thread pool, which deadlocks
    # when `--threads 1` has shrunk it to one thread: read with more.
    threads = dr.thread_count()
    dr.set_thread_count(max(2, threads))
    try:
        return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]
    finally:
        dr.set_thread_count(threads)


def mse(image, reference):
    """Mean squared error over all pixels and channels, or None without a reference."""
    if reference is None:
        return None
    import numpy as np
    return float(np.mean((np.asarray(image, dtype=np.float64)[..., :3] - reference) ** 2))


def time_mitsuba(mi, variant, runs, warmup, reference):
    """Best wall time (s) of `runs` renders of the Cornell box and their mean
    squared error against `reference` (None without one), or (None, None)."""
    try:
        mi.set_variant(variant)
    except Exception as e:  # e.g. libLLVM missing
        print(f"mitsuba {variant}: unavailable ({e})", file=sys.stderr)
        return None, None
    import drjit as dr
    import numpy as np

    desc = mi.cornell_box()
    desc["integrator"]["max_depth"] = MAX_DEPTH
    scene = mi.load_dict(desc)
    best, errors = float("inf"), []
    for i in range(warmup + runs):
        t0 = time.perf_counter()
        img = mi.render(scene, spp=SPP, seed=i)
        dr.eval(img)
        pixels = np.array(img)  # force evaluation and readback
        dt = time.perf_counter() - t0
        if i >= warmup:
            best = min(best, dt)
            errors.append(mse(pixels, reference))
        print(f"  mitsuba {variant} run {i + 1}{' (warm-up)' if i < warmup else ''}:"
              f" {dt:.3f} s", file=sys.stderr)
    return best, mean_of(errors)


def mean_of(values):
    """The mean of `values`, or None if any is None or there are none."""
    if not values or any(v is None for v in values):
        return None
    return sum(values) / len(values)


def time_radiant(mi, binary, scene, runs, threads, reference):
    """Best Msamples/s reported by `radiant render` and the renders' mean
    squared error against `reference` (None without one), or (None, None)."""
    if not os.path.exists(binary):
        print(f"radiant binary {binary} not found; skipping", file=sys.stderr)
        return None, None
    best, errors = None, []
    out = "/tmp/radiant_peer.exr"
    for i in range(runs):
        cmd = [binary, "render", scene, "--spp", str(SPP), "--seed", str(i), "-o", out]
        if threads:
            cmd += ["--threads", str(threads)]
        p = subprocess.run(cmd, capture_output=True, text=True)
        lines = p.stderr.strip().splitlines()
        m = RADIANT_RE.search(lines[-1]) if lines else None
        if p.returncode != 0 or not m:
            print(f"radiant run failed (rc={p.returncode}):\n{p.stderr}", file=sys.stderr)
            return best, None
        msps = float(m.group(5))
        print(f"  radiant run {i + 1}: {m.group(0)}", file=sys.stderr)
        best = msps if best is None else max(best, msps)
        errors.append(mse(read_rgb(mi, out), reference) if reference is not None else None)
    return best, mean_of(errors)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--radiant", default="target/release/radiant",
                    help="path to the radiant binary")
    ap.add_argument("--scene", default="scenes/cornell-box.yaml")
    ap.add_argument("--reference", default="tests/data/cornell-box-mitsuba.exr",
                    help="converged image for the equal-error comparison")
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

    reference = None
    if args.scene == "scenes/cornell-box.yaml" and os.path.exists(args.reference):
        mi.set_variant("scalar_rgb")
        reference = read_rgb(mi, args.reference)
    else:
        print("no reference for this scene: equal-error ratios skipped", file=sys.stderr)

    llvm_time, llvm_mse = time_mitsuba(mi, "llvm_ad_rgb", args.runs, 1, reference)
    scalar_time, scalar_mse = time_mitsuba(mi, "scalar_rgb", 1, 0, reference)
    radiant_msps, radiant_mse = time_radiant(mi, args.radiant, args.scene, args.runs,
                                             args.threads, reference)
    # name: (Msamples/s, MSE at 64 spp)
    results = {
        "mitsuba llvm_ad_rgb": (msps(llvm_time), llvm_mse),
        "mitsuba scalar_rgb": (msps(scalar_time), scalar_mse),
        "radiant": (radiant_msps, radiant_mse),
    }

    threads = args.threads or "all"
    print(f"\nCornell box {W}x{H}, {SPP} spp, max_depth {MAX_DEPTH}, {threads} threads")
    print(f"CPU: {cpu_summary()}")
    print(f"{'renderer':<22}{'Msamples/s':>12}{'MSE (64 spp)':>16}")
    for name, (v, e) in results.items():
        print(f"{name:<22}{(f'{v:.3f}' if v else 'n/a'):>12}{(f'{e:.4e}' if e else 'n/a'):>16}")
    r, r_mse = results["radiant"]
    for name in ("mitsuba llvm_ad_rgb", "mitsuba scalar_rgb"):
        m, m_mse = results[name]
        if r and m:
            line = f"radiant / {name[8:]:<13}{r / m:>11.2f}x samples/s"
            if r_mse and m_mse:
                # Time to a given error is proportional to MSE / (samples/s).
                line += f", {(m_mse / m) / (r_mse / r):.2f}x at equal error"
            print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())

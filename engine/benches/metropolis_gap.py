#!/usr/bin/env python3
"""Time for `pssmlt` and `erpt` to reach the error that `path` reaches in
60 s on scenes/veach-gap.yaml (light enters the room only through a narrow
gap). Results and the command: engine/benches/METROPOLIS.md.

The error is the mean squared error against a path-traced reference made
of two independent halves (seeds 11 and 12): the MSE of an image X
against one half is MSE(X) + var(half), so MSE(X) = the mean over both
halves of MSE(X, half) − MSE(half 1, half 2)/2, without reference bias.

`path` renders for `--path-time` seconds (`--time`, all cores). Each
Metropolis configuration renders at doubling budgets (mutations per pixel)
until its MSE falls below path's; the time to reach it is interpolated
between the two budgets around it in log-log (MSE ∝ 1/time locally).
Times are the wall seconds of the render alone (radiant's `rendered … in
T s` line), so run it on an otherwise idle machine; the reference and
path's image are kept in the output folder and reused.

Usage: engine/benches/metropolis_gap.py [--radiant target/release/radiant]
       [--scene scenes/veach-gap.yaml] [--out gap-figure] [--ref-spp 4096] [--path-time 60]
       [--config 'pssmlt' --config 'erpt, seeds: 32, chain_length: 1024' ...]
"""
import argparse, math, os, re, subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "scenes", "veach-gap.yaml")
CONFIGS = [
    "pssmlt",
    "pssmlt, chains: 256, large_step: 0.1",
    "erpt",
    "erpt, seeds: 32, chain_length: 1024",
]


def render(radiant, scene, out, *args):
    r = subprocess.run([radiant, "render", scene, "-o", out, *args],
                       capture_output=True, text=True, check=True)
    line = [l for l in r.stderr.splitlines() if l.startswith(("rendered", "time up"))]
    m = re.search(r"in ([0-9.]+) s", r.stderr)
    return (float(m.group(1)) if m else None), (line[-1] if line else "")


def rmse(radiant, a, b):
    r = subprocess.run([radiant, "compare", a, b], capture_output=True, text=True, check=True)
    return float(re.search(r"rmse\s+([0-9.eE+-]+)", r.stdout).group(1))


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--radiant", default=os.path.join(ROOT, "target", "release", "radiant"))
    p.add_argument("--scene", default=SCENE)
    p.add_argument("--out", default="gap-figure")
    p.add_argument("--ref-spp", type=int, default=4096)
    p.add_argument("--path-time", type=float, default=60.0)
    p.add_argument("--config", action="append")
    p.add_argument("--max-spp", type=int, default=1024)
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    # Every render uses a box filter of radius 0.5: the Metropolis
    # integrators' splat film divides by the filter's whole integral, which
    # darkens the pixels within a wider filter's reach of the image's edge.
    with open(a.scene) as f:
        text = re.sub(r"filter: \{[^}]*\}", "filter: {type: box}", f.read(), count=1)
    scene = os.path.join(a.out, "scene.yaml")
    with open(scene, "w") as f:
        f.write(text)
    refs = [os.path.join(a.out, f"ref-{s}.exr") for s in (11, 12)]
    for s, ref in zip((11, 12), refs):
        if not os.path.exists(ref):
            render(a.radiant, scene, ref, "--spp", str(a.ref_spp), "--seed", str(s))
    var_half = rmse(a.radiant, refs[0], refs[1]) ** 2 / 2

    def mse(img):
        return sum(rmse(a.radiant, img, r) ** 2 for r in refs) / 2 - var_half

    path = os.path.join(a.out, "path.exr")
    if not os.path.exists(path):
        _, line = render(a.radiant, scene, path, "--time", f"{a.path_time:g}s",
                         "--spp", "1000000", "--seed", "1")
        print(f"path: {line}")
    target = mse(path)
    print(f"path, {a.path_time:g} s: MSE {target:.4g} (reference halves' variance "
          f"{var_half:.3g} subtracted)")
    for k, config in enumerate(a.config or CONFIGS):
        variant = os.path.join(a.out, f"config-{k}.yaml")
        with open(variant, "w") as f:
            f.write(text.replace("{type: path,", "{type: %s," % config, 1))
        prev, spp, reached = None, 16, None
        while spp <= a.max_spp:
            img = os.path.join(a.out, f"config-{k}-{spp}.exr")
            t, _ = render(a.radiant, variant, img, "--spp", str(spp), "--seed", "1")
            e = mse(img)
            print(f"  [{config}] {spp:5d} mutations/pixel: {t:7.2f} s, MSE {e:.4g} "
                  f"({e / target:.2f}× path's)")
            if e <= target:
                if prev is None:
                    reached = t
                else:
                    (t0, e0) = prev
                    s = math.log(t / t0) / math.log(e / e0)
                    reached = t0 * (target / e0) ** s
                break
            prev, spp = (t, e), spp * 2
        if reached is None:
            print(f"[{config}] did not reach path's MSE by {a.max_spp} mutations per pixel")
        else:
            print(f"[{config}] reaches path's {a.path_time:g}-s MSE in {reached:.1f} s: "
                  f"{reached / a.path_time:.2f} of path's time")


if __name__ == "__main__":
    main()

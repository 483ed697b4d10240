"""GPU speed against Mitsuba 3's CUDA variant (issue 15), and the CPU backend
on the same machine.

Usage (from the repository root):
    python3 engine/benches/gpu/gpu_bench.py --radiant target/release/radiant \
        --models ../shared/data/models [--peer ../shared/peers/mitsuba_gpu.py] \
        [--cpu] [--spp 16,64,256] [--repeat 3] [--out DIR]

    python3 engine/benches/gpu/gpu_bench.py --radiant target/release/radiant \
        --models ../shared/data/models --analysis [--peer ...]

    python3 engine/benches/gpu/gpu_bench.py --radiant target/release/radiant \
        --models ../shared/data/models --bvh binary,wide --scenes bunny,ogre,ogres

    python3 engine/benches/gpu/gpu_bench.py --radiant target/release/radiant \
        --models ../shared/data/models --kernels megakernel,wavefront

Renders cornell.yaml and cornell-bunny.yaml (1024x1024, max_depth 8) with
`--backend gpu`, once to warm up and then --repeat times, and prints the best
render time (the CLI's `rendered ... in T s`: kernel time and readback, not
scene loading, BVH building or kernel compilation) as Msamples/s and
Mrays/s. With --peer, runs Mitsuba's script in the same run (it needs
Mitsuba 3 with `cuda_ad_rgb` on PYTHONPATH) and prints the ratio. With
--cpu, renders the same scenes with `--backend cpu`. Skips, saying why,
where there is no GPU adapter or no Mitsuba.

--bvh renders every GPU scene once per hierarchy layout (`--gpu-bvh`:
binary, wide) and, with more than one, compares them: Msamples/s and the
traversal work per ray (`--gpu-stats`: nodes visited, primitives tested).
--scenes picks the scenes of the timed renders: cornell, bunny, ogre
(cornell-ogre.yaml, 124k triangles), ogres (24 instances of it).

--kernels renders every GPU scene once per GPU kernel (`--gpu-kernel`:
megakernel, wavefront; the first layout of --bvh) and, with more than one,
compares them: Msamples/s, and the GPU time per stage of one 16-spp render
each (`--gpu-stats`: `stages (KERNEL): generate … ms, extend …`).

--analysis instead explains the GPU time: rays by kind and traversal work
per ray (`--gpu-stats`), render time against max_depth 1..8 (the
differences are the cost of each bounce), the large-mesh scenes
(cornell-ogre.yaml, 124k triangles; cornell-ogres.yaml, 24 instances of it),
and equal error: the time Radiant needs to reach the mean squared error of
Mitsuba's 256-spp render, each measured against its own converged reference
(Radiant 8192 spp, Mitsuba 4096 spp, with --peer).
"""
import argparse
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = [("cornell", "cornell.yaml"), ("bunny", "cornell-bunny.yaml")]
ALL_SCENES = dict(SCENES + [("ogre", "cornell-ogre.yaml"), ("ogres", "cornell-ogres.yaml")])
LINE = re.compile(r"rendered (\d+)x(\d+), (\d+) spp in ([0-9.]+) s \(([0-9.]+) Msamples/s, ([0-9.]+) Mrays/s\)")


def render(radiant, scene, spp, backend, out, bvh=None, kernel=None):
    cmd = [radiant, "render", os.path.join(HERE, scene), "-o", out, "--spp", str(spp), "--backend", backend]
    if bvh:
        cmd += ["--gpu-bvh", bvh]
    if kernel:
        cmd += ["--gpu-kernel", kernel]
    p = subprocess.run(cmd, capture_output=True, text=True)
    m = LINE.search(p.stderr)
    if p.returncode != 0 or not m:
        return None, p.stderr.strip().splitlines()[-3:]
    return (float(m.group(4)), float(m.group(5)), float(m.group(6))), None


def bench(radiant, backend, spps, repeat, out, scenes=SCENES, bvh=None, kernel=None):
    results = {}
    label = " ".join(x for x in [backend, bvh, kernel] if x)
    for name, scene in scenes:
        for spp in spps:
            path = os.path.join(out, f"radiant-{backend}-{name}.exr")
            first, err = render(radiant, scene, spp, backend, path, bvh, kernel)
            if first is None:
                print(f"skip: radiant --backend {backend} failed on {scene}: {' | '.join(err)}")
                return None
            runs = [render(radiant, scene, spp, backend, path, bvh, kernel)[0] for _ in range(repeat)]
            best = min(runs, key=lambda r: r[0])
            results[(name, spp)] = best
            print(f"radiant {label} {name} 1024x1024 spp {spp}: best {best[0]:.4f}s of "
                  f"{['%.4f' % r[0] for r in runs]} -> {best[1]:.1f} Msamples/s, {best[2]:.1f} Mrays/s",
                  flush=True)
    return results


PER_RAY = re.compile(r"per ray ([0-9.]+) nodes visited, ([0-9.]+) primitives tested")


def compare_bvh(radiant, layouts, scenes, spps, timed):
    """Traversal work per ray of each layout (16 spp, --gpu-stats) beside the timed renders."""
    work = {}
    for name, scene in scenes:
        for bvh in layouts:
            lines = counts(radiant, scene, 16, bvh)
            m = PER_RAY.search(lines[0]) if lines else None
            work[(name, bvh)] = (float(m.group(1)), float(m.group(2))) if m else None
            print(f"counts {name} {bvh} 16 spp: {lines[0] if lines else 'failed'}", flush=True)
    base = layouts[0]
    head = " | ".join(f"{b} Msamples/s | {b} nodes/ray | {b} prims/ray" for b in layouts)
    print(f"\n| scene | spp | {head} | " + " | ".join(f"{b}/{base}" for b in layouts[1:]) + " |")
    print("|---|---|" + "---|---|---|" * len(layouts) + "---|" * (len(layouts) - 1))
    for name, _ in scenes:
        for spp in spps:
            cells, speed = [], {}
            for b in layouts:
                r = (timed.get(b) or {}).get((name, spp))
                speed[b] = r[1] if r else None
                w = work.get((name, b))
                cells += [f"{r[1]:.1f}" if r else "-", f"{w[0]:.1f}" if w else "-", f"{w[1]:.1f}" if w else "-"]
            ratios = [f"{speed[b] / speed[base]:.2f}x" if speed[b] and speed[base] else "-" for b in layouts[1:]]
            print(f"| {name} | {spp} | " + " | ".join(cells + ratios) + " |")


def peer(script, models, out):
    env = dict(os.environ, OUT=out, PYTHONUNBUFFERED="1")
    p = subprocess.run([sys.executable, script, "cuda_ad_rgb", os.path.join(models, "stanford-bunny.obj")],
                       capture_output=True, text=True, env=env)
    print(p.stdout, end="")
    if p.returncode != 0:
        print(f"skip: the Mitsuba peer failed: {' | '.join(p.stderr.strip().splitlines()[-3:])}")
        return {}
    found = {}
    for line in p.stdout.splitlines():
        m = re.match(r"\S+ (\w+) \d+x\d+ spp (\d+): best ([0-9.]+)s .* -> ([0-9.]+) Msamples/s", line)
        if m:
            found[(m.group(1), int(m.group(2)))] = float(m.group(4))
    return found


def counts(radiant, scene, spp, bvh=None, kernel=None):
    cmd = [radiant, "render", os.path.join(HERE, scene), "-o", "/tmp/stats.exr", "--spp", str(spp),
           "--backend", "gpu", "--gpu-stats"]
    if bvh:
        cmd += ["--gpu-bvh", bvh]
    if kernel:
        cmd += ["--gpu-kernel", kernel]
    p = subprocess.run(cmd, capture_output=True, text=True)
    return [l for l in p.stderr.splitlines() if l.startswith(("rays:", "stages"))]


def compare_kernels(radiant, kernels, scenes, spps, timed, bvh):
    """Msamples/s of each GPU kernel, and GPU time per stage of one 16-spp render each."""
    for name, scene in scenes:
        for kernel in kernels:
            for line in counts(radiant, scene, 16, bvh, kernel):
                print(f"counts {name} {kernel} 16 spp: {line}", flush=True)
    base = kernels[0]
    print("\n| scene | spp | " + " | ".join(f"{k} Msamples/s" for k in kernels) + " | "
          + " | ".join(f"{k}/{base}" for k in kernels[1:]) + " |")
    print("|---|---|" + "---|" * (2 * len(kernels) - 1))
    for name, _ in scenes:
        for spp in spps:
            speed = {k: ((timed.get(k) or {}).get((name, spp)) or (None, None))[1] for k in kernels}
            cells = [f"{speed[k]:.1f}" if speed[k] else "-" for k in kernels]
            ratios = [f"{speed[k] / speed[base]:.2f}x" if speed[k] and speed[base] else "-" for k in kernels[1:]]
            print(f"| {name} | {spp} | " + " | ".join(cells + ratios) + " |")


def read_exr(path):
    import mitsuba as mi
    import numpy as np
    if mi.variant() is None:
        mi.set_variant("scalar_rgb" if "scalar_rgb" in mi.variants() else mi.variants()[0])
    return np.array(mi.Bitmap(path), dtype=np.float64)[:, :, :3]


def mse(a, b):
    return float(((a - b) ** 2).mean())


def equal_error(radiant, peer_script, models, out):
    """Radiant's time to Mitsuba's 256-spp error, each against its own reference."""
    import mitsuba as mi
    for name, scene in SCENES:
        ref = os.path.join(out, f"ref-radiant-{name}.exr")
        render(radiant, scene, 8192, "gpu", ref)
        r_ref = read_exr(ref)
        times = {}
        errors = {}
        for spp in [16, 32, 64, 128, 256]:
            path = os.path.join(out, f"eq-{name}-{spp}.exr")
            subprocess.run([radiant, "render", os.path.join(HERE, scene), "-o", path, "--spp", str(spp),
                            "--backend", "gpu", "--seed", "77"], capture_output=True, text=True)
            best, _ = render(radiant, scene, spp, "gpu", os.path.join(out, "tmp.exr"))
            times[spp] = best[0]
            errors[spp] = mse(read_exr(path), r_ref)
            print(f"radiant {name} spp {spp}: MSE {errors[spp]:.4e} in {times[spp]:.4f}s", flush=True)
        if not peer_script:
            continue
        # Mitsuba: a 4096-spp reference and a 256-spp render, timed.
        code = f"""
import sys, time, drjit as dr, mitsuba as mi, numpy as np
mi.set_variant('cuda_ad_rgb')
sys.argv = ['x', 'cuda_ad_rgb']
exec(open({peer_script!r}).read().split('bench("cornell"')[0])
d = cornell(1024, {os.path.join(models, 'stanford-bunny.obj')!r} if {name!r} == 'bunny' else None)
scene = mi.load_dict(d)
ref = np.zeros((1024, 1024, 3))
for s in range(8):
    ref += np.array(mi.render(scene, spp=512, seed=100 + s))[:, :, :3] / 8
np.array(mi.render(scene, spp=256, seed=1)); dr.sync_thread()
t0 = time.perf_counter(); img = np.array(mi.render(scene, spp=256, seed=2)); dr.sync_thread(); t = time.perf_counter() - t0
print('MITSUBA', t, float(((img[:, :, :3] - ref) ** 2).mean()))
"""
        p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
        line = [l for l in p.stdout.splitlines() if l.startswith("MITSUBA")]
        if not line:
            print(f"skip: Mitsuba equal-error run failed: {p.stderr.strip().splitlines()[-3:]}")
            continue
        _, t_m, e_m = line[0].split()
        t_m, e_m = float(t_m), float(e_m)
        reach = [spp for spp in sorted(errors) if errors[spp] <= e_m]
        if reach:
            spp = reach[0]
            print(f"equal error {name}: Mitsuba 256 spp MSE {e_m:.4e} in {t_m:.4f}s; Radiant reaches it at "
                  f"{spp} spp in {times[spp]:.4f}s -> {t_m / times[spp]:.2f}x faster at equal error", flush=True)
        else:
            print(f"equal error {name}: Mitsuba MSE {e_m:.4e} in {t_m:.4f}s; Radiant at 256 spp {errors[256]:.4e}")


def analysis(radiant, peer_script, models, out):
    scenes = SCENES + [("ogre", "cornell-ogre.yaml"), ("ogres", "cornell-ogres.yaml")]
    for name, scene in scenes:
        for line in counts(radiant, scene, 16):
            print(f"counts {name} 16 spp: {line}", flush=True)
    for name, scene in scenes[2:]:
        best, err = render(radiant, scene, 64, "gpu", os.path.join(out, "tmp.exr"))
        if best:
            print(f"radiant gpu {name} 1024x1024 spp 64: {best[1]:.1f} Msamples/s, {best[2]:.1f} Mrays/s", flush=True)
    for name, scene in SCENES:
        prev = 0.0
        for depth in range(1, 9):
            cmd = [radiant, "render", os.path.join(HERE, scene), "-o", os.path.join(out, "tmp.exr"), "--spp", "64",
                   "--backend", "gpu", "--max-depth", str(depth)]
            runs = []
            for _ in range(3):
                p = subprocess.run(cmd, capture_output=True, text=True)
                m = LINE.search(p.stderr)
                if m:
                    runs.append(float(m.group(4)))
            t = min(runs)
            print(f"depth {name} max_depth {depth}: {t:.4f}s (+{t - prev:.4f}s)", flush=True)
            prev = t
    equal_error(radiant, peer_script, models, out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--radiant", default="target/release/radiant")
    ap.add_argument("--models", required=True, help="folder holding stanford-bunny.obj")
    ap.add_argument("--peer", help="Mitsuba's benchmark script (../shared/peers/mitsuba_gpu.py)")
    ap.add_argument("--cpu", action="store_true", help="also render with the CPU backend")
    ap.add_argument("--spp", default="16,64,256")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default=os.environ.get("OUT", "."))
    ap.add_argument("--analysis", action="store_true", help="explain the time instead (see above)")
    ap.add_argument("--bvh", default="binary", help="GPU hierarchy layouts to render with: binary, wide (see above)")
    ap.add_argument("--scenes", default="cornell,bunny", help="scenes of the timed renders: cornell, bunny, ogre, ogres")
    ap.add_argument("--kernels", default="megakernel", help="GPU kernels to render with: megakernel, wavefront (see above)")
    a = ap.parse_args()
    link = os.path.join(HERE, "models")
    if os.path.islink(link):
        os.remove(link)
    if not os.path.exists(link):
        os.symlink(os.path.abspath(a.models), link)
    if a.analysis:
        analysis(a.radiant, a.peer, a.models, a.out)
        return
    spps = [int(s) for s in a.spp.split(",")]
    scenes = [(n, ALL_SCENES[n]) for n in a.scenes.split(",")]
    layouts = a.bvh.split(",")
    kernels = a.kernels.split(",")
    first = None if kernels[0] == "megakernel" else kernels[0]
    timed = {b: bench(a.radiant, "gpu", spps, a.repeat, a.out, scenes, b, first) for b in layouts}
    if len(layouts) > 1:
        compare_bvh(a.radiant, layouts, scenes, spps, timed)
    if len(kernels) > 1:
        by_kernel = {kernels[0]: timed[layouts[0]]}
        for k in kernels[1:]:
            by_kernel[k] = bench(a.radiant, "gpu", spps, a.repeat, a.out, scenes, layouts[0], k)
        compare_kernels(a.radiant, kernels, scenes, spps, by_kernel, layouts[0])
    gpu = timed[layouts[0]]
    mitsuba = peer(a.peer, a.models, a.out) if a.peer else {}
    cpu = bench(a.radiant, "cpu", spps, 1, a.out, scenes) if a.cpu else None
    if gpu:
        print("\n| scene | spp | Radiant GPU Msamples/s | Mrays/s | Mitsuba cuda_ad_rgb Msamples/s | ratio | Radiant CPU Msamples/s | GPU/CPU |")
        print("|---|---|---|---|---|---|---|---|")
        for (name, spp), (t, ms, mr) in gpu.items():
            m = mitsuba.get((name, spp))
            c = cpu.get((name, spp)) if cpu else None
            print(f"| {name} | {spp} | {ms:.1f} | {mr:.1f} | {m if m else '-'} | "
                  f"{f'{ms / m:.2f}x' if m else '-'} | {f'{c[1]:.2f}' if c else '-'} | "
                  f"{f'{ms / c[1]:.0f}x' if c else '-'} |")


if __name__ == "__main__":
    main()

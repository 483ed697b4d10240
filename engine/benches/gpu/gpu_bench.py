"""GPU speed against Mitsuba 3's CUDA variant (issue 15), and the CPU backend
on the same machine.

Usage (from the repository root):
    python3 engine/benches/gpu/gpu_bench.py --radiant target/release/radiant \
        --models ../shared/data/models [--peer ../shared/peers/mitsuba_gpu.py] \
        [--cpu] [--spp 16,64,256] [--repeat 3] [--out DIR]

Renders cornell.yaml and cornell-bunny.yaml (1024x1024, max_depth 8) with
`--backend gpu`, once to warm up and then --repeat times, and prints the best
render time (the CLI's `rendered ... in T s`: kernel time and readback, not
scene loading, BVH building or kernel compilation) as Msamples/s and
Mrays/s. With --peer, runs Mitsuba's script in the same run (it needs
Mitsuba 3 with `cuda_ad_rgb` on PYTHONPATH) and prints the ratio. With
--cpu, renders the same scenes with `--backend cpu`. Skips, saying why,
where there is no GPU adapter or no Mitsuba.
"""
import argparse
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = [("cornell", "cornell.yaml"), ("bunny", "cornell-bunny.yaml")]
LINE = re.compile(r"rendered (\d+)x(\d+), (\d+) spp in ([0-9.]+) s \(([0-9.]+) Msamples/s, ([0-9.]+) Mrays/s\)")


def render(radiant, scene, spp, backend, out):
    cmd = [radiant, "render", os.path.join(HERE, scene), "-o", out, "--spp", str(spp), "--backend", backend]
    p = subprocess.run(cmd, capture_output=True, text=True)
    m = LINE.search(p.stderr)
    if p.returncode != 0 or not m:
        return None, p.stderr.strip().splitlines()[-3:]
    return (float(m.group(4)), float(m.group(5)), float(m.group(6))), None


def bench(radiant, backend, spps, repeat, out):
    results = {}
    for name, scene in SCENES:
        for spp in spps:
            path = os.path.join(out, f"radiant-{backend}-{name}.exr")
            first, err = render(radiant, scene, spp, backend, path)
            if first is None:
                print(f"skip: radiant --backend {backend} failed on {scene}: {' | '.join(err)}")
                return None
            runs = [render(radiant, scene, spp, backend, path)[0] for _ in range(repeat)]
            best = min(runs, key=lambda r: r[0])
            results[(name, spp)] = best
            print(f"radiant {backend} {name} 1024x1024 spp {spp}: best {best[0]:.4f}s of "
                  f"{['%.4f' % r[0] for r in runs]} -> {best[1]:.1f} Msamples/s, {best[2]:.1f} Mrays/s",
                  flush=True)
    return results


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


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--radiant", default="target/release/radiant")
    ap.add_argument("--models", required=True, help="folder holding stanford-bunny.obj")
    ap.add_argument("--peer", help="Mitsuba's benchmark script (../shared/peers/mitsuba_gpu.py)")
    ap.add_argument("--cpu", action="store_true", help="also render with the CPU backend")
    ap.add_argument("--spp", default="16,64,256")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default=os.environ.get("OUT", "."))
    a = ap.parse_args()
    link = os.path.join(HERE, "models")
    if os.path.islink(link):
        os.remove(link)
    if not os.path.exists(link):
        os.symlink(os.path.abspath(a.models), link)
    spps = [int(s) for s in a.spp.split(",")]
    gpu = bench(a.radiant, "gpu", spps, a.repeat, a.out)
    mitsuba = peer(a.peer, a.models, a.out) if a.peer else {}
    cpu = bench(a.radiant, "cpu", spps, 1, a.out) if a.cpu else None
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

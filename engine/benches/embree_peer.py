#!/usr/bin/env python3
"""Peer benchmark of the ray-tracing core: Radiant's BVH vs Embree.

Builds Embree (through ``embreex``, Embree 4 with its default build) over
triangles and times single-ray closest-hit and occlusion queries on the rays
``engine/examples/trace_probe.rs`` uses, then runs the probe and prints
nanoseconds per ray of both and Radiant's time as a ratio of Embree's. Both
run single-threaded on the same machine, best of 5 passes. ``--robust`` turns
on Embree's robust mode, whose guarantee Radiant's queries always give
(watertight triangles, box tests that cover their rounding), and
``--quality high`` its high-quality build, which Mitsuba 3 uses; neither
applies to ``--binding``'s figures.

* The Cornell box, always (the scene of the Mitsuba speed benchmark): the
  probe writes its 36 triangles (``--cornell-obj``); 1M rays start at
  uniform points of [-0.9, 0.9]^3 around the box's centre and go in uniform
  directions; shadow rays are the same rays cut at distance 0.5.
* Each mesh given: 1M rays from a sphere around the mesh towards uniform
  points of its bounding box (shadow rays end at that point).

    pip install embreex numpy
    cargo build --release --example trace_probe
    python3 engine/benches/embree_peer.py --probe target/release/examples/trace_probe \\
        [../shared/data/models/stanford-bunny.obj]

Embree is called as Radiant is: a whole batch of rays in one call, a C
loop (``embree_batch.c``, compiled here with ``cc`` against the library the
``embreex`` wheel ships) calling ``rtcIntersect1``/``rtcOccluded1`` per ray,
so no per-ray cost of a Python binding is counted (the binding's own loop,
``EmbreeScene.run``, costs about 20 ns more per ray; ``--binding`` prints
its figures too). Embree 4's packet calls (``rtcIntersect8``) are not used:
they pay off for coherent rays, and these are incoherent. The rays are
drawn from the same distribution, not bit for bit the same rays (numpy's
generator, not the probe's).
"""
import argparse
import ctypes
import glob
import os
import re
import subprocess
import sys
import tempfile
import time

RAYS = 1_000_000
PASSES = 5
PROBE_RE = re.compile(r"^\s+(closest|occluded):\s+([\d.]+) ns/ray")
SCENE_RE = re.compile(r"^(\S.*): \d+ primitives")


def load_obj(path):
    """Triangles (n, 3, 3) float32 of an OBJ file (polygons fanned)."""
    import numpy as np

    vertices, faces = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                vertices.append([float(x) for x in parts[1:4]])
            elif parts[0] == "f":
                idx = [int(p.split("/")[0]) for p in parts[1:]]
                idx = [i - 1 if i > 0 else len(vertices) + i for i in idx]
                for k in range(1, len(idx) - 1):
                    faces.append((idx[0], idx[k], idx[k + 1]))
    v = np.asarray(vertices, dtype=np.float32)
    return v[np.asarray(faces, dtype=np.int64)]


def mesh_rays(triangles, rng):
    """Rays from a sphere around `triangles` towards uniform points of their
    bounding box: (origins, unit directions, distances to those points)."""
    import numpy as np

    pts = triangles.reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre, radius = (lo + hi) * 0.5, np.linalg.norm(hi - lo)
    d = rng.normal(size=(RAYS, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    origins = (centre + d * radius).astype(np.float32)
    targets = (lo + rng.random((RAYS, 3)) * (hi - lo)).astype(np.float32)
    dirs = targets - origins
    dists = np.linalg.norm(dirs, axis=1).astype(np.float32)
    return origins, (dirs / dists[:, None]).astype(np.float32), dists


def cornell_rays(rng):
    """Rays inside the Cornell box in render space (centre at z = -3.9), in
    uniform directions; shadow rays end at distance 0.5."""
    import numpy as np

    origins = (rng.random((RAYS, 3)) * 1.8 - 0.9 - [0.0, 0.0, 3.9]).astype(np.float32)
    d = rng.normal(size=(RAYS, 3))
    dirs = (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)
    return origins, dirs, np.full(RAYS, 0.5, dtype=np.float32)


def time_embree(triangles, rays):
    """(closest ns/ray, occluded ns/ray, build ms) of Embree on `triangles`
    for `rays` = (origins, directions, shadow distances)."""
    import numpy as np
    from embreex import rtcore_scene as rtcs
    from embreex.mesh_construction import TriangleMesh

    start = time.perf_counter()
    scene = rtcs.EmbreeScene()
    TriangleMesh(scene=scene, vertices=triangles)
    # The BVH is built on the first query; build it with a single ray.
    one = np.zeros((1, 3), dtype=np.float32)
    scene.run(one, one + 1.0, query="OCCLUDED")
    build_ms = (time.perf_counter() - start) * 1e3

    origins, dirs, dists = rays

    best = [float("inf")] * 2
    for _ in range(PASSES):
        t0 = time.perf_counter()
        hit = scene.run(origins, dirs, query="INTERSECT")
        best[0] = min(best[0], time.perf_counter() - t0)
        t0 = time.perf_counter()
        blocked = scene.run(origins, dirs, dists=dists, query="OCCLUDED")
        best[1] = min(best[1], time.perf_counter() - t0)
    print(f"  embree: {int((hit >= 0).sum())} of {RAYS} hit, "
          f"{int((blocked >= 0).sum())} blocked", file=sys.stderr)
    return best[0] / RAYS * 1e9, best[1] / RAYS * 1e9, build_ms


def load_batch(tmp):
    """The batch driver, compiled into `tmp` against embreex's Embree."""
    import embreex

    libs = os.path.join(os.path.dirname(os.path.dirname(embreex.__file__)), "embreex.libs")
    lib = glob.glob(os.path.join(libs, "libembree4*.so*"))[0]
    src = os.path.join(os.path.dirname(os.path.abspath(__file__)), "embree_batch.c")
    out = os.path.join(tmp, "embree_batch.so")
    subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", out, src, lib,
                    f"-Wl,-rpath,{libs}"], check=True)
    peer = ctypes.CDLL(out)
    peer.peer_scene.restype = ctypes.c_void_p
    peer.peer_scene.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int, ctypes.c_int]
    peer.peer_release.argtypes = [ctypes.c_void_p]
    peer.peer_intersect.argtypes = [ctypes.c_void_p] * 3 + [ctypes.c_size_t] + [ctypes.c_void_p] * 2
    peer.peer_occluded.argtypes = [ctypes.c_void_p] * 4 + [ctypes.c_size_t, ctypes.c_void_p]
    return peer


# Embree's scene settings, from the command line (see `main`): scene flags
# and build quality.
SCENE = {"flags": 0, "quality": 1}


def time_embree_batch(peer, triangles, rays):
    """(closest ns/ray, occluded ns/ray, build ms) of Embree called on whole
    batches from C ([`load_batch`]), with the `SCENE` settings."""
    import numpy as np

    tris = np.ascontiguousarray(triangles, dtype=np.float32)
    start = time.perf_counter()
    scene = peer.peer_scene(tris.ctypes.data, len(tris), SCENE["flags"], SCENE["quality"])
    build_ms = (time.perf_counter() - start) * 1e3
    origins, dirs, dists = (np.ascontiguousarray(a, dtype=np.float32) for a in rays)
    n = len(origins)
    hit = np.empty(n, dtype=np.int32)
    t = np.empty(n, dtype=np.float32)
    blocked = np.empty(n, dtype=np.uint8)
    best = [float("inf")] * 2
    for _ in range(PASSES):
        t0 = time.perf_counter()
        peer.peer_intersect(scene, origins.ctypes.data, dirs.ctypes.data, n,
                            hit.ctypes.data, t.ctypes.data)
        best[0] = min(best[0], time.perf_counter() - t0)
        t0 = time.perf_counter()
        peer.peer_occluded(scene, origins.ctypes.data, dirs.ctypes.data, dists.ctypes.data,
                           n, blocked.ctypes.data)
        best[1] = min(best[1], time.perf_counter() - t0)
    peer.peer_release(scene)
    print(f"  embree (batch): {int((hit >= 0).sum())} of {n} hit, "
          f"{int(blocked.sum())} blocked", file=sys.stderr)
    return best[0] / n * 1e9, best[1] / n * 1e9, build_ms


def time_probe(probe, args):
    """{scene name: (closest, occluded) ns/ray} the probe reports for each
    scene it measures (the Cornell box, directly and through a top level,
    then the mesh if `args` names one)."""
    out = subprocess.run([probe, *args], capture_output=True, text=True, check=True).stdout
    scenes, name, times = {}, None, {}
    for line in out.splitlines():
        header = SCENE_RE.match(line)
        if header:
            name, times = header.group(1), {}
            continue
        m = PROBE_RE.match(line)
        if m and name is not None:
            times[m.group(1)] = float(m.group(2))
            if len(times) == 2:
                scenes[name] = (times["closest"], times["occluded"])
    return scenes


def report(name, triangles, rays, radiant, peer, binding):
    """Times Embree on `triangles` (batch from C; with `binding`, also
    through embreex's per-ray loop) and prints it against `radiant`'s
    (closest, occluded) ns/ray."""
    e_closest, e_occluded, build_ms = time_embree_batch(peer, triangles, rays)
    b = time_embree(triangles, rays) if binding else None
    for k, (query, e, r) in enumerate([("closest", e_closest, radiant[0]),
                                       ("occluded", e_occluded, radiant[1])]):
        extra = f" {b[k]:10.1f} {r / b[k]:10.2f}x" if b else ""
        print(f"{name:24} {len(triangles):9} {query:>9} {e:10.1f} {r:10.1f} "
              f"{r / e:14.2f}x{extra}")
    print(f"  embree build {build_ms:.0f} ms", file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--probe", default="target/release/examples/trace_probe")
    ap.add_argument("--binding", action="store_true",
                    help="also time Embree through embreex's per-ray loop")
    ap.add_argument("--robust", action="store_true",
                    help="Embree's robust mode (RTC_SCENE_FLAG_ROBUST): no optimisation that "
                         "loses accuracy, watertight as Radiant's queries always are")
    ap.add_argument("--quality", choices=["medium", "high"], default="medium",
                    help="Embree's build quality (medium: its default; high: Mitsuba 3's)")
    ap.add_argument("meshes", nargs="*")
    args = ap.parse_args()
    SCENE["flags"] = 4 if args.robust else 0
    SCENE["quality"] = {"medium": 1, "high": 2}[args.quality]
    try:
        import numpy  # noqa: F401
        import embreex  # noqa: F401
    except ImportError as e:
        print(f"skipping: {e} (pip install embreex numpy)", file=sys.stderr)
        return 0
    import numpy as np

    rng = np.random.default_rng(12345)
    with tempfile.TemporaryDirectory() as tmp:
        peer = load_batch(tmp)
        far = np.array([[[1e3, 1e3, 1e3], [1e3 + 1e-3, 1e3, 1e3], [1e3, 1e3 + 1e-3, 1e3]]],
                       dtype=np.float32)
        floor = time_embree_batch(peer, far, cornell_rays(rng))
        print(f"embree floor (one far-away triangle, batch from C): {floor[0]:.1f} ns "
              f"closest, {floor[1]:.1f} ns occluded")
        if args.binding:
            floor = time_embree(far, cornell_rays(rng))
            print(f"embree floor through the binding: {floor[0]:.1f} ns closest, "
                  f"{floor[1]:.1f} ns occluded")
        binding = (f" {'binding ns':>10} {'r/binding':>11}" if args.binding else "")
        print(f"{'scene':24} {'triangles':>9} {'query':>9} {'embree ns':>10} "
              f"{'radiant ns':>10} {'radiant/embree':>15}{binding}")
        obj = os.path.join(tmp, "cornell-box.obj")
        probe = time_probe(args.probe, ["--cornell-obj", obj])
        rays = cornell_rays(rng)
        report("cornell-box", load_obj(obj), rays, probe["cornell box"], peer, args.binding)
        report("cornell-box, top level", load_obj(obj), rays,
               probe["cornell box through a top level"], peer, args.binding)
        for mesh in args.meshes:
            triangles = load_obj(mesh)
            name = mesh.rsplit("/", 1)[-1]
            radiant = time_probe(args.probe, [mesh])[name]
            report(name, triangles, mesh_rays(triangles, rng), radiant, peer, args.binding)
    return 0


if __name__ == "__main__":
    sys.exit(main())

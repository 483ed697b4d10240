#!/usr/bin/env python3
"""Peer benchmark of the ray-tracing core: Radiant's BVH vs Embree.

Builds Embree (through ``embreex``, Embree 4 with its default build) over
triangles and times single-ray closest-hit and occlusion queries on the rays
``engine/examples/trace_probe.rs`` uses, then runs the probe and prints
nanoseconds per ray of both and Radiant's time as a ratio of Embree's. Both
run single-threaded on the same machine, best of 5 passes.

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

Embree's figures include the binding's cost of a call per ray (a Cython loop
around ``rtcIntersect1``/``rtcOccluded1``); the script prints that floor,
measured on one far-away triangle that no ray comes near, so it can be
subtracted. The rays are drawn from the same distribution, not bit for bit the same
rays (numpy's generator, not the probe's).
"""
import argparse
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


def report(name, triangles, rays, radiant):
    """Times Embree on `triangles` and prints it against `radiant`'s
    (closest, occluded) ns/ray."""
    e_closest, e_occluded, build_ms = time_embree(triangles, rays)
    for query, e, r in [("closest", e_closest, radiant[0]),
                        ("occluded", e_occluded, radiant[1])]:
        print(f"{name:24} {len(triangles):9} {query:>9} {e:10.1f} {r:10.1f} "
              f"{r / e:14.2f}x")
    print(f"  embree build {build_ms:.0f} ms", file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--probe", default="target/release/examples/trace_probe")
    ap.add_argument("meshes", nargs="*")
    args = ap.parse_args()
    try:
        import numpy  # noqa: F401
        import embreex  # noqa: F401
    except ImportError as e:
        print(f"skipping: {e} (pip install embreex numpy)", file=sys.stderr)
        return 0
    import numpy as np

    rng = np.random.default_rng(12345)
    far = np.array([[[1e3, 1e3, 1e3], [1e3 + 1e-3, 1e3, 1e3], [1e3, 1e3 + 1e-3, 1e3]]],
                   dtype=np.float32)
    floor = time_embree(far, cornell_rays(rng))
    print(f"embree binding floor (one far-away triangle): {floor[0]:.1f} ns closest, "
          f"{floor[1]:.1f} ns occluded")
    print(f"{'scene':24} {'triangles':>9} {'query':>9} {'embree ns':>10} "
          f"{'radiant ns':>10} {'radiant/embree':>15}")
    with tempfile.TemporaryDirectory() as tmp:
        obj = os.path.join(tmp, "cornell-box.obj")
        probe = time_probe(args.probe, ["--cornell-obj", obj])
        rays = cornell_rays(rng)
        report("cornell-box", load_obj(obj), rays, probe["cornell box"])
        report("cornell-box, top level", load_obj(obj), rays,
               probe["cornell box through a top level"])
    for mesh in args.meshes:
        triangles = load_obj(mesh)
        name = mesh.rsplit("/", 1)[-1]
        radiant = time_probe(args.probe, [mesh])[name]
        report(name, triangles, mesh_rays(triangles, rng), radiant)
    return 0


if __name__ == "__main__":
    sys.exit(main())

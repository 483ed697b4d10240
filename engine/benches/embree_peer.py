#!/usr/bin/env python3
"""Peer benchmark of the ray-tracing core: Radiant's BVH vs Embree.

Builds Embree (through ``embreex``, Embree 4 with its default build) over a
triangle mesh and times single-ray closest-hit and occlusion queries on the
rays ``engine/examples/trace_probe.rs`` uses for meshes: 1M rays from a
sphere around the mesh towards uniform points of its bounding box (shadow
rays end at that point). Then runs the probe on the same mesh and prints
nanoseconds per ray of both and Radiant's time as a ratio of Embree's.
Both run single-threaded on the same machine, best of 5 passes.

    pip install embreex numpy
    cargo build --release --example trace_probe
    python3 engine/benches/embree_peer.py --probe target/release/examples/trace_probe \\
        ../shared/data/models/stanford-bunny.obj

The rays are drawn from the same distribution, not bit for bit the same
rays (numpy's generator, not the probe's).
"""
import argparse
import re
import subprocess
import sys
import time

RAYS = 1_000_000
PASSES = 5
PROBE_RE = re.compile(r"^\s+(closest|occluded):\s+([\d.]+) ns/ray")


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


def time_embree(triangles):
    """(closest ns/ray, occluded ns/ray, build ms) of Embree on `triangles`."""
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

    rng = np.random.default_rng(12345)
    pts = triangles.reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre, radius = (lo + hi) * 0.5, np.linalg.norm(hi - lo)
    d = rng.normal(size=(RAYS, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    origins = (centre + d * radius).astype(np.float32)
    targets = (lo + rng.random((RAYS, 3)) * (hi - lo)).astype(np.float32)
    dirs = targets - origins
    dists = np.linalg.norm(dirs, axis=1).astype(np.float32)
    dirs = (dirs / dists[:, None]).astype(np.float32)

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


def time_probe(probe, mesh):
    """(closest, occluded) ns/ray the probe reports for `mesh`."""
    out = subprocess.run([probe, mesh], capture_output=True, text=True, check=True).stdout
    # The probe prints the Cornell box first, then the mesh.
    times = {}
    for line in out.splitlines():
        m = PROBE_RE.match(line)
        if m:
            times[m.group(1)] = float(m.group(2))
    return times["closest"], times["occluded"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--probe", default="target/release/examples/trace_probe")
    ap.add_argument("meshes", nargs="+")
    args = ap.parse_args()
    try:
        import numpy  # noqa: F401
        import embreex  # noqa: F401
    except ImportError as e:
        print(f"skipping: {e} (pip install embreex numpy)", file=sys.stderr)
        return 0
    print(f"{'mesh':24} {'triangles':>9} {'query':>9} {'embree ns':>10} "
          f"{'radiant ns':>10} {'radiant/embree':>15}")
    for mesh in args.meshes:
        triangles = load_obj(mesh)
        e_closest, e_occluded, build_ms = time_embree(triangles)
        r_closest, r_occluded = time_probe(args.probe, mesh)
        name = mesh.rsplit("/", 1)[-1]
        for query, e, r in [("closest", e_closest, r_closest),
                            ("occluded", e_occluded, r_occluded)]:
            print(f"{name:24} {len(triangles):9} {query:>9} {e:10.1f} {r:10.1f} "
                  f"{r / e:14.2f}x")
        print(f"  embree build {build_ms:.0f} ms", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())

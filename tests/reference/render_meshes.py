#!/usr/bin/env python3
"""Make the mesh-format test data for Radiant, and the smooth-normal
reference with Mitsuba 3.

Writes into ``tests/data/meshes/``:

1. ``torus.obj``: a low-poly torus (16 x 8 quads, 256 triangles) without
   normals or texture coordinates, so that its shading depends on the
   vertex normals the renderer computes.
2. ``torus-ascii.ply``, ``torus-le.ply``, ``torus-be.ply``: the same torus
   as ASCII and binary little- and big-endian PLY.
3. ``torus-uv.obj``, ``torus-uv-ascii.ply``, ``torus-uv-le.ply``,
   ``torus-uv-be.ply``, ``torus-uv.gltf``, ``torus-uv.glb``: the torus with its own vertex
   normals and texture coordinates in each format (OBJ's v up the image,
   PLY's and glTF's down it, as each format's readers expect), for the test
   that every format renders the same image.
4. ``scene.gltf`` and ``checks.png``: a small glTF scene around the same
   torus: a parent node that translates and a child that turns and scales
   it, a metallic-roughness material with a base-colour texture (the
   8 x 8 checkerboard ``checks.png``), a perspective camera and a
   ``KHR_lights_punctual`` point, spot and directional light, each on a
   node of its own (the spot and the sun turned); the test
   renders it against the same scene written in Radiant's YAML.
5. ``smooth.yaml`` (the torus, diffuse, lit by a point light and a dim
   environment) and its Mitsuba render ``smooth-mitsuba.exr``, where
   Mitsuba computes the vertex normals of ``torus.obj`` (its OBJ loader's
   default, ``face_normals`` false).

Every coordinate is a float32 value written with 9 significant digits, so
that the text formats and the binary ones hold the same numbers bit for
bit. The committed files were made with:

    pip install mitsuba numpy
    python3 tests/reference/render_meshes.py --spp 4096
"""
import argparse
import base64
import json
import math
import os
import struct

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
DIR = os.path.join(ROOT, "tests", "data", "meshes")
WIDTH, HEIGHT = 96, 64
ALBEDO = [0.7, 0.7, 0.7]
LIGHT = ([3.0, 3.0, 2.0], 25.0)
ENVIRONMENT = 0.1
TRANSFORM = [("rotate", ([1, 0, 0], 55)), ("rotate", ([0, 1, 0], 20))]


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def fmt(x):
    return f"{x:.9g}"


def torus(major=16, minor=8, r_major=1.0, r_minor=0.45):
    """Vertices (position, normal, uv) and triangles of a torus about z;
    the seam vertices are shared (no duplicates), so smoothing sees a
    closed surface. uv: u around the ring, v around the tube, v = 0 at the
    top of the image."""
    verts, tris = [], []
    for i in range(major):
        a = 2 * math.pi * i / major
        for j in range(minor):
            b = 2 * math.pi * j / minor
            n = [math.cos(b) * math.cos(a), math.cos(b) * math.sin(a), math.sin(b)]
            p = [(r_major + r_minor * math.cos(b)) * math.cos(a),
                 (r_major + r_minor * math.cos(b)) * math.sin(a), r_minor * math.sin(b)]
            verts.append(([f32(c) for c in p], [f32(c) for c in n],
                          [f32(i / major), f32(j / minor)]))
    for i in range(major):
        for j in range(minor):
            a = i * minor + j
            b = ((i + 1) % major) * minor + j
            c = ((i + 1) % major) * minor + (j + 1) % minor
            d = i * minor + (j + 1) % minor
            tris += [(a, b, c), (a, c, d)]
    return verts, tris


def write_obj(path, verts, tris, attributes):
    with open(path, "w") as f:
        f.write("# The torus of tests/reference/render_meshes.py\n")
        for p, n, uv in verts:
            f.write("v " + " ".join(map(fmt, p)) + "\n")
            if attributes:
                f.write("vn " + " ".join(map(fmt, n)) + "\n")
                # OBJ's v runs up the image.
                f.write(f"vt {fmt(uv[0])} {fmt(f32(1 - uv[1]))}\n")
        for t in tris:
            if attributes:
                f.write("f " + " ".join(f"{k + 1}/{k + 1}/{k + 1}" for k in t) + "\n")
            else:
                f.write("f " + " ".join(str(k + 1) for k in t) + "\n")


def write_ply(path, verts, tris, attributes, encoding):
    props = ["x", "y", "z"] + (["nx", "ny", "nz", "u", "v"] if attributes else [])
    header = [f"ply", f"format {encoding} 1.0", "comment The torus of tests/reference/render_meshes.py",
              f"element vertex {len(verts)}"]
    header += [f"property float {p}" for p in props]
    header += [f"element face {len(tris)}", "property list uchar int vertex_indices", "end_header"]
    rows = [p + (n + uv if attributes else []) for p, n, uv in verts]
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode())
        if encoding == "ascii":
            for r in rows:
                f.write((" ".join(map(fmt, r)) + "\n").encode())
            for t in tris:
                f.write(("3 " + " ".join(map(str, t)) + "\n").encode())
        else:
            e = "<" if encoding == "binary_little_endian" else ">"
            for r in rows:
                f.write(struct.pack(e + "f" * len(r), *r))
            for t in tris:
                f.write(struct.pack(e + "Biii", 3, *t))


def write_gltf(path, verts, tris, glb=False):
    """One mesh, one node, normals and texture coordinates, the buffer
    embedded as a data URI (or, with ``glb``, as the binary chunk of a GLB
    file)."""
    pos = b"".join(struct.pack("<3f", *p) for p, _, _ in verts)
    nrm = b"".join(struct.pack("<3f", *n) for _, n, _ in verts)
    uvs = b"".join(struct.pack("<2f", *uv) for _, _, uv in verts)
    idx = b"".join(struct.pack("<3I", *t) for t in tris)
    data = pos + nrm + uvs + idx
    views, offset = [], 0
    for chunk, target in [(pos, 34962), (nrm, 34962), (uvs, 34962), (idx, 34963)]:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(chunk), "target": target})
        offset += len(chunk)
    lo = [min(p[k] for p, _, _ in verts) for k in range(3)]
    hi = [max(p[k] for p, _, _ in verts) for k in range(3)]
    doc = {
        "asset": {"version": "2.0", "generator": "tests/reference/render_meshes.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "torus"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                                    "indices": 3, "mode": 4}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(verts), "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5126, "count": len(verts), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": len(verts), "type": "VEC2"},
            {"bufferView": 3, "componentType": 5125, "count": 3 * len(tris), "type": "SCALAR"},
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
    }
    if glb:
        del doc["buffers"][0]["uri"]
        text = json.dumps(doc).encode()
        text += b" " * (-len(text) % 4)
        data += b"\0" * (-len(data) % 4)
        chunks = (struct.pack("<II", len(text), 0x4E4F534A) + text
                  + struct.pack("<II", len(data), 0x004E4942) + data)
        with open(path, "wb") as f:
            f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks)
        return
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def write_png(path, size=8):
    """An 8-bit RGB checkerboard of size x size pixels (2 x 2 squares)."""
    import zlib
    rows = b""
    for y in range(size):
        rows += b"\0" + b"".join(
            bytes([230, 200, 50]) if (x * 2 // size + y * 2 // size) % 2 == 0 else bytes([25, 50, 150])
            for x in range(size))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def write_scene_gltf(path, mesh_path):
    """The glTF scene: nodes, material, texture, camera and light around
    the mesh (and buffer) of ``mesh_path``."""
    with open(mesh_path) as f:
        doc = json.load(f)
    half = math.sqrt(0.5)
    doc["extensionsUsed"] = ["KHR_lights_punctual"]
    doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1.0, 0.9, 0.8], "intensity": 25.0, "name": "lamp"},
        {"type": "spot", "color": [0.5, 0.5, 1.0], "intensity": 40.0, "name": "spot",
         "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.5}},
        {"type": "directional", "color": [1.0, 1.0, 1.0], "intensity": 0.5, "name": "sun"}]}}
    doc["scenes"] = [{"nodes": [0, 2, 3, 4, 5]}]
    # The spot turns -30 degrees about x (it shines along (0, -sin 30, -cos 30)),
    # the sun 45 degrees about y (it shines along (-sin 45, 0, -cos 45)).
    spot = [math.sin(math.radians(-15)), 0.0, 0.0, math.cos(math.radians(-15))]
    sun = [0.0, math.sin(math.radians(22.5)), 0.0, math.cos(math.radians(22.5))]
    doc["nodes"] = [
        {"name": "root", "translation": [0.3, -0.2, 0.0], "children": [1]},
        {"name": "torus", "mesh": 0, "rotation": [half, 0.0, 0.0, half], "scale": [0.8, 0.8, 0.8]},
        {"name": "camera", "camera": 0, "translation": [0.0, 0.0, 6.0]},
        {"name": "lamp", "translation": [3.0, 3.0, 2.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "spot", "translation": [-1.0, 2.0, 4.0], "rotation": spot,
         "extensions": {"KHR_lights_punctual": {"light": 1}}},
        {"name": "sun", "rotation": sun, "extensions": {"KHR_lights_punctual": {"light": 2}}},
    ]
    doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": math.radians(30), "znear": 0.01}}]
    doc["meshes"][0]["primitives"][0]["material"] = 0
    doc["materials"] = [{"name": "checked metal", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": 0}, "metallicFactor": 0.3, "roughnessFactor": 0.6}}]
    doc["textures"] = [{"source": 0}]
    doc["images"] = [{"uri": "checks.png"}]
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def yaml_transform(ops):
    parts = []
    for op, arg in ops:
        axis, angle = arg
        parts.append(f"{{rotate: {{axis: {axis}, angle: {angle}}}}}")
    return "[" + ", ".join(parts) + "]"


def mitsuba_transform(mi, ops):
    t = mi.ScalarTransform4f()
    for _, (axis, angle) in ops:
        t = t @ mi.ScalarTransform4f().rotate(axis, angle)
    return t


def yaml_scene(spp):
    return "\n".join([
        "# Made by tests/reference/render_meshes.py; the reference is smooth-mitsuba.exr.",
        "integrator: {type: path, max_depth: 2}",
        f"film: {{width: {WIDTH}, height: {HEIGHT}, filter: {{type: gaussian, stddev: 0.5}}}}",
        f"sampler: {{type: independent, spp: {spp}}}",
        "camera: {type: perspective, fov: 30, fov_axis: y, look_at: {origin: [0, 0, 6], target: [0, 0, 0], up: [0, 1, 0]}}",
        "shapes:",
        f"  - {{type: mesh, filename: torus.obj, material: {{type: diffuse, reflectance: {ALBEDO}}}, "
        f"transform: {yaml_transform(TRANSFORM)}}}",
        "lights:",
        f"  - {{type: point, position: {LIGHT[0]}, intensity: {LIGHT[1]}}}",
        f"  - {{type: environment, radiance: {ENVIRONMENT}}}",
    ]) + "\n"


def mitsuba_scene(mi, spp):
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 2},
        "sensor": {
            "type": "perspective", "fov": 30, "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 6], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": WIDTH, "height": HEIGHT,
                     "rfilter": {"type": "gaussian", "stddev": 0.5}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "light": {"type": "point", "position": LIGHT[0],
                  "intensity": {"type": "rgb", "value": LIGHT[1]}},
        "environment": {"type": "constant", "radiance": {"type": "rgb", "value": ENVIRONMENT}},
        "torus": {"type": "obj", "filename": os.path.join(DIR, "torus.obj"),
                  "to_world": mitsuba_transform(mi, TRANSFORM),
                  "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": ALBEDO}}},
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--test-spp", type=int, default=128,
                    help="spp written into the YAML (what the Radiant test renders)")
    args = ap.parse_args()
    os.makedirs(DIR, exist_ok=True)
    verts, tris = torus()
    write_obj(os.path.join(DIR, "torus.obj"), verts, tris, False)
    write_obj(os.path.join(DIR, "torus-uv.obj"), verts, tris, True)
    for name, encoding in [("ascii", "ascii"), ("le", "binary_little_endian"), ("be", "binary_big_endian")]:
        write_ply(os.path.join(DIR, f"torus-{name}.ply"), verts, tris, False, encoding)
        write_ply(os.path.join(DIR, f"torus-uv-{name}.ply"), verts, tris, True, encoding)
    write_gltf(os.path.join(DIR, "torus-uv.gltf"), verts, tris)
    write_gltf(os.path.join(DIR, "torus-uv.glb"), verts, tris, glb=True)
    write_png(os.path.join(DIR, "checks.png"))
    write_scene_gltf(os.path.join(DIR, "scene.gltf"), os.path.join(DIR, "torus-uv.gltf"))
    with open(os.path.join(DIR, "smooth.yaml"), "w") as f:
        f.write(yaml_scene(args.test_spp))
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    image = mi.render(mi.load_dict(mitsuba_scene(mi, args.spp)), seed=1)
    mi.Bitmap(image).write(os.path.join(DIR, "smooth-mitsuba.exr"))
    print("wrote the meshes, smooth.yaml and smooth-mitsuba.exr")


if __name__ == "__main__":
    main()

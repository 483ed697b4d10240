#!/usr/bin/env python3
"""Make the tangent-frame references for Radiant with Mitsuba 3.

Writes into ``tests/data/tangents/``:

1. ``ridges-normals.png``: a raw tangent-space normal map of ridges that run
   along v (their normals lean along +u and -u) with a constant lean along
   +v, so that a turned tangent or a flipped bitangent changes the lighting.
2. ``ridges-height.png``: a raw grey height field of ridges along u and
   gentler ones along v.
3. ``uv-sphere.obj``: a latitude-longitude sphere with smooth normals and
   texture coordinates (u with the longitude, v with the latitude).
4. ``cylinder.obj``: a section of a cylinder about y, bulging towards +z,
   with smooth normals, u along the arc and v along the axis. Its
   MikkTSpace tangents and Mitsuba's ∂p/∂u agree on this shape, so the
   reference holds for both.
5. Three scenes ``<name>.yaml`` for Radiant and their Mitsuba renders
   ``<name>-mitsuba.exr``, lit by point lights at a grazing angle:

   * ``anisotropic``: a turned sphere and a turned ``uv-sphere.obj`` of
     rough mirror metal, GGX alpha_u 0.05, alpha_v 0.4;
   * ``normal-map``: a plate, the same plate turned 90 degrees about its
     normal, and ``cylinder.obj``, each diffuse with ``ridges-normals.png``;
   * ``bump``: a plate and the same plate turned 90 degrees, each diffuse
     bump-mapped with ``ridges-height.png``.

   Each object has a material of its own under ``materials:``, so that a
   test can change one object's material at a time.

The YAML and the Mitsuba scene are made from the same description here, so
they cannot drift apart. The committed files were made with:

    pip install mitsuba numpy
    python3 tests/reference/render_tangents.py --spp 4096
"""
import argparse
import math
import os

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
DIR = os.path.join(ROOT, "tests", "data", "tangents")
HEIGHT = 64
MAP_SIZE = 64
ALBEDO = [0.7, 0.7, 0.7]

# Transforms are lists of (operation, argument), applied like Mitsuba's
# T().translate().rotate()... (the last operation acts first).
ANISOTROPIC = {
    "lights": [((3.0, 2.5, 4.0), 30.0), ((-3.5, -1.0, 3.0), 20.0)],
    "environment": 0.05,
    "objects": [
        ("sphere", {}, [("translate", [-1.1, 0, 0]), ("rotate", ([1, 0, 0], -60)),
                        ("rotate", ([0, 0, 1], 30)), ("scale", 0.85)]),
        ("mesh", {"filename": "uv-sphere.obj"},
         [("translate", [1.1, 0, 0]), ("rotate", ([1, 0, 0], -50)),
          ("rotate", ([0, 1, 0], 35)), ("scale", 0.85)]),
    ],
}
NORMAL_MAP = {
    "lights": [((4.0, 1.8, 1.2), 40.0)],
    "environment": 0.0,
    "objects": [
        ("rectangle", {}, [("translate", [-2.1, 0, 0]), ("scale", 0.8)]),
        ("rectangle", {}, [("translate", [0, 0, 0]), ("rotate", ([0, 0, 1], 90)),
                           ("scale", 0.8)]),
        ("mesh", {"filename": "cylinder.obj"}, [("translate", [2.1, 0, 0]), ("scale", 0.8)]),
    ],
}
BUMP = {
    "lights": [((4.0, 1.8, 1.2), 40.0)],
    "environment": 0.0,
    "objects": [
        ("rectangle", {}, [("translate", [-1.1, 0, 0]), ("scale", 0.8)]),
        ("rectangle", {}, [("translate", [1.1, 0, 0]), ("rotate", ([0, 0, 1], 90)),
                           ("scale", 0.8)]),
    ],
}
BUMP_SCALE = 0.1


def ridges_normals(np):
    """The normal map, 8-bit, rows from the top (v down the image)."""
    u = (np.arange(MAP_SIZE) + 0.5) / MAP_SIZE
    lean = 0.7 * np.sin(2 * np.pi * 3 * u) + 0.35
    n = np.stack([lean, np.full_like(u, 0.3), np.ones_like(u)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    row = np.round((0.5 * n + 0.5) * 255).astype(np.uint8)
    return np.repeat(row[None, :, :], MAP_SIZE, axis=0)


def ridges_height(np):
    """The height field, 8-bit grey, rows from the top."""
    c = (np.arange(MAP_SIZE) + 0.5) / MAP_SIZE
    u, v = np.meshgrid(c, c)
    h = 0.5 + 0.35 * np.sin(2 * np.pi * 3 * u) + 0.15 * np.sin(2 * np.pi * 2 * v)
    return np.round(h * 255).astype(np.uint8)[:, :, None]


def write_uv_sphere(path, rings=32, segments=64):
    """A unit latitude-longitude sphere: u = phi/2pi, OBJ v = 1 - theta/pi
    (so Mitsuba's default flip gives v = theta/pi, as on its sphere)."""
    with open(path, "w") as f:
        f.write("# The UV sphere of tests/reference/render_tangents.py\n")
        for i in range(rings + 1):
            theta = math.pi * i / rings
            for j in range(segments + 1):
                phi = 2 * math.pi * j / segments
                x, y, z = math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)
                f.write(f"v {x:.6f} {y:.6f} {z:.6f}\nvn {x:.6f} {y:.6f} {z:.6f}\n")
                f.write(f"vt {j / segments:.6f} {1 - i / rings:.6f}\n")
        for i in range(rings):
            for j in range(segments):
                a = i * (segments + 1) + j + 1
                b, c, d = a + 1, a + segments + 2, a + segments + 1
                # Outward winding: theta grows along i, phi along j.
                if i > 0:
                    f.write(f"f {a}/{a}/{a} {c}/{c}/{c} {b}/{b}/{b}\n")
                if i < rings - 1:
                    f.write(f"f {a}/{a}/{a} {d}/{d}/{d} {c}/{c}/{c}\n")


def write_cylinder(path, arcs=24, lengths=2, half_angle=50.0):
    """x = sin a, z = cos a - 1 for a in [-half_angle, half_angle], y in
    [-1, 1]; normals (sin a, 0, cos a); u along a, v along y."""
    with open(path, "w") as f:
        f.write("# The cylinder section of tests/reference/render_tangents.py\n")
        for j in range(lengths + 1):
            y = -1 + 2 * j / lengths
            for i in range(arcs + 1):
                a = math.radians(-half_angle + 2 * half_angle * i / arcs)
                f.write(f"v {math.sin(a):.7f} {y:.7f} {math.cos(a) - 1:.7f}\n")
                f.write(f"vn {math.sin(a):.7f} 0 {math.cos(a):.7f}\n")
                f.write(f"vt {i / arcs:.7f} {j / lengths:.7f}\n")
        for j in range(lengths):
            for i in range(arcs):
                a = j * (arcs + 1) + i + 1
                b, c, d = a + 1, a + arcs + 2, a + arcs + 1
                f.write(f"f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}\n")
                f.write(f"f {a}/{a}/{a} {c}/{c}/{c} {d}/{d}/{d}\n")


def width(desc):
    return 64 * len(desc["objects"])


def yaml_transform(ops):
    parts = []
    for op, arg in ops:
        if op == "rotate":
            axis, angle = arg
            parts.append(f"{{rotate: {{axis: {axis}, angle: {angle}}}}}")
        else:
            parts.append(f"{{{op}: {arg}}}")
    return "[" + ", ".join(parts) + "]"


def mitsuba_transform(mi, ops):
    t = mi.ScalarTransform4f()
    for op, arg in ops:
        if op == "rotate":
            axis, angle = arg
            t = t @ mi.ScalarTransform4f().rotate(axis, angle)
        elif op == "translate":
            t = t @ mi.ScalarTransform4f().translate(arg)
        else:
            t = t @ mi.ScalarTransform4f().scale(arg)
    return t


def yaml_material(name):
    if name == "anisotropic":
        return "{type: conductor, material: none, alpha_u: 0.05, alpha_v: 0.4}"
    diffuse = f"{{type: diffuse, reflectance: {ALBEDO}}}"
    if name == "normal-map":
        return f"{{type: normal_map, normals: ridges, material: {diffuse}}}"
    return f"{{type: bump, height: ridges, scale: {BUMP_SCALE}, material: {diffuse}}}"


def mitsuba_material(name):
    if name == "anisotropic":
        return {"type": "roughconductor", "distribution": "ggx", "material": "none",
                "alpha_u": 0.05, "alpha_v": 0.4}
    diffuse = {"type": "diffuse", "reflectance": {"type": "rgb", "value": ALBEDO}}
    if name == "normal-map":
        return {"type": "normalmap", "bsdf": diffuse,
                "normalmap": {"type": "bitmap", "raw": True,
                              "filename": os.path.join(DIR, "ridges-normals.png")}}
    return {"type": "bumpmap", "bsdf": diffuse, "scale": BUMP_SCALE,
            "texture": {"type": "bitmap", "raw": True,
                        "filename": os.path.join(DIR, "ridges-height.png")}}


def yaml_scene(name, desc, spp):
    lines = [
        f"# Made by tests/reference/render_tangents.py; the reference is {name}-mitsuba.exr.",
        "integrator: {type: path, max_depth: 2}",
        f"film: {{width: {width(desc)}, height: {HEIGHT}, filter: {{type: gaussian, stddev: 0.5}}}}",
        f"sampler: {{type: independent, spp: {spp}}}",
        "camera: {type: perspective, fov: 28, fov_axis: y, look_at: {origin: [0, 0, 5], target: [0, 0, 0], up: [0, 1, 0]}}",
    ]
    if name == "normal-map":
        lines += ["textures:", "  ridges: {type: image, filename: ridges-normals.png, raw: true}"]
    elif name == "bump":
        lines += ["textures:", "  ridges: {type: image, filename: ridges-height.png, raw: true}"]
    lines.append("materials:")
    for k in range(len(desc["objects"])):
        lines.append(f"  object{k}: {yaml_material(name)}")
    lines.append("shapes:")
    for k, (shape, extra, ops) in enumerate(desc["objects"]):
        keys = [f"type: {shape}", f"material: object{k}", f"transform: {yaml_transform(ops)}"]
        if "filename" in extra:
            keys.append(f"filename: {extra['filename']}")
        lines.append("  - {" + ", ".join(keys) + "}")
    lines.append("lights:")
    for position, intensity in desc["lights"]:
        lines.append(f"  - {{type: point, position: {list(position)}, intensity: {intensity}}}")
    if desc["environment"] > 0:
        lines.append(f"  - {{type: environment, radiance: {desc['environment']}}}")
    return "\n".join(lines) + "\n"


def mitsuba_scene(mi, name, desc, spp):
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 2},
        "sensor": {
            "type": "perspective", "fov": 28, "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": width(desc), "height": HEIGHT,
                     "rfilter": {"type": "gaussian", "stddev": 0.5}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }
    for k, (position, intensity) in enumerate(desc["lights"]):
        scene[f"light{k}"] = {"type": "point", "position": list(position),
                              "intensity": {"type": "rgb", "value": intensity}}
    if desc["environment"] > 0:
        scene["environment"] = {"type": "constant",
                                "radiance": {"type": "rgb", "value": desc["environment"]}}
    for k, (shape, extra, ops) in enumerate(desc["objects"]):
        d = {"type": "obj" if shape == "mesh" else shape,
             "to_world": mitsuba_transform(mi, ops),
             "bsdf": mitsuba_material(name)}
        if "filename" in extra:
            d["filename"] = os.path.join(DIR, extra["filename"])
        scene[f"object{k}"] = d
    return scene


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--test-spp", type=int, default=128,
                    help="spp written into the YAML (what the Radiant test renders)")
    args = ap.parse_args()
    import numpy as np
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    os.makedirs(DIR, exist_ok=True)
    mi.Bitmap(ridges_normals(np), pixel_format=mi.Bitmap.PixelFormat.RGB).write(
        os.path.join(DIR, "ridges-normals.png"))
    mi.Bitmap(ridges_height(np), pixel_format=mi.Bitmap.PixelFormat.Y).write(
        os.path.join(DIR, "ridges-height.png"))
    write_uv_sphere(os.path.join(DIR, "uv-sphere.obj"))
    write_cylinder(os.path.join(DIR, "cylinder.obj"))
    for name, desc in [("anisotropic", ANISOTROPIC), ("normal-map", NORMAL_MAP), ("bump", BUMP)]:
        with open(os.path.join(DIR, f"{name}.yaml"), "w") as f:
            f.write(yaml_scene(name, desc, args.test_spp))
        scene = mi.load_dict(mitsuba_scene(mi, name, desc, args.spp))
        image = mi.render(scene, seed=1)
        mi.Bitmap(image).write(os.path.join(DIR, f"{name}-mitsuba.exr"))
        print(f"wrote {name}.yaml and {name}-mitsuba.exr")


if __name__ == "__main__":
    main()

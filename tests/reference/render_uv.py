#!/usr/bin/env python3
"""Make the texture-coordinate references for Radiant with Mitsuba 3.

Writes into ``tests/data/uv/``:

1. ``letter.png``: a 24x32 image of a white "F" on blue with a red square in
   its top-left corner (no flip or quarter turn leaves it unchanged).
2. ``quad.obj``: a 3x3-vertex quad whose texture coordinates are turned a
   quarter against its x and y axes, written with OBJ's bottom-up v.
3. For each shape (rectangle, sphere, cube, mesh) a scene ``<shape>.yaml``
   for Radiant and its Mitsuba render ``<shape>-mitsuba.exr``: two copies
   side by side, the left one textured with the letter, the right one with a
   checkerboard, both diffuse, under a constant white environment with
   ``max_depth: 2``, so that each pixel shows the texture's value where the
   camera sees it. The sphere and the cube are turned, so that their
   texture coordinates must follow the object. The mesh's right copy reads
   its file with ``flip_tex_coords: false``.

The YAML and the Mitsuba scene are made from the same description here, so
they cannot drift apart. The committed files were made with:

    pip install mitsuba numpy
    python3 tests/reference/render_uv.py --spp 1024
"""
import argparse
import os

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
DIR = os.path.join(ROOT, "tests", "data", "uv")
WIDTH, HEIGHT = 128, 64
BLUE = (38, 77, 204)
WHITE = (242, 242, 230)
RED = (230, 26, 26)
CHECKS = ([0.9, 0.8, 0.2], [0.1, 0.2, 0.6])

# Each shape: its Radiant keys, its Mitsuba dict, and its transform as a
# list of (operation, argument), applied like Mitsuba's
# T().translate().rotate()... (the last operation acts first), after a
# translation to its side of the picture.
SHAPES = {
    "rectangle": ([("rotate", ([0, 0, 1], 25)), ("scale", 0.85)], {}),
    "sphere": ([("rotate", ([1, 0, 0], -70)), ("rotate", ([0, 1, 0], 40)), ("scale", 0.85)], {}),
    "cube": ([("rotate", ([0, 1, 0], 35)), ("rotate", ([1, 0, 0], 25)), ("scale", 0.6)], {}),
    "mesh": ([("rotate", ([0, 0, 1], -15)), ("scale", 0.85)], {"filename": "quad.obj"}),
}


def letter(np):
    """The letter image, 8-bit sRGB, rows from the top."""
    img = np.zeros((32, 24, 3), dtype=np.uint8)
    img[:, :] = BLUE
    img[5:28, 6:10] = WHITE  # the stem
    img[5:9, 6:19] = WHITE  # the top bar
    img[14:18, 6:16] = WHITE  # the middle bar
    img[0:4, 0:4] = RED  # the top-left corner
    return img


def write_quad(path):
    """A 3x3-vertex quad in z = 0 over [-1, 1]^2 whose (u, v) turn a quarter
    against (x, y): u = (y + 1)/2, v = 1 - (x + 1)/2 (OBJ's bottom-up v)."""
    with open(path, "w") as f:
        f.write("# The quad of tests/reference/render_uv.py\n")
        for j in range(3):
            for i in range(3):
                x, y = i - 1.0, j - 1.0
                f.write(f"v {x} {y} 0\n")
        for j in range(3):
            for i in range(3):
                x, y = i - 1.0, j - 1.0
                f.write(f"vt {(y + 1) / 2} {1 - (x + 1) / 2}\n")
        for j in range(2):
            for i in range(2):
                a = j * 3 + i + 1
                b, c, d = a + 1, a + 4, a + 3
                f.write(f"f {a}/{a} {b}/{b} {c}/{c}\nf {a}/{a} {c}/{c} {d}/{d}\n")


def yaml_transform(side, ops):
    parts = [f"{{translate: [{side}, 0, 0]}}"]
    for op, arg in ops:
        if op == "rotate":
            axis, angle = arg
            parts.append(f"{{rotate: {{axis: {axis}, angle: {angle}}}}}")
        else:
            parts.append(f"{{scale: {arg}}}")
    return "[" + ", ".join(parts) + "]"


def mitsuba_transform(mi, side, ops):
    t = mi.ScalarTransform4f().translate([side, 0, 0])
    for op, arg in ops:
        if op == "rotate":
            axis, angle = arg
            t = t @ mi.ScalarTransform4f().rotate(axis, angle)
        else:
            t = t @ mi.ScalarTransform4f().scale(arg)
    return t


def yaml_scene(shape, ops, extra, spp):
    c0, c1 = CHECKS
    lines = [
        f"# Made by tests/reference/render_uv.py; the reference is {shape}-mitsuba.exr.",
        "integrator: {type: path, max_depth: 2}",
        f"film: {{width: {WIDTH}, height: {HEIGHT}, filter: {{type: gaussian, stddev: 0.5}}}}",
        f"sampler: {{type: independent, spp: {spp}}}",
        "camera: {type: perspective, fov: 45, fov_axis: x, look_at: {origin: [0, 0, 5], target: [0, 0, 0], up: [0, 1, 0]}}",
        "textures:",
        "  letter_image: {type: image, filename: letter.png}",
        "  letter: {type: uv_transform, texture: letter_image}",
        f"  checks_plain: {{type: checkerboard, color0: {c0}, color1: {c1}}}",
        "  checks: {type: uv_transform, texture: checks_plain}",
        "shapes:",
    ]
    kind = "mesh" if shape == "mesh" else shape
    for side, texture in [(-1.1, "letter"), (1.1, "checks")]:
        keys = [f"type: {kind}", f"material: {{type: diffuse, reflectance: {texture}}}",
                f"transform: {yaml_transform(side, ops)}"]
        if "filename" in extra:
            keys.append(f"filename: {extra['filename']}")
            if texture == "checks":
                keys.append("flip_tex_coords: false")
        lines.append("  - {" + ", ".join(keys) + "}")
    lines.append("lights:")
    lines.append("  - {type: environment, radiance: 1}")
    return "\n".join(lines) + "\n"


def mitsuba_scene(mi, shape, ops, extra, spp):
    c0, c1 = CHECKS
    textures = {
        "letter": {"type": "bitmap", "filename": os.path.join(DIR, "letter.png")},
        "checks": {"type": "checkerboard", "color0": {"type": "rgb", "value": c0},
                   "color1": {"type": "rgb", "value": c1}},
    }
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 2},
        "sensor": {
            "type": "perspective", "fov": 45, "fov_axis": "x",
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": WIDTH, "height": HEIGHT,
                     "rfilter": {"type": "gaussian", "stddev": 0.5}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "light": {"type": "constant", "radiance": {"type": "rgb", "value": 1.0}},
    }
    for side, texture in [(-1.1, "letter"), (1.1, "checks")]:
        d = {"type": "obj" if shape == "mesh" else shape,
             "to_world": mitsuba_transform(mi, side, ops),
             "bsdf": {"type": "diffuse", "reflectance": textures[texture]}}
        if "filename" in extra:
            d["filename"] = os.path.join(DIR, extra["filename"])
            d["flip_tex_coords"] = texture != "checks"
        scene[f"{shape}_{texture}"] = d
    return scene


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--test-spp", type=int, default=256,
                    help="spp written into the YAML (what the Radiant test renders)")
    args = ap.parse_args()
    import numpy as np
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    os.makedirs(DIR, exist_ok=True)
    mi.Bitmap(letter(np), pixel_format=mi.Bitmap.PixelFormat.RGB).write(os.path.join(DIR, "letter.png"))
    write_quad(os.path.join(DIR, "quad.obj"))
    for shape, (ops, extra) in SHAPES.items():
        with open(os.path.join(DIR, f"{shape}.yaml"), "w") as f:
            f.write(yaml_scene(shape, ops, extra, args.test_spp))
        scene = mi.load_dict(mitsuba_scene(mi, shape, ops, extra, args.spp))
        image = mi.render(scene, seed=1)
        mi.Bitmap(image).write(os.path.join(DIR, f"{shape}-mitsuba.exr"))
        print(f"wrote {shape}.yaml and {shape}-mitsuba.exr")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Speed suite: Radiant against Mitsuba 3 on six scenes of users' kinds.

Each scene is described once here and written both as Radiant YAML
(``scenes/bench/NAME.yaml``, committed) and as a Mitsuba 3 scene dictionary,
so the two renderers see the same geometry, materials and lights:

* ``bunny-gold``: the Cornell box's walls and light, the 69k-triangle
  Stanford bunny as rough gold (GGX alpha 0.2);
* ``spot-point``: the teapot on a finely checkered floor, lit only by a
  spot light and a point light;
* ``plastic-pane``: the ogre (124k triangles) as rough plastic (alpha 0.1)
  behind a thin glass pane, lit by a small rectangle light;
* ``glass-spheres``: a rough (alpha 0.1) and a smooth glass sphere on a
  floor, small rectangle light;
* ``textured-env``: the textured cow ``spot`` (sRGB image, bilinear) on a
  checkered floor under the environment map ``scenes/environment-sky.exr``;
* ``veach-plates``: Veach's four glossy plates (alpha 0.01 to 0.25) lit by
  four spheres from 0.03 to 0.6 in radius, radiance in inverse proportion to
  their area.

``cornell-box`` (``scenes/cornell-box.yaml`` and ``mi.cornell_box()``) is
timed with them, as the scene that must not get slower.

Meshes come from a folder outside the repository (``$RADIANT_MODELS``,
default ``/work/shared/data/models``: ``stanford-bunny.obj``, ``teapot.obj``,
``ogre.obj``, ``spot_triangulated.obj``, ``spot_texture.png``); the scenes
name them as ``models/FILE``, and this script links ``scenes/bench/models``
to that folder (git ignores the link). Scenes whose files are missing are
skipped with a message saying which file.

Commands::

    python3 engine/benches/suite.py write           # (re)writes scenes/bench/*.yaml
    python3 engine/benches/suite.py references      # converged Mitsuba references
    python3 engine/benches/suite.py bench --radiant target/release/radiant [--runs 5]
    python3 engine/benches/suite.py bench ... --isa avx2   # an AVX2-only host, stood in for

``references`` renders each scene with Mitsuba ``llvm_ad_rgb`` in two
halves of ``--spp/2`` samples (default 4096 in all) into
``$RADIANT_BENCH_REFS`` (default ``~/.cache/radiant-bench``): the mean is
the reference and the halves' difference estimates the reference's own
variance, which ``bench`` subtracts from every MSE.

``bench`` times both renderers in the same run, interleaved (Radiant, then
Mitsuba, repeated ``--runs`` times, each render with its own seed), on the
same number of threads; Mitsuba's kernel is compiled in a warm-up render
that is not timed. Radiant's time is the render time it reports, Mitsuba's
the wall time of ``mi.render`` plus the read-back of the image. It reports
per scene the median time of each and their ratio per sample (speed:
Mitsuba's ``stratified``, ``multijitter``, ``orthogonal`` and ``ldsampler``
round the spp up), the MSE of each
against the reference (mean over the runs, less the reference's variance),
the equal-error ratio (T·MSE of Mitsuba) / (T·MSE of Radiant) and the
geometric means over the scenes other than the Cornell box.
"""
import argparse
import math
import os
import re
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mitsuba_peer import cpu_summary, find_libllvm, read_rgb  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
BENCH = os.path.join(ROOT, "scenes", "bench")
MODELS = os.environ.get("RADIANT_MODELS", "/work/shared/data/models")
REFS = os.environ.get("RADIANT_BENCH_REFS", os.path.expanduser("~/.cache/radiant-bench"))
SKY = os.path.join(ROOT, "scenes", "environment-sky.exr")
W = H = 256
MAX_DEPTH = 8
RADIANT_RE = re.compile(r"rendered (\d+)x(\d+), (\d+) spp in ([\d.]+) s "
                        r"\(([\d.]+) Msamples/s, ([\d.]+) Mrays/s\)")

# ---------------------------------------------------------------------------
# Scene descriptions. Transforms are lists of operations applied like
# Radiant's and Mitsuba's T().translate(..).rotate(..).scale(..): the last
# acts first. Materials use Radiant's parameter names.

CORNELL_WHITE = [0.885809, 0.698859, 0.666422]
CORNELL_WALLS = [
    ("floor", [("translate", [0, -1, 0]), ("rotate", ([1, 0, 0], -90))], "white"),
    ("ceiling", [("translate", [0, 1, 0]), ("rotate", ([1, 0, 0], 90))], "white"),
    ("back", [("translate", [0, 0, -1])], "white"),
    ("green wall", [("translate", [1, 0, 0]), ("rotate", ([0, 1, 0], -90))], "green"),
    ("red wall", [("translate", [-1, 0, 0]), ("rotate", ([0, 1, 0], 90))], "red"),
]
CORNELL_MATERIALS = {
    "white": {"type": "diffuse", "reflectance": CORNELL_WHITE},
    "green": {"type": "diffuse", "reflectance": [0.105421, 0.37798, 0.076425]},
    "red": {"type": "diffuse", "reflectance": [0.570068, 0.0430135, 0.0443706]},
}
CORNELL_CAMERA = {"fov": 39.3077, "fov_axis": "smaller",
                  "origin": [0, 0, 3.9], "target": [0, 0, 0], "up": [0, 1, 0]}


# Radiant's sampler in the written scenes: its default (scenes without a
# `sampler` block get it), Owen-scrambled Sobol points.
RADIANT_SAMPLER = "sobol"


def rect(name, transform, material, emitter=None):
    return {"name": name, "type": "rectangle", "transform": transform,
            "material": material, "emitter": emitter}


def plate_tilt(center, camera, light):
    """Rotation about x (degrees) that turns a rectangle's +z normal towards
    the half vector between the directions to the camera and to the light."""
    def unit(v):
        n = math.sqrt(sum(x * x for x in v))
        return [x / n for x in v]
    a = unit([c - p for c, p in zip(camera, center)])
    b = unit([c - p for c, p in zip(light, center)])
    h = unit([x + y for x, y in zip(a, b)])
    # normal (0, cos t, sin t) = rotation of +z by t - 90 degrees about x
    return math.degrees(math.atan2(h[2], h[1])) - 90.0


def veach_plates():
    camera = [0, 2.0, 6.0]
    light_c = [0, 2.6, -2.0]
    plates = []
    for i, (y, z, alpha) in enumerate([(0.15, 1.2, 0.01), (0.35, 0.4, 0.04),
                                       (0.6, -0.35, 0.1), (0.9, -1.05, 0.25)]):
        tilt = plate_tilt([0, y, z], camera, light_c)
        plates.append({"name": f"plate {i}", "type": "rectangle",
                       "transform": [("translate", [0, y, z]), ("rotate", ([1, 0, 0], tilt)),
                                     ("scale", [2.4, 0.3, 1])],
                       "material": f"plate{i}", "emitter": None})
    lights = []
    for i, (x, r) in enumerate([(-2.6, 0.03), (-1.1, 0.1), (0.5, 0.25), (2.2, 0.6)]):
        radiance = 2.0 * (0.6 / r) ** 2
        lights.append({"name": f"light {i}", "type": "sphere", "center": [x, 2.6, -2.0],
                       "radius": r, "material": "black",
                       "emitter": [radiance * c for c in (1.0, 0.9, 0.8)]})
    materials = {f"plate{i}": {"type": "conductor", "material": "none", "alpha": a,
                               "specular_reflectance": 0.8}
                 for i, a in enumerate([0.01, 0.04, 0.1, 0.25])}
    materials["black"] = {"type": "diffuse", "reflectance": 0.0}
    materials["grey"] = {"type": "diffuse", "reflectance": 0.1}
    return {
        "doc": "Veach's four glossy plates (GGX alpha 0.01, 0.04, 0.1, 0.25), lit by four spheres\n"
               "of radius 0.03 to 0.6 whose radiance falls with their area.",
        "spp": 32, "files": [],
        "camera": {"fov": 40, "fov_axis": "x", "origin": camera, "target": [0, 0.6, 0],
                   "up": [0, 1, 0]},
        "materials": materials, "textures": {},
        "shapes": plates + lights + [
            rect("floor", [("translate", [0, -0.2, 0]), ("rotate", ([1, 0, 0], -90)),
                           ("scale", 6)], "grey"),
            rect("back", [("translate", [0, 0, -4]), ("scale", 6)], "grey"),
        ],
        "lights": [],
    }


def suite():
    """name -> scene description."""
    models = "models"
    scenes = {}
    scenes["bunny-gold"] = {
        "doc": "The Cornell box's walls and light around the Stanford bunny (69k triangles)\n"
               "as rough gold (GGX alpha 0.2).",
        "spp": 32, "files": ["stanford-bunny.obj"], "camera": CORNELL_CAMERA,
        "materials": dict(CORNELL_MATERIALS,
                          gold={"type": "conductor", "material": "Au", "alpha": 0.2}),
        "textures": {},
        "shapes": [rect("light", [("translate", [0, 0.99, 0.01]), ("rotate", ([1, 0, 0], 90)),
                                  ("scale", [0.23, 0.19, 0.19])], "white",
                        [18.387, 13.9873, 6.75357])]
        + [rect(n, t, m) for n, t, m in CORNELL_WALLS]
        + [{"name": "bunny", "type": "mesh", "filename": f"{models}/stanford-bunny.obj",
            "transform": [("translate", [0.136, -1.264, 0.012]), ("scale", 8)],
            "material": "gold", "emitter": None}],
        "lights": [],
    }
    scenes["spot-point"] = {
        "doc": "The teapot on a finely checkered floor, lit only by a spot light and a\n"
               "point light (the point light has more power; the spot lights most of the view).",
        "spp": 32, "files": ["teapot.obj"],
        "camera": {"fov": 45, "fov_axis": "x", "origin": [0, 4, 7], "target": [0, 0.8, 0],
                   "up": [0, 1, 0]},
        "textures": {"checks": {"type": "checkerboard", "color0": 0.7, "color1": 0.15,
                                "scale": 16}},
        "materials": {"floor": {"type": "diffuse", "reflectance": "checks"},
                      "pot": {"type": "diffuse", "reflectance": [0.7, 0.5, 0.3]}},
        "shapes": [
            rect("floor", [("rotate", ([1, 0, 0], -90)), ("scale", 6)], "floor"),
            {"name": "teapot", "type": "mesh", "filename": f"{models}/teapot.obj",
             "transform": [("translate", [-0.2, 0, 0]), ("scale", 0.6)],
             "material": "pot", "emitter": None},
        ],
        "lights": [
            {"type": "spot", "position": [1.5, 5, 2], "target": [0, 0, 0],
             "intensity": [60, 55, 50], "cutoff_angle": 35, "beam_width": 25},
            {"type": "point", "position": [-4, 3, -5], "intensity": [40, 40, 45]},
        ],
    }
    scenes["plastic-pane"] = {
        "doc": "The ogre (124k triangles) as rough plastic (GGX alpha 0.1) behind a thin glass\n"
               "pane, lit by a small rectangle light.",
        "spp": 32, "files": ["ogre.obj"],
        "camera": {"fov": 45, "fov_axis": "x", "origin": [0, 1.4, 4.5], "target": [0, 0.9, 0],
                   "up": [0, 1, 0]},
        "textures": {},
        "materials": {"plastic": {"type": "plastic", "diffuse_reflectance": [0.2, 0.35, 0.6],
                                  "alpha": 0.1},
                      "glass": {"type": "thin_dielectric"},
                      "grey": {"type": "diffuse", "reflectance": 0.5},
                      "black": {"type": "diffuse", "reflectance": 0.0}},
        "shapes": [
            rect("floor", [("rotate", ([1, 0, 0], -90)), ("scale", 5)], "grey"),
            rect("back", [("translate", [0, 0, -2]), ("scale", 5)], "grey"),
            {"name": "ogre", "type": "mesh", "filename": f"{models}/ogre.obj",
             "transform": [("translate", [0, 0.0005, -0.3]), ("scale", 0.06)],
             "material": "plastic", "emitter": None},
            rect("pane", [("translate", [0.5, 0.8, 1.2]), ("rotate", ([0, 1, 0], -20)),
                          ("scale", [0.7, 0.8, 1])], "glass"),
            rect("light", [("translate", [1.0, 3.0, 1.5]), ("rotate", ([1, 0, 0], 90)),
                           ("scale", 0.15)], "black", [120, 110, 100]),
        ],
        "lights": [],
    }
    scenes["glass-spheres"] = {
        "doc": "A rough glass sphere (GGX alpha 0.1) and a smooth one on a floor, lit by a\n"
               "small rectangle light.",
        "spp": 32, "files": [],
        "camera": {"fov": 40, "fov_axis": "x", "origin": [0, 1.5, 5], "target": [0, 0.6, 0],
                   "up": [0, 1, 0]},
        "textures": {},
        "materials": {"rough": {"type": "dielectric", "alpha": 0.1},
                      "smooth": {"type": "dielectric"},
                      "grey": {"type": "diffuse", "reflectance": 0.5},
                      "wall": {"type": "diffuse", "reflectance": [0.6, 0.55, 0.45]},
                      "black": {"type": "diffuse", "reflectance": 0.0}},
        "shapes": [
            rect("floor", [("rotate", ([1, 0, 0], -90)), ("scale", 5)], "grey"),
            rect("back", [("translate", [0, 0, -2.5]), ("scale", 5)], "wall"),
            {"name": "rough ball", "type": "sphere", "center": [-0.75, 0.7, 0], "radius": 0.7,
             "material": "rough", "emitter": None},
            {"name": "smooth ball", "type": "sphere", "center": [0.8, 0.6, 0.4], "radius": 0.6,
             "material": "smooth", "emitter": None},
            rect("light", [("translate", [-0.5, 3.0, 1.0]), ("rotate", ([1, 0, 0], 90)),
                           ("scale", 0.2)], "black", [100, 95, 85]),
        ],
        "lights": [],
    }
    scenes["textured-env"] = {
        "doc": "The textured cow `spot` (sRGB image, bilinear) on a checkered floor under the\n"
               "environment map environment-sky.exr (a sky with a small bright sun).",
        "spp": 32, "files": ["spot_triangulated.obj", "spot_texture.png"],
        "camera": {"fov": 40, "fov_axis": "x", "origin": [2.2, 1.6, 3.2],
                   "target": [0, 0.35, 0], "up": [0, 1, 0]},
        "textures": {"checks": {"type": "checkerboard", "color0": 0.6, "color1": 0.25,
                                "scale": 8},
                     "hide": {"type": "image", "filename": f"{models}/spot_texture.png"}},
        "materials": {"floor": {"type": "diffuse", "reflectance": "checks"},
                      "cow": {"type": "diffuse", "reflectance": "hide"}},
        "shapes": [
            rect("floor", [("rotate", ([1, 0, 0], -90)), ("scale", 4)], "floor"),
            {"name": "cow", "type": "mesh", "filename": f"{models}/spot_triangulated.obj",
             "transform": [("translate", [0, 0.737, 0]), ("rotate", ([0, 1, 0], 150))],
             "material": "cow", "emitter": None},
        ],
        "lights": [{"type": "environment", "filename": "../environment-sky.exr",
                    "rotate_y": 60}],
    }
    scenes["veach-plates"] = veach_plates()
    return scenes


# ---------------------------------------------------------------------------
# Radiant YAML


def yaml_value(v):
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(yaml_value(x) for x in v) + "]"
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def yaml_transform(ops):
    parts = []
    for op, arg in ops:
        if op == "rotate":
            axis, angle = arg
            parts.append(f"{{rotate: {{axis: {yaml_value(axis)}, angle: {yaml_value(float(angle))}}}}}")
        else:
            parts.append(f"{{{op}: {yaml_value(arg)}}}")
    return "[" + ", ".join(parts) + "]"


def yaml_map(d):
    return "{" + ", ".join(f"{k}: {yaml_value(v)}" for k, v in d.items()) + "}"


def radiant_yaml(name, s):
    lines = [f"# {line}" for line in s["doc"].splitlines()]
    lines += ["# Written by engine/benches/suite.py (`write`) with its Mitsuba 3 twin; edit",
              "# the description there, not this file. Meshes are read from models/, a link",
              "# to $RADIANT_MODELS that the script makes.",
              f"integrator: {{type: path, max_depth: {MAX_DEPTH}}}",
              "film:", f"  width: {W}", f"  height: {H}",
              "  filter: {type: gaussian, stddev: 0.5}",
              f"sampler: {{type: {RADIANT_SAMPLER}, spp: {s['spp']}}}"]
    c = s["camera"]
    lines += ["camera:", "  type: perspective", f"  fov: {c['fov']}", f"  fov_axis: {c['fov_axis']}",
              f"  look_at: {{origin: {yaml_value(c['origin'])}, target: {yaml_value(c['target'])}, "
              f"up: {yaml_value(c['up'])}}}"]
    if s["textures"]:
        lines.append("textures:")
        for tname, t in s["textures"].items():
            if t["type"] == "checkerboard":
                lines.append(f"  {tname}_base: {{type: checkerboard, color0: {t['color0']}, "
                             f"color1: {t['color1']}}}")
                lines.append(f"  {tname}: {{type: uv_transform, texture: {tname}_base, "
                             f"scale: {t['scale']}}}")
            else:
                lines.append(f"  {tname}: {yaml_map(t)}")
    lines.append("materials:")
    for mname, m in s["materials"].items():
        lines.append(f"  {mname}: {yaml_map(m)}")
    lines.append("shapes:")
    for sh in s["shapes"]:
        lines.append(f"  - name: {sh['name']}")
        lines.append(f"    type: {sh['type']}")
        if sh["type"] == "mesh":
            lines.append(f"    filename: {sh['filename']}")
        if sh["type"] == "sphere":
            lines.append(f"    center: {yaml_value(sh['center'])}")
            lines.append(f"    radius: {sh['radius']}")
        if sh.get("transform"):
            lines.append(f"    transform: {yaml_transform(sh['transform'])}")
        lines.append(f"    material: {sh['material']}")
        if sh.get("emitter"):
            lines.append(f"    emitter: {{type: area, radiance: {yaml_value(sh['emitter'])}}}")
    if s["lights"]:
        lines.append("lights:")
        for light in s["lights"]:
            d = {k: v for k, v in light.items() if k != "rotate_y"}
            line = "  - " + yaml_map(d)
            if "rotate_y" in light:
                line = line[:-1] + (f", transform: {{rotate: {{axis: [0, 1, 0], "
                                    f"angle: {light['rotate_y']}}}}}}}")
            lines.append(line)
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------
# Mitsuba dictionaries


def mi_transform(mi, ops):
    t = mi.ScalarTransform4f()
    for op, arg in ops:
        if op == "translate":
            t = t.translate(arg)
        elif op == "rotate":
            t = t.rotate(arg[0], arg[1])
        elif op == "scale":
            t = t.scale(arg if isinstance(arg, list) else [arg, arg, arg])
    return t


def mi_rgb(v):
    return {"type": "rgb", "value": v if isinstance(v, list) else [v, v, v]}


def mi_texture(mi, s, value):
    if isinstance(value, str):
        t = s["textures"][value]
        if t["type"] == "checkerboard":
            return {"type": "checkerboard", "color0": mi_rgb(t["color0"]),
                    "color1": mi_rgb(t["color1"]),
                    "to_uv": mi.ScalarTransform4f().scale([t["scale"], t["scale"], 1])}
        return {"type": "bitmap", "filename": os.path.join(BENCH, t["filename"]),
                "filter_type": "bilinear"}
    return mi_rgb(value)


def mi_bsdf(mi, s, m):
    ty = m["type"]
    if ty == "diffuse":
        return {"type": "diffuse", "reflectance": mi_texture(mi, s, m["reflectance"])}
    if ty == "conductor":
        d = {"type": "roughconductor", "distribution": "ggx", "alpha": m["alpha"],
             "material": m["material"]}
        if "specular_reflectance" in m:
            d["specular_reflectance"] = mi_rgb(m["specular_reflectance"])
        return d
    if ty == "plastic":
        return {"type": "roughplastic", "distribution": "ggx", "alpha": m["alpha"],
                "diffuse_reflectance": mi_rgb(m["diffuse_reflectance"])}
    if ty == "dielectric":
        if "alpha" in m:
            return {"type": "roughdielectric", "distribution": "ggx", "alpha": m["alpha"]}
        return {"type": "dielectric"}
    if ty == "thin_dielectric":
        return {"type": "thindielectric"}
    raise ValueError(ty)


def mitsuba_dict(mi, s, spp):
    c = s["camera"]
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": MAX_DEPTH},
        "sensor": {
            "type": "perspective", "fov": c["fov"], "fov_axis": c["fov_axis"],
            "to_world": mi.ScalarTransform4f().look_at(origin=c["origin"], target=c["target"],
                                                       up=c["up"]),
            "film": {"type": "hdrfilm", "width": W, "height": H,
                     "rfilter": {"type": "gaussian", "stddev": 0.5}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},  # `--mitsuba-sampler`
        },
    }
    for i, sh in enumerate(s["shapes"]):
        shape = {"bsdf": mi_bsdf(mi, s, s["materials"][sh["material"]])}
        if sh["type"] == "mesh":
            shape.update(type="obj", filename=os.path.join(BENCH, sh["filename"]))
        else:
            shape["type"] = sh["type"]
        if sh["type"] == "sphere":
            shape.update(center=sh["center"], radius=sh["radius"])
        if sh.get("transform"):
            shape["to_world"] = mi_transform(mi, sh["transform"])
        if sh.get("emitter"):
            shape["emitter"] = {"type": "area", "radiance": mi_rgb(sh["emitter"])}
        d[f"shape{i}"] = shape
    for i, light in enumerate(s["lights"]):
        if light["type"] == "point":
            e = {"type": "point", "position": light["position"],
                 "intensity": mi_rgb(light["intensity"])}
        elif light["type"] == "spot":
            e = {"type": "spot", "intensity": mi_rgb(light["intensity"]),
                 "cutoff_angle": light["cutoff_angle"], "beam_width": light["beam_width"],
                 "to_world": mi.ScalarTransform4f().look_at(
                     origin=light["position"], target=light["target"], up=[0, 1, 0])}
        elif light["type"] == "environment":
            e = {"type": "envmap", "filename": SKY,
                 "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], light["rotate_y"])}
        else:
            raise ValueError(light["type"])
        d[f"light{i}"] = e
    return d


# ---------------------------------------------------------------------------
# Commands


def link_models():
    """Links scenes/bench/models to $RADIANT_MODELS; False if that is missing."""
    link = os.path.join(BENCH, "models")
    if not os.path.isdir(MODELS):
        return False
    if os.path.islink(link) and os.readlink(link) != MODELS:
        os.unlink(link)
    if not os.path.lexists(link):
        os.symlink(MODELS, link)
    return True


def missing_files(s):
    return [f for f in s["files"] if not os.path.exists(os.path.join(MODELS, f))]


def cmd_write(_args):
    os.makedirs(BENCH, exist_ok=True)
    for name, s in suite().items():
        path = os.path.join(BENCH, f"{name}.yaml")
        with open(path, "w") as f:
            f.write(radiant_yaml(name, s))
        print(f"wrote {path}")
    return 0


# What Dr.Jit's LLVM backend compiles for with `--mitsuba-isa avx2`: an
# AVX2-only CPU (Haswell and later, Zen 1-3), eight lanes.
AVX2_TARGET = (b"haswell", b"+avx2,+fma,+f16c,+bmi,+bmi2,+lzcnt,+popcnt,+sse4.2,"
               b"-avx512f,-avx512vl,-avx512dq,-avx512bw,-avx512cd", 8)


def setup_mitsuba(threads, isa="native"):
    if "DRJIT_LIBLLVM_PATH" not in os.environ and find_libllvm():
        os.environ["DRJIT_LIBLLVM_PATH"] = find_libllvm()
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    import drjit as dr
    if threads:
        dr.set_thread_count(threads)
    if isa == "avx2":
        # Dr.Jit's C++ `jit_llvm_set_target(cpu, features, vector_width)`,
        # which its Python module does not expose: kernels compiled after
        # it target an AVX2-only CPU, as on such a host.
        import ctypes
        import glob
        core = ctypes.CDLL(glob.glob(os.path.join(os.path.dirname(dr.__file__),
                                                  "libdrjit-core.so"))[0])
        set_target = core._Z19jit_llvm_set_targetPKcS0_j
        set_target.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_uint32]
        set_target(*AVX2_TARGET)
    return mi


def ref_paths(name):
    return (os.path.join(REFS, f"{name}.exr"), os.path.join(REFS, f"{name}.halfdiff.exr"))


def load_scene(mi, name, s, spp, sampler="independent"):
    if name == "cornell-box":
        desc = mi.cornell_box()
        desc["integrator"]["max_depth"] = MAX_DEPTH
    else:
        desc = mitsuba_dict(mi, s, spp)
    desc["sensor"]["sampler"]["sample_count"] = spp
    desc["sensor"]["sampler"]["type"] = sampler
    return mi.load_dict(desc)


def selected(args):
    scenes = {"cornell-box": {"spp": 64, "files": []}}
    scenes.update(suite())
    if args.scenes:
        wanted = args.scenes.split(",")
        unknown = [w for w in wanted if w not in scenes]
        if unknown:
            sys.exit(f"unknown scene(s) {unknown}; the suite has {list(scenes)}")
        scenes = {k: v for k, v in scenes.items() if k in wanted}
    have_models = link_models()
    out = {}
    for name, s in scenes.items():
        gone = missing_files(s)
        if gone:
            print(f"skipping {name}: {', '.join(gone)} not found in {MODELS} "
                  f"(set RADIANT_MODELS){'' if have_models else '; the folder is missing'}",
                  file=sys.stderr)
            continue
        out[name] = s
    return out


def cmd_references(args):
    import numpy as np
    mi = setup_mitsuba(args.threads)
    os.makedirs(REFS, exist_ok=True)
    half = max(1, args.spp // 2)
    pass_spp = min(half, 512)
    for name, s in selected(args).items():
        out, diff = ref_paths(name)
        if os.path.exists(out) and not args.force:
            print(f"{name}: {out} exists (--force renders it again)")
            continue
        t0 = time.time()
        scene = load_scene(mi, name, s, pass_spp)
        halves = []
        for h in range(2):
            acc = None
            for i in range(max(1, half // pass_spp)):
                img = np.array(mi.render(scene, spp=pass_spp, seed=100000 + 1000 * h + i),
                               dtype=np.float64)[..., :3]
                acc = img if acc is None else acc + img
            halves.append(acc / max(1, half // pass_spp))
        mean = (halves[0] + halves[1]) / 2
        bitmap = mi.Bitmap
        bitmap(mean.astype(np.float32), pixel_format=bitmap.PixelFormat.RGB).write(out)
        bitmap(((halves[0] - halves[1]) / 2).astype(np.float32),
               pixel_format=bitmap.PixelFormat.RGB).write(diff)
        print(f"{name}: wrote {out} ({2 * half} spp, {time.time() - t0:.0f} s, "
              f"mean {mean.reshape(-1, 3).mean(axis=0)})", flush=True)
    return 0


def radiant_run(binary, scene, spp, seed, threads, out, extra):
    cmd = [binary, "render", scene, "--spp", str(spp), "--seed", str(seed), "-o", out]
    if threads:
        cmd += ["--threads", str(threads)]
    cmd += extra
    p = subprocess.run(cmd, capture_output=True, text=True)
    lines = p.stderr.strip().splitlines()
    m = RADIANT_RE.search(lines[-1]) if lines else None
    if p.returncode != 0 or not m:
        sys.exit(f"radiant failed on {scene} (rc={p.returncode}):\n{p.stderr}")
    return float(m.group(4))


def scene_variant(yaml, selection="", sampler=""):
    """A copy of the scene `yaml` beside it (so relative paths hold) whose
    integrator selects lights by `selection` and whose sampler is `sampler`
    (each unchanged where empty); git ignores it."""
    with open(yaml) as f:
        text = f.read()
    if selection:
        text, n = re.subn(r"^integrator: \{type: path, ",
                          f"integrator: {{type: path, light_selection: {selection}, ", text,
                          flags=re.M)
        if n == 0:  # the Cornell box's block form
            text, n = re.subn(r"^  type: path$", f"  type: path\n  light_selection: {selection}",
                              text, flags=re.M)
        if n != 1:
            sys.exit(f"cannot set light_selection in {yaml}")
    if sampler:
        text, n = re.subn(r"^sampler: \{type: \w+", f"sampler: {{type: {sampler}", text, flags=re.M)
        if n == 0:  # block form
            text, n = re.subn(r"^(sampler:\n  type:) \w+", f"\\1 {sampler}", text, flags=re.M)
        if n != 1:
            sys.exit(f"cannot set the sampler in {yaml}")
    # scenes/bench/ (the Cornell box names no files, so it may move there).
    out = os.path.join(BENCH, f".suite-{os.path.basename(yaml)}")
    with open(out, "w") as f:
        f.write(text)
    return out


def cmd_bench(args):
    import numpy as np
    import drjit as dr
    if args.isa != "native":
        # Both renderers held to the instruction set: Mitsuba's kernels
        # compiled for it, Radiant's traversal capped at it.
        args.mitsuba_isa = args.isa
    mi = setup_mitsuba(args.threads, args.mitsuba_isa)
    extra = args.radiant_args.split() if args.radiant_args else []
    if args.isa != "native":
        extra += ["--max-isa", args.isa]
    rows = []
    for name, s in selected(args).items():
        ref_path, diff_path = ref_paths(name)
        if not os.path.exists(ref_path):
            print(f"skipping {name}: no reference {ref_path} (run `references` first)",
                  file=sys.stderr)
            continue
        ref = read_rgb(mi, ref_path)
        # Variance of the reference's mean: ((A - B)/2)^2 estimates it per pixel.
        ref_var = float(np.mean(read_rgb(mi, diff_path) ** 2))
        spp = args.spp or s["spp"]
        yaml = (os.path.join(ROOT, "scenes", "cornell-box.yaml") if name == "cornell-box"
                else os.path.join(BENCH, f"{name}.yaml"))
        if args.light_selection or args.sampler:
            yaml = scene_variant(yaml, args.light_selection, args.sampler)
        scene = load_scene(mi, name, s, spp, args.mitsuba_sampler)
        img = mi.render(scene, spp=spp, seed=999)  # compiles the kernel
        dr.eval(img)
        # What Mitsuba takes: its stratified samplers round the spp up (32
        # becomes 36, 35, 49 or 64), so speeds are compared per sample.
        m_spp = scene.sensors()[0].sampler().sample_count()
        rt, mt, rerr, merr = [], [], [], []
        out = f"/tmp/radiant-suite-{os.getpid()}.exr"
        for i in range(args.runs):
            rt.append(radiant_run(args.radiant, yaml, spp, i + 1, args.threads, out, extra))
            rerr.append(float(np.mean((read_rgb(mi, out) - ref) ** 2)))
            t0 = time.perf_counter()
            img = mi.render(scene, spp=spp, seed=i + 1)
            pixels = np.array(img, dtype=np.float64)[..., :3]
            mt.append(time.perf_counter() - t0)
            merr.append(float(np.mean((pixels - ref) ** 2)))
        r_t, m_t = statistics.median(rt), statistics.median(mt)
        r_mse, m_mse = (max(statistics.mean(e) - ref_var, 1e-30) for e in (rerr, merr))
        rows.append((name, spp, m_spp, r_t, m_t, r_mse, m_mse))
        print(f"  {name}: radiant {['%.2f' % t for t in rt]} s, mitsuba {['%.2f' % t for t in mt]}"
              f" s; MSE {r_mse:.3e} / {m_mse:.3e} (reference variance {ref_var:.1e})",
              file=sys.stderr, flush=True)
    if os.path.exists(f"/tmp/radiant-suite-{os.getpid()}.exr"):
        os.unlink(f"/tmp/radiant-suite-{os.getpid()}.exr")
    threads = args.threads or os.cpu_count()
    print(f"\n{W}x{H}, max_depth {MAX_DEPTH}, {threads} threads, medians of {args.runs} "
          f"interleaved runs; {cpu_summary()}"
          + (f"; Radiant with light_selection: {args.light_selection}" if args.light_selection else "")
          + (f"; Radiant's sampler: {args.sampler}" if args.sampler else "")
          + f"; Mitsuba's sampler: {args.mitsuba_sampler}"
          + (f"; Mitsuba compiled for {args.mitsuba_isa}" if args.mitsuba_isa != "native" else "")
          + (f"; Radiant's traversal capped at {args.isa}" if args.isa != "native" else ""))
    print("| scene | spp | Radiant s | Mitsuba s | speed | MSE Radiant | MSE Mitsuba | at equal error |")
    print("|---|---|---|---|---|---|---|---|")
    speeds, equal = [], []
    for name, spp, m_spp, r_t, m_t, r_mse, m_mse in rows:
        # Samples per second, Radiant's over Mitsuba's.
        speed, eq = (m_t * spp) / (r_t * m_spp), (m_t * m_mse) / (r_t * r_mse)
        if name != "cornell-box":
            speeds.append(speed)
            equal.append(eq)
        spps = f"{spp}" if m_spp == spp else f"{spp} (Mitsuba {m_spp})"
        print(f"| {name} | {spps} | {r_t:.2f} | {m_t:.2f} | {speed:.2f}x | {r_mse:.3e} | "
              f"{m_mse:.3e} | {eq:.2f}x |")
    if speeds:
        def gmean(v):
            return math.exp(sum(math.log(x) for x in v) / len(v))
        print(f"| geometric mean (without cornell-box) | | | | {gmean(speeds):.2f}x | | | "
              f"{gmean(equal):.2f}x |")
    return 0


# Where `profile` files a symbol (first match wins).
CATEGORIES = [
    ("traversal (closest hits)", ("intersect_slots", "accel::triangle", "Accel::primitive",
                                  "hit_sphere")),
    ("load, BVH build, output", ("obvhs::", "tobj::", "extract::", "accel::wide::Collapse",
                                "accel::blas::", "scene::", "ply_rs", "gltf", "png::", "image::",
                                "miniz", "zune", "exr::", "load_image")),
    ("traversal (shadow rays)", ("occluded_each",)),
    ("shaders", ("radiant_shaders::",)),
    ("textures", ("radiant_textures::",)),
    ("lights", ("radiant_lights::",)),
    ("sampler", ("radiant_samplers::",)),
    ("film", ("film::",)),
    ("integrator bookkeeping", ("integrators::", "backend::cpu")),
    ("kernel + libc", ("[k]", "mem", "__")),
]


def cmd_profile(args):
    """perf profile of each scene on one thread, by category and symbol."""
    scenes = selected(args)
    rows = []
    for name in scenes:
        yaml = (os.path.join(ROOT, "scenes", "cornell-box.yaml") if name == "cornell-box"
                else os.path.join(BENCH, f"{name}.yaml"))
        if args.light_selection:
            yaml = scene_variant(yaml, args.light_selection)
        data = f"/tmp/radiant-profile-{name}.data"
        cmd = ["perf", "record", "-F", "1999", "-o", data, "--", args.radiant, "render", yaml,
               "--spp", str(args.spp), "--threads", "1", "-o", f"/tmp/radiant-profile-{name}.exr"]
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit(f"perf failed on {name}:\n{p.stderr}")
        report = subprocess.run(["perf", "report", "-i", data, "--no-children", "--sort", "symbol",
                                 "--stdio", "--percent-limit", "0"],
                                capture_output=True, text=True).stdout
        totals, symbols = {}, []
        for line in report.splitlines():
            m = re.match(r"\s*([\d.]+)%\s+(\[.\])\s+(.*?)\s*$", line)
            if not m:
                continue
            share, kind, sym = float(m.group(1)), m.group(2), m.group(3)
            full = f"{kind} {sym}"
            cat = next((c for c, keys in CATEGORIES if any(k in full for k in keys)), "other")
            totals[cat] = totals.get(cat, 0.0) + share
            symbols.append((share, cat, sym))
        print(f"\n### {name} ({args.spp} spp, one thread)\n")
        print("| where | share of samples |\n|---|---|")
        for cat, share in sorted(totals.items(), key=lambda kv: -kv[1]):
            print(f"| {cat} | {share:.1f} % |")
        print("\ntop symbols: " + "; ".join(f"{s:.1f} % {sym[:70]}"
                                             for s, _, sym in symbols[:args.top]))
        rows.append((name, totals))
    columns = [c for c, _ in CATEGORIES] + ["other"]
    print("\n| scene | traversal | " + " | ".join(columns) + " |")
    print("|---" * (len(columns) + 2) + "|")
    for name, totals in rows:
        trav = sum(v for k, v in totals.items() if k.startswith("traversal"))
        cells = [f"{totals.get(c, 0.0):.1f} %" for c in columns]
        print(f"| {name} | {trav:.1f} % | " + " | ".join(cells) + " |")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("write", help="write scenes/bench/*.yaml")
    r = sub.add_parser("references", help="render converged Mitsuba references")
    r.add_argument("--spp", type=int, default=4096)
    r.add_argument("--force", action="store_true")
    b = sub.add_parser("bench", help="time both renderers and print the table")
    b.add_argument("--radiant", default=os.path.join(ROOT, "target", "release", "radiant"))
    b.add_argument("--runs", type=int, default=5)
    b.add_argument("--spp", type=int, default=0, help="override every scene's spp")
    b.add_argument("--light-selection", default="",
                   help="run Radiant with this integrator light_selection (power, uniform, spatial)")
    b.add_argument("--sampler", default="",
                   help="run Radiant with this sampler (default: each scene's own, sobol in "
                        "scenes/bench, independent in the Cornell box)")
    b.add_argument("--mitsuba-sampler", default="independent",
                   help="Mitsuba's sampler (independent, its default; or ldsampler, multijitter, "
                        "orthogonal, stratified)")
    b.add_argument("--mitsuba-isa", default="native", choices=["native", "avx2"],
                   help="the instruction set Mitsuba's kernels are compiled for: the host's "
                        "(native), or an AVX2-only CPU's, eight lanes (avx2), to stand in for "
                        "such a host in Mitsuba's kernels only")
    b.add_argument("--isa", default="native", choices=["native", "avx2"],
                   help="an AVX2-only host stood in for on both sides: Mitsuba's kernels "
                        "compiled for it (as --mitsuba-isa avx2) and Radiant's traversal "
                        "capped at it (radiant render --max-isa avx2)")
    b.add_argument("--radiant-args", default="",
                   help="extra arguments for radiant render (one string)")
    pr = sub.add_parser("profile", help="perf profile of each scene on one thread")
    pr.add_argument("--radiant", default=os.path.join(ROOT, "target", "release", "radiant"))
    pr.add_argument("--spp", type=int, default=16)
    pr.add_argument("--top", type=int, default=12, help="symbols listed per scene")
    pr.add_argument("--light-selection", default="")
    for p in (r, b, pr):
        p.add_argument("--scenes", default="", help="comma-separated subset")
        p.add_argument("--threads", type=int, default=0, help="threads for both (default all)")
    args = ap.parse_args()
    return {"write": cmd_write, "references": cmd_references, "bench": cmd_bench,
            "profile": cmd_profile}[args.cmd](args)


if __name__ == "__main__":
    sys.exit(main())

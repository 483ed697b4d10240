#!/usr/bin/env python3
"""Writes the scale and translation variants of scenes/cornell-box.yaml
used by tests/torture_scale.rs: every shape's transform gets one more
operation applied last (a uniform scale or a translation), and the camera's
look_at is moved the same way, so each variant images the same box.

Run from the workspace root: python3 scenes/hard/make_cornell_variants.py
"""

import copy
import yaml

VARIANTS = {
    "cornell-scaled-1e-4.yaml": ("scale", 1e-4),
    "cornell-scaled-1e5.yaml": ("scale", 1e5),
    "cornell-translated-1e6.yaml": ("translate", [1e6, 1e6, 1e6]),
}


class NoAliases(yaml.SafeDumper):
    """Radiant's YAML reader does not accept anchors and aliases."""

    def ignore_aliases(self, data):
        return True


def moved(p, op, value):
    if op == "scale":
        return [c * value for c in p]
    return [c + v for c, v in zip(p, value)]


def main():
    with open("scenes/cornell-box.yaml") as f:
        base = yaml.safe_load(f)
    for name, (op, value) in VARIANTS.items():
        scene = copy.deepcopy(base)
        look = scene["camera"]["look_at"]
        look["origin"] = moved(look["origin"], op, value)
        look["target"] = moved(look["target"], op, value)
        for shape in scene["shapes"]:
            ops = shape.get("transform", [])
            ops = ops if isinstance(ops, list) else [ops]
            shape["transform"] = [{op: copy.deepcopy(value)}] + ops
        with open(f"scenes/hard/{name}", "w") as f:
            f.write(
                f"# The Cornell box of scenes/cornell-box.yaml with `{op}: {value}`\n"
                "# applied to every shape and to the camera (written by\n"
                "# make_cornell_variants.py). Its image must match the original's.\n"
            )
            yaml.dump(
                scene, f, Dumper=NoAliases, sort_keys=False, default_flow_style=None, width=100
            )


if __name__ == "__main__":
    main()

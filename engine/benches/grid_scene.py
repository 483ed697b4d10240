#!/usr/bin/env python3
"""Writes a one-level scene far larger than the caches: a 5x5 grid of the
Stanford bunny, the ogre and nefertiti (25 meshes, about 2.4 million
triangles, all static, so one hierarchy), gold on a grey floor under an
environment and a directional light.

    python3 engine/benches/grid_scene.py OUT.yaml MODELS_DIR
    target/release/radiant render OUT.yaml --spp 8 --threads 1 -o grid.exr

Used to time the traversal where it waits on memory (see
engine/benches/ANIMATION.md, stop 27); the suite's scenes mostly stay
cached.
"""
import sys

NAMES = ["stanford-bunny", "ogre", "nefertiti"]
SCALE = {"stanford-bunny": 8, "ogre": 0.25, "nefertiti": 0.004}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    out, models = sys.argv[1], sys.argv[2].rstrip("/")
    shapes = []
    for k in range(25):
        i, j = divmod(k, 5)
        name = NAMES[k % 3]
        shapes.append(
            f"  - type: mesh\n"
            f"    filename: {models}/{name}.obj\n"
            f"    transform: [{{translate: [{(i - 2) * 1.6}, 0, {-j * 1.6}]}}, "
            f"{{rotate: {{axis: [0, 1, 0], angle: {37 * (k + 1)}}}}}, {{scale: {SCALE[name]}}}]\n"
            f"    material: gold")
    with open(out, "w") as f:
        f.write("""integrator: {type: path, max_depth: 8}
film: {width: 256, height: 256}
sampler: {type: sobol, spp: 16}
camera: {type: perspective, fov: 50, look_at: {origin: [0, 3, 4], target: [0, 0, -3]}}
materials:
  gold: {type: conductor, material: Au, alpha: 0.2}
  grey: {type: diffuse, reflectance: 0.5}
shapes:
""" + "\n".join(shapes) + """
  - {type: rectangle, transform: [{rotate: {axis: [1, 0, 0], angle: -90}}, {scale: 20}], material: grey}
lights:
  - {type: environment, radiance: 0.6}
  - {type: directional, direction: [-0.3, -1, -0.4], irradiance: 3}
""")


if __name__ == "__main__":
    main()

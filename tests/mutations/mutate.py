#!/usr/bin/env python3
"""Mutation check of the sampling tests: does the suite notice a small bias?

Applies each mutation of ``MUTATIONS`` (one deliberate bias in one line of
the renderer) to a scratch worktree of the current commit, one at a time,
runs the tests, and reports which mutations made a test fail ("caught").
The scratch worktree has its own target directory, so the first run
builds everything once; later mutations rebuild only what they touch.

    python3 tests/mutations/mutate.py                 # the sampling suite
    python3 tests/mutations/mutate.py --all           # the whole workspace
    python3 tests/mutations/mutate.py --only cone     # mutations whose id contains "cone"

The report (a Markdown table) is printed and written to
``tests/mutations/last-result.md``. Each mutation's ``find`` text must
occur exactly once in its file, so that a refactoring that moves the
code makes the script fail loudly instead of testing nothing.
"""
import argparse
import os
import subprocess
import sys
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))

# (id, bias in words, file, text to find, replacement)
MUTATIONS = [
    ("sphere-sample-pdf-2%", "sphere light: pdf returned by sampling 2 % too small, eval_hits right",
     "modules/lights/src/area.rs",
     "return (p, n, self.part_probability(part) * cone.pdf());",
     "return (p, n, 0.98 * self.part_probability(part) * cone.pdf());"),
    ("sphere-sample-pdf-1%", "sphere light: pdf returned by sampling 1 % too small, eval_hits right",
     "modules/lights/src/area.rs",
     "return (p, n, self.part_probability(part) * cone.pdf());",
     "return (p, n, 0.99 * self.part_probability(part) * cone.pdf());"),
    ("cone-pdf-1%", "sphere light cone pdf 1 % too small (both sides)", "modules/lights/src/sphere.rs",
     "1.0 / (TAU * self.one_minus_cos_max)", "0.99 / (TAU * self.one_minus_cos_max)"),
    ("aperture+2%", "thin-lens aperture 2 % too large", "modules/cameras/src/thin_lens.rs",
     "square_to_disk_concentric(*u) * self.aperture_radius", "square_to_disk_concentric(*u) * (1.02 * self.aperture_radius)"),
    ("aperture-2%", "thin-lens aperture 2 % too small", "modules/cameras/src/thin_lens.rs",
     "square_to_disk_concentric(*u) * self.aperture_radius", "square_to_disk_concentric(*u) * (0.98 * self.aperture_radius)"),
    ("envmap-sample-pdf+2%", "environment map: pdf returned by sampling 2 % too large, eval right",
     "modules/lights/src/environment.rs",
     "(d, m.lookup(su, sv), pdf)", "(d, m.lookup(su, sv), 1.02 * pdf)"),
    ("envmap-pdf+1%", "environment map pdf 1 % too large (both sides)", "modules/lights/src/environment.rs",
     "self.distribution.pdf(c) / (rows * TAU * band)", "1.01 * self.distribution.pdf(c) / (rows * TAU * band)"),
    ("ggx-d+1%", "GGX D 1 % too large", "modules/shaders/src/microfacet.rs",
     "let d = 1.0 / (PI * self.alpha_u", "let d = 1.01 / (PI * self.alpha_u"),
    ("rectangle-solid-angle-1%", "rectangle light solid angle 1 % too large (both sides)",
     "modules/lights/src/rectangle.rs",
     "let solid_angle = g0 + g1 + g2 + g3 - two_pi;",
     "let solid_angle = 1.01 * (g0 + g1 + g2 + g3 - two_pi);"),
    ("diffuse-eval-2%", "diffuse eval 2 % too small (sampling unchanged)", "modules/shaders/src/diffuse.rs",
     "value: *a * (FRAC_1_PI * wi.z),", "value: *a * (0.98 * FRAC_1_PI * wi.z),"),
    ("aperture+1%", "thin-lens aperture 1 % too large", "modules/cameras/src/thin_lens.rs",
     "square_to_disk_concentric(*u) * self.aperture_radius", "square_to_disk_concentric(*u) * (1.01 * self.aperture_radius)"),
    ("point-intensity+2%", "point light 2 % too bright", "modules/lights/src/point.rs",
     "self.intensity / dist2", "self.intensity * 1.02 / dist2"),
    ("cone-pdf-2%", "sphere light cone pdf 2 % too small (both sides)", "modules/lights/src/sphere.rs",
     "1.0 / (TAU * self.one_minus_cos_max)", "0.98 / (TAU * self.one_minus_cos_max)"),
    ("rr-survival+5%", "Russian roulette divides by a 5 % larger survival probability",
     "engine/src/integrators/path.rs",
     "beta /= survival;", "beta /= survival * 1.05;"),
    ("ggx-d+3%", "GGX D 3 % too large", "modules/shaders/src/microfacet.rs",
     "let d = 1.0 / (PI * self.alpha_u", "let d = 1.03 / (PI * self.alpha_u"),
    ("envmap-pdf+3%", "environment map pdf 3 % too large (both sides)", "modules/lights/src/environment.rs",
     "self.distribution.pdf(c) / (rows * TAU * band)", "1.03 * self.distribution.pdf(c) / (rows * TAU * band)"),
    ("rectangle-solid-angle-2%", "rectangle light solid angle 2 % too large (both sides)",
     "modules/lights/src/rectangle.rs",
     "let solid_angle = g0 + g1 + g2 + g3 - two_pi;",
     "let solid_angle = 1.02 * (g0 + g1 + g2 + g3 - two_pi);"),
    ("aperture+5%", "thin-lens aperture 5 % too large", "modules/cameras/src/thin_lens.rs",
     "square_to_disk_concentric(*u) * self.aperture_radius", "square_to_disk_concentric(*u) * (1.05 * self.aperture_radius)"),
    ("envmap-lower-pdf+3%", "environment map pdf 3 % too large below the horizon only (both sides)",
     "modules/lights/src/environment.rs",
     "self.distribution.pdf(c) / (rows * TAU * band)",
     "self.distribution.pdf(c) / (rows * TAU * band) * if 2 * c.y > self.size.y { 1.03 } else { 1.0 }"),
    ("srgb-gamma-2.2", "sRGB decoded by a plain 2.2 power", "modules/textures/src/srgb.rs",
     "((c + 0.055) / 1.055).powf(2.4)", "c.powf(2.2)"),
    ("spatial-mis-pmf+2%", "spatial light selection: MIS probability 2 % above the chosen one",
     "engine/src/extract/lights.rs",
     "share * b.importance(p) / total", "1.02 * share * b.importance(p) / total"),
    ("light-tree-mis-pmf+2%", "light tree: MIS probability 2 % above the chosen one",
     "engine/src/extract/lights.rs",
     "return share * tree.pmf(p, slot);", "return 1.02 * share * tree.pmf(p, slot);"),
    ("gpu-spatial-nee-pmf+2%", "GPU spatial selection: the spot's next-event probability 2 % high",
     "engine/src/backend/gpu/wgsl/light_selection.wgsl",
     "    return vec2f(last.x, share * last.y / total);",
     "    return vec2f(last.x, share * last.y / total * select(1.0, 1.02, last.x == 1.0));"),
    ("gpu-spatial-mis-pmf+2%", "GPU spatial selection: MIS probability 2 % above the chosen one",
     "engine/src/backend/gpu/wgsl/light_selection.wgsl",
     "        return share * sel_importance(sel_record(slot), p) / total;",
     "        return 1.02 * share * sel_importance(sel_record(slot), p) / total;"),
    ("gpu-light-tree-nee-pmf+2%", "GPU light tree: one spot's next-event probability 2 % high",
     "engine/src/backend/gpu/wgsl/light_selection.wgsl",
     "                    return vec2f(f32(param_u32(r + 13u)), share * pmf);",
     "                    return vec2f(f32(param_u32(r + 13u)), share * pmf * select(1.0, 1.02, param_u32(r + 13u) == 10u));"),
    ("gpu-light-tree-mis-pmf+2%", "GPU light tree: MIS probability 2 % above the chosen one",
     "engine/src/backend/gpu/wgsl/light_selection.wgsl",
     "            return share * pmf;\n        }\n        return 0.0;",
     "            return 1.02 * share * pmf;\n        }\n        return 0.0;"),
    ("spot-bounds-narrow", "spot light bounds: fall-off cone 10 % narrower than the light's",
     "modules/lights/src/spot.rs",
     "(self.cutoff - self.beam).cos(),", "(0.9 * (self.cutoff - self.beam)).cos(),"),
]

# The tests that pin sampling routines: the module crates' unit tests and
# the workspace tests about lights, shaders, cameras and whole renders.
SAMPLING_SUITE = [
    "-p", "radiant-core", "-p", "radiant-lights", "-p", "radiant-shaders", "-p", "radiant-cameras",
    "-p", "radiant-textures", "-p", "radiant-tests", "--lib",
    "--test", "light_densities", "--test", "sampling_renders", "--test", "lights",
    "--test", "shaders_energy", "--test", "shaders_sampling", "--test", "shaders_scenes",
    "--test", "depth_of_field", "--test", "environment", "--test", "cornell_box",
    "--test", "lens_and_filter_sampling", "--test", "delta_lights", "--test", "torture_lights",
    "--test", "light_selection", "--test", "gpu_light_selection",
]


def run(cmd, cwd, log):
    with open(log, "w") as f:
        return subprocess.run(cmd, cwd=cwd, stdout=f, stderr=subprocess.STDOUT).returncode


def failed_tests(log):
    names = []
    with open(log, errors="replace") as f:
        for line in f:
            line = line.strip()
            if line.startswith("test ") and line.endswith("FAILED"):
                names.append(line[len("test "):-len(" ... FAILED")])
    return names


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--all", action="store_true", help="run the whole workspace's tests")
    ap.add_argument("--only", default="", help="run the mutations whose id contains this")
    ap.add_argument("--worktree", default="/tmp/radiant-mutants")
    args = ap.parse_args()
    tests = ["--workspace"] if args.all else SAMPLING_SUITE
    cmd = ["cargo", "test", "--no-fail-fast"] + tests
    wt = args.worktree
    head = subprocess.check_output(["git", "rev-parse", "HEAD"], cwd=ROOT, text=True).strip()
    if not os.path.isdir(wt):
        subprocess.check_call(["git", "worktree", "add", "--detach", wt, head], cwd=ROOT)
    subprocess.check_call(["git", "checkout", "--quiet", "--detach", head], cwd=wt)
    subprocess.check_call(["git", "checkout", "--quiet", "--", "."], cwd=wt)
    logs = os.path.join(wt, "mutation-logs")
    os.makedirs(logs, exist_ok=True)

    start = time.time()
    if run(cmd, wt, os.path.join(logs, "baseline.log")) != 0:
        sys.exit(f"the unmutated suite fails: see {logs}/baseline.log")
    rows = []
    for ident, words, path, find, replace in MUTATIONS:
        if args.only not in ident:
            continue
        file = os.path.join(wt, path)
        with open(file) as f:
            text = f.read()
        if text.count(find) != 1:
            sys.exit(f"{ident}: `{find}` occurs {text.count(find)} times in {path}, not once")
        with open(file, "w") as f:
            f.write(text.replace(find, replace))
        t = time.time()
        log = os.path.join(logs, f"{ident}.log")
        code = run(cmd, wt, log)
        subprocess.check_call(["git", "checkout", "--quiet", "--", path], cwd=wt)
        caught = failed_tests(log) if code != 0 else []
        verdict = "caught" if code != 0 else "**not caught**"
        if code != 0 and not caught:
            caught = ["(build or harness failure: see the log)"]
        rows.append((ident, words, verdict, ", ".join(caught[:4]) + (" …" if len(caught) > 4 else "")))
        print(f"{ident}: {verdict} in {time.time() - t:.0f} s {caught[:4]}", flush=True)
        write_report(head, args.all, rows, time.time() - start)


def write_report(head, whole, rows, seconds):
    """Writes the report so far to `tests/mutations/last-result.md`."""
    report = [
        f"# Mutation check of commit {head[:10]}",
        "",
        f"`python3 tests/mutations/mutate.py{' --all' if whole else ''}`: "
        f"{len(rows)} mutations, {seconds:.0f} s.",
        "",
        "| mutation | bias | verdict | failing tests |",
        "| --- | --- | --- | --- |",
    ] + [f"| `{i}` | {w} | {v} | {c} |" for i, w, v, c in rows]
    text = "\n".join(report) + "\n"
    with open(os.path.join(ROOT, "tests", "mutations", "last-result.md"), "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()

//! Kernel assembly: a frame's WGSL, made of exactly the module types it
//! uses and the integrator paths its effects need.
//!
//! Plain generation, no composition crate: module code is a set of flat
//! functions with fixed names per kind, so assembly is concatenation —
//! the prelude, each library once, each used type once — plus generated
//! dispatchers (a `switch` on the type tag where a kind has several types,
//! a direct call where it has one), and the integrator's and geometry's
//! sources with the blocks between `//#if FEATURE` and `//#endif` kept
//! only where the frame has the feature. What a scene does not use is
//! not in its source, so a reader of the dumped WGSL (`--dump-wgsl`) sees
//! what runs, and a compile error's line falls in a named part
//! ([`Kernel::part_at`]). Numeric switches (depth, roulette) are
//! pipeline-overridable constants, set when the pipeline is made.

use super::modules::{KindTypes, Modules};
use super::upload::Geometry;
use crate::extract::RenderScene;
use radiant_core::{Effects, GpuLibrary};
use std::fmt::Write;

const GEOMETRY: &str = include_str!("wgsl/geometry.wgsl");
const WIDE_BVH: &str = include_str!("wgsl/cwbvh.wgsl");
const PATH: &str = include_str!("wgsl/path.wgsl");
const WAVEFRONT: &str = include_str!("wgsl/wavefront.wgsl");
const HEADER: &str = include_str!("wgsl/header.wgsl");
const MEDIUM: &str = include_str!("wgsl/medium.wgsl");
const LIGHT_SELECTION: &str = include_str!("wgsl/light_selection.wgsl");

/// Features that select blocks of the kernel's own sources.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Features {
    /// Instances through a top level.
    pub instances: bool,
    /// Sphere primitives.
    pub spheres: bool,
    /// Textures that vary (interpolated texture coordinates).
    pub textures: bool,
    /// Shading frames oriented by the surface's parametrization, with its
    /// derivatives (anisotropic lobes, normal and bump maps).
    pub tangent_frames: bool,
    /// Rays that carry a time in the shutter (motion blur): moving
    /// instances, deforming meshes, a moving camera.
    pub motion: bool,
    /// Any light (next-event estimation).
    pub lights: bool,
    /// Surfaces that emit.
    pub area_lights: bool,
    /// Lights chosen by their bounds' importance at the shading point
    /// (`light_selection: spatial` with more than one light).
    pub spatial_lights: bool,
    /// Lights at infinity that escaped rays see.
    pub environment: bool,
    /// Participating media or `null` boundaries (`wgsl/medium.wgsl`, the
    /// media's and phase functions' code, shadow rays that return a
    /// transmittance).
    pub media: bool,
    /// Counting of traversal work (`--gpu-stats`).
    pub stats: bool,
    /// The wavefront's stages (`wgsl/wavefront.wgsl`, `--gpu-kernel
    /// wavefront`) next to the megakernel.
    pub wavefront: bool,
    /// Hierarchies in the compressed wide layout (`wgsl/cwbvh.wgsl`)
    /// rather than the binary one.
    pub wide_bvh: bool,
    /// Samples splatted over the pixels in the filter's reach (the film's
    /// default, as the CPU and Mitsuba do) rather than placed by filter
    /// importance sampling.
    pub splat: bool,
}

impl Features {
    /// The features of a frame.
    pub fn of(scene: &RenderScene, geometry: &Geometry, modules: &Modules) -> Self {
        Self {
            instances: geometry.instanced,
            spheres: geometry.spheres,
            textures: scene.effects.contains(Effects::TEXTURES),
            tangent_frames: geometry.tangent_frames,
            motion: geometry.motion,
            lights: !scene.lights.is_empty(),
            area_lights: modules.area_lights,
            spatial_lights: scene.lights.is_spatial(),
            environment: modules.environment,
            media: modules.has_media,
            stats: false,
            wavefront: false,
            wide_bvh: geometry.layout == super::BvhLayout::Wide,
            splat: scene.settings.filter_sampling == crate::settings::FilterSampling::Splat,
        }
    }

    fn enabled(&self, name: &str) -> Option<bool> {
        Some(match name {
            "INSTANCES" => self.instances,
            "SPHERES" => self.spheres,
            "TEXTURES" => self.textures,
            "TANGENT_FRAMES" => self.tangent_frames,
            "MOTION" => self.motion,
            "LIGHTS" => self.lights,
            "AREA_LIGHTS" => self.area_lights,
            "SPATIAL_LIGHTS" => self.spatial_lights,
            "ENVIRONMENT" => self.environment,
            "MEDIA" => self.media,
            "STATS" => self.stats,
            "WIDE_BVH" => self.wide_bvh,
            "SPLAT" => self.splat,
            _ => return None,
        })
    }

    /// The names of the features that are on.
    pub fn names(&self) -> Vec<&'static str> {
        [
            ("instances", self.instances),
            ("spheres", self.spheres),
            ("textures", self.textures),
            ("tangent frames", self.tangent_frames),
            ("motion blur", self.motion),
            ("next-event estimation", self.lights),
            ("area lights", self.area_lights),
            ("spatial light selection", self.spatial_lights),
            ("environment", self.environment),
            ("participating media", self.media),
            ("filter splatting", self.splat),
            ("wavefront stages", self.wavefront),
            ("compressed wide BVH", self.wide_bvh),
        ]
        .into_iter()
        .filter_map(|(n, on)| on.then_some(n))
        .collect()
    }
}

/// Keeps the lines of `source` outside disabled `//#if` blocks (`//#else`
/// flips a block; blocks nest).
fn preprocess(source: &str, features: &Features) -> String {
    let mut out = String::with_capacity(source.len());
    // Per open block: whether its current branch is kept.
    let mut stack: Vec<bool> = Vec::new();
    for line in source.lines() {
        let t = line.trim();
        if let Some(name) = t.strip_prefix("//#if ") {
            let on = features.enabled(name.trim()).unwrap_or(false);
            stack.push(on);
        } else if t == "//#else" {
            if let Some(top) = stack.last_mut() {
                *top = !*top;
            }
        } else if t == "//#endif" {
            stack.pop();
        } else if stack.iter().all(|&on| on) {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// An assembled kernel: its source and the part each line range came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Kernel {
    /// The WGSL.
    pub source: String,
    /// (first line, part name) in source order: lines from `first` on
    /// belong to that part until the next entry.
    parts: Vec<(usize, String)>,
    /// The features compiled in.
    pub features: Features,
}

impl Kernel {
    /// Assembles the kernel for `modules` and `features`.
    pub fn assemble(modules: &Modules, features: Features) -> Self {
        let mut k = Kernel {
            source: String::new(),
            parts: Vec::new(),
            features,
        };
        k.part("the parameter header (wgsl/header.wgsl)", HEADER);
        k.modules(modules);
        k.part("the generated dispatchers", &dispatchers(modules));
        k.geometry(&features);
        k.part(
            "the GPU backend's path integrator (wgsl/path.wgsl)",
            &preprocess(PATH, &features),
        );
        k.part(
            "the GPU backend's light selection (wgsl/light_selection.wgsl)",
            &preprocess(LIGHT_SELECTION, &features),
        );
        if features.media {
            k.part(
                "the GPU backend's medium stage (wgsl/medium.wgsl)",
                &preprocess(MEDIUM, &features),
            );
        }
        if features.wavefront {
            k.part(
                "the GPU backend's wavefront stages (wgsl/wavefront.wgsl)",
                &preprocess(WAVEFRONT, &features),
            );
        }
        k
    }

    /// A kernel that runs `body` once per probe input (see
    /// [`super::probe`]): the prelude, `modules`' code, the texture
    /// dispatcher, and an entry point around `body`.
    pub fn assemble_probe(modules: &Modules, body: &str) -> Self {
        let mut k = Kernel {
            source: String::new(),
            parts: Vec::new(),
            features: Features::default(),
        };
        k.part(
            "the probe's bindings",
            "@group(0) @binding(0) var<storage, read> module_params: array<u32>;\n\
             @group(0) @binding(1) var<storage, read> probe_in: array<f32>;\n\
             @group(0) @binding(2) var<storage, read_write> probe_out: array<f32>;\n",
        );
        k.part("the parameter header (wgsl/header.wgsl)", HEADER);
        k.modules(modules);
        k.part("the generated dispatchers", &dispatchers(modules));
        k.part("the probe", body);
        k
    }

    /// A kernel that traces given rays through the geometry of `features`
    /// (closest hit and occlusion), for tests of traversal against the CPU
    /// (see [`super::GpuBackend::trace_rays`]).
    pub fn assemble_trace(features: Features) -> Self {
        let mut k = Kernel {
            source: String::new(),
            parts: Vec::new(),
            features,
        };
        k.part(
            "the tracer's bindings",
            "@group(0) @binding(0) var<storage, read> module_params: array<u32>;\n\
             @group(0) @binding(1) var<storage, read> nodes: array<vec4f>;\n\
             @group(0) @binding(2) var<storage, read> prims: array<vec4f>;\n\
             @group(0) @binding(3) var<storage, read> shading: array<vec4f>;\n\
             @group(0) @binding(4) var<storage, read> instances: array<vec4f>;\n\
             @group(0) @binding(5) var<storage, read> rays: array<vec4f>;\n\
             @group(0) @binding(6) var<storage, read_write> hits: array<vec4f>;\n",
        );
        k.part("the parameter header (wgsl/header.wgsl)", HEADER);
        k.part(
            "the module prelude (radiant-core)",
            radiant_core::gpu::PRELUDE,
        );
        k.geometry(&features);
        k.part(
            "the tracer",
            &preprocess(
                "@compute @workgroup_size(64)\n\
             fn trace(@builtin(global_invocation_id) g: vec3u) {\n\
             \x20   let i = g.x;\n\
             \x20   if i >= arrayLength(&rays) / 2u { return; }\n\
             \x20   let o = rays[2u * i].xyz;\n\
             \x20   let tmax = rays[2u * i].w;\n\
             \x20   let d = rays[2u * i + 1u].xyz;\n\
             //#if MOTION\n\
             \x20   ray_time = rays[2u * i + 1u].w;\n\
             //#endif\n\
             \x20   let h = closest_hit(o, d);\n\
             \x20   var prim = 0xffffffffu;\n\
             \x20   if h.slot != NO_HIT { prim = prim_info(h.slot).w; }\n\
             \x20   let blocked = select(0.0, 1.0, occluded(o, d, tmax));\n\
             \x20   hits[i] = vec4f(h.t, bitcast<f32>(prim), blocked, 0.0);\n\
             }\n",
                &features,
            ),
        );
        k
    }

    /// The prelude, the libraries the modules call and the modules' code.
    fn modules(&mut self, modules: &Modules) {
        let k = self;
        k.part(
            "the module prelude (radiant-core)",
            radiant_core::gpu::PRELUDE,
        );
        let mut libraries: Vec<GpuLibrary> = Vec::new();
        let kinds = [
            ("camera", &modules.camera),
            ("sampler", &modules.sampler),
            ("shader", &modules.shaders),
            ("texture", &modules.textures),
            ("light", &modules.lights),
            ("medium", &modules.media),
            ("phase", &modules.phases),
        ];
        if modules.has_media {
            // The medium stage's types, with or without media types.
            add_library(&mut libraries, &radiant_core::gpu::MEDIUM);
        }
        for (_, types) in kinds {
            for t in &types.types {
                for lib in t.requires {
                    add_library(&mut libraries, lib);
                }
            }
        }
        for lib in &libraries {
            k.part(&format!("the library `{}`", lib.name), lib.wgsl);
        }
        for (kind, types) in kinds {
            for t in &types.types {
                k.part(&format!("the {kind} module `{}`", t.ident), &t.wgsl);
            }
        }
    }

    /// The backend's geometry, with the wide BVH's traversal in place of
    /// the binary one's where the features ask for it.
    fn geometry(&mut self, features: &Features) {
        self.part(
            "the GPU backend's geometry (wgsl/geometry.wgsl)",
            &preprocess(GEOMETRY, features),
        );
        if features.wide_bvh {
            self.part(
                "the GPU backend's wide BVH traversal (wgsl/cwbvh.wgsl)",
                &preprocess(WIDE_BVH, features),
            );
        }
    }

    fn part(&mut self, name: &str, source: &str) {
        let line = self.source.lines().count();
        self.parts.push((line, name.to_string()));
        writeln!(self.source, "// ---- {name} ----").expect("writing to a String");
        self.source.push_str(source);
        if !source.ends_with('\n') {
            self.source.push('\n');
        }
    }

    /// The part of the kernel that line `line` (0-based) lies in.
    pub fn part_at(&self, line: usize) -> Option<&str> {
        self.parts
            .iter()
            .rev()
            .find(|(first, _)| *first <= line)
            .map(|(_, name)| name.as_str())
    }
}

/// Adds `lib` after the libraries it requires, each once.
fn add_library(libraries: &mut Vec<GpuLibrary>, lib: &GpuLibrary) {
    if libraries.iter().any(|l| l.name == lib.name) {
        return;
    }
    for dep in lib.requires {
        add_library(libraries, dep);
    }
    libraries.push(*lib);
}

/// The (tag, identifier) of each type of a kind.
pub(super) fn tagged(types: &KindTypes) -> Vec<(u32, &str)> {
    types
        .types
        .iter()
        .enumerate()
        .map(|(i, t)| (i as u32, t.ident.as_str()))
        .collect()
}

/// A function `name(args)` that calls `prefix_T(offset, args)` for the
/// instance's type `T`: directly where the kind has one type, else by a
/// `switch` on the tag. `entry` is the WGSL expression of the instance's
/// (tag, offset) pair.
pub(super) fn dispatcher(
    out: &mut String,
    signature: &str,
    entry: &str,
    prefix: &str,
    args: &str,
    types: &[(u32, &str)],
) {
    let call = |t: &str| format!("return {prefix}_{t}(e.y{args});");
    let mut body = format!("fn {signature} {{\n    let e = {entry};\n");
    match types {
        [] => {}
        [(_, only)] => body += &format!("    {}\n", call(only)),
        [rest @ .., (_, last)] => {
            body += "    switch e.x {\n";
            for (tag, t) in rest {
                body += &format!("        case {tag}u: {{ {} }}\n", call(t));
            }
            body += &format!("        default: {{ {} }}\n    }}\n", call(last));
        }
    }
    out.push_str(&body);
    out.push_str("}\n\n");
}

/// The generated entry points the integrator calls.
fn dispatchers(m: &Modules) -> String {
    let mut s = String::new();
    if let [cam] = m.camera.types.as_slice() {
        let _ = writeln!(
            s,
            "fn camera_ray(film: vec2f, lens: vec2f) -> CameraRay {{\n    return camera_ray_{}(param_u32(H_CAMERA), film, lens);\n}}\n",
            cam.ident
        );
    }
    if let [smp] = m.sampler.types.as_slice() {
        let t = &smp.ident;
        let _ = writeln!(
            s,
            "fn sample_1d(pixel: u32, index: u32, dim: u32) -> f32 {{\n    return sample_1d_{t}(param_u32(H_SAMPLER), pixel, index, dim);\n}}\n"
        );
        // A sampler without 2D code draws its pairs as two 1D values.
        let pair = if smp.wgsl.contains(&format!("fn sample_2d_{t}(")) {
            format!("sample_2d_{t}(param_u32(H_SAMPLER), pixel, index, dim)")
        } else {
            "vec2f(sample_1d(pixel, index, dim), sample_1d(pixel, index, dim + 1u))".into()
        };
        let _ = writeln!(
            s,
            "fn sample_2d(pixel: u32, index: u32, dim: u32) -> vec2f {{\n    return {pair};\n}}\n"
        );
    }
    if m.shaders.types.is_empty() {
        return texture_dispatcher(m, s);
    }
    let material = "vec2u(param_u32(param_u32(H_MATERIALS) + 4u * m), param_u32(param_u32(H_MATERIALS) + 4u * m + 1u))";
    // With media, the materials' dispatchers are `surface_*`, behind ones
    // that also take medium events (`media.rs`).
    let surface = if m.has_media { "surface_" } else { "" };
    dispatcher(
        &mut s,
        &format!("{surface}bsdf_sample(m: u32, s: ShadingPoint, u: vec3f) -> BsdfSample"),
        material,
        "bsdf_sample",
        ", s, u",
        &tagged(&m.shaders),
    );
    dispatcher(
        &mut s,
        &format!("{surface}bsdf_eval(m: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval"),
        material,
        "bsdf_eval",
        ", s, wi",
        &tagged(&m.shaders),
    );
    let smooth = if m.has_media {
        "surface_has_smooth_lobes"
    } else {
        "material_has_smooth_lobes"
    };
    let _ = writeln!(
        s,
        "fn {smooth}(m: u32) -> bool {{\n    return param_u32(param_u32(H_MATERIALS) + 4u * m + 2u) != 0u;\n}}\n"
    );
    if m.has_media {
        super::media::dispatchers(m, &mut s);
    }
    s = texture_dispatcher(m, s);
    if !m.lights.types.is_empty() {
        let light = "vec2u(param_u32(param_u32(H_LIGHTS) + 4u * l), param_u32(param_u32(H_LIGHTS) + 4u * l + 1u))";
        dispatcher(
            &mut s,
            "light_sample(l: u32, r: vec3f, u: vec2f) -> LightSample",
            light,
            "light_sample",
            ", r, u",
            &tagged(&m.lights),
        );
        if m.area_lights {
            // Only surface lights are ever hit: dispatch among those types.
            let hit_types: Vec<(u32, &str)> = tagged(&m.lights)
                .into_iter()
                .filter(|(tag, t)| {
                    m.lights.types[*tag as usize]
                        .wgsl
                        .contains(&format!("fn light_hit_{t}("))
                })
                .collect();
            let mut hit = String::new();
            dispatcher(
                &mut hit,
                "light_hit(l: u32, h: EmitterHit) -> EmitterEval",
                light,
                "light_hit",
                ", h",
                &hit_types,
            );
            s.push_str(&hit);
        }
        if m.environment {
            // Only lights at infinity are asked: dispatch among those types.
            let escaped_types: Vec<(u32, &str)> = tagged(&m.lights)
                .into_iter()
                .filter(|(tag, t)| {
                    m.lights.types[*tag as usize]
                        .wgsl
                        .contains(&format!("fn light_escaped_{t}("))
                })
                .collect();
            dispatcher(
                &mut s,
                "light_escaped(l: u32, dir: vec3f) -> EmitterEval",
                light,
                "light_escaped",
                ", dir",
                &escaped_types,
            );
        }
    }
    s
}

/// `texture_eval`, appended to `s`.
fn texture_dispatcher(m: &Modules, mut s: String) -> String {
    let texture = "vec2u(param_u32(param_u32(H_TEXTURES) + 4u * id), param_u32(param_u32(H_TEXTURES) + 4u * id + 1u))";
    if !m.textures.types.is_empty() {
        dispatcher(
            &mut s,
            "texture_eval(id: u32, uv: vec2f) -> vec3f",
            texture,
            "texture",
            ", uv",
            &tagged(&m.textures),
        );
    } else {
        let _ = writeln!(
            s,
            "fn texture_eval(id: u32, uv: vec2f) -> vec3f {{\n    return vec3f(0.0);\n}}\n"
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disabled_blocks_are_left_out_and_else_branches_flip() {
        let src = "a\n//#if SPHERES\nb\n//#else\nc\n//#endif\n//#if TEXTURES\n//#if SPHERES\nd\n//#endif\ne\n//#endif\nf\n";
        let none = preprocess(src, &Features::default());
        assert_eq!(none, "a\nc\nf\n");
        let spheres = Features {
            spheres: true,
            ..Features::default()
        };
        assert_eq!(preprocess(src, &spheres), "a\nb\nf\n");
        let both = Features {
            spheres: true,
            textures: true,
            ..Features::default()
        };
        assert_eq!(preprocess(src, &both), "a\nb\nd\ne\nf\n");
    }
}

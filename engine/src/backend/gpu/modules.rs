//! The frame's modules on the GPU: each instance's [`GpuModule`] gathered,
//! its parameters placed in the one parameter buffer, and the tables the
//! kernel looks instances up in (a header, then per kind a directory of
//! (type, parameter offset, flags, value) entries), with the pixel
//! filter tabulated for importance sampling.
//!
//! A module without GPU code makes the frame fail with an error that names
//! it ([`GpuError::MissingCode`]).

use super::error::GpuError;
use super::upload::Geometry;
use crate::extract::RenderScene;
use radiant_core::{
    Effects, Filter, FilterSampler, GpuLibrary, GpuModule, TextureId, TextureRef, TextureTable,
};

/// Cells per axis of the tabulated filter.
const FILTER_RES: u32 = 64;

/// Words of the header at the start of the parameter buffer (the `H_*`
/// constants of `wgsl/path.wgsl`).
const HEADER_WORDS: usize = 20;

/// One module type of a kind, as the kernel includes it.
#[derive(Debug, Clone, PartialEq)]
pub struct ModuleType {
    /// Identifier in its functions' names.
    pub ident: String,
    /// Its WGSL.
    pub wgsl: String,
    /// Libraries it calls.
    pub requires: &'static [GpuLibrary],
}

/// The module types of one kind in a frame, in order of first use (an
/// instance's type tag is its index here).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KindTypes {
    /// The types.
    pub types: Vec<ModuleType>,
}

impl KindTypes {
    /// The tag of `module`'s type, adding the type where it is new.
    pub(super) fn tag(&mut self, module: &GpuModule) -> u32 {
        match self.types.iter().position(|t| t.ident == module.ident) {
            Some(i) => i as u32,
            None => {
                self.types.push(ModuleType {
                    ident: module.ident.to_string(),
                    wgsl: module.wgsl.to_string(),
                    requires: module.requires,
                });
                self.types.len() as u32 - 1
            }
        }
    }
}

/// The frame's modules in GPU form.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Modules {
    /// The parameter buffer: header, directories, module parameters,
    /// light CDF, filter table.
    pub params: Vec<u32>,
    /// The camera's type.
    pub camera: KindTypes,
    /// The sampler's type.
    pub sampler: KindTypes,
    /// The shader types.
    pub shaders: KindTypes,
    /// The light types.
    pub lights: KindTypes,
    /// The texture types (the built-in `constant` first where used).
    pub textures: KindTypes,
    /// Whether the lights include surface emitters that rays hit.
    pub area_lights: bool,
    /// Whether the lights include lights at infinity that escaped rays
    /// see (their indices follow the light CDF: header word 12 says where,
    /// word 13 how many).
    pub environment: bool,
    /// The medium types (where the scene has media or `null` boundaries).
    pub media: KindTypes,
    /// The phase function types.
    pub phases: KindTypes,
    /// Whether the frame has media or `null` boundaries: the kernel's
    /// medium stage (`wgsl/medium.wgsl`) and the media table (header word
    /// 19, `media.rs`).
    pub has_media: bool,
}

/// The built-in texture type of constant values.
const CONSTANT_TEXTURE: &str =
    "fn texture_constant(p: u32, uv: vec2f) -> vec3f {\n    return param_vec3(p);\n}\n";

impl Modules {
    /// Gathers the modules of `scene`.
    pub fn new(scene: &RenderScene) -> Result<Self, GpuError> {
        if !scene.integrator.gpu() {
            return Err(GpuError::MissingCode {
                kind: "integrator",
                name: String::new(),
                type_name: crate::backend::cpu::integrator_name(scene).into(),
            });
        }
        if scene.settings.adaptive.is_some() {
            return Err(GpuError::MissingCode {
                kind: "sampler option",
                name: "adaptive".into(),
                type_name: "adaptive sampling".into(),
            });
        }
        let mut m = Modules {
            params: vec![0; HEADER_WORDS],
            ..Modules::default()
        };
        let modules = &scene.modules;
        let type_of = |kind: radiant_core::ModuleKind| {
            modules
                .iter()
                .filter(|(k, _)| *k == kind)
                .map(|(_, t)| t.as_str())
                .collect::<Vec<_>>()
                .join(" or ")
        };
        // Camera and sampler: one instance each.
        let camera = scene.camera.gpu().ok_or_else(|| GpuError::MissingCode {
            kind: "camera",
            name: String::new(),
            type_name: type_of(radiant_core::ModuleKind::Camera),
        })?;
        m.camera.tag(&camera);
        m.params[1] = m.push(&camera);
        let sampler = scene.sampler.gpu().ok_or_else(|| GpuError::MissingCode {
            kind: "sampler",
            name: String::new(),
            type_name: type_of(radiant_core::ModuleKind::Sampler),
        })?;
        m.sampler.tag(&sampler);
        m.params[2] = m.push(&sampler);
        m.filter_table(scene.filter.as_ref());
        m.splat_table(scene.filter.as_ref());
        m.materials(scene)?;
        m.textures(&scene.textures, &scene.texture_names)?;
        m.lights(scene)?;
        if super::media::active(scene) {
            super::media::gather(&mut m, scene, &type_of)?;
        }
        Ok(m)
    }

    /// Appends `module`'s parameters; returns their offset.
    pub(super) fn push(&mut self, module: &GpuModule) -> u32 {
        let at = self.params.len() as u32;
        self.params.extend_from_slice(module.params.words());
        at
    }

    /// The filter's [`FilterSampler`] tables: the marginal CDF of the rows,
    /// each row's CDF, then the sign of f per cell.
    fn filter_table(&mut self, filter: &dyn Filter) {
        let sampler = FilterSampler::new(filter, FILTER_RES);
        let d = sampler.distribution();
        // The CDFs without their leading 0, as `filter_sample` reads them.
        let mut table: Vec<f32> = d.marginal().cdf()[1..].to_vec();
        for row in d.rows() {
            table.extend_from_slice(&row.cdf()[1..]);
        }
        table.extend(sampler.values().iter().map(|v| 1.0f32.copysign(*v)));
        self.params[3] = self.params.len() as u32;
        self.params[4] = FILTER_RES;
        self.params[5] = sampler.radius().to_bits();
        self.params[6] = sampler.abs_integral().to_bits();
        self.params.extend(table.iter().map(|v| v.to_bits()));
    }

    /// The filter tabulated for splatting as the CPU's
    /// [`FilterTable`](crate::film::FilterTable) tabulates it: 64×64 values
    /// at cell centres over the quadrant [0, r]² (header words 14–16: where,
    /// cells per pixel, reach in pixels).
    fn splat_table(&mut self, filter: &dyn Filter) {
        let res = 64usize;
        let radius = filter.radius();
        let step = radius / res as f32;
        self.params[14] = self.params.len() as u32;
        self.params[15] = (res as f32 / radius).to_bits();
        self.params[16] = (radius + 0.5).ceil() as u32;
        for y in 0..res {
            for x in 0..res {
                let v = filter.eval((x as f32 + 0.5) * step, (y as f32 + 0.5) * step);
                self.params.push(v.to_bits());
            }
        }
    }

    /// The materials' directory: (type, offset, flags, 0) per material;
    /// flag 1: the shader has smooth lobes (next-event estimation
    /// evaluates it).
    fn materials(&mut self, scene: &RenderScene) -> Result<(), GpuError> {
        let mut entries = Vec::with_capacity(4 * scene.shaders.len());
        for (i, shader) in scene.shaders.iter().enumerate() {
            let module = shader.gpu().ok_or_else(|| GpuError::MissingCode {
                kind: "material",
                name: scene
                    .material_names
                    .get(i)
                    .cloned()
                    .unwrap_or_else(|| format!("#{i}")),
                type_name: scene.material_types.get(i).cloned().unwrap_or_default(),
            })?;
            let tag = self.shaders.tag(&module);
            let at = self.push(&module);
            let smooth = u32::from(shader.effects().contains(Effects::SMOOTH_LOBES));
            entries.extend([tag, at, smooth, 0]);
        }
        self.params[7] = self.params.len() as u32;
        self.params.extend(entries);
        Ok(())
    }

    /// The textures' directory: (type, offset, 0, 0) per texture;
    /// `names` (the named textures) name one without GPU code.
    fn textures(
        &mut self,
        textures: &TextureTable,
        names: &[(TextureId, String, String)],
    ) -> Result<(), GpuError> {
        let constant = GpuModule::new("constant", CONSTANT_TEXTURE, Default::default());
        let mut entries = Vec::with_capacity(4 * textures.len());
        for i in 0..textures.len() as u32 {
            let module = match textures.get(TextureId(i)) {
                TextureRef::Constant(c) => GpuModule {
                    params: radiant_core::GpuParams::new().rgb(c),
                    ..constant.clone()
                },
                TextureRef::Module(t) => t.gpu().ok_or_else(|| {
                    let named = names.iter().find(|(id, ..)| id.0 == i);
                    let (name, type_name) = named.map_or_else(
                        || (format!("#{i}, written inline,"), "unrecorded".into()),
                        |(_, name, ty)| (name.clone(), ty.clone()),
                    );
                    GpuError::MissingCode {
                        kind: "texture",
                        name,
                        type_name,
                    }
                })?,
            };
            let tag = self.textures.tag(&module);
            let at = self.push(&module);
            entries.extend([tag, at, 0, 0]);
        }
        self.params[8] = self.params.len() as u32;
        self.params.extend(entries);
        Ok(())
    }

    /// The lights' directory: (type, offset, delta, probability) per
    /// light, then the CDF of the probabilities, the lights at infinity,
    /// and spatial selection's tables (`light_selection.rs`).
    fn lights(&mut self, scene: &RenderScene) -> Result<(), GpuError> {
        let table = &scene.lights;
        let mut entries = Vec::with_capacity(4 * table.len());
        for (i, light) in table.lights().iter().enumerate() {
            let module = light.gpu().ok_or_else(|| GpuError::MissingCode {
                kind: "light",
                name: format!("#{}", i + 1),
                type_name: scene.light_types.get(i).cloned().unwrap_or_default(),
            })?;
            self.environment |= light.effects().contains(Effects::ENVIRONMENT);
            self.area_lights |= light.effects().contains(Effects::AREA_LIGHTS);
            let tag = self.lights.tag(&module);
            let at = self.push(&module);
            entries.extend([
                tag,
                at,
                u32::from(table.is_delta(i)),
                table.pmf(i).to_bits(),
            ]);
        }
        self.params[9] = self.params.len() as u32;
        self.params[10] = table.len() as u32;
        self.params.extend(entries);
        self.params[11] = self.params.len() as u32;
        let mut acc = 0.0f64;
        for i in 0..table.len() {
            acc += table.pmf(i) as f64;
            let c = if i + 1 == table.len() {
                1.0
            } else {
                acc as f32
            };
            self.params.push(c.to_bits());
        }
        self.params[12] = self.params.len() as u32;
        self.params[13] = table.environment().len() as u32;
        self.params
            .extend(table.environment().iter().map(|&i| i as u32));
        // Spatial selection's tables (header word 18), where it is on.
        if let Some(words) = super::light_selection::words(table, self.params.len()) {
            self.params[18] = self.params.len() as u32;
            self.params.extend(words);
        }
        Ok(())
    }

    /// Writes where `geometry`'s traversal starts and its camera motion
    /// record into the header.
    pub(super) fn locate(&mut self, geometry: &Geometry) {
        self.params[0] = geometry.root;
        self.params[17] = geometry.camera_motion;
    }

    /// The parameter block of a probe ([`super::probe`]): the header and
    /// the texture directory of `textures`, then `module`'s parameters,
    /// whose offset is returned; `module`'s type is listed under `kind`'s
    /// types so that the kernel includes its code.
    pub(super) fn for_probe(
        textures: &TextureTable,
        module: &GpuModule,
        kind: super::probe::ProbeKind,
    ) -> Result<(Self, u32), GpuError> {
        let mut m = Modules {
            params: vec![0; HEADER_WORDS],
            ..Modules::default()
        };
        m.textures(textures, &[])?;
        let at = m.push(module);
        use super::probe::ProbeKind;
        let types = match kind {
            ProbeKind::Camera => &mut m.camera,
            ProbeKind::Sampler => &mut m.sampler,
            ProbeKind::Shader => &mut m.shaders,
            ProbeKind::Light => &mut m.lights,
            ProbeKind::Texture => &mut m.textures,
        };
        types.tag(module);
        Ok((m, at))
    }

    /// Every module type in use, by kind, for `radiant info`.
    pub fn summary(&self) -> Vec<(&'static str, Vec<&str>)> {
        fn names(k: &KindTypes) -> Vec<&str> {
            k.types.iter().map(|t| t.ident.as_str()).collect()
        }
        vec![
            ("camera", names(&self.camera)),
            ("sampler", names(&self.sampler)),
            ("shaders", names(&self.shaders)),
            ("textures", names(&self.textures)),
            ("lights", names(&self.lights)),
            ("media", names(&self.media)),
            ("phases", names(&self.phases)),
        ]
    }
}

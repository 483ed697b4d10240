//! Extract of participating media: builds the scene's media and their
//! phase functions through the registry, and lays out per material
//! whether it is a medium interface (interior, exterior) and whether it is
//! an index-matched `null` boundary, for the path integrator's medium
//! stage (`integrators/medium.rs`).
//!
//! Media are built once per sequence (their parameters are not animated),
//! in render space (`render_origin`), which is fixed for a sequence.

use crate::error::{SceneError, module_error};
use crate::scene::media::NO_MEDIUM;
use crate::world::{ModuleSpec, Scene};
use radiant_core::{
    BuildContext, Coefficients, Effects, Medium, ModuleKind, Phase, Registry, Shader, TextureTable,
};
use std::collections::{BTreeSet, HashMap};

/// The render data of the scene's media.
pub struct MediaTable {
    /// Coefficients per medium (where its density is 1).
    pub coefficients: Vec<Coefficients>,
    /// The media, whose [`Medium::profile`] says how the density varies.
    pub media: Vec<Box<dyn Medium>>,
    /// Phase function per medium.
    pub phases: Vec<Box<dyn Phase>>,
    /// Medium names, for messages.
    pub names: Vec<String>,
    /// The medium camera rays start in ([`NO_MEDIUM`]: vacuum).
    pub camera: u32,
    /// Per material: the media behind and in front of its surfaces
    /// ([interior, exterior], exterior on the side the geometric normal
    /// points to), or `None` where the material bounds no medium (rays
    /// crossing it stay in their medium).
    pub interfaces: Vec<Option<[u32; 2]>>,
    /// Per material: whether it is an index-matched `null` boundary.
    pub null: Vec<bool>,
}

impl MediaTable {
    /// Whether any medium is in use (the [`Effects::MEDIA`] bit).
    pub fn in_use(&self) -> bool {
        self.camera != NO_MEDIUM || self.interfaces.iter().any(Option::is_some)
    }

    /// The medium a ray enters leaving a surface of `material` in
    /// direction `d` (geometric normal `ng`), coming from `current`.
    #[inline]
    pub fn after_crossing(&self, material: u32, current: u32, d_dot_ng: f32) -> u32 {
        match self.interfaces[material as usize] {
            Some([inside, outside]) => {
                if d_dot_ng > 0.0 {
                    outside
                } else {
                    inside
                }
            }
            None => current,
        }
    }

    /// Builds the media of `scene`.
    pub(super) fn build(
        scene: &Scene,
        registry: &Registry,
        render_origin: glam::DVec3,
        shaders: &[Box<dyn Shader>],
        modules: &mut BTreeSet<(ModuleKind, String)>,
    ) -> Result<Self, SceneError> {
        let media = &scene.media;
        let mut textures = TextureTable::default();
        let names = HashMap::new();
        let mut ctx = BuildContext::standalone(&scene.dir, &mut textures, &names);
        ctx.render_origin = render_origin;
        let located = |spec: &ModuleSpec, e| module_error(&scene.file, spec, e);
        let mut coefficients = Vec::with_capacity(media.media.len());
        let mut built = Vec::with_capacity(media.media.len());
        let mut phases = Vec::with_capacity(media.media.len());
        let isotropic = crate::scene::default_module("isotropic");
        for m in &media.media {
            let medium = registry
                .build::<dyn Medium>(&m.spec.type_name, &m.spec.params, &mut ctx)
                .map_err(|e| located(&m.spec, e))?;
            coefficients.push(medium.coefficients());
            built.push(medium);
            modules.insert((ModuleKind::Medium, m.spec.type_name.clone()));
            let spec = m.phase.as_ref().unwrap_or(&isotropic);
            let phase = registry
                .build::<dyn Phase>(&spec.type_name, &spec.params, &mut ctx)
                .map_err(|e| located(spec, e))?;
            modules.insert((ModuleKind::Phase, spec.type_name.clone()));
            phases.push(phase);
        }
        let mut interfaces = vec![None; shaders.len()];
        for &(material, sides) in &media.interfaces {
            interfaces[material as usize] = Some(sides);
        }
        Ok(Self {
            coefficients,
            media: built,
            phases,
            names: media.media.iter().map(|m| m.name.clone()).collect(),
            camera: media.camera,
            interfaces,
            null: shaders
                .iter()
                .map(|s| s.effects().contains(Effects::NULL_INTERFACE))
                .collect(),
        })
    }
}

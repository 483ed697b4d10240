//! Participating media on the GPU: the frame's media and phase functions
//! gathered into the parameter buffer, the table the kernel's medium
//! stage (`wgsl/medium.wgsl`) reads, and the dispatchers it calls.
//!
//! Only frames whose effects contain [`Effects::MEDIA`] or
//! [`Effects::NULL_INTERFACE`] get any of it; others' kernels have no
//! medium code at all. The media table (header word 19, `H_MEDIA`):
//!
//! ```text
//! T + 0        the camera's medium (NO_MEDIUM: vacuum)
//! T + 1        where the media directory starts
//! T + 4 + 4·k  material k: flags (1: bounds media, 2: `null`), interior, exterior, 0
//! D + 4·m      medium m: medium type, parameter offset, phase type, parameter offset
//! ```
//!
//! Medium events reach the surface dispatchers as materials numbered from
//! `MEDIUM_EVENT` on (one per medium), which the generated `bsdf_sample`,
//! `bsdf_eval` and `material_has_smooth_lobes` send to the medium's phase
//! function: next-event estimation and the continuation are then the
//! surfaces' own code (`wgsl/path.wgsl`), as on the CPU, where events are
//! sorted after the materials.

use super::error::GpuError;
use super::kernel::{dispatcher, tagged};
use super::modules::Modules;
use crate::extract::RenderScene;
use radiant_core::{Effects, ModuleKind};
use std::fmt::Write;

/// The media table's header word.
const H_MEDIA: usize = 19;

/// Whether the frame runs the medium stage: media, or `null` boundaries
/// that shadow rays pass (as `integrators/medium.rs` decides).
pub fn active(scene: &RenderScene) -> bool {
    scene
        .effects
        .intersects(Effects::MEDIA | Effects::NULL_INTERFACE)
}

/// Adds the media table and the media's and phase functions' parameters
/// of `scene` to `m`; `type_of` names a kind's types for a missing-code
/// error.
pub(super) fn gather(
    m: &mut Modules,
    scene: &RenderScene,
    type_of: &dyn Fn(ModuleKind) -> String,
) -> Result<(), GpuError> {
    let media = &scene.media;
    m.has_media = true;
    let mut directory = Vec::with_capacity(4 * media.media.len());
    for (i, (medium, phase)) in media.media.iter().zip(&media.phases).enumerate() {
        let name = || media.names.get(i).cloned().unwrap_or_default();
        let module = medium.gpu().ok_or_else(|| GpuError::MissingCode {
            kind: "medium",
            name: name(),
            type_name: type_of(ModuleKind::Medium),
        })?;
        let phase = phase.gpu().ok_or_else(|| GpuError::MissingCode {
            kind: "phase function of medium",
            name: name(),
            type_name: type_of(ModuleKind::Phase),
        })?;
        directory.extend([
            m.media.tag(&module),
            m.push(&module),
            m.phases.tag(&phase),
            m.push(&phase),
        ]);
    }
    let table = m.params.len();
    m.params[H_MEDIA] = table as u32;
    m.params.extend([media.camera, 0, 0, 0]);
    for (interface, null) in media.interfaces.iter().zip(&media.null) {
        let [inside, outside] = interface.unwrap_or([0, 0]);
        let flags = u32::from(interface.is_some()) | (u32::from(*null) << 1);
        m.params.extend([flags, inside, outside, 0]);
    }
    m.params[table + 1] = m.params.len() as u32;
    m.params.extend(directory);
    Ok(())
}

/// The dispatchers of the medium stage: `medium_flight`,
/// `medium_transmittance`, `phase_sample`, `phase_eval` (by the media
/// directory), and `bsdf_sample`, `bsdf_eval`, `material_has_smooth_lobes`
/// that send medium events to the phase functions and surfaces to
/// `surface_*` (the materials' own dispatchers, renamed).
pub(super) fn dispatchers(m: &Modules, s: &mut String) {
    let medium = "vec2u(media_word(m, 0u), media_word(m, 1u))";
    let phase = "vec2u(media_word(m, 2u), media_word(m, 3u))";
    let _ = writeln!(s, "const H_MEDIA: u32 = {H_MEDIA}u;\n");
    let _ = writeln!(
        s,
        "fn media_word(m: u32, i: u32) -> u32 {{\n    return param_u32(param_u32(param_u32(H_MEDIA) + 1u) + 4u * m + i);\n}}\n"
    );
    let media = tagged(&m.media);
    let phases = tagged(&m.phases);
    if media.is_empty() {
        // `null` boundaries without media: no path is ever in a medium.
        s.push_str(
            "fn medium_flight(m: u32, o: vec3f, d: vec3f, t_max: f32, beta: vec3f, u: vec2f, rng: ptr<function, Stream>) -> MediumFlight {\n    return MediumFlight(t_max, false, beta, vec3f(0.0));\n}\n\n\
             fn medium_transmittance(m: u32, o: vec3f, d: vec3f, t_max: f32, rng: ptr<function, Stream>) -> vec3f {\n    return vec3f(1.0);\n}\n\n\
             fn phase_sample(m: u32, wo: vec3f, u: vec2f) -> BsdfSample {\n    return bsdf_sample_failed();\n}\n\n\
             fn phase_eval(m: u32, wo: vec3f, wi: vec3f) -> BsdfEval {\n    return bsdf_eval_zero();\n}\n\n",
        );
    } else {
        dispatcher(
            s,
            "medium_flight(m: u32, o: vec3f, d: vec3f, t_max: f32, beta: vec3f, u: vec2f, rng: ptr<function, Stream>) -> MediumFlight",
            medium,
            "medium_flight",
            ", o, d, t_max, beta, u, rng",
            &media,
        );
        dispatcher(
            s,
            "medium_transmittance(m: u32, o: vec3f, d: vec3f, t_max: f32, rng: ptr<function, Stream>) -> vec3f",
            medium,
            "medium_transmittance",
            ", o, d, t_max, rng",
            &media,
        );
        dispatcher(
            s,
            "phase_sample(m: u32, wo: vec3f, u: vec2f) -> BsdfSample",
            phase,
            "phase_sample",
            ", wo, u",
            &phases,
        );
        dispatcher(
            s,
            "phase_eval(m: u32, wo: vec3f, wi: vec3f) -> BsdfEval",
            phase,
            "phase_eval",
            ", wo, wi",
            &phases,
        );
    }
    s.push_str(
        "fn bsdf_sample(m: u32, s: ShadingPoint, u: vec3f) -> BsdfSample {\n    if m >= MEDIUM_EVENT {\n        return phase_sample(m - MEDIUM_EVENT, s.wo, u.yz);\n    }\n    return surface_bsdf_sample(m, s, u);\n}\n\n\
         fn bsdf_eval(m: u32, s: ShadingPoint, wi: vec3f) -> BsdfEval {\n    if m >= MEDIUM_EVENT {\n        return phase_eval(m - MEDIUM_EVENT, s.wo, wi);\n    }\n    return surface_bsdf_eval(m, s, wi);\n}\n\n\
         fn material_has_smooth_lobes(m: u32) -> bool {\n    return m >= MEDIUM_EVENT || surface_has_smooth_lobes(m);\n}\n\n",
    );
}

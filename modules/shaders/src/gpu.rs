//! The shaders' GPU sides: WGSL shared by several types (GGX and Fresnel
//! terms, the lobes of [`crate::lobes`], scalar inputs), and the code of
//! every built-in shader type.
//!
//! Each built-in type's functions (`bsdf_sample_T`, `bsdf_eval_T` and its
//! helpers) are a library named after the type, and the type's module
//! carries only a comment as its own WGSL ([`module`]). A kernel then holds
//! a type's code once whether the type is used as a material, inside a
//! `blend`, or both, and a blend calls its parts' functions directly (WGSL
//! forbids recursion, so a blend cannot go through the kernel's generic
//! `bsdf_sample` dispatcher, which would call the blend again).

use radiant_core::{GpuLibrary, GpuModule, GpuParams};
use std::sync::Mutex;

/// Scalar texture inputs, luminance, glam's `try_normalize`.
pub(crate) const COMMON: GpuLibrary = GpuLibrary {
    name: "shaders::common",
    wgsl: include_str!("gpu/common.wgsl"),
    requires: &[],
};

/// GGX distribution, masking and visible-normal sampling.
pub(crate) const MICROFACET: GpuLibrary = GpuLibrary {
    name: "shaders::microfacet",
    wgsl: include_str!("gpu/microfacet.wgsl"),
    requires: &[],
};

/// Conductor, dielectric and Schlick Fresnel reflectance.
pub(crate) const FRESNEL: GpuLibrary = GpuLibrary {
    name: "shaders::fresnel",
    wgsl: include_str!("gpu/fresnel.wgsl"),
    requires: &[],
};

/// GGX reflection without Fresnel and the rough dielectric interface
/// ([`crate::lobes`]).
pub(crate) const LOBES: GpuLibrary = GpuLibrary {
    name: "shaders::lobes",
    wgsl: include_str!("gpu/lobes.wgsl"),
    requires: &[COMMON, MICROFACET, FRESNEL],
};

/// What `ward` and `ashikhmin_shirley` share (`half_vector.rs`).
pub(crate) const HALF_VECTOR: GpuLibrary = GpuLibrary {
    name: "shaders::half_vector",
    wgsl: include_str!("gpu/half_vector.wgsl"),
    requires: &[COMMON],
};

/// The library `name` (`shaders::<type>`) of a built-in shader type's
/// code (`src/<type>.wgsl`), calling `requires`.
const fn type_code(
    name: &'static str,
    wgsl: &'static str,
    requires: &'static [GpuLibrary],
) -> GpuLibrary {
    GpuLibrary {
        name,
        wgsl,
        requires,
    }
}

/// `diffuse`.
pub(crate) const DIFFUSE: GpuLibrary =
    type_code("shaders::diffuse", include_str!("diffuse.wgsl"), &[]);

/// `rough_diffuse`.
pub(crate) const ROUGH_DIFFUSE: GpuLibrary = type_code(
    "shaders::rough_diffuse",
    include_str!("rough_diffuse.wgsl"),
    &[COMMON],
);

/// `conductor`.
pub(crate) const CONDUCTOR: GpuLibrary = type_code(
    "shaders::conductor",
    include_str!("conductor.wgsl"),
    &[COMMON, MICROFACET, FRESNEL],
);

/// `dielectric`.
pub(crate) const DIELECTRIC: GpuLibrary = type_code(
    "shaders::dielectric",
    include_str!("dielectric.wgsl"),
    &[LOBES],
);

/// `thin_dielectric`.
pub(crate) const THIN_DIELECTRIC: GpuLibrary = type_code(
    "shaders::thin_dielectric",
    include_str!("thin_dielectric.wgsl"),
    &[FRESNEL],
);

/// `plastic`.
pub(crate) const PLASTIC: GpuLibrary =
    type_code("shaders::plastic", include_str!("plastic.wgsl"), &[LOBES]);

/// `principled`.
pub(crate) const PRINCIPLED: GpuLibrary = type_code(
    "shaders::principled",
    include_str!("principled.wgsl"),
    &[LOBES],
);

/// `ward`.
pub(crate) const WARD: GpuLibrary =
    type_code("shaders::ward", include_str!("ward.wgsl"), &[HALF_VECTOR]);

/// `ashikhmin_shirley`.
pub(crate) const ASHIKHMIN_SHIRLEY: GpuLibrary = type_code(
    "shaders::ashikhmin_shirley",
    include_str!("ashikhmin_shirley.wgsl"),
    &[FRESNEL, HALF_VECTOR],
);

/// The own WGSL of a built-in type's module: its code is in its library.
/// (It names no function, which is how `blend` tells such a type from one
/// whose code is its module's own.)
pub(crate) const CODE_IN_LIBRARY: &str =
    "// This type's code is the library named after it (shaders::<type>).\n";

/// The GPU side of an instance of the built-in type `ident`, whose code is
/// the library `code` (one of the constants above).
pub(crate) fn module(
    ident: &'static str,
    code: &'static [GpuLibrary],
    params: GpuParams,
) -> GpuModule {
    GpuModule::new(ident, CODE_IN_LIBRARY, params).with_libraries(code)
}

/// `libraries` (sorted by name, each once) as a `'static` slice, for a
/// module whose libraries are only known from its parts (`blend`). Each
/// distinct set is allocated once and kept for the process's lifetime:
/// there are finitely many sets of (static) libraries, so this is bounded.
pub(crate) fn interned(libraries: &[GpuLibrary]) -> &'static [GpuLibrary] {
    static SETS: Mutex<Vec<&'static [GpuLibrary]>> = Mutex::new(Vec::new());
    let mut set: Vec<GpuLibrary> = Vec::with_capacity(libraries.len());
    for lib in libraries {
        if !set.iter().any(|l| l.name == lib.name) {
            set.push(*lib);
        }
    }
    set.sort_by_key(|l| l.name);
    // A panic elsewhere while holding the lock leaves a usable list.
    let mut sets = SETS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(known) = sets.iter().find(|s| **s == set.as_slice()) {
        return known;
    }
    let leaked: &'static [GpuLibrary] = Box::leak(set.into_boxed_slice());
    sets.push(leaked);
    leaked
}

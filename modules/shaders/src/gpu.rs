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
use std::borrow::Cow;
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

/// What `normal_map` and `bump` share (`perturb.rs`).
pub(crate) const PERTURB: GpuLibrary = GpuLibrary {
    name: "shaders::perturb",
    wgsl: include_str!("gpu/perturb.wgsl"),
    requires: &[COMMON],
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

/// The start of every blend's GPU identifier.
pub(crate) const BLEND_PREFIX: &str = "blend_";

/// The start of every `normal_map`'s and `bump`'s GPU identifier.
pub(crate) const PERTURBED_PREFIX: &str = "perturbed_";

/// The WGSL of a composite type (a `blend`, a `normal_map`, a `bump`):
/// code made from templates per combination of its parts' types, calling
/// their functions directly (WGSL forbids the recursion a call through the
/// kernel's `bsdf_sample` dispatcher would be). Every name in a
/// composite's code contains its identifier, so that one identifier always
/// means the same code and a composite nested in another can be included
/// renamed.
pub(crate) struct Composite {
    ident: String,
    wgsl: String,
    libraries: Vec<GpuLibrary>,
}

impl Composite {
    /// A composite named `ident` whose templates call `libraries`.
    pub(crate) fn new(ident: String, libraries: &[GpuLibrary]) -> Self {
        Self {
            ident,
            wgsl: String::new(),
            libraries: libraries.to_vec(),
        }
    }

    /// Adds the part `part` and returns the identifier its functions are
    /// called by: its own where its code is in libraries (every built-in
    /// type's), `<this identifier><suffix>` where it is a composite, whose
    /// code is included renamed; `None` for a type whose code is its
    /// module's own (an outside crate's), which cannot be renamed safely.
    pub(crate) fn part(&mut self, part: &GpuModule, suffix: &str) -> Option<String> {
        self.libraries.extend_from_slice(part.requires);
        if !part.wgsl.contains("fn ") {
            return Some(part.ident.to_string());
        }
        let composite = [BLEND_PREFIX, PERTURBED_PREFIX]
            .iter()
            .any(|prefix| part.ident.starts_with(prefix));
        if !composite {
            return None;
        }
        let renamed = format!("{}{suffix}", self.ident);
        self.wgsl += &part.wgsl.replace(&*part.ident, &renamed);
        Some(renamed)
    }

    /// Adds the code of `template` (its header comment, up to the first
    /// blank line, left out) with `$SELF` and each `(from, to)` of
    /// `names` replaced.
    pub(crate) fn template(&mut self, template: &str, names: &[(&str, &str)]) {
        let mut code = template
            .split_once("\n\n")
            .map_or(template, |(_header, code)| code)
            .replace("$SELF", &self.ident);
        for (from, to) in names {
            code = code.replace(from, to);
        }
        self.wgsl += &code;
    }

    /// The module with the composite's code and `params`.
    pub(crate) fn finish(self, params: GpuParams) -> GpuModule {
        GpuModule {
            requires: interned(&self.libraries),
            ident: Cow::Owned(self.ident),
            wgsl: Cow::Owned(self.wgsl),
            params,
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Parts whose code is in libraries are called by their own names,
    /// composites' code is included renamed, and a type whose code is its
    /// module's own (an outside crate's) cannot be a part.
    #[test]
    fn composites_take_library_and_composite_parts_only() {
        let mut code = Composite::new("blend_3_abc_def".into(), &[COMMON]);
        let library = module("diffuse", &[DIFFUSE], GpuParams::new());
        assert_eq!(code.part(&library, "__a").as_deref(), Some("diffuse"));
        let nested = GpuModule {
            ident: Cow::Borrowed("blend_1_x_y"),
            wgsl: Cow::Borrowed("fn bsdf_eval_blend_1_x_y() {}\n"),
            requires: &[],
            params: GpuParams::new(),
        };
        assert_eq!(
            code.part(&nested, "__b").as_deref(),
            Some("blend_3_abc_def__b")
        );
        let outside = GpuModule::new("stripes", "fn bsdf_eval_stripes() {}\n", GpuParams::new());
        assert_eq!(code.part(&outside, "__c"), None);
        code.template(
            "// header\n\nfn f_$SELF() { g_$A(); }\n",
            &[("$A", "diffuse")],
        );
        let m = code.finish(GpuParams::new());
        assert_eq!(
            m.wgsl,
            "fn bsdf_eval_blend_3_abc_def__b() {}\nfn f_blend_3_abc_def() { g_diffuse(); }\n"
        );
        let names: Vec<_> = m.requires.iter().map(|l| l.name).collect();
        assert_eq!(names, ["shaders::common", "shaders::diffuse"]);
    }
}

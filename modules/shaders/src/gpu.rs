//! WGSL shared by the shaders' GPU sides: GGX and Fresnel terms, as
//! [`crate::microfacet`] and the Fresnel module compute them on the CPU.

use radiant_core::GpuLibrary;

/// GGX distribution, masking and visible-normal sampling.
pub(crate) const MICROFACET: GpuLibrary = GpuLibrary {
    name: "shaders::microfacet",
    wgsl: include_str!("gpu/microfacet.wgsl"),
    requires: &[],
};

/// Conductor and dielectric Fresnel reflectance.
pub(crate) const FRESNEL: GpuLibrary = GpuLibrary {
    name: "shaders::fresnel",
    wgsl: include_str!("gpu/fresnel.wgsl"),
    requires: &[],
};

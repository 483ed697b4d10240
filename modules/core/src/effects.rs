//! Light-transport features a scene calls for.
//!
//! Every module instance declares the [`Effects`] it needs; the engine's
//! extract step unions them into the scene's effect set and compiles only the
//! integrator paths those effects require.

use bitflags::bitflags;

bitflags! {
    /// A set of light-transport features.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
    pub struct Effects: u32 {
        /// Emitters on surfaces that rays can hit (area lights).
        const AREA_LIGHTS = 1 << 0;
        /// Lights with a delta distribution (point, spot, directional).
        const DELTA_LIGHTS = 1 << 1;
        /// Light arriving from infinitely far away (environment maps).
        const ENVIRONMENT = 1 << 2;
        /// Textures that vary over a surface (anything but constants).
        const TEXTURES = 1 << 3;
        /// Smooth (non-delta) reflection lobes: diffuse or glossy.
        const SMOOTH_LOBES = 1 << 4;
        /// Glossy (microfacet) lobes.
        const GLOSSY = 1 << 5;
        /// Perfectly specular (delta) lobes.
        const DELTA_LOBES = 1 << 6;
        /// Transmission through surfaces.
        const TRANSMISSION = 1 << 7;
        /// A camera with a finite aperture.
        const DEPTH_OF_FIELD = 1 << 8;
        /// Geometry or the camera moving while the shutter is open: rays
        /// carry a time (set by the engine, not by modules).
        const MOTION_BLUR = 1 << 9;
        /// A shader whose response depends on the direction of the shading
        /// frame's tangent or on ∂p/∂u and ∂p/∂v (anisotropic lobes, normal
        /// and bump maps): hits orient their frames by the texture
        /// parametrisation and shaders receive the derivatives.
        const TANGENT_FRAMES = 1 << 10;
        /// Participating media: paths sample distances in media and shadow
        /// rays carry a transmittance (set by the engine where a shape or
        /// the camera names a medium).
        const MEDIA = 1 << 11;
        /// An index-matched boundary (the `null` material) that rays pass
        /// straight through, shadow rays included.
        const NULL_INTERFACE = 1 << 12;
    }
}

impl Effects {
    /// Human-readable names of the effects in this set, in declaration order.
    pub fn names(self) -> Vec<&'static str> {
        self.iter_names().map(|(name, _)| name).collect()
    }
}

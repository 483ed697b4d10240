//! An outside module crate: how a user adds their own module to Radiant.
//!
//! It defines a `stripes` texture and registers it through the same
//! `register(&mut Registry)` call the built-in modules use. A program that
//! wants it builds its registry as
//!
//! ```
//! let mut registry = radiant::builtin_registry();
//! radiant_example_module::register(&mut registry);
//! ```
//!
//! and scenes can then say `type: stripes` (and `integrator: {type:
//! directions}`, an example integrator: [`directions`]). The texture also
//! has a GPU side (`Texture::gpu`): its WGSL, `stripes.wgsl`, and its
//! parameters packed as words, so scenes that use it render with
//! `--backend gpu` too.

pub mod directions;

use radiant::core::glam::Vec2;
use radiant::core::{
    Color, Effects, GpuModule, GpuParams, ModuleInfo, ParamDoc, Params, Registry, Rgb, Texture,
};
use serde::Deserialize;

/// Alternating stripes along the surface's u coordinate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stripes {
    a: Rgb,
    b: Rgb,
    count: f32,
}

impl Texture for Stripes {
    fn eval(&self, uv: &[Vec2], out: &mut [Rgb]) {
        for (uv, o) in uv.iter().zip(out.iter_mut()) {
            let stripe = (uv.x * self.count).floor() as i64;
            *o = if stripe.rem_euclid(2) == 0 {
                self.a
            } else {
                self.b
            };
        }
    }

    fn mean(&self) -> Rgb {
        (self.a + self.b) * 0.5
    }

    fn effects(&self) -> Effects {
        Effects::TEXTURES
    }

    /// `texture_stripes` in `stripes.wgsl`, reading a, b and count.
    fn gpu(&self) -> Option<GpuModule> {
        let params = GpuParams::new().rgb(self.a).rgb(self.b).f32(self.count);
        Some(GpuModule::new(
            "stripes",
            include_str!("stripes.wgsl"),
            params,
        ))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StripesParams {
    a: Color,
    b: Color,
    #[serde(default = "two")]
    count: f32,
}

fn two() -> f32 {
    2.0
}

const DOCS: &[ParamDoc] = &[
    ParamDoc {
        name: "a",
        ty: "rgb",
        default: "required",
        doc: "Colour of even stripes.",
    },
    ParamDoc {
        name: "b",
        ty: "rgb",
        default: "required",
        doc: "Colour of odd stripes.",
    },
    ParamDoc {
        name: "count",
        ty: "number",
        default: "2",
        doc: "Stripes across u ∈ [0, 1].",
    },
];

/// Registers the `stripes` texture and the `directions` integrator.
pub fn register(registry: &mut Registry) {
    directions::register(registry);
    registry.register::<dyn Texture>(
        ModuleInfo {
            type_name: "stripes",
            summary: "Stripes along u (an example outside module).",
            params: DOCS,
        },
        |params: &Params, _| {
            let p: StripesParams = params.parse()?;
            Ok(Box::new(Stripes {
                a: p.a.0,
                b: p.b.0,
                count: p.count,
            }) as Box<dyn Texture>)
        },
    );
}

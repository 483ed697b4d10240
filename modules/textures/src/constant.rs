//! The `constant` texture: one value everywhere (inline values in a scene
//! become constants without any module).

use radiant_core::glam::Vec2;
use radiant_core::{
    Color, Effects, GpuModule, GpuParams, ModuleInfo, ParamDoc, Params, Registry, Rgb, Texture,
};
use serde::Deserialize;

/// A texture with the same value everywhere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Constant {
    value: Rgb,
}

impl Texture for Constant {
    fn eval(&self, uv: &[Vec2], out: &mut [Rgb]) {
        out[..uv.len()].fill(self.value);
    }

    fn constant(&self) -> Option<Rgb> {
        Some(self.value)
    }

    fn mean(&self) -> Rgb {
        self.value
    }

    fn effects(&self) -> Effects {
        Effects::empty()
    }

    /// The engine's own constant type (a table holds constants as values,
    /// so this is only asked of an instance held elsewhere): its value.
    fn gpu(&self) -> Option<GpuModule> {
        Some(GpuModule::new(
            "constant",
            "fn texture_constant(p: u32, uv: vec2f) -> vec3f {\n    return param_vec3(p);\n}\n",
            GpuParams::new().rgb(self.value),
        ))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConstantParams {
    value: Color,
}

const CONSTANT_DOCS: &[ParamDoc] = &[ParamDoc {
    name: "value",
    ty: "rgb | number",
    default: "required",
    doc: "The value everywhere.",
}];

pub(crate) fn register(registry: &mut Registry) {
    registry.register::<dyn Texture>(
        ModuleInfo {
            type_name: "constant",
            summary: "The same value everywhere.",
            params: CONSTANT_DOCS,
        },
        |params: &Params, _| {
            let p: ConstantParams = params.parse()?;
            Ok(Box::new(Constant { value: p.value.0 }) as Box<dyn Texture>)
        },
    );
}

#[cfg(test)]
mod tests {
    // `unwrap` in this test code is the assertion: the inputs are the test's
    // own, so a failure is a bug, and the panic reports it with the error.
    use super::*;
    use radiant_core::params::check_param_docs;

    #[test]
    fn documented_parameters_match() {
        check_param_docs::<ConstantParams>(CONSTANT_DOCS).unwrap();
    }

    #[test]
    fn constant_is_constant() {
        let t = Constant {
            value: Rgb::new(0.1, 0.2, 0.3),
        };
        let mut out = [Rgb::ZERO; 3];
        t.eval(&[Vec2::ZERO, Vec2::ONE, Vec2::splat(0.5)], &mut out);
        assert!(out.iter().all(|&c| c == Rgb::new(0.1, 0.2, 0.3)));
        assert_eq!(t.constant(), Some(t.value));
    }
}

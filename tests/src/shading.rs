//! Shaders under test: built from YAML through the built-in registry,
//! exactly as a scene builds them (with two test textures and inline
//! nested materials), evaluated one direction at a time; and the zoom map
//! that lets the chi-square test resolve very narrow lobes.
//!
//! Shaders that ask for [`Effects::TANGENT_FRAMES`] get surface
//! derivatives [`DP_DU`] and [`DP_DV`] that are neither unit, orthogonal
//! to each other, nor in the tangent plane, as on a curved, sheared
//! parametrization, so that the sampling and energy tests exercise the
//! frames that wrappers build from them.

use glam::{DVec3, UVec2, Vec2, Vec3};
use radiant_core::registry::Registry;
use radiant_core::{
    BsdfEval, BsdfSample, BuildContext, Effects, Frame, MaterialSource, ParamError, Params, Rgb,
    ShadeContext, Shader, SurfaceBatch, Texture, TextureTable,
};
use std::collections::HashMap;
use std::path::Path;

/// The texture coordinates every test point has.
pub const UV: Vec2 = Vec2::new(0.3, 0.6);

/// ∂p/∂u of every test point (local frame), for shaders with
/// [`Effects::TANGENT_FRAMES`].
pub const DP_DU: Vec3 = Vec3::new(-1.1, 1.3, 0.4);

/// ∂p/∂v likewise.
pub const DP_DV: Vec3 = Vec3::new(-0.5, -0.2, -0.15);

/// A smooth height field, h = 0.3 sin(6u) + 0.2 v, named `ramp` in tests
/// (for `bump`).
struct Ramp;

impl Texture for Ramp {
    fn eval(&self, uv: &[Vec2], out: &mut [Rgb]) {
        for (o, uv) in out.iter_mut().zip(uv) {
            *o = Rgb::splat(0.3 * (6.0 * uv.x).sin() + 0.2 * uv.y);
        }
    }

    fn mean(&self) -> Rgb {
        Rgb::splat(0.1)
    }
}

/// Builds nested materials given inline (`{type: …, …}`).
struct Inline<'r>(&'r Registry);

fn split_type(node: &marked_yaml::Node) -> Result<(String, Params), ParamError> {
    let map = node
        .as_mapping()
        .ok_or_else(|| ParamError::at(node.span(), "tests nest materials inline"))?;
    let ty = map
        .get_scalar("type")
        .ok_or_else(|| ParamError::at(node.span(), "the material needs a `type`"))?
        .as_str()
        .to_string();
    let mut rest = marked_yaml::types::MarkedMappingNode::new_empty(*node.span());
    for (k, v) in map.iter() {
        if k.as_str() != "type" {
            rest.insert(k.clone(), v.clone());
        }
    }
    Ok((ty, Params::new(marked_yaml::Node::Mapping(rest))))
}

impl MaterialSource for Inline<'_> {
    fn build_material(
        &self,
        node: &marked_yaml::Node,
        ctx: &mut BuildContext<'_>,
    ) -> Result<Box<dyn Shader>, ParamError> {
        let (ty, params) = split_type(node)?;
        self.0
            .build::<dyn Shader>(&ty, &params, ctx)
            .map_err(|e| ParamError::new(e.to_string()))
    }
}

/// A shader and the textures it reads.
pub struct TestShader {
    /// The scene's texture table.
    pub textures: TextureTable,
    /// The shader.
    pub shader: Box<dyn Shader>,
}

/// Builds the shader `yaml` (a mapping with a `type`), or the error a scene
/// would report.
pub fn build(yaml: &str) -> Result<TestShader, ParamError> {
    let registry = radiant::builtin_registry();
    let mut textures = TextureTable::default();
    let mut named = HashMap::new();
    named.insert("ramp".to_string(), textures.add(Box::new(Ramp)));
    named.insert(
        "tilt".to_string(),
        textures.add_constant(Rgb::new(0.75, 0.4, 0.85)),
    );
    let node = Params::from_yaml(yaml)?;
    let (ty, params) = split_type(node.node())?;
    let source = Inline(&registry);
    let mut ctx = BuildContext::standalone(Path::new("."), &mut textures, &named);
    ctx.resolution = UVec2::ONE;
    ctx.materials = Some(&source);
    let shader = registry
        .build::<dyn Shader>(&ty, &params, &mut ctx)
        .map_err(|e| match e {
            radiant_core::registry::BuildError::Params(p) => p,
            other => ParamError::new(other.to_string()),
        })?;
    Ok(TestShader { textures, shader })
}

/// Builds a shader that must be valid.
pub fn shader(yaml: &str) -> TestShader {
    build(yaml).unwrap_or_else(|e| panic!("{yaml}: {e}"))
}

impl TestShader {
    /// Samples the shader once per `u`, all at outgoing direction `wo`.
    pub fn sample(&self, wo: Vec3, u: &[Vec3]) -> Vec<BsdfSample> {
        let n = u.len();
        let wos = vec![wo; n];
        let uvs = vec![UV; n];
        let mut out = vec![BsdfSample::default(); n];
        let (du, dv) = (vec![DP_DU; n], vec![DP_DV; n]);
        let mut ctx = ShadeContext::new(&self.textures);
        let surface = self.surface(&wos, &uvs, &du, &dv);
        self.shader.sample(&mut ctx, surface, u, &mut out);
        out
    }

    /// Evaluates the shader for one pair of directions.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> BsdfEval {
        let mut out = [BsdfEval::default()];
        let mut ctx = ShadeContext::new(&self.textures);
        let wo = [wo];
        let surface = self.surface(&wo, &[UV], &[DP_DU], &[DP_DV]);
        self.shader.eval(&mut ctx, surface, &[wi], &mut out);
        out[0]
    }

    /// The batch of points seen from `wo` at `uv`, with the derivatives
    /// where the shader asks for them.
    fn surface<'a>(
        &self,
        wo: &'a [Vec3],
        uv: &'a [Vec2],
        dp_du: &'a [Vec3],
        dp_dv: &'a [Vec3],
    ) -> SurfaceBatch<'a> {
        if self.shader.effects().contains(Effects::TANGENT_FRAMES) {
            SurfaceBatch {
                wo,
                uv,
                dp_du,
                dp_dv,
            }
        } else {
            SurfaceBatch::new(wo, uv)
        }
    }
}

/// The direction at polar cosine `cos` and azimuth `phi`.
pub fn direction(cos: f32, phi: f32) -> Vec3 {
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)
}

/// A bijection of the sphere that magnifies the neighbourhood of a
/// direction: with u = (1 − cos θ)/2 measured from `centre`, u′ =
/// ln(1 + u/ε)/ln(1 + 1/ε), azimuth kept. A lobe of angular width ~√ε
/// then spreads over the whole sphere, so a chi-square grid resolves it;
/// densities transform by the Jacobian du′/du.
pub struct Zoom {
    frame: Frame,
    eps: f64,
    log: f64,
}

/// (1 − cos θ)/2 of a local direction, accurate near the pole.
fn half_versine(l: DVec3) -> f64 {
    let r2 = l.x * l.x + l.y * l.y;
    if l.z > 0.0 {
        r2 / (2.0 * (1.0 + l.z))
    } else {
        (1.0 - l.z) / 2.0
    }
}

fn from_half_versine(u: f64, x: f64, y: f64) -> DVec3 {
    let u = u.clamp(0.0, 1.0);
    let r = 2.0 * (u * (1.0 - u)).sqrt();
    let phi = y.atan2(x);
    DVec3::new(r * phi.cos(), r * phi.sin(), 1.0 - 2.0 * u)
}

impl Zoom {
    /// Magnifies around `centre` (unit) at scale `eps`.
    pub fn new(centre: Vec3, eps: f64) -> Self {
        Self {
            frame: Frame::from_normal(centre.normalize()),
            eps,
            log: (1.0 + 1.0 / eps).ln(),
        }
    }

    /// Maps a sampled direction into the zoomed sphere.
    pub fn forward(&self, d: Vec3) -> Vec3 {
        let l = self.frame.to_local(d).as_dvec3();
        let u = half_versine(l);
        let v = (1.0 + u / self.eps).ln() / self.log;
        from_half_versine(v, l.x, l.y).as_vec3()
    }

    /// The density on the zoomed sphere of a routine whose density is
    /// `pdf`, at zoomed direction `z`.
    pub fn pdf(&self, z: Vec3, pdf: impl Fn(Vec3) -> f64) -> f64 {
        let l = z.as_dvec3();
        let v = half_versine(l);
        let u = self.eps * ((v * self.log).exp() - 1.0);
        let d = self
            .frame
            .to_world(from_half_versine(u, l.x, l.y).as_vec3())
            .normalize();
        pdf(d) * (self.eps + u) * self.log
    }
}

/// One shader configuration for every family, used where a test applies
/// to all of them (finite values, parameter round trips).
pub const ALL: &[&str] = &[
    "{type: diffuse, reflectance: 0.8}",
    "{type: rough_diffuse, reflectance: 0.8, alpha: 0.6}",
    "{type: conductor}",
    "{type: conductor, material: Au, alpha: 0.2}",
    "{type: conductor, material: Cu, alpha_u: 0.4, alpha_v: 0.02}",
    "{type: conductor, eta: [0.2, 0.9, 1.1], k: [3.9, 2.4, 2.1], alpha: 0.001}",
    "{type: dielectric}",
    "{type: dielectric, alpha: 0.3}",
    "{type: dielectric, int_ior: 3, alpha: 0.001}",
    "{type: dielectric, int_ior: 1.0001, ext_ior: 1, alpha: 0.5}",
    "{type: thin_dielectric}",
    "{type: plastic}",
    "{type: plastic, alpha: 0.2, nonlinear: true}",
    "{type: principled}",
    "{type: principled, metallic: 1, roughness: 0.03, base_color: [0.9, 0.6, 0.3]}",
    "{type: principled, transmission: 1, roughness: 0.2}",
    "{type: principled, metallic: 0.3, transmission: 0.5, roughness: 1, specular: 1}",
    "{type: ashikhmin_shirley, exponent_u: 10, exponent_v: 1000}",
    "{type: ward, alpha_u: 0.3, alpha_v: 0.015}",
    "{type: blend, weight: 0.3, materials: [{type: diffuse}, {type: conductor, alpha: 0.1}]}",
    "{type: blend, weight: 0.5, materials: [{type: conductor}, {type: dielectric, alpha: 0.2}]}",
    "{type: normal_map, normals: tilt, material: {type: conductor, alpha: 0.2}}",
    "{type: bump, height: ramp, scale: 1, material: {type: plastic, alpha: 0.1}}",
];

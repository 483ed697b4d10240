//! Shaders (BSDFs): sampling and evaluation of scattering at surfaces.
//!
//! All directions are in the local shading frame: +z is the shading normal,
//! `wo` points towards where light goes (the previous vertex), `wi` towards
//! where it comes from. Values include the cosine foreshortening factor
//! |cos θi|, so a path's throughput is multiplied by `weight` directly.

use crate::{Effects, Frame, GpuModule, Rgb, TextureId, TextureTable};
use glam::{Vec2, Vec3};

/// The surface points of one shading batch.
///
/// The local shading frame's tangent (+x) points along ∂p/∂u made
/// orthogonal to the shading normal — or, on meshes, along the vertex
/// tangents MikkTSpace makes from the texture coordinates — wherever the
/// frame's effects contain [`Effects::TANGENT_FRAMES`](crate::Effects);
/// elsewhere its direction about the normal is arbitrary.
#[derive(Clone, Copy)]
pub struct SurfaceBatch<'a> {
    /// Outgoing directions, local frame, unit length.
    pub wo: &'a [Vec3],
    /// Surface texture coordinates; zero unless the frame's effects
    /// contain [`Effects::TEXTURES`](crate::Effects), which every varying
    /// texture declares (a shader that reads them without a texture
    /// declares it too).
    pub uv: &'a [Vec2],
    /// ∂p/∂u in the local shading frame, with its length (scene units per
    /// unit of u); empty unless the frame's effects contain
    /// [`Effects::TANGENT_FRAMES`](crate::Effects).
    pub dp_du: &'a [Vec3],
    /// ∂p/∂v likewise.
    pub dp_dv: &'a [Vec3],
}

impl<'a> SurfaceBatch<'a> {
    /// A batch of points without surface derivatives (for shaders that do
    /// not declare [`Effects::TANGENT_FRAMES`](crate::Effects)).
    pub fn new(wo: &'a [Vec3], uv: &'a [Vec2]) -> Self {
        Self {
            wo,
            uv,
            dp_du: &[],
            dp_dv: &[],
        }
    }

    /// The same points with outgoing directions `wo`; texture coordinates
    /// and derivatives are passed on as they are, so a wrapper that turns
    /// the frame must re-express the derivatives itself.
    pub fn with_wo<'b>(&self, wo: &'b [Vec3]) -> SurfaceBatch<'b>
    where
        'a: 'b,
    {
        SurfaceBatch { wo, ..*self }
    }

    /// The points `range` of the batch.
    pub fn slice(&self, range: std::ops::Range<usize>) -> SurfaceBatch<'a> {
        let part = |v: &'a [Vec3]| if v.is_empty() { v } else { &v[range.clone()] };
        SurfaceBatch {
            wo: &self.wo[range.clone()],
            uv: &self.uv[range.clone()],
            dp_du: part(self.dp_du),
            dp_dv: part(self.dp_dv),
        }
    }

    /// Number of surface points in the batch.
    pub fn len(&self) -> usize {
        self.wo.len()
    }

    /// Whether the batch is empty.
    pub fn is_empty(&self) -> bool {
        self.wo.is_empty()
    }
}

/// The result of sampling a BSDF.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// The sampled incident direction, local frame.
    pub wi: Vec3,
    /// f · |cos θi| / pdf; zero marks a failed sample.
    pub weight: Rgb,
    /// Solid-angle density of `wi` (for delta lobes: the lobe's selection
    /// probability, and `delta` is set).
    pub pdf: f32,
    /// Whether `wi` came from a delta (perfectly specular) lobe.
    pub delta: bool,
    /// Relative index of refraction η_t/η_i crossed by a transmitted
    /// sample (1 for reflection and for unbending transmission). Refraction
    /// scales radiance by 1/η², which `weight` includes; the integrator
    /// multiplies it back out for Russian roulette, as Mitsuba 3 does, so
    /// that a path is not cut for entering glass.
    pub eta: f32,
}

impl Default for BsdfSample {
    /// A failed sample: zero weight and density.
    fn default() -> Self {
        Self {
            wi: Vec3::ZERO,
            weight: Rgb::ZERO,
            pdf: 0.0,
            delta: false,
            eta: 1.0,
        }
    }
}

/// The result of evaluating a BSDF for a given pair of directions.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BsdfEval {
    /// f · |cos θi|.
    pub value: Rgb,
    /// Solid-angle density with which `sample` would produce `wi`.
    pub pdf: f32,
}

/// Per-thread state a shader may use while shading a batch: the scene's
/// textures and reusable scratch buffers (so no per-ray allocation).
pub struct ShadeContext<'a> {
    textures: &'a TextureTable,
    scratch: [Vec<Rgb>; 4],
    /// What each scratch buffer holds, where it holds a texture's values at
    /// texture coordinates inside `stable`: the texture and the
    /// coordinates' address and length.
    held: [Option<(TextureId, usize, usize)>; 4],
    /// Texture coordinates that cannot change while the context lives
    /// (see [`ShadeContext::with_stable_uv`]).
    stable: &'a [Vec2],
    pool: Scratch,
}

/// Free lists of buffers that shaders borrow with [`ShadeContext::take`]
/// and give back with [`ShadeContext::recycle`]. Wrapper shaders (`blend`,
/// `normal_map`, `bump`) gather sub-batches into them and layered shaders
/// keep per-point parameters in them; nesting works because a buffer is
/// moved out of the pool while it is in use.
#[derive(Default)]
pub struct Scratch {
    vec3: Vec<Vec<Vec3>>,
    vec2: Vec<Vec<Vec2>>,
    float: Vec<Vec<f32>>,
    index: Vec<Vec<u32>>,
    samples: Vec<Vec<BsdfSample>>,
    evals: Vec<Vec<BsdfEval>>,
    frames: Vec<Vec<Frame>>,
}

/// Element types that [`ShadeContext::take`] can lend buffers of.
pub trait Pooled: Copy + Default + 'static {
    /// The free list of buffers of this type.
    fn pool(scratch: &mut Scratch) -> &mut Vec<Vec<Self>>;
}

macro_rules! pooled {
    ($($t:ty => $field:ident),*) => {$(
        impl Pooled for $t {
            fn pool(scratch: &mut Scratch) -> &mut Vec<Vec<Self>> {
                &mut scratch.$field
            }
        }
    )*};
}

pooled!(Vec3 => vec3, Vec2 => vec2, f32 => float, u32 => index, BsdfSample => samples, BsdfEval => evals, Frame => frames);

impl<'a> ShadeContext<'a> {
    /// Creates a context over the scene's textures.
    pub fn new(textures: &'a TextureTable) -> Self {
        Self {
            textures,
            scratch: Default::default(),
            held: [None; 4],
            stable: &[],
            pool: Scratch::default(),
        }
    }

    /// This context, told that `uv` holds the texture coordinates of the
    /// batches it shades: a [`lookup`](Self::lookup) at a slice of them
    /// that the same scratch buffer already answered for the same
    /// texture returns those values again instead of evaluating the
    /// texture anew, as when a shader's `sample` and `eval` look up the
    /// same textures of one batch. `uv` is borrowed for the context's
    /// lifetime, so it cannot change meanwhile; coordinates elsewhere (a
    /// shader's own buffers) are always evaluated.
    pub fn with_stable_uv(mut self, uv: &'a [Vec2]) -> Self {
        self.stable = uv;
        self.held = [None; 4];
        self
    }

    /// The address and length of `uv` where it lies inside `stable`.
    fn stable_key(&self, uv: &[Vec2]) -> Option<(usize, usize)> {
        let range = self.stable.as_ptr_range();
        let (start, end) = (range.start as usize, range.end as usize);
        let at = uv.as_ptr() as usize;
        let size = std::mem::size_of_val(uv);
        (!uv.is_empty() && at >= start && at + size <= end).then_some((at, uv.len()))
    }

    /// Borrows a buffer of `len` default values (colours are `Vec3`);
    /// give it back with [`recycle`](Self::recycle) so that later batches
    /// reuse its allocation.
    pub fn take<T: Pooled>(&mut self, len: usize) -> Vec<T> {
        let mut v = T::pool(&mut self.pool).pop().unwrap_or_default();
        v.clear();
        v.resize(len, T::default());
        v
    }

    /// Returns a buffer obtained from [`take`](Self::take).
    pub fn recycle<T: Pooled>(&mut self, buffer: Vec<T>) {
        T::pool(&mut self.pool).push(buffer);
    }

    /// The scene's textures.
    pub fn textures(&self) -> &'a TextureTable {
        self.textures
    }

    /// Evaluates up to four textures at the batch's texture coordinates and
    /// returns their values, one slice per texture.
    pub fn lookup<const N: usize>(&mut self, ids: [TextureId; N], uv: &[Vec2]) -> [&[Rgb]; N] {
        const { assert!(N <= 4, "at most four textures per lookup") };
        let textures = self.textures;
        let key = self.stable_key(uv);
        let mut bufs = self.scratch.iter_mut().zip(&mut self.held);
        ids.map(|id| {
            let (buf, held) = bufs.next().expect("N <= 4");
            let now = key.map(|(at, len)| (id, at, len));
            if now.is_none() || *held != now {
                if buf.len() < uv.len() {
                    buf.resize(uv.len(), Rgb::ZERO);
                }
                textures.eval(id, uv, buf);
                *held = now;
            }
            &buf[..uv.len()]
        })
    }
}

/// A shader module (a BSDF).
///
/// Conventions (those of Mitsuba 3 and pbrt):
///
/// * Directions are unit vectors in each point's *local shading frame*:
///   +z is the shading normal on the surface's front (the side its
///   geometric normal points to: the winding's side for triangles, the
///   outside of spheres), x and y the tangents (see [`SurfaceBatch`]).
/// * Both directions point *away* from the surface: `wo` towards where the
///   path came from (the camera's side), `wi` towards the light or the
///   next vertex.
/// * So `cos θ = w.z`: positive on the front, negative behind. A
///   reflection has `wo.z` and `wi.z` of the same sign, a transmission
///   opposite signs. The engine does not turn the frame towards the
///   viewer: a one-sided shader sees `wo.z ≤ 0` on a back face and answers
///   black (as the built-in `diffuse` does; `radiant info` warns where the
///   camera sees mostly such backs); a two-sided or transmissive one
///   handles both signs.
/// * Values include the cosine: [`eval`](Self::eval) gives f · |cos θi|
///   (`wi.z.abs()`), [`sample`](Self::sample) the weight f · |cos θi| / pdf;
///   densities are per unit solid angle.
/// * Batches: `out[i]` answers point `i` of `surface`, for every `i`
///   below `surface.len()`. Write every element — `out` is not cleared
///   between batches — with [`BsdfSample::default`] or
///   [`BsdfEval::default`] where there is nothing. Allocate nothing while
///   shading: borrow buffers from the [`ShadeContext`].
/// * Helpers the built-in shaders use are public in [`crate::shading`]:
///   range-checked inputs ([`fraction`](crate::fraction)) and
///   [`reflection_sample`](crate::reflection_sample).
pub trait Shader: Send + Sync {
    /// Samples an incident direction for each surface point, using the
    /// samples `u[i]` (a 1D value in `x` for lobe selection, a 2D value in
    /// `y`, `z`); `out[i].wi` points away from the surface.
    fn sample(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        u: &[Vec3],
        out: &mut [BsdfSample],
    );

    /// Whether [`sample`](Self::sample) reads the lobe choice `u[i].x`. A
    /// shader with one lobe returns `false`, and the integrator then draws
    /// no lobe samples for it (their contents are unspecified). The
    /// default, `true`, is always correct.
    fn uses_lobe_samples(&self) -> bool {
        true
    }

    /// Evaluates the BSDF for each surface point and incident direction
    /// `wi[i]` (local frame).
    fn eval(
        &self,
        ctx: &mut ShadeContext<'_>,
        surface: SurfaceBatch<'_>,
        wi: &[Vec3],
        out: &mut [BsdfEval],
    );

    /// The surface's albedo seen from each `wo`: the fraction of light it
    /// scatters (reflected and transmitted, with refraction's 1/η² radiance
    /// scaling undone), clamped to [0, 1]. The integrator asks for it only
    /// where an `albedo` pass or the denoiser needs it (the albedo guide of
    /// Open Image Denoise: a matte surface's colour, a metal's specular
    /// colour, 1 for clear glass). The default, [`estimate_albedo`], is the
    /// mean sample weight over a fixed stratified set of samples — exact
    /// for a Lambertian or perfectly specular lobe; a shader may override
    /// it with a closed form.
    fn albedo(&self, ctx: &mut ShadeContext<'_>, surface: SurfaceBatch<'_>, out: &mut [Rgb]) {
        estimate_albedo(self, ctx, surface, out);
    }

    /// The shader's GPU side (see [`crate::gpu`]), `None` where the type has
    /// none (the GPU backend then refuses the scene, naming it).
    fn gpu(&self) -> Option<GpuModule> {
        None
    }
    /// Effects this shader needs (its lobes, its textures).
    fn effects(&self) -> Effects;
}

/// Samples per point of [`estimate_albedo`]: a 4×4 grid of the direction's
/// 2D sample, each with its own lobe choice.
pub const ALBEDO_SAMPLES: u32 = 16;

/// The albedo of each surface point of `surface` (see [`Shader::albedo`]):
/// the mean of `shader`'s sample weights (times η², undoing refraction's
/// radiance scaling) over [`ALBEDO_SAMPLES`] fixed stratified samples,
/// clamped to [0, 1]. The samples are the same for every point, so the
/// estimate is deterministic and uses none of the sampler's dimensions.
pub fn estimate_albedo<S: Shader + ?Sized>(
    shader: &S,
    ctx: &mut ShadeContext<'_>,
    surface: SurfaceBatch<'_>,
    out: &mut [Rgb],
) {
    let n = surface.len();
    let out = &mut out[..n];
    out.fill(Rgb::ZERO);
    let mut u = ctx.take::<Vec3>(n);
    let mut samples = ctx.take::<BsdfSample>(n);
    for k in 0..ALBEDO_SAMPLES {
        let (i, j) = (k % 4, k / 4);
        // Lobe choices in a permuted order, so that they do not follow the
        // grid's rows.
        let choice = ((k * 7) % ALBEDO_SAMPLES) as f32 + 0.5;
        u.fill(Vec3::new(
            choice / ALBEDO_SAMPLES as f32,
            (i as f32 + 0.5) / 4.0,
            (j as f32 + 0.5) / 4.0,
        ));
        shader.sample(ctx, surface, &u, &mut samples);
        for (o, s) in out.iter_mut().zip(&samples) {
            let w = s.weight * (s.eta * s.eta);
            if s.pdf > 0.0 && w.is_finite() {
                *o += w;
            }
        }
    }
    for o in out.iter_mut() {
        *o = (*o / ALBEDO_SAMPLES as f32).clamp(Rgb::ZERO, Rgb::ONE);
    }
    ctx.recycle(u);
    ctx.recycle(samples);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Texture;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// u + v in every channel, counting the points it evaluates.
    struct Counting(Arc<AtomicUsize>);

    impl Texture for Counting {
        fn eval(&self, uv: &[Vec2], out: &mut [Rgb]) {
            self.0.fetch_add(uv.len(), Ordering::Relaxed);
            for (o, p) in out.iter_mut().zip(uv) {
                *o = Rgb::splat(p.x + p.y);
            }
        }

        fn mean(&self) -> Rgb {
            Rgb::ONE
        }
    }

    /// A second lookup of the same texture at the same stable coordinates
    /// is answered from the first; other textures, other slices and
    /// coordinates outside the stable ones are evaluated anew.
    #[test]
    fn stable_coordinates_are_looked_up_once() {
        let counted = Arc::new(AtomicUsize::new(0));
        let mut textures = TextureTable::default();
        let a = textures.add(Box::new(Counting(counted.clone())));
        let b = textures.add(Box::new(Counting(counted.clone())));
        let uv: Vec<Vec2> = (0..8).map(|i| Vec2::new(i as f32, 0.5)).collect();
        let evaluated = || counted.load(Ordering::Relaxed);
        let mut ctx = ShadeContext::new(&textures).with_stable_uv(&uv);
        let first = ctx.lookup([a], &uv[2..6])[0].to_vec();
        assert_eq!(evaluated(), 4);
        let again = ctx.lookup([a], &uv[2..6])[0].to_vec();
        assert_eq!(
            (evaluated(), &again),
            (4, &first),
            "answered from the buffer"
        );
        ctx.lookup([b], &uv[2..6]);
        assert_eq!(evaluated(), 8, "another texture in the same buffer");
        let [x, y] = ctx.lookup([b, a], &uv[2..6]);
        assert_eq!((x.to_vec(), y.to_vec()), (again.clone(), again.clone()));
        assert_eq!(evaluated(), 12, "b from its buffer, a in another one");
        ctx.lookup([a], &uv[2..5]);
        assert_eq!(evaluated(), 15, "another slice");
        // Coordinates of a shader's own, which it may change in place.
        let mut own = uv[2..6].to_vec();
        ctx.lookup([a], &own);
        own[0].x += 1.0;
        let changed = ctx.lookup([a], &own)[0].to_vec();
        assert_eq!(evaluated(), 23);
        assert_eq!(changed[0], first[0] + Rgb::ONE);
        // Without stable coordinates every lookup evaluates.
        let mut plain = ShadeContext::new(&textures);
        plain.lookup([a], &uv);
        plain.lookup([a], &uv);
        assert_eq!(evaluated(), 39);
    }
}

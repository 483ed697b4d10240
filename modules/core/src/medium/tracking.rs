//! Heterogeneous media: distance sampling by delta (spectral) tracking and
//! transmittance by ratio tracking against piecewise-constant majorants.
//!
//! A [`DensityField`] gives a scalar density ρ(p) and, along a ray, the
//! segments over which a bound ρ̄ ≥ ρ holds (a grid medium walks its coarse
//! majorant grid with a DDA). The medium's coefficients at p are ρ(p) times
//! its base coefficients, so the majorant per unit length is the grey
//! μ̄ = ρ̄·max(σt) and tentative collisions are exponential with rate μ̄.
//! At each one, [`delta_track`] chooses absorption, scattering or a null
//! collision with probabilities proportional to the channel averages of
//! σa·β, σs·β and σn·β (σn = μ̄ − σt: Kutz et al. 2017's history-aware
//! spectral tracking; for grey media this is classic delta tracking with
//! weights 1), and gathers emission σa·Le/μ̄ at every tentative collision.
//! [`ratio_track`] multiplies 1 − σt/μ̄ over the tentative collisions, with
//! pbrt-v4's roulette once the estimate is small.
//!
//! Random numbers come from a [`Stream`] keyed by the path's sampler
//! values: the number a tracking walk needs is not bounded.

use super::Coefficients;
use crate::Rgb;
use crate::hash::{hash4, unit_float};
use glam::Vec3;

/// A scalar density field with majorants along rays (render space).
pub trait DensityField: Send + Sync {
    /// ρ at the render-space point `p` (0 outside the field).
    fn density(&self, p: Vec3) -> f32;
    /// Visits, in order of t, segments [t0, t1] ⊆ [0, `t_max`] of the ray
    /// `o + t·d` (`d` a unit vector) with a bound ρ̄ ≥ ρ on each, calling
    /// `visit(t0, t1, ρ̄)` until it returns `false`; parts of the ray
    /// outside the field (ρ = 0) need no segment.
    fn majorants(&self, o: Vec3, d: Vec3, t_max: f32, visit: &mut dyn FnMut(f32, f32, f32) -> bool);
}

/// A stream of uniform random numbers from a hashed key and a counter.
#[derive(Debug, Clone, Copy)]
pub struct Stream {
    key: u32,
    counter: u32,
}

impl Stream {
    /// A stream keyed by four words (e.g. a pixel, a sample index, a
    /// dimension and a sampler value's bits).
    pub fn new(a: u32, b: u32, c: u32, d: u32) -> Self {
        Self {
            key: hash4(a, b, c, d),
            counter: 0,
        }
    }

    /// The next number in [0, 1).
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        self.counter = self.counter.wrapping_add(1);
        unit_float(hash4(self.key, self.counter, 0x6d65_6469, 0x756d))
    }
}

/// The outcome of [`delta_track`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tracked {
    /// Distance of the scattering event, or `t_max` where the ray passes.
    pub t: f32,
    /// Whether the path scatters at `t`.
    pub scattered: bool,
    /// The path's new throughput: for a scattering event it includes σs(t)
    /// (as the homogeneous free flight's weight·σs); zero where it was
    /// absorbed.
    pub beta: Rgb,
    /// Emitted radiance gathered along the way (already times the path's
    /// throughput).
    pub emitted: Rgb,
}

/// Samples the path's next interaction along `o + t·d` (`d` unit, up to
/// `t_max`) in the field `field` of base coefficients `c`, for a path of
/// throughput `beta` (see the module's description).
pub fn delta_track(
    field: &dyn DensityField,
    c: &Coefficients,
    (o, d, t_max): (Vec3, Vec3, f32),
    beta: Rgb,
    rng: &mut Stream,
) -> Tracked {
    let sigma_t = c.sigma_t();
    let top = sigma_t.max_element();
    let mut out = Tracked {
        t: t_max,
        scattered: false,
        beta,
        emitted: Rgb::ZERO,
    };
    if top <= 0.0 {
        return out;
    }
    let emits = c.emission.max_element() > 0.0 && c.sigma_a.max_element() > 0.0;
    collisions(field, top, (o, d, t_max), rng, |t, rho, mu, rng| {
        let (sa, ss) = (c.sigma_a * rho, c.sigma_s * rho);
        let sn = (Rgb::splat(mu) - sigma_t * rho).max(Rgb::ZERO);
        let b = out.beta;
        if emits {
            out.emitted += b * sa * c.emission / mu;
        }
        let (pa, ps, pn) = (avg(sa * b), avg(ss * b), avg(sn * b));
        let total = pa + ps + pn;
        let u = rng.next_f32() * total;
        if total <= 0.0 || u < pa {
            // Absorbed: the path ends here.
            out.beta = Rgb::ZERO;
            out.t = t;
            return false;
        }
        let (sigma, p) = if u < pa + ps { (ss, ps) } else { (sn, pn) };
        // β·σx/(μ̄·P_x) with P_x = p/total and total = μ̄·avg(β).
        out.beta = b * sigma * (total / (mu * p));
        if u < pa + ps {
            out.t = t;
            out.scattered = true;
            return false;
        }
        true
    });
    out
}

#[inline]
fn avg(c: Rgb) -> f32 {
    c.element_sum() / 3.0
}

/// Ratio-tracking estimate of the transmittance along `o + t·d` (`d` unit,
/// t ∈ [0, `t_max`]) through the field `field` of base extinction
/// `sigma_t`: unbiased, per channel.
pub fn ratio_track(
    field: &dyn DensityField,
    sigma_t: Rgb,
    (o, d, t_max): (Vec3, Vec3, f32),
    rng: &mut Stream,
) -> Rgb {
    let top = sigma_t.max_element();
    let mut tr = Rgb::ONE;
    if top <= 0.0 {
        return tr;
    }
    collisions(field, top, (o, d, t_max), rng, |_, rho, mu, rng| {
        tr *= (Rgb::ONE - sigma_t * (rho / mu)).max(Rgb::ZERO);
        let m = tr.max_element();
        if m <= 0.0 {
            return false;
        }
        if m < 0.05 {
            // Roulette (pbrt-v4): survive with probability 1/4.
            if rng.next_f32() < 0.75 {
                tr = Rgb::ZERO;
                return false;
            }
            tr *= 4.0;
        }
        true
    });
    tr
}

/// Walks the tentative collisions along `o + t·d` up to `t_max`: within
/// each majorant segment, exponential steps of rate μ̄ = ρ̄·`top`; calls
/// `at(t, ρ(t), μ̄, rng)` at each until it returns `false`.
fn collisions(
    field: &dyn DensityField,
    top: f32,
    (o, d, t_max): (Vec3, Vec3, f32),
    rng: &mut Stream,
    mut at: impl FnMut(f32, f32, f32, &mut Stream) -> bool,
) {
    field.majorants(o, d, t_max, &mut |t0, t1, bound| {
        let mu = bound * top;
        if mu <= 0.0 {
            return true;
        }
        let mut t = t0;
        loop {
            // 1 − u in (0, 1]: the logarithm is finite.
            t -= (1.0 - rng.next_f32()).ln() / mu;
            if t >= t1 {
                return true;
            }
            if !at(t, field.density(o + d * t), mu, rng) {
                return false;
            }
        }
    });
}

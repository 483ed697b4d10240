//! Multiple importance sampling weights of bidirectional strategies, by
//! the power heuristic (β = 2), computed with the recursive quantities of
//! seed 001's SBDPT (van Antwerpen, §8.2) so that a connection costs the
//! same whatever the path's length.
//!
//! A path x₀ … x₍ₙ₋₁₎ (x₀ on the lens, x₍ₙ₋₁₎ on a light) is made by the
//! strategy (s, t) from a camera subpath of t vertices and a light subpath
//! of s. Its density p(s, t) is the product of each vertex's density from
//! the side that sampled it: `fwd` along its own subpath, `rev` were it
//! sampled from the other side. The weight is
//! w = p(s, t)² / Σ p(s′, t′)², over the strategies that can make the path:
//! t′ ≥ 1 (light paths never hit the lens), no connection at a vertex whose
//! scattering was a delta lobe, s′ = 0 only for lights that can be hit.
//!
//! Dividing by p(s, t)², each side's sum is a recursion over its subpath
//! (the thesis's dᵢ/pᵢ, normalised as in Georgiev's vertex connection):
//!
//! acc[k] = (rev[k] / fwd[k])² · (head[k] + acc[k − 1])
//!
//! where head[k] is 1 if the strategy whose connection edge is
//! (v[k − 1], v[k]) can make the path and 0 if not (a delta vertex at
//! either end: the thesis's "drop the p₍ᵢ₋₁₎ term"); rev[k] needs the two
//! vertices after v[k], so every acc is complete once the subpath has grown
//! two vertices past it, and a connection computes the last two from the
//! other subpath's end: four densities and four multiplications, whatever
//! the length. The camera side starts at acc[0] = 0 (no strategy samples
//! the lens from a light path); the light side at acc[−1] = 0, with
//! head[0] = 1 where a camera path can hit the light (not a point or
//! directional light).
//!
//! One strategy samples its light endpoint differently: next-event
//! estimation (s = 1, t ≥ 2) picks the point on the light by the light's
//! own `sample` (density D), whereas light paths start from emitted rays
//! (density L = choice × `pdf_pos`). The strategy s′ = 1 therefore enters
//! the light side's head[1] as (D / L)², and a next-event estimate divides
//! both sums by (D / L)².

/// The power heuristic's ratio term (a / b)², 0 where `b` is not positive.
#[inline]
pub(super) fn ratio2(a: f32, b: f32) -> f32 {
    if b > 0.0 {
        let r = a / b;
        if r.is_finite() { r * r } else { f32::MAX }
    } else {
        0.0
    }
}

/// The MIS state of one subpath vertex.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Mis {
    /// Density of the vertex from its own subpath's side (per unit area,
    /// or per unit solid angle for a light at infinity).
    pub fwd: f32,
    /// Whether the vertex scattered by a delta lobe (it cannot be a
    /// connection's end).
    pub delta: bool,
    /// A factor on head[k] (the light side's (D / L)² at k = 1; 1 else;
    /// head[0] of the light side is this factor alone).
    pub eps: f32,
    /// acc[k], once the vertex has two successors.
    pub acc: f32,
}

/// Which subpath a slice of [`Mis`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Side {
    /// Starts on the lens: acc[0] = 0.
    Camera,
    /// Starts on a light: head[0] = `eps` of vertex 0.
    Light,
}

/// head[k] of `v`, where vertex `end` is a connection's end (its own
/// scattering is then the connection's, never a delta lobe).
#[inline]
fn head(v: &[Mis], k: usize, side: Side, end: usize) -> f32 {
    let delta = |i: usize| i != end && v[i].delta;
    match (side, k) {
        (Side::Light, 0) => v[0].eps,
        (_, 0) => 0.0,
        _ if delta(k) || delta(k - 1) => 0.0,
        _ => v[k].eps,
    }
}

/// acc[k] of `v` with the density `rev` of vertex k from the other side,
/// `before` being acc[k − 1].
#[inline]
pub(super) fn acc(v: &[Mis], k: usize, side: Side, rev: f32, before: f32, end: usize) -> f32 {
    if side == Side::Camera && k == 0 {
        return 0.0;
    }
    ratio2(rev, v[k].fwd) * (head(v, k, side, end) + before)
}

/// Completes acc[k] of a subpath once vertex k + 2 exists (`rev` is then
/// known): what the subpath's walk calls.
#[inline]
pub(super) fn complete(v: &mut [Mis], k: usize, side: Side, rev: f32) {
    let before = if k == 0 { 0.0 } else { v[k - 1].acc };
    v[k].acc = acc(v, k, side, rev, before, usize::MAX);
}

/// One side's sum Σ p(s′, t′)² / p(s, t)² over the strategies with more
/// vertices on the other side, for a connection at vertex `e` of `v`:
/// `rev_end` is the density of vertex e from the other side, `rev_prev`
/// that of vertex e − 1 (sampled from e, given the other side's end).
#[inline]
pub(super) fn side_sum(v: &[Mis], side: Side, e: usize, rev_end: f32, rev_prev: f32) -> f32 {
    let prev = if e == 0 {
        0.0
    } else {
        let before = if e >= 2 { v[e - 2].acc } else { 0.0 };
        acc(v, e - 1, side, rev_prev, before, e)
    };
    acc(v, e, side, rev_end, prev, e)
}

/// The weight 1 / (1 + camera side + light side), each side divided by
/// `scale` ((D / L)² for next-event estimation, else 1).
#[inline]
pub(super) fn weight(camera: f32, light: f32, scale: f32) -> f32 {
    let w = 1.0 / (1.0 + (camera + light) / scale);
    if w.is_finite() { w } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic generator for the test's random paths.
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 40) as f32 + 0.5) / (1u64 << 24) as f32
        }
    }

    /// A full path's densities: per vertex, from the camera side `c` and
    /// from the light side `l`, delta flags, and the light endpoint's
    /// next-event density `d`; whether the light can be hit.
    struct Path {
        c: Vec<f32>,
        l: Vec<f32>,
        delta: Vec<bool>,
        d: f32,
        hittable: bool,
    }

    impl Path {
        fn random(n: usize, rng: &mut Lcg) -> Self {
            let mut delta: Vec<bool> = (0..n).map(|_| rng.next() < 0.3).collect();
            delta[0] = false;
            delta[n - 1] = false;
            Path {
                c: (0..n).map(|_| 0.05 + 3.0 * rng.next()).collect(),
                l: (0..n).map(|_| 0.05 + 3.0 * rng.next()).collect(),
                delta,
                d: 0.05 + 3.0 * rng.next(),
                hittable: rng.next() < 0.7,
            }
        }

        /// Whether (s, t) can make the path, and its density.
        fn strategy(&self, s: usize) -> Option<f64> {
            let n = self.c.len();
            let t = n - s;
            if t == 0 {
                return None;
            }
            if s == 0 && !self.hittable {
                return None;
            }
            if s >= 1 && (self.delta[t - 1] || self.delta[t]) {
                return None;
            }
            let mut p = 1.0f64;
            for i in 1..t {
                p *= self.c[i] as f64;
            }
            for i in t..n {
                p *= if i == n - 1 && s == 1 && t >= 2 {
                    self.d
                } else {
                    self.l[i]
                } as f64;
            }
            Some(p)
        }

        /// The weight of (s, t) by brute force.
        fn brute(&self, s: usize) -> f64 {
            let Some(p) = self.strategy(s) else {
                return 0.0;
            };
            let total: f64 = (0..=self.c.len())
                .filter_map(|s| self.strategy(s))
                .map(|q| q * q)
                .sum();
            p * p / total
        }

        /// The weight of (s, t) by the recursion, from the two subpaths as
        /// the integrator holds them.
        fn recursive(&self, s: usize) -> f64 {
            let n = self.c.len();
            let t = n - s;
            if self.strategy(s).is_none() {
                return 0.0;
            }
            // Camera subpath x₀ … x₍t₋₁₎, light subpath x₍ₙ₋₁₎ … x_t.
            let mut cam: Vec<Mis> = (0..t)
                .map(|i| Mis {
                    fwd: self.c[i],
                    delta: self.delta[i],
                    eps: 1.0,
                    acc: 0.0,
                })
                .collect();
            for k in 0..t.saturating_sub(2) {
                complete(&mut cam, k, Side::Camera, self.l[k]);
            }
            let eps1 = ratio2(self.d, self.l[n - 1]);
            let mut light: Vec<Mis> = (0..s)
                .map(|j| {
                    let i = n - 1 - j;
                    Mis {
                        fwd: self.l[i],
                        delta: self.delta[i],
                        eps: match j {
                            0 => f32::from(u8::from(self.hittable)),
                            1 => eps1,
                            _ => 1.0,
                        },
                        acc: 0.0,
                    }
                })
                .collect();
            for k in 0..s.saturating_sub(2) {
                complete(&mut light, k, Side::Light, self.c[n - 1 - k]);
            }
            if s == 0 {
                // The camera path hit the light: its last vertex's density
                // from the light side is L, and the strategy s′ = 1 samples
                // it with D.
                let e = t - 1;
                let mut v = cam.clone();
                v[e].eps = if e >= 2 {
                    ratio2(self.d, self.l[e])
                } else {
                    1.0
                };
                let sum = side_sum(&v, Side::Camera, e, self.l[e], self.l[e - 1]);
                return weight(sum, 0.0, 1.0) as f64;
            }
            let cam_sum = side_sum(
                &cam,
                Side::Camera,
                t - 1,
                self.l[t - 1],
                self.l[t - 2.min(t - 1)],
            );
            let light_sum = side_sum(
                &light,
                Side::Light,
                s - 1,
                self.c[t],
                self.c[(t + 1).min(n - 1)],
            );
            let scale = if s == 1 && t >= 2 { eps1 } else { 1.0 };
            weight(cam_sum, light_sum, scale) as f64
        }
    }

    #[test]
    fn recursive_weights_match_brute_force_and_sum_to_one() {
        let mut rng = Lcg(7);
        for n in 2..9 {
            for _ in 0..400 {
                let path = Path::random(n, &mut rng);
                let mut total = 0.0;
                for s in 0..=n {
                    let (a, b) = (path.recursive(s), path.brute(s));
                    assert!(
                        (a - b).abs() < 1e-4 * b.max(1e-3),
                        "n {n} s {s}: {a} vs {b}"
                    );
                    total += a;
                }
                let any = (0..=n).any(|s| path.strategy(s).is_some());
                if any {
                    assert!((total - 1.0).abs() < 1e-4, "n {n}: Σw = {total}");
                }
            }
        }
    }
}

//! Spatial bounds of a light's emission, for light selection that knows
//! where the shading point is.
//!
//! A light that has a place in the scene reports [`LightBounds`] through
//! [`Light::bounds`](crate::Light::bounds): the box that holds it, its
//! power, and the cone of directions in which it emits (pbrt-v4's
//! `LightBounds`, after Conty and Kulla 2018). The engine's spatial light
//! selection weighs every light by [`LightBounds::importance`] at the
//! shading point — a conservative estimate of the irradiance the light can
//! deliver there — instead of by power alone. Importance is 0 only where
//! the light cannot send any light to the point, so selection by it stays
//! unbiased.

use glam::{BVec4A, Vec3, Vec4};

/// Where a light is and in which directions it emits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightBounds {
    /// Smallest corner of the box holding the light (render space).
    pub min: Vec3,
    /// Largest corner of that box.
    pub max: Vec3,
    /// Emitted power as seen by selection: radiance × area for surfaces,
    /// intensity for point-like lights (so that φ / d² estimates irradiance).
    pub phi: f32,
    /// Unit axis of the cone that holds the surface normals (or the
    /// emission direction of a spot light).
    pub axis: Vec3,
    /// Cosine of the half angle of that cone (−1: every direction).
    pub cos_theta_o: f32,
    /// Cosine of the angle beyond the normals' cone in which light still
    /// leaves (0 for surfaces emitting over their hemisphere).
    pub cos_theta_e: f32,
    /// Whether the surfaces emit from both sides.
    pub two_sided: bool,
}

/// cos(max(0, a − b)) from the sines and cosines of a and b.
#[inline]
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// sin(max(0, a − b)) from the sines and cosines of a and b.
#[inline]
fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        0.0
    } else {
        sin_a * cos_b - cos_a * sin_b
    }
}

#[inline]
fn sin_from_cos(c: f32) -> f32 {
    (1.0 - c * c).max(0.0).sqrt()
}

impl LightBounds {
    /// Bounds of a point-like light at `p` emitting into the cone of half
    /// angle θo about `axis` (−1 for every direction), with a fall-off
    /// reaching θe further.
    pub fn point(p: Vec3, phi: f32, axis: Vec3, cos_theta_o: f32, cos_theta_e: f32) -> Self {
        Self {
            min: p,
            max: p,
            phi,
            axis,
            cos_theta_o,
            cos_theta_e,
            two_sided: false,
        }
    }

    /// The importance of the light for a shading point `p`: φ · cos θ' / d²,
    /// where d is the distance to the box's centre (at least half its
    /// diagonal) and θ' the smallest angle between the emission cone and
    /// the direction to `p` that the box allows. 0 where the light cannot
    /// reach `p`.
    #[inline]
    pub fn importance(&self, p: Vec3) -> f32 {
        self.prepare().importance(p)
    }

    /// The bounds with what [`importance`](Self::importance) derives from
    /// them computed once, for selection that evaluates it at many points.
    #[inline]
    pub fn prepare(&self) -> PreparedBounds {
        let diagonal = self.max - self.min;
        PreparedBounds {
            bounds: *self,
            centre: (self.min + self.max) * 0.5,
            half_diagonal: diagonal.length() * 0.5,
            radius2: diagonal.length_squared() * 0.25,
            sin_theta_o: sin_from_cos(self.cos_theta_o),
            isotropic_point: self.cos_theta_o <= -1.0 && self.min == self.max,
        }
    }

    /// Bounds of surfaces with the given box, the summed area-weighted
    /// normal `normal_sum`, the unit normals `normals` (to find the cone)
    /// and power `phi`, emitting over the front hemisphere.
    pub fn surface(
        min: Vec3,
        max: Vec3,
        phi: f32,
        normal_sum: Vec3,
        normals: impl Iterator<Item = Vec3>,
    ) -> Self {
        let axis = normal_sum.normalize_or_zero();
        let cos_theta_o = if axis == Vec3::ZERO {
            -1.0
        } else {
            normals.fold(1.0f32, |c, n| c.min(axis.dot(n)))
        };
        // Rounding must not narrow the cone: widen it a little.
        let cos_theta_o = if cos_theta_o >= 1.0 - 1e-6 {
            1.0 - 1e-6
        } else {
            (cos_theta_o - 1e-4).max(-1.0)
        };
        Self {
            min,
            max,
            phi,
            axis: if axis == Vec3::ZERO { Vec3::Z } else { axis },
            cos_theta_o,
            cos_theta_e: 0.0,
            two_sided: false,
        }
    }
}

/// [`LightBounds`] with the box's centre, half diagonal and the sine of
/// the cone's angle computed once ([`LightBounds::prepare`]): its
/// [`importance`](Self::importance) is [`LightBounds::importance`], bit
/// for bit, in fewer operations per point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreparedBounds {
    bounds: LightBounds,
    centre: Vec3,
    /// Half the box's diagonal (the least distance² importance divides by).
    half_diagonal: f32,
    /// The squared radius of the box's bounding sphere.
    radius2: f32,
    sin_theta_o: f32,
    /// A point emitting in every direction: no angular bound applies.
    isotropic_point: bool,
}

impl PreparedBounds {
    /// [`LightBounds::importance`] at `p`.
    #[inline]
    pub fn importance(&self, p: Vec3) -> f32 {
        let b = &self.bounds;
        let to_p = p - self.centre;
        let d2 = to_p.length_squared().max(self.half_diagonal);
        if d2 <= 0.0 {
            // A point light at p sends nothing there.
            return 0.0;
        }
        if self.isotropic_point {
            return b.phi * (1.0 / d2);
        }
        // The angle the box subtends from p (all directions from inside).
        let radius2 = self.radius2;
        let dist2 = to_p.length_squared();
        let inside = p.cmpge(b.min).all() && p.cmple(b.max).all();
        // One reciprocal of the distance serves the box's angle and the
        // axis's cosine (the box's radius is its half diagonal).
        let len = dist2.sqrt();
        let inv_len = 1.0 / len;
        let (sin_b, cos_b) = if inside || dist2 <= radius2 {
            (0.0, -1.0)
        } else {
            let sin_b = self.half_diagonal * inv_len;
            (sin_b, (1.0 - sin_b * sin_b).max(0.0).sqrt())
        };
        let mut cos_w = if len > 0.0 {
            to_p.dot(b.axis) * inv_len
        } else {
            1.0
        };
        if b.two_sided {
            cos_w = cos_w.abs();
        }
        let sin_w = sin_from_cos(cos_w);
        let (sin_o, cos_o) = (self.sin_theta_o, b.cos_theta_o);
        // θw − θo, then minus θb.
        let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
        let sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_o);
        let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
        if cos_p <= b.cos_theta_e {
            return 0.0;
        }
        (b.phi * cos_p * (1.0 / d2)).max(0.0)
    }
}

/// Four lights' [`PreparedBounds`] side by side (structure of arrays), so
/// that their importance at a point is evaluated for all four at once:
/// [`importance`](Self::importance) gives each lane's
/// [`PreparedBounds::importance`] bit for bit (the same IEEE operations in
/// the same order, branches turned into selects).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundsLanes {
    centre: [Vec4; 3],
    min: [Vec4; 3],
    max: [Vec4; 3],
    axis: [Vec4; 3],
    half_diagonal: Vec4,
    radius2: Vec4,
    phi: Vec4,
    cos_theta_o: Vec4,
    sin_theta_o: Vec4,
    cos_theta_e: Vec4,
    two_sided: BVec4A,
    isotropic_point: BVec4A,
}

impl BoundsLanes {
    /// The lanes of `bounds`, one to four lights (lanes beyond repeat the
    /// last light).
    ///
    /// # Panics
    ///
    /// Where `bounds` is empty or holds more than four lights.
    pub fn new(bounds: &[PreparedBounds]) -> Self {
        assert!((1..=4).contains(&bounds.len()), "one to four lights");
        let lane = |i: usize| &bounds[i.min(bounds.len() - 1)];
        let f = |get: &dyn Fn(&PreparedBounds) -> f32| {
            Vec4::new(get(lane(0)), get(lane(1)), get(lane(2)), get(lane(3)))
        };
        let v = |get: &dyn Fn(&PreparedBounds) -> Vec3| {
            [0, 1, 2].map(|axis| f(&|b: &PreparedBounds| get(b)[axis]))
        };
        let m = |get: &dyn Fn(&PreparedBounds) -> bool| {
            BVec4A::new(get(lane(0)), get(lane(1)), get(lane(2)), get(lane(3)))
        };
        Self {
            centre: v(&|b| b.centre),
            min: v(&|b| b.bounds.min),
            max: v(&|b| b.bounds.max),
            axis: v(&|b| b.bounds.axis),
            half_diagonal: f(&|b| b.half_diagonal),
            radius2: f(&|b| b.radius2),
            phi: f(&|b| b.bounds.phi),
            cos_theta_o: f(&|b| b.bounds.cos_theta_o),
            sin_theta_o: f(&|b| b.sin_theta_o),
            cos_theta_e: f(&|b| b.bounds.cos_theta_e),
            two_sided: m(&|b| b.bounds.two_sided),
            isotropic_point: m(&|b| b.isotropic_point),
        }
    }

    /// Each lane's [`PreparedBounds::importance`] at `p`.
    #[inline]
    pub fn importance(&self, p: Vec3) -> Vec4 {
        self.importance_at(p.to_array().map(Vec4::splat))
    }

    /// Each lane's [`PreparedBounds::importance`] at its own point, given
    /// as lanes of coordinates `[x, y, z]`. With one light in every lane
    /// (`new(&[bounds])`) this evaluates one light at four points, which
    /// is how a batch of shading points is weighed: four independent
    /// evaluations rather than one long chain of square roots and
    /// divisions per point.
    #[inline]
    pub fn importance_at(&self, p: [Vec4; 3]) -> Vec4 {
        let (zero, one) = (Vec4::ZERO, Vec4::ONE);
        let [cx, cy, cz] = self.centre;
        let (tx, ty, tz) = (p[0] - cx, p[1] - cy, p[2] - cz);
        let dist2 = tx * tx + ty * ty + tz * tz;
        let d2 = dist2.max(self.half_diagonal);
        if self.isotropic_point.all() {
            // Point lights in every lane (one light at four points): the
            // last select below, without the angular bounds it discards.
            return Vec4::select(d2.cmple(zero), zero, self.phi * (one / d2));
        }
        let inside = [0, 1, 2].iter().fold(BVec4A::splat(true), |acc, &k| {
            acc & p[k].cmpge(self.min[k]) & p[k].cmple(self.max[k])
        });
        let radius2 = self.radius2;
        let small = inside | dist2.cmple(radius2);
        let len = dist2.sqrt();
        let inv_len = one / len;
        let sin_b = self.half_diagonal * inv_len;
        let cos_b = Vec4::select(small, -one, (one - sin_b * sin_b).max(zero).sqrt());
        let sin_b = Vec4::select(small, zero, sin_b);
        let [ax, ay, az] = self.axis;
        let cos_w = Vec4::select(
            len.cmpgt(zero),
            (tx * ax + ty * ay + tz * az) * inv_len,
            one,
        );
        let cos_w = Vec4::select(self.two_sided, cos_w.abs(), cos_w);
        let sin_w = (one - cos_w * cos_w).max(zero).sqrt();
        let (sin_o, cos_o) = (self.sin_theta_o, self.cos_theta_o);
        // θw − θo, then minus θb (`cos_sub_clamped`, `sin_sub_clamped`).
        let within = cos_w.cmpgt(cos_o);
        let cos_x = Vec4::select(within, one, cos_w * cos_o + sin_w * sin_o);
        let sin_x = Vec4::select(within, zero, sin_w * cos_o - cos_w * sin_o);
        let cos_p = Vec4::select(cos_x.cmpgt(cos_b), one, cos_x * cos_b + sin_x * sin_b);
        let inv_d2 = one / d2;
        let cone = Vec4::select(
            cos_p.cmple(self.cos_theta_e),
            zero,
            (self.phi * cos_p * inv_d2).max(zero),
        );
        let value = Vec4::select(self.isotropic_point, self.phi * inv_d2, cone);
        Vec4::select(d2.cmple(zero), zero, value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_falls_off_with_distance_squared() {
        let b = LightBounds::point(Vec3::ZERO, 2.0, Vec3::Z, -1.0, 0.0);
        assert!((b.importance(Vec3::new(0.0, 0.0, 2.0)) - 0.5).abs() < 1e-6);
        assert!((b.importance(Vec3::new(0.0, -4.0, 0.0)) - 0.125).abs() < 1e-6);
    }

    #[test]
    fn a_spot_is_dark_outside_its_cone() {
        let (o, e) = (30f32.to_radians().cos(), 10f32.to_radians().cos());
        let b = LightBounds::point(Vec3::ZERO, 1.0, Vec3::Z, o, e);
        assert!(b.importance(Vec3::new(0.0, 0.0, 1.0)) > 0.99);
        // 35° off axis: inside θo + θe = 40°.
        let a = 35f32.to_radians();
        assert!(b.importance(Vec3::new(a.sin(), 0.0, a.cos())) > 0.0);
        // 45° off axis: outside.
        let a = 45f32.to_radians();
        assert_eq!(b.importance(Vec3::new(a.sin(), 0.0, a.cos())), 0.0);
        assert_eq!(b.importance(Vec3::new(0.0, 0.0, -1.0)), 0.0);
    }

    #[test]
    fn a_one_sided_rectangle_is_dark_behind_and_bright_in_front() {
        let b = LightBounds::surface(
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            4.0,
            Vec3::Z * 4.0,
            [Vec3::Z, Vec3::Z].into_iter(),
        );
        assert!(b.importance(Vec3::new(0.0, 0.0, 3.0)) > 0.0);
        assert!(b.importance(Vec3::new(5.0, 0.0, 0.01)) > 0.0);
        assert_eq!(b.importance(Vec3::new(0.0, 0.0, -3.0)), 0.0);
        assert_eq!(b.importance(Vec3::new(2.0, 0.0, -2.0)), 0.0);
        // Never more than φ / (half diagonal) anywhere.
        assert!(b.importance(Vec3::new(0.0, 0.0, 1e-3)) <= 4.0 / 2f32.sqrt() + 1e-5);
    }

    #[test]
    fn lanes_give_each_lights_importance_bit_for_bit() {
        // Every branch of `importance`: an isotropic point, a spot, one-
        // and two-sided surfaces, points inside a box and on a point light.
        let (o, e) = (30f32.to_radians().cos(), 10f32.to_radians().cos());
        let mut two_sided = LightBounds::surface(
            Vec3::new(-1.0, 0.5, -1.0),
            Vec3::new(1.0, 0.5, 1.0),
            3.0,
            Vec3::Y,
            [Vec3::Y].into_iter(),
        );
        two_sided.two_sided = true;
        let lights = [
            LightBounds::point(Vec3::new(0.3, 1.0, 0.0), 2.0, Vec3::Z, -1.0, 0.0),
            LightBounds::point(Vec3::new(0.0, 2.0, 0.0), 5.0, -Vec3::Y, o, e),
            LightBounds::surface(
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.2),
                4.0,
                Vec3::Z,
                [Vec3::Z, Vec3::new(0.0, 0.6, 0.8)].into_iter(),
            ),
            two_sided,
        ]
        .map(|b| b.prepare());
        let mut points = vec![
            Vec3::new(0.3, 1.0, 0.0),
            Vec3::ZERO,
            Vec3::new(0.5, 0.5, 0.1),
        ];
        points.extend((0..2000).map(|i| {
            let t = i as f32 * 0.618_034;
            Vec3::new(
                (t * 1.7).sin() * 3.0,
                (t * 2.3).cos() * 3.0,
                (t * 0.9).sin() * 2.0,
            )
        }));
        for n in 1..=4 {
            let lanes = BoundsLanes::new(&lights[..n]);
            let mut lit = 0;
            for &p in &points {
                let got = lanes.importance(p).to_array();
                for (b, g) in lights[..n].iter().zip(got) {
                    assert_eq!(g.to_bits(), b.importance(p).to_bits(), "{n} lights at {p}");
                    lit += usize::from(g > 0.0);
                }
            }
            assert!(lit > points.len() / 2, "most points see some light");
        }
        // One light in every lane, four points at a time.
        for b in &lights {
            let lanes = BoundsLanes::new(&[*b]);
            for quad in points.chunks_exact(4) {
                let at = [0, 1, 2].map(|k| Vec4::from_array([0, 1, 2, 3].map(|j| quad[j][k])));
                let got = lanes.importance_at(at).to_array();
                for (p, g) in quad.iter().zip(got) {
                    assert_eq!(g.to_bits(), b.importance(*p).to_bits(), "at {p}");
                }
            }
        }
    }
}

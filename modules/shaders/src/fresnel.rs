//! Fresnel reflectance of smooth interfaces: exact dielectric (with total
//! internal reflection), exact conductor (complex index), Schlick's
//! approximation, and the hemispherical average of the dielectric one.

use radiant_core::Rgb;

/// The result of [`dielectric`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DielectricFresnel {
    /// Reflectance, 1 under total internal reflection.
    pub r: f32,
    /// Signed cosine of the transmitted direction (opposite side to the
    /// incident one; 0 under total internal reflection).
    pub cos_t: f32,
    /// Relative index η_t/η_i for the side of incidence.
    pub eta_it: f32,
    /// Its inverse η_i/η_t.
    pub eta_ti: f32,
}

/// Unpolarised Fresnel reflectance of a dielectric interface with relative
/// index `eta` (inside over outside), for the signed incident cosine
/// `cos_i` (negative: arriving from inside).
#[inline]
pub fn dielectric(cos_i: f32, eta: f32) -> DielectricFresnel {
    let (eta_it, eta_ti) = if cos_i >= 0.0 {
        (eta, 1.0 / eta)
    } else {
        (1.0 / eta, eta)
    };
    let cos_i_abs = cos_i.abs().min(1.0);
    let cos_t2 = 1.0 - (1.0 - cos_i_abs * cos_i_abs) * eta_ti * eta_ti;
    if cos_t2 <= 0.0 {
        return DielectricFresnel {
            r: 1.0,
            cos_t: 0.0,
            eta_it,
            eta_ti,
        };
    }
    let cos_t_abs = cos_t2.sqrt();
    // In double precision: near-matched indices (η = 1.0001) cancel in
    // single precision and would give an exact zero for a tiny reflectance.
    let r = if eta == 1.0 {
        0.0
    } else if cos_i_abs == 0.0 {
        1.0
    } else {
        let (ci, et) = (cos_i_abs as f64, eta_it as f64);
        let ct = (1.0 - (1.0 - ci * ci) / (et * et)).max(0.0).sqrt();
        let a_s = (ci - et * ct) / (ci + et * ct);
        let a_p = (ct - et * ci) / (ct + et * ci);
        (0.5 * (a_s * a_s + a_p * a_p)).min(1.0) as f32
    };
    DielectricFresnel {
        r,
        cos_t: if cos_i >= 0.0 { -cos_t_abs } else { cos_t_abs },
        eta_it,
        eta_ti,
    }
}

/// Unpolarised Fresnel reflectance of a conductor of complex relative index
/// `eta + i k`, per colour channel, for the incident cosine `cos_i` ≥ 0
/// (after K. D. Möller, *Optics*, as in Mitsuba 3).
#[inline]
pub fn conductor(cos_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    let c2 = (cos_i * cos_i).min(1.0);
    let s2 = 1.0 - c2;
    let s4 = s2 * s2;
    let t1 = eta * eta - k * k - Rgb::splat(s2);
    let a2pb2 = (t1 * t1 + 4.0 * k * k * eta * eta).max(Rgb::ZERO);
    let a2pb2 = Rgb::new(a2pb2.x.sqrt(), a2pb2.y.sqrt(), a2pb2.z.sqrt());
    let a = (0.5 * (a2pb2 + t1)).max(Rgb::ZERO);
    let a = Rgb::new(a.x.sqrt(), a.y.sqrt(), a.z.sqrt());
    let term1 = a2pb2 + Rgb::splat(c2);
    let term2 = 2.0 * cos_i.abs() * a;
    let rs = (term1 - term2) / (term1 + term2).max(Rgb::splat(f32::MIN_POSITIVE));
    let term3 = a2pb2 * c2 + Rgb::splat(s4);
    let term4 = term2 * s2;
    let rp = rs * (term3 - term4) / (term3 + term4).max(Rgb::splat(f32::MIN_POSITIVE));
    (0.5 * (rs + rp)).clamp(Rgb::ZERO, Rgb::ONE)
}

/// Schlick's approximation R0 + (1 − R0)(1 − cos)^5, per channel.
#[inline]
pub fn schlick(cos_i: f32, r0: Rgb) -> Rgb {
    let m = (1.0 - cos_i.abs()).clamp(0.0, 1.0);
    let m2 = m * m;
    r0 + (Rgb::ONE - r0) * (m2 * m2 * m)
}

/// Diffuse Fresnel reflectance 2∫₀¹ F(μ, η) μ dμ of a smooth interface
/// with relative index `eta`, seen from the side where light arrives with
/// index ratio `eta` (η < 1: from the denser side). Integrated numerically
/// (computed once per material).
pub fn diffuse_reflectance(eta: f32) -> f32 {
    let n = 4096;
    let mut sum = 0.0f64;
    for i in 0..n {
        let mu = (i as f32 + 0.5) / n as f32;
        sum += (dielectric(mu, eta).r * mu) as f64;
    }
    (2.0 * sum / n as f64) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_limits() {
        // Normal incidence: ((η−1)/(η+1))².
        let f = dielectric(1.0, 1.5);
        assert!((f.r - 0.04).abs() < 1e-6, "{}", f.r);
        assert!((f.cos_t + 1.0).abs() < 1e-6);
        // Grazing: total reflection; index-matched: none.
        assert_eq!(dielectric(0.0, 1.5).r, 1.0);
        assert_eq!(dielectric(0.3, 1.0).r, 0.0);
        // Total internal reflection beyond the critical angle from inside.
        let crit = (1.0f32 - (1.0 / 1.5f32).powi(2)).sqrt();
        assert_eq!(dielectric(-(crit - 1e-3), 1.5).r, 1.0);
        assert!(dielectric(-(crit + 1e-3), 1.5).r < 1.0);
        // Reciprocity of reflectance across the interface (Stokes).
        let out = dielectric(0.7, 1.33);
        let inside = dielectric(out.cos_t, 1.33);
        assert!((out.r - inside.r).abs() < 1e-5);
        assert!((inside.cos_t - 0.7).abs() < 1e-5);
    }

    #[test]
    fn conductor_matches_dielectric_for_real_index() {
        for cos in [1.0f32, 0.8, 0.3, 0.05] {
            let c = conductor(cos, Rgb::splat(1.5), Rgb::ZERO).x;
            let d = dielectric(cos, 1.5).r;
            assert!((c - d).abs() < 1e-4, "{cos}: {c} vs {d}");
        }
        // Normal incidence: ((η−1)² + k²)/((η+1)² + k²).
        let (eta, k) = (0.2f32, 3.9f32);
        let expect = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
        let c = conductor(1.0, Rgb::splat(eta), Rgb::splat(k)).x;
        assert!((c - expect).abs() < 1e-5);
    }

    #[test]
    fn diffuse_reflectance_matches_known_values() {
        // d'Eon and Irving's fit (accurate to 0.1 %) for η = 1.5: 0.0918;
        // from inside (1/η): 1 − (1 − 0.0918)/η² = 0.5963.
        assert!((diffuse_reflectance(1.5) - 0.0918).abs() < 1e-3);
        assert!((diffuse_reflectance(1.0 / 1.5) - 0.5963).abs() < 1e-3);
    }
}

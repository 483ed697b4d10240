//! The light table: every light of the frame and the distribution that
//! chooses one per next-event estimate, proportional to power or uniform
//! ([`LightSelection`]).

use crate::settings::LightSelection;
use radiant_core::{Effects, Light};

/// The scene's lights with their selection probabilities.
#[derive(Default)]
pub struct LightTable {
    lights: Vec<Box<dyn Light>>,
    cdf: Vec<f32>,
    pmf: Vec<f32>,
    delta: Vec<bool>,
    environment: Vec<usize>,
}

impl LightTable {
    /// Builds the table; with [`LightSelection::Power`] lights are chosen in
    /// proportion to [`Light::power`] (uniformly if no light reports a
    /// positive power), with [`LightSelection::Uniform`] uniformly.
    pub fn new(lights: Vec<Box<dyn Light>>, selection: LightSelection) -> Self {
        let powers: Vec<f64> = lights
            .iter()
            .map(|l| {
                let p = match selection {
                    LightSelection::Power => l.power() as f64,
                    LightSelection::Uniform => 1.0,
                };
                if p.is_finite() && p > 0.0 { p } else { 0.0 }
            })
            .collect();
        let total: f64 = powers.iter().sum();
        let pmf: Vec<f32> = if total > 0.0 {
            powers.iter().map(|p| (p / total) as f32).collect()
        } else {
            vec![1.0 / lights.len().max(1) as f32; lights.len()]
        };
        let mut acc = 0.0f64;
        let mut cdf: Vec<f32> = pmf
            .iter()
            .map(|&p| {
                acc += p as f64;
                acc as f32
            })
            .collect();
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let delta = lights.iter().map(|l| l.is_delta()).collect();
        let environment = (0..lights.len())
            .filter(|&i| lights[i].effects().contains(Effects::ENVIRONMENT))
            .collect();
        Self {
            lights,
            cdf,
            pmf,
            delta,
            environment,
        }
    }

    /// Puts each `(i, light)` of `replacements` in place of light `i`,
    /// and chooses lights anew by `selection`.
    pub fn replace(
        &mut self,
        replacements: Vec<(usize, Box<dyn Light>)>,
        selection: LightSelection,
    ) {
        let mut lights = std::mem::take(&mut self.lights);
        for (i, light) in replacements {
            lights[i] = light;
        }
        *self = Self::new(lights, selection);
    }

    /// The lights.
    pub fn lights(&self) -> &[Box<dyn Light>] {
        &self.lights
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// Whether there is no light.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// Chooses a light with the uniform sample `u`; returns its index, its
    /// probability, and `u` rescaled to [0, 1) for reuse.
    #[inline]
    pub fn select(&self, u: f32) -> (usize, f32, f32) {
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len() - 1);
        let lo = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let p = self.pmf[i];
        let rescaled = if p > 0.0 {
            ((u - lo) / p).clamp(0.0, 0.999_999_94)
        } else {
            0.0
        };
        (i, p, rescaled)
    }

    /// Whether light `i` is a delta light (cannot be hit, no MIS).
    #[inline]
    pub fn is_delta(&self, i: usize) -> bool {
        self.delta[i]
    }

    /// Indices of the lights that rays leaving the scene can reach (those
    /// whose effects contain [`Effects::ENVIRONMENT`]).
    pub fn environment(&self) -> &[usize] {
        &self.environment
    }

    /// Probability of choosing light `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_core::LightSample;
    use radiant_core::glam::{Vec2, Vec3};

    struct Fixed(f32);
    impl Light for Fixed {
        fn power(&self) -> f32 {
            self.0
        }
        fn is_delta(&self) -> bool {
            true
        }
        fn sample(&self, _: &[Vec3], _: &[Vec2], _: &mut [LightSample]) {}
        fn effects(&self) -> Effects {
            Effects::DELTA_LIGHTS
        }
    }

    fn counts(selection: LightSelection) -> [usize; 3] {
        let table = LightTable::new(
            vec![
                Box::new(Fixed(1.0)),
                Box::new(Fixed(3.0)),
                Box::new(Fixed(0.0)),
            ],
            selection,
        );
        let n = 9_999;
        let mut counts = [0usize; 3];
        for i in 0..n {
            let (l, p, r) = table.select((i as f32 + 0.5) / n as f32);
            counts[l] += 1;
            assert_eq!(p, table.pmf(l));
            assert!((0.0..1.0).contains(&r));
        }
        counts
    }

    #[test]
    fn selection_is_proportional_to_power() {
        let [a, b, c] = counts(LightSelection::Power);
        assert!(a.abs_diff(2500) <= 1 && b.abs_diff(7499) <= 1 && c == 0);
    }

    #[test]
    fn uniform_selection_ignores_power() {
        assert!(
            counts(LightSelection::Uniform)
                .iter()
                .all(|c| c.abs_diff(3333) <= 1)
        );
    }
}

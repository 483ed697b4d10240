//! The order in which the wavefront groups its paths by material.
//!
//! After each bounce the path tracer sorts its live paths by material
//! (`sort_by_key`) and shades each material's slice with one shader call.
//! Next-event estimation reads only the materials with smooth lobes
//! ([`Effects::SMOOTH_LOBES`]): a purely specular one (glass, a mirror, a
//! thin pane) gives every light sample zero weight. Ranking those
//! materials after the others leaves the paths that take light samples as
//! one prefix of the sorted paths, so light selection, light sampling and
//! the shadow-ray set-up run over that prefix alone. Which shader shades
//! which slice is unchanged, and so is every path's result.

use radiant_core::{Effects, Shader};

/// Whether next-event estimation reads `shader`'s light samples: where it
/// has smooth lobes, whose `eval` towards a light sample can be non-zero.
#[inline]
pub(super) fn reads_light_samples(shader: &dyn Shader) -> bool {
    shader.effects().contains(Effects::SMOOTH_LOBES)
}

/// A permutation of a scene's materials: those with smooth lobes first (in
/// material order), then the rest (in material order).
#[derive(Debug, Default)]
pub(super) struct ShadingOrder {
    /// Per material, its rank: the sort key of its paths.
    rank: Vec<u32>,
    /// Per rank, its material.
    material: Vec<u32>,
    /// How many ranks have smooth lobes (the ranks before this).
    lit: usize,
    /// Whether every material's rank is its number (no purely specular
    /// material comes before one with smooth lobes).
    identity: bool,
}

impl ShadingOrder {
    /// Ranks `shaders` (a scene's materials, in material order). Keeps its
    /// buffers: called once per batch, it allocates only when the scene
    /// has more materials than before.
    pub(super) fn update(&mut self, shaders: &[Box<dyn Shader>]) {
        let smooth = |m: &usize| reads_light_samples(shaders[*m].as_ref());
        self.material.clear();
        self.material
            .extend((0..shaders.len()).filter(smooth).map(|m| m as u32));
        self.lit = self.material.len();
        self.material
            .extend((0..shaders.len()).filter(|m| !smooth(m)).map(|m| m as u32));
        self.rank.clear();
        self.rank.resize(shaders.len(), 0);
        for (r, &m) in self.material.iter().enumerate() {
            self.rank[m as usize] = r as u32;
        }
        self.identity = self.rank.iter().enumerate().all(|(m, &r)| r as usize == m);
    }

    /// Whether every material is its own rank, so that a sort may key
    /// paths by material without [`Self::rank`].
    pub(super) fn is_identity(&self) -> bool {
        self.identity
    }

    /// The sort key of material `material`.
    #[inline(always)]
    pub(super) fn rank(&self, material: u32) -> u32 {
        self.rank[material as usize]
    }

    /// The material of rank `rank`.
    #[inline]
    pub(super) fn material(&self, rank: usize) -> usize {
        self.material[rank] as usize
    }

    /// How many paths, of those sorted by rank with `offsets` (as
    /// `sort_by_key` leaves them), are at materials with smooth lobes.
    pub(super) fn lit_paths(&self, offsets: &[u32]) -> usize {
        offsets[self.lit] as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use radiant_core::{BsdfEval, BsdfSample, ShadeContext, SurfaceBatch};

    /// A shader that does nothing but declare `effects`.
    struct Declares(Effects);

    impl Shader for Declares {
        fn sample(
            &self,
            _: &mut ShadeContext<'_>,
            _: SurfaceBatch<'_>,
            _: &[Vec3],
            _: &mut [BsdfSample],
        ) {
        }
        fn eval(
            &self,
            _: &mut ShadeContext<'_>,
            _: SurfaceBatch<'_>,
            _: &[Vec3],
            _: &mut [BsdfEval],
        ) {
        }
        fn effects(&self) -> Effects {
            self.0
        }
    }

    #[test]
    fn smooth_materials_rank_first_and_the_ranks_invert() {
        let (smooth, delta) = (Effects::SMOOTH_LOBES, Effects::DELTA_LOBES);
        let shaders: Vec<Box<dyn Shader>> =
            [delta, smooth, delta | Effects::TRANSMISSION, smooth | delta]
                .into_iter()
                .map(|e| Box::new(Declares(e)) as Box<dyn Shader>)
                .collect();
        let mut order = ShadingOrder::default();
        order.update(&shaders);
        assert_eq!(order.material, [1, 3, 0, 2]);
        assert_eq!(order.lit, 2);
        assert!(!order.is_identity());
        for m in 0..4 {
            assert_eq!(order.material(order.rank(m as u32) as usize), m);
        }
        // Paths per rank 3, 1, 0, 2: the first four are lit.
        assert_eq!(order.lit_paths(&[0, 3, 4, 4, 6]), 4);
        // Again with fewer materials: the buffers shrink with them.
        order.update(&shaders[..1]);
        assert_eq!((order.material.as_slice(), order.lit), ([0].as_slice(), 0));
        assert!(order.is_identity());
        // Smooth materials already first: every material is its own rank.
        order.update(&shaders[1..3]);
        assert!(order.is_identity() && order.lit == 1);
    }
}

//! Acceleration: two levels of bounding volume hierarchies and robust
//! ray queries.
//!
//! The bottom level ([`Blas`]) holds primitives in their own space: all
//! static shapes merged in render space, or one shape in object space — a
//! mesh placed many times, a shape that moves, a mesh that deforms. The
//! top level is a hierarchy over [`Instance`]s, each a bottom level and
//! its placement in render space (none, a fixed transform, or a motion
//! during the shutter). A scene of static shapes alone is one instance
//! without placement, queried directly without a top level, as if there
//! were one hierarchy. Hits name the instance and the primitive; primitives
//! are numbered across all bottom levels (each level's numbers start at
//! its base), so a hit's primitive addresses the shading arrays directly.
//!
//! Both levels are 8-wide BVHs collapsed from obvhs' binary ones
//! ([`hierarchy`]). Queries run the traversal compiled for the best
//! instruction set the CPU has, chosen once per accelerator
//! ([`InstructionSet`]: the baseline, AVX2, or the AVX2 code compiled with
//! AVX-512 F and VL enabled, whose 32 vector registers spill less), up to
//! a limit a benchmark may set ([`limit_instruction_set`]). Triangles use
//! the watertight test of Woop et al. 2013.
//! Spawned rays start at origins offset by a conservative bound on the hit
//! point's floating-point error ([`offset`]), which keeps self-intersection
//! away at every scene scale without a fixed epsilon; instance transforms
//! carry those bounds across ([`instance`]).

/// `$target.$method::<$isa, MOVING, SPHERES>(args)` for the bottom-level
/// flags `$flags` (whether a level moves under the shutter, whether it
/// holds spheres; [`Blas::flags`]): each combination is its own compiled
/// query.
macro_rules! by_flags {
    ($flags:expr, $target:ident.$method:ident::<$isa:ident>($($arg:expr),*)) => {
        match $flags {
            (false, false) => $target.$method::<$isa, false, false>($($arg),*),
            (false, true) => $target.$method::<$isa, false, true>($($arg),*),
            (true, false) => $target.$method::<$isa, true, false>($($arg),*),
            (true, true) => $target.$method::<$isa, true, true>($($arg),*),
        }
    };
}

mod blas;
mod coherent;
pub mod hierarchy;
mod huge;
pub mod instance;
mod instanced;
mod interleave;
pub mod offset;
pub mod prefetch;
pub mod sphere;
pub mod triangle;
mod wide;

pub use crate::settings::BuildQuality;
pub use blas::Blas;
pub use hierarchy::{Update, UpdatePolicy};
pub use instance::{Motion, Placement};

use glam::{Vec3, Vec3A};
use hierarchy::Hierarchy;
use huge::HugeArray;
use obvhs::aabb::Aabb;
use std::borrow::Cow;
use std::marker::PhantomData;
use std::ops::Range;
use std::sync::atomic::{AtomicU8, Ordering};
use std::time::{Duration, Instant};
use wide::{Avx2, Baseline, Isa, LeafCost, LeafVisitor, RayBoxes};

/// A primitive as the intersector sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Primitive {
    /// A triangle by its vertices.
    Triangle([Vec3; 3]),
    /// A sphere by centre and radius.
    Sphere(Vec3, f32),
}

/// The closest hit of a ray.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Hit {
    /// Distance along the ray (in units of the direction's length).
    pub t: f32,
    /// Index of the primitive (numbered across bottom levels, leaf order).
    pub prim: u32,
    /// Index of the instance that was hit.
    pub inst: u32,
    /// Barycentric coordinates of vertices 1 and 2 (triangles only).
    pub b1: f32,
    /// See `b1`.
    pub b2: f32,
}

impl Hit {
    /// What a ray that hits nothing gets from batch queries: `t` infinite,
    /// `prim` `u32::MAX`.
    pub const MISS: Hit = Hit {
        t: f32::INFINITY,
        prim: u32::MAX,
        inst: u32::MAX,
        b1: 0.0,
        b2: 0.0,
    };
}

/// Where an instance's bottom level lies in render space.
#[derive(Debug, Clone, PartialEq)]
pub enum Place {
    /// Already in render space (the merged static shapes).
    Identity,
    /// Through a fixed transform.
    Fixed(Placement),
    /// Through a transform that moves while the shutter is open (boxed:
    /// four matrices, which would make every instance four times larger).
    Moving(Box<Motion>),
}

impl Place {
    /// The placement at shutter time `tau`, `None` for the identity (or
    /// where a motion passes through a singular transform).
    #[inline]
    pub fn at(&self, tau: f32) -> Option<Placement> {
        match self {
            Place::Identity => None,
            Place::Fixed(p) => Some(*p),
            Place::Moving(m) => m.at(tau),
        }
    }
}

/// A bottom level placed in render space.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    /// Index of the bottom level.
    pub blas: u32,
    /// Its placement.
    pub place: Place,
}

/// The scene's acceleration structure: bottom levels, their instances and
/// the top level over them.
pub struct Accel {
    blases: Vec<Blas>,
    /// Per bottom level, the number of its first primitive.
    bases: Vec<u32>,
    instances: Vec<Instance>,
    tlas: Hierarchy,
    /// Instance indices in the top level's leaf order.
    tlas_items: Vec<u32>,
    /// What traversal needs of each instance, in the top level's leaf order
    /// (instances a ray meets one after the other lie side by side).
    tlas_entries: HugeArray<TopEntry>,
    /// Whether queries go straight to instance 0 (one instance, no
    /// placement).
    direct: bool,
    quality: BuildQuality,
    /// The instruction set queries are compiled for (the best the CPU
    /// has within [`limit_instruction_set`]'s limit).
    level: InstructionSet,
    /// Time the last build or update of the top level took.
    pub build_time: Duration,
}

/// The instruction sets a query is compiled for. [`Accel`] picks the best
/// the CPU has, up to the limit [`limit_instruction_set`] sets, once, when
/// it is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum InstructionSet {
    /// The target's baseline: SSE4.2 on x86_64 (the build's
    /// x86-64-v2), portable code elsewhere.
    Baseline,
    /// AVX2: eight box lanes per instruction.
    Avx2,
    /// The AVX2 traversal compiled with AVX-512 (F and VL) enabled: the
    /// same operations, but 32 vector registers instead of 16, so that
    /// fewer of the traversal's per-ray constants are spilled to the stack
    /// and reloaded at every node.
    Avx512,
}

/// The widest instruction set accelerators may use (as a `u8`), set by
/// [`limit_instruction_set`]; no limit by default.
static WIDEST: AtomicU8 = AtomicU8::new(InstructionSet::Avx512 as u8);

/// Accelerators made from now on query with at most `widest`, even where
/// the CPU has wider instructions: to measure on one machine what a CPU
/// without them gets (`radiant render --max-isa avx2` stands in for an
/// AVX2-only CPU on an AVX-512 one). Every instruction set gives the same
/// hits; only the speed differs.
pub fn limit_instruction_set(widest: InstructionSet) {
    WIDEST.store(widest as u8, Ordering::Relaxed);
}

impl InstructionSet {
    /// The levels this CPU supports, worst first.
    fn supported() -> Vec<InstructionSet> {
        let mut levels = vec![InstructionSet::Baseline];
        #[cfg(target_arch = "x86_64")]
        if Avx2::detected() {
            levels.push(InstructionSet::Avx2);
            if std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512vl")
            {
                levels.push(InstructionSet::Avx512);
            }
        }
        levels
    }

    /// The best level this CPU supports up to `widest`.
    fn best_within(widest: InstructionSet) -> InstructionSet {
        InstructionSet::supported()
            .into_iter()
            .rfind(|&level| level <= widest)
            .unwrap_or(InstructionSet::Baseline)
    }

    /// The best level this CPU supports within the limit of
    /// [`limit_instruction_set`].
    pub fn detected() -> InstructionSet {
        let widest = match WIDEST.load(Ordering::Relaxed) {
            0 => InstructionSet::Baseline,
            1 => InstructionSet::Avx2,
            _ => InstructionSet::Avx512,
        };
        InstructionSet::best_within(widest)
    }
}

/// `$accel.$with::<I>(args)` for the instruction set of `$accel.level`:
/// the generic query inlined into a function compiled with that level's
/// target features.
macro_rules! dispatch {
    ($accel:ident.$with:ident($($arg:ident: $ty:ty),* $(,)?) -> $ret:ty) => {{
        let result: $ret;
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2")]
            fn avx2(accel: &Accel, $($arg: $ty),*) -> $ret {
                accel.$with::<Avx2>($($arg),*)
            }
            #[target_feature(enable = "avx2,avx512f,avx512vl")]
            fn avx512(accel: &Accel, $($arg: $ty),*) -> $ret {
                accel.$with::<Avx2>($($arg),*)
            }
            result = match $accel.level {
                InstructionSet::Baseline => $accel.$with::<Baseline>($($arg),*),
                // SAFETY: `level` is only ever a level the CPU supports
                // (`InstructionSet::supported`).
                InstructionSet::Avx2 => unsafe { avx2($accel, $($arg),*) },
                // SAFETY: as above.
                InstructionSet::Avx512 => unsafe { avx512($accel, $($arg),*) },
            };
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            result = $accel.$with::<Baseline>($($arg),*);
        }
        result
    }};
}

impl Accel {
    /// The accelerator over `blases` placed by `instances`; `quality` is
    /// the top level's build quality.
    ///
    /// # Panics
    ///
    /// If an instance names a bottom level that does not exist, or there
    /// are more than 2³² primitives.
    pub fn new(blases: Vec<Blas>, instances: Vec<Instance>, quality: BuildQuality) -> Self {
        let start = Instant::now();
        let mut bases = Vec::with_capacity(blases.len());
        let mut next = 0u32;
        for b in &blases {
            bases.push(next);
            next = next
                .checked_add(b.len() as u32)
                .expect("fewer than 2^32 primitives");
        }
        assert!(instances.iter().all(|i| (i.blas as usize) < blases.len()));
        let direct = matches!(
            instances.as_slice(),
            [Instance {
                blas: 0,
                place: Place::Identity
            }]
        );
        let mut accel = Self {
            blases,
            bases,
            instances,
            tlas: Hierarchy::default(),
            tlas_items: Vec::new(),
            tlas_entries: HugeArray::default(),
            direct,
            quality,
            level: InstructionSet::detected(),
            build_time: Duration::default(),
        };
        accel.build_top_level();
        accel.build_time = start.elapsed();
        accel
    }

    /// One bottom level over `prims` in render space, as its only instance;
    /// returns it and, for each leaf-order index, the index of the
    /// primitive in `prims`.
    pub fn build(prims: &[Primitive], quality: BuildQuality) -> (Self, Vec<u32>) {
        let start = Instant::now();
        let blas = Blas::build(prims, None, quality);
        let order = blas.order().to_vec();
        let instance = Instance {
            blas: 0,
            place: Place::Identity,
        };
        let mut accel = Self::new(vec![blas], vec![instance], quality);
        accel.build_time = start.elapsed();
        (accel, order)
    }

    /// The instances' boxes in render space (containing their motion).
    fn instance_boxes(&self) -> Vec<Option<Aabb>> {
        (0..self.instances.len())
            .map(|i| self.instance_bounds(i))
            .collect()
    }

    /// The render-space box of instance `i` (containing its motion): the
    /// union of its bottom level's top boxes placed, tighter than its
    /// whole box placed where the placement turns it.
    pub fn instance_bounds(&self, i: usize) -> Option<Aabb> {
        let inst = &self.instances[i];
        let blas = &self.blases[inst.blas as usize];
        let placed = match &inst.place {
            Place::Identity => blas.bounds()?,
            Place::Fixed(p) => blas
                .cover()
                .iter()
                .map(|b| p.bounds(b))
                .reduce(|a, b| a.union(&b))?,
            Place::Moving(m) => m.bounds(&blas.bounds()?),
        };
        (placed.min.is_finite() && placed.max.is_finite()).then_some(placed)
    }

    fn build_top_level(&mut self) {
        let boxes = self.instance_boxes();
        let items = &mut self.tlas_items;
        items.clear();
        self.tlas = Hierarchy::build(&boxes, self.quality, LeafCost::INSTANCES, |leaf| {
            store_instances(leaf, items)
        });
        self.lay_out_entries();
    }

    /// Writes the traversal entries in leaf order.
    fn lay_out_entries(&mut self) {
        let (instances, bases) = (&self.instances, &self.bases);
        let items = &self.tlas_items;
        self.tlas_entries = HugeArray::from_fn(items.len(), |k| {
            let i = items[k];
            let inst = &instances[i as usize];
            let (kind, to_object) = match &inst.place {
                Place::Identity => (EntryKind::Identity, glam::Affine3A::IDENTITY),
                Place::Fixed(p) => (EntryKind::Fixed, p.to_object),
                Place::Moving(_) => (EntryKind::Moving, glam::Affine3A::IDENTITY),
            };
            TopEntry::new(
                to_object,
                [i, inst.blas, bases[inst.blas as usize], kind as u32],
            )
        });
    }

    /// Updates the top level after instances moved ([`Accel::instances_mut`])
    /// or bottom levels changed ([`Accel::blas_mut`]): refits it, or
    /// rebuilds it where the refit has degraded past `policy`.
    pub fn update_top_level(&mut self, policy: UpdatePolicy) -> Update {
        let start = Instant::now();
        let boxes = self.instance_boxes();
        let items = &mut self.tlas_items;
        let mut fresh = Vec::new();
        let mut update = self
            .tlas
            .update(&boxes, policy, |leaf| store_instances(leaf, &mut fresh));
        if update.rebuilt {
            *items = fresh;
        }
        self.lay_out_entries();
        update.time = start.elapsed();
        self.build_time = update.time;
        update
    }

    /// The instances, to move them (then call [`Accel::update_top_level`]).
    pub fn instances_mut(&mut self) -> &mut [Instance] {
        &mut self.instances
    }

    /// Whether queries go through a top level (more than one instance, or
    /// one that is placed), rather than straight to one bottom level.
    pub fn has_top_level(&self) -> bool {
        !self.direct
    }

    /// The instances.
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }

    /// Bottom level `i`, to update it (then call
    /// [`Accel::update_top_level`]); its primitive count must stay.
    pub fn blas_mut(&mut self, i: usize) -> &mut Blas {
        &mut self.blases[i]
    }

    /// The bottom levels.
    pub fn blases(&self) -> &[Blas] {
        &self.blases
    }

    /// The number of the first primitive of bottom level `i`.
    pub fn base(&self, i: usize) -> u32 {
        self.bases[i]
    }

    /// The top level (for its SAH cost).
    pub fn top_level(&self) -> &Hierarchy {
        &self.tlas
    }

    /// The primitive `hit` found, in its bottom level's space at shutter
    /// time `tau`, with the instance's placement there (`None`: the
    /// primitive is in render space).
    #[inline(always)]
    pub fn primitive(&self, hit: &Hit, tau: f32) -> (Cow<'_, Primitive>, Option<Placement>) {
        if self.direct {
            return (self.blases[0].primitive(hit.prim as usize, tau), None);
        }
        let inst = &self.instances[hit.inst as usize];
        let (blas, local) = self.located(inst, hit.prim);
        let prim = self.blases[blas].primitive(local, tau);
        (prim, inst.place.at(tau))
    }

    /// The bottom level of instance `inst` and the index there (leaf
    /// order) of its primitive numbered `prim` across bottom levels.
    #[inline(always)]
    fn located(&self, inst: &Instance, prim: u32) -> (usize, usize) {
        let blas = inst.blas as usize;
        (blas, (prim - self.bases[blas]) as usize)
    }

    /// Starts loading the record of `hit`'s instance (its placement) into
    /// the cache; does nothing for a miss or where there are no placed
    /// instances. With thousands of instances the records are rarely
    /// cached, so batch stages ask a few hits ahead of resolving them, and
    /// [`Accel::prefetch_primitive`] reads the record later.
    #[inline(always)]
    pub fn prefetch_instance(&self, hit: &Hit) {
        if let (false, Some(inst)) = (self.direct, self.instances.get(hit.inst as usize)) {
            prefetch::prefetch(inst);
        }
    }

    /// Starts loading `hit`'s primitive, which [`Accel::primitive`] reads,
    /// into the cache; does nothing for a miss. It reads the instance's
    /// record: ask [`Accel::prefetch_instance`] for it a few hits earlier.
    #[inline(always)]
    pub fn prefetch_primitive(&self, hit: &Hit) {
        let (blas, local) = if self.direct {
            (0, hit.prim as usize)
        } else {
            // A miss names no instance.
            let Some(inst) = self.instances.get(hit.inst as usize) else {
                return;
            };
            self.located(inst, hit.prim)
        };
        if let Some(prim) = self
            .blases
            .get(blas)
            .and_then(|b| b.primitives().get(local))
        {
            prefetch::prefetch(prim);
        }
    }

    /// Whether `hit`'s primitive lies in render space as stored (no
    /// placement moves it): then the shading records made in render space
    /// (face frames) serve it. Reads the instance's record.
    #[inline(always)]
    pub fn in_render_space(&self, hit: &Hit) -> bool {
        self.direct
            || self
                .instances
                .get(hit.inst as usize)
                .is_some_and(|inst| matches!(inst.place, Place::Identity))
    }

    /// Finds the closest hit along `origin + t·dir` for `t` in (0, `tmax`).
    #[inline]
    pub fn intersect(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Option<Hit> {
        self.intersect_at(origin, dir, tmax, 0.0)
    }

    /// [`Accel::intersect`] at shutter time `tau`.
    #[inline]
    pub fn intersect_at(&self, origin: Vec3, dir: Vec3, tmax: f32, tau: f32) -> Option<Hit> {
        let hit = dispatch!(self.closest_with(origin: Vec3, dir: Vec3, tmax: f32, tau: f32) -> Hit);
        (hit.prim != Hit::MISS.prim).then_some(hit)
    }

    /// Whether anything blocks `origin + t·dir` for `t` in (0, `tmax`).
    #[inline]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        self.occluded_at(origin, dir, tmax, 0.0)
    }

    /// [`Accel::occluded`] at shutter time `tau`.
    #[inline]
    pub fn occluded_at(&self, origin: Vec3, dir: Vec3, tmax: f32, tau: f32) -> bool {
        dispatch!(self.any_with(origin: Vec3, dir: Vec3, tmax: f32, tau: f32) -> bool)
    }

    /// Closest hits of a batch of rays: for each `slot` in `slots`, the ray
    /// `origins[slot] + t·dirs[slot]`, t in (0, ∞), at shutter time
    /// `times[slot]` (0 without `times`), gets its hit in `hits[slot]`
    /// ([`Hit::MISS`] if it hits nothing). The instruction set is chosen
    /// once for the batch and the loop compiled for it.
    ///
    /// # Panics
    ///
    /// If a slot is out of bounds of `origins`, `dirs`, `times` or `hits`.
    pub fn intersect_slots(
        &self,
        slots: &[u32],
        origins: &[Vec3],
        dirs: &[Vec3],
        times: Option<&[f32]>,
        hits: &mut [Hit],
    ) {
        dispatch!(self.intersect_slots_with(
            slots: &[u32],
            origins: &[Vec3],
            dirs: &[Vec3],
            times: Option<&[f32]>,
            hits: &mut [Hit]
        ) -> ())
    }

    /// [`Self::intersect_slots`] for rays that come in coherent groups:
    /// each eight consecutive slots start at about the same point and head
    /// in about the same direction, as the camera rays of one pixel do.
    /// Where the CPU has AVX2 and no shutter times are given, such a
    /// group is traced as one packet, through both levels
    /// (`accel/coherent.rs`);
    /// every ray gets the hit it gets from [`Self::intersect_slots`], up
    /// to which of two primitives at exactly the same distance is named.
    ///
    /// # Panics
    ///
    /// As [`Self::intersect_slots`].
    pub fn intersect_coherent_slots(
        &self,
        slots: &[u32],
        origins: &[Vec3],
        dirs: &[Vec3],
        times: Option<&[f32]>,
        hits: &mut [Hit],
    ) {
        dispatch!(self.intersect_coherent_slots_with(
            slots: &[u32],
            origins: &[Vec3],
            dirs: &[Vec3],
            times: Option<&[f32]>,
            hits: &mut [Hit]
        ) -> ())
    }

    /// For a batch of shadow rays `origins[j] + t·dirs[j]`, t in
    /// (0, `tmax`), at shutter time `times[j]` (0 without `times`): whether
    /// anything blocks ray `j`, in `blocked[j]`. The instruction set is
    /// chosen once for the batch.
    ///
    /// # Panics
    ///
    /// If the slices differ in length.
    pub fn occluded_each(
        &self,
        origins: &[Vec3],
        dirs: &[Vec3],
        times: Option<&[f32]>,
        tmax: f32,
        blocked: &mut [bool],
    ) {
        assert!(origins.len() == dirs.len() && dirs.len() == blocked.len());
        assert!(times.is_none_or(|t| t.len() == origins.len()));
        dispatch!(self.occluded_each_with(
            origins: &[Vec3],
            dirs: &[Vec3],
            times: Option<&[f32]>,
            tmax: f32,
            blocked: &mut [bool]
        ) -> ())
    }

    /// [`Self::intersect_slots`] with the instruction set `I`.
    #[inline(always)]
    fn intersect_slots_with<I: Isa>(
        &self,
        slots: &[u32],
        origins: &[Vec3],
        dirs: &[Vec3],
        times: Option<&[f32]>,
        hits: &mut [Hit],
    ) {
        match times {
            // One level without shutter times: the rays' traversals
            // interleaved. (Through a top level, interleaved closest-hit
            // walks were measured slower: `instanced.rs`.)
            None if self.direct => self.blases[0].closest_each::<I>(slots, origins, dirs, hits),
            None => {
                for &slot in slots {
                    let i = slot as usize;
                    hits[i] = self.closest_with::<I>(origins[i], dirs[i], f32::INFINITY, 0.0);
                }
            }
            Some(times) => {
                for &slot in slots {
                    let i = slot as usize;
                    hits[i] = self.closest_with::<I>(origins[i], dirs[i], f32::INFINITY, times[i]);
                }
            }
        }
    }

    /// [`Self::occluded_each`] with the instruction set `I`.
    #[inline(always)]
    fn occluded_each_with<I: Isa>(
        &self,
        origins: &[Vec3],
        dirs: &[Vec3],
        times: Option<&[f32]>,
        tmax: f32,
        blocked: &mut [bool],
    ) {
        // Without shutter times the rays' traversals are interleaved: of
        // the one level, or through the top level where the bottom levels
        // share their flags.
        let flags = self.interleaved_flags(times);
        match (times, flags) {
            (None, _) if self.direct => self.blases[0].any_each::<I>(origins, dirs, tmax, blocked),
            (None, Some(flags)) => {
                by_flags!(
                    flags,
                    self.any_each_instanced::<I>(origins, dirs, tmax, blocked)
                )
            }
            (None, None) => {
                for ((b, &o), &d) in blocked.iter_mut().zip(origins).zip(dirs) {
                    *b = self.any_with::<I>(o, d, tmax, 0.0);
                }
            }
            (Some(times), _) => {
                let rays = origins.iter().zip(dirs).zip(times);
                for (b, ((&o, &d), &tau)) in blocked.iter_mut().zip(rays) {
                    *b = self.any_with::<I>(o, d, tmax, tau);
                }
            }
        }
    }

    /// The bottom levels' flags where a batch without shutter `times`
    /// goes through the top level interleaved ([`instanced`]): the flags
    /// every bottom level shares, if they do and the top level is not
    /// empty.
    #[inline(always)]
    fn interleaved_flags(&self, times: Option<&[f32]>) -> Option<(bool, bool)> {
        if times.is_some() || self.direct || self.tlas.wide.is_empty() {
            return None;
        }
        self.uniform_flags()
    }

    /// Queries run the traversal compiled for `level` from now on (to
    /// test one instruction set against another); `level` must be one the
    /// CPU supports.
    #[cfg(test)]
    fn use_level(&mut self, level: InstructionSet) {
        assert!(InstructionSet::supported().contains(&level));
        self.level = level;
    }

    /// The closest hit with the instruction set `I`; [`Hit::MISS`] where
    /// nothing is hit.
    #[inline(always)]
    fn closest_with<I: Isa>(&self, origin: Vec3, dir: Vec3, tmax: f32, tau: f32) -> Hit {
        if self.direct {
            // Instance 0 of bottom level 0, whose primitives start at 0.
            return self.blases[0].closest::<I>(origin, dir, tmax, tau, 0);
        }
        if self.tlas.wide.is_empty() || !ray_is_valid(origin, dir, tmax) {
            return Hit::MISS;
        }
        let mut query = self.top_query::<I>(origin, dir, tau);
        self.tlas
            .wide
            .closest::<I>(&RayBoxes::new(origin, dir), tmax, &mut query);
        query.best
    }

    /// A query of the top level for the ray `origin + t·dir` at shutter
    /// time `tau`.
    #[inline(always)]
    fn top_query<I: Isa>(&self, origin: Vec3, dir: Vec3, tau: f32) -> TopQuery<'_, I> {
        TopQuery {
            accel: self,
            origin,
            dir,
            tau,
            best: Hit::MISS,
            isa: PhantomData,
        }
    }

    /// Whether anything is hit, with the instruction set `I`.
    #[inline(always)]
    fn any_with<I: Isa>(&self, origin: Vec3, dir: Vec3, tmax: f32, tau: f32) -> bool {
        if self.direct {
            return self.blases[0].any::<I>(origin, dir, tmax, tau);
        }
        if self.tlas.wide.is_empty() || !ray_is_valid(origin, dir, tmax) {
            return false;
        }
        let mut query = self.top_query::<I>(origin, dir, tau);
        self.tlas
            .wide
            .any::<I>(&RayBoxes::new(origin, dir), tmax, &mut query)
    }
}

/// Stores one top-level leaf: its instances (input indices) in `items`;
/// returns their range.
fn store_instances(leaf: &[u32], items: &mut Vec<u32>) -> Range<u32> {
    let start = items.len() as u32;
    items.extend_from_slice(leaf);
    start..items.len() as u32
}

/// How a ray enters an instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum EntryKind {
    /// As it is.
    Identity,
    /// Through the entry's `to_object`.
    Fixed,
    /// Through the instance's motion at the ray's time.
    Moving,
}

/// An instance as top-level traversal reads it: one cache line, the
/// render-to-object transform's columns (for [`EntryKind::Fixed`]) with
/// the instance, its bottom level, that level's first primitive number
/// and the [`EntryKind`] in their fourth lanes. Those lanes are stored as
/// `bits ^ ONE_BITS`, normal floats for any count below 2²³, so that the
/// transform's arithmetic, which computes them and throws them away,
/// never meets a subnormal (slow on Intel CPUs).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
struct TopEntry {
    cols: [glam::Vec4; 4],
}

/// The bits of 1.0, which [`TopEntry`]'s fourth lanes are XORed with.
const ONE_BITS: u32 = 0x3F80_0000;

impl TopEntry {
    /// The entry of transform `to_object` and `words`: instance, bottom
    /// level, first primitive number and kind.
    fn new(to_object: glam::Affine3A, words: [u32; 4]) -> Self {
        let m = to_object.matrix3;
        let columns = [m.x_axis, m.y_axis, m.z_axis, to_object.translation];
        Self {
            cols: std::array::from_fn(|i| columns[i].extend(f32::from_bits(words[i] ^ ONE_BITS))),
        }
    }

    /// Render space to object space (for [`EntryKind::Fixed`]).
    #[inline(always)]
    fn transform(&self) -> glam::Affine3A {
        let [x, y, z, w] = self.cols.map(Vec3A::from_vec4);
        glam::Affine3A::from_cols(x, y, z, w)
    }

    #[inline(always)]
    fn word(&self, i: usize) -> u32 {
        self.cols[i].w.to_bits() ^ ONE_BITS
    }

    /// The instance.
    #[inline(always)]
    fn inst(&self) -> u32 {
        self.word(0)
    }

    /// Its bottom level.
    #[inline(always)]
    fn blas(&self) -> u32 {
        self.word(1)
    }

    /// That level's first primitive number.
    #[inline(always)]
    fn base(&self) -> u32 {
        self.word(2)
    }

    /// How a ray enters it.
    #[inline(always)]
    fn kind(&self) -> EntryKind {
        match self.word(3) {
            0 => EntryKind::Identity,
            1 => EntryKind::Fixed,
            _ => EntryKind::Moving,
        }
    }
}

/// One ray's query of the top level: at each leaf, the ray enters each
/// instance's space and traverses its bottom level.
struct TopQuery<'a, I> {
    accel: &'a Accel,
    origin: Vec3,
    dir: Vec3,
    tau: f32,
    best: Hit,
    isa: PhantomData<I>,
}

impl<I: Isa> TopQuery<'_, I> {
    /// The ray in `entry`'s instance space at the query's time: origin,
    /// direction and how far the origin moved along the ray; `None` where
    /// the instance cannot be entered (a singular transform).
    #[inline(always)]
    fn enter(&self, entry: &TopEntry) -> Option<(Vec3, Vec3, f32)> {
        self.accel.enter(entry, self.origin, self.dir, self.tau)
    }
}

impl Accel {
    /// The ray `origin + t·dir` in `entry`'s instance space at shutter
    /// time `tau`: origin, direction and how far the origin moved along
    /// the ray; `None` where the instance cannot be entered (a singular
    /// transform).
    #[inline(always)]
    fn enter(
        &self,
        entry: &TopEntry,
        origin: Vec3,
        dir: Vec3,
        tau: f32,
    ) -> Option<(Vec3, Vec3, f32)> {
        match entry.kind() {
            EntryKind::Identity => Some((origin, dir, 0.0)),
            EntryKind::Fixed => Some(instance::ray_to_object(&entry.transform(), origin, dir)),
            EntryKind::Moving => match &self.instances[entry.inst() as usize].place {
                Place::Moving(m) => Some(m.at(tau)?.ray_to_object(origin, dir)),
                _ => None,
            },
        }
    }
}

impl<I: Isa> LeafVisitor for TopQuery<'_, I> {
    #[inline(always)]
    fn closest(&mut self, range: Range<usize>, mut tmax: f32) -> f32 {
        let accel = self.accel;
        for entry in &accel.tlas_entries[range] {
            let Some((o, d, dt)) = self.enter(entry) else {
                continue;
            };
            let blas = &accel.blases[entry.blas() as usize];
            let hit = blas.closest::<I>(o, d, tmax - dt, self.tau, entry.base());
            if hit.prim != Hit::MISS.prim {
                tmax = hit.t + dt;
                self.best = Hit {
                    t: tmax,
                    inst: entry.inst(),
                    ..hit
                };
            }
        }
        tmax
    }

    #[inline(always)]
    fn any(&mut self, range: Range<usize>, tmax: f32) -> bool {
        let accel = self.accel;
        for entry in &accel.tlas_entries[range] {
            let Some((o, d, dt)) = self.enter(entry) else {
                continue;
            };
            if accel.blases[entry.blas() as usize].any::<I>(o, d, tmax - dt, self.tau) {
                return true;
            }
        }
        false
    }
}

/// Whether a query can hit anything: finite origin and direction, and a
/// positive `tmax` (not NaN). Other rays hit nothing.
#[inline(always)]
fn ray_is_valid(origin: Vec3, dir: Vec3, tmax: f32) -> bool {
    // x·0 is 0 for finite x and NaN for ±∞ and NaN: one comparison checks
    // all six coordinates.
    let zeros = Vec3A::from(origin) * 0.0 + Vec3A::from(dir) * 0.0;
    zeros.cmpeq(Vec3A::ZERO).all() && tmax > 0.0
}

#[cfg(test)]
mod packet_tests;

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use triangle::RayPrep;

    /// A small deterministic generator of uniform numbers in [0, 1), for
    /// the accelerator's tests.
    pub(crate) fn lcg(state: &mut u64) -> f32 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 40) as f32 / (1u64 << 24) as f32
    }

    fn brute_force(prims: &[Primitive], o: Vec3, d: Vec3) -> Option<(f32, usize)> {
        let prep = RayPrep::new(o, d);
        prims
            .iter()
            .enumerate()
            .filter_map(|(i, p)| match *p {
                Primitive::Triangle(v) => {
                    triangle::intersect(&prep, &v, f32::INFINITY).map(|h| (h.0, i))
                }
                Primitive::Sphere(c, r) => {
                    sphere::intersect(o, d, c, r, f32::INFINITY).map(|t| (t, i))
                }
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// A limit picks the best level the CPU has at or below it: the
    /// limit itself where the CPU has it, never a wider one.
    #[test]
    fn the_instruction_set_limit_caps_the_level() {
        let supported = InstructionSet::supported();
        let best = *supported.last().expect("the baseline at least");
        for widest in [
            InstructionSet::Baseline,
            InstructionSet::Avx2,
            InstructionSet::Avx512,
        ] {
            let level = InstructionSet::best_within(widest);
            assert!(level <= widest, "{widest:?} gave {level:?}");
            assert!(supported.contains(&level));
            assert_eq!(level, best.min(widest), "{widest:?}");
        }
    }

    #[test]
    fn bvh_agrees_with_brute_force_on_random_soups() {
        for (seed, count) in [(1u64, 1usize), (2, 2), (3, 50), (4, 2000)] {
            let mut s = seed;
            let mut prims = Vec::new();
            for i in 0..count {
                let c = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 10.0 - 5.0;
                if i % 10 == 9 {
                    prims.push(Primitive::Sphere(c, 0.1 + lcg(&mut s)));
                } else {
                    let mut v =
                        || c + (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5) * 2.0;
                    prims.push(Primitive::Triangle([v(), v(), v()]));
                }
            }
            let (accel, order) = Accel::build(&prims, BuildQuality::Medium);
            // Every instruction set the CPU has gives the same answers.
            let others: Vec<Accel> = InstructionSet::supported()
                .into_iter()
                .map(|level| {
                    let mut other = Accel::build(&prims, BuildQuality::Medium).0;
                    other.use_level(level);
                    other
                })
                .collect();
            for _ in 0..2000 {
                let o = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 16.0 - 8.0;
                let d = (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5).normalize();
                let expected = brute_force(&prims, o, d);
                let got = accel.intersect(o, d, f32::INFINITY);
                match (expected, got) {
                    (None, None) => {}
                    (Some((t, i)), Some(h)) => {
                        assert!((t - h.t).abs() <= 1e-5 * t.max(1.0), "t {t} vs {}", h.t);
                        // Equal distances may pick either primitive.
                        if order[h.prim as usize] as usize != i {
                            assert_eq!(t, h.t);
                        }
                    }
                    other => panic!("BVH and brute force disagree: {other:?}"),
                }
                assert_eq!(accel.occluded(o, d, f32::INFINITY), expected.is_some());
                if let Some((t, _)) = expected {
                    assert!(!accel.occluded(o, d, t * 0.999));
                }
                for other in &others {
                    assert_eq!(
                        other.intersect(o, d, f32::INFINITY),
                        got,
                        "{:?}",
                        other.level
                    );
                    for tmax in [f32::INFINITY, got.map_or(1.0, |h| h.t * 0.999)] {
                        assert_eq!(other.occluded(o, d, tmax), accel.occluded(o, d, tmax));
                    }
                }
            }
        }
    }

    #[test]
    fn empty_scene_hits_nothing() {
        let (accel, _) = Accel::build(&[], BuildQuality::Fast);
        assert!(
            accel
                .intersect(Vec3::ZERO, Vec3::Z, f32::INFINITY)
                .is_none()
        );
        assert!(!accel.occluded(Vec3::ZERO, Vec3::Z, f32::INFINITY));
    }

    #[test]
    fn single_primitive_scenes() {
        let tri = Primitive::Triangle([Vec3::ZERO, Vec3::X, Vec3::Y]);
        let (accel, order) = Accel::build(&[tri], BuildQuality::Medium);
        assert_eq!(order, [0]);
        let hit = accel.intersect(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, f32::INFINITY);
        assert_eq!(hit.map(|h| (h.t, h.prim)), Some((1.0, 0)));
        assert!(accel.occluded(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 2.0));
        assert!(!accel.occluded(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 1.0));

        let (accel, _) = Accel::build(&[Primitive::Sphere(Vec3::ZERO, 1.0)], BuildQuality::Fast);
        let hit = accel.intersect(Vec3::new(0.0, 0.0, -3.0), Vec3::Z, f32::INFINITY);
        assert_eq!(hit.map(|h| (h.t, h.prim)), Some((2.0, 0)));
    }

    #[test]
    fn degenerate_and_non_finite_primitives_are_never_hit() {
        let good = Primitive::Triangle([
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(3.0, -1.0, 0.0),
            Vec3::new(-1.0, 3.0, 0.0),
        ]);
        let prims = [
            // Zero area: collinear, a repeated vertex, a point.
            Primitive::Triangle([Vec3::ZERO, Vec3::new(0.5, 0.5, 0.5), Vec3::ONE]),
            Primitive::Triangle([Vec3::ZERO, Vec3::ZERO, Vec3::Y]),
            Primitive::Triangle([Vec3::splat(0.3); 3]),
            // Needles: long and thin, in front of the good triangle.
            Primitive::Triangle([
                Vec3::new(0.0, 0.0, 0.5),
                Vec3::new(1.0, 0.0, 0.5),
                Vec3::new(0.5, 1e-7, 0.5),
            ]),
            Primitive::Triangle([
                Vec3::new(0.0, 0.3, 0.6),
                Vec3::new(1.0, 0.3, 0.6),
                Vec3::new(0.0, 0.3, 0.6 + 1e-30),
            ]),
            // Not finite.
            Primitive::Triangle([Vec3::NAN, Vec3::X, Vec3::Y]),
            Primitive::Triangle([Vec3::INFINITY, Vec3::X, Vec3::Y]),
            Primitive::Sphere(Vec3::new(f32::NAN, 0.0, 0.0), 1.0),
            Primitive::Sphere(Vec3::ZERO, f32::INFINITY),
            good,
        ];
        let (accel, order) = Accel::build(&prims, BuildQuality::Medium);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..prims.len() as u32).collect::<Vec<_>>());
        let mut s = 9;
        for _ in 0..5000 {
            let target = Vec3::new(lcg(&mut s), lcg(&mut s), 0.0) * 0.99;
            let o = Vec3::new(lcg(&mut s) - 0.5, lcg(&mut s) - 0.5, 2.0);
            let d = target - o;
            let hit = accel.intersect(o, d, f32::INFINITY);
            let h = hit.unwrap_or_else(|| panic!("ray to {target} missed"));
            assert!(h.t.is_finite() && h.b1.is_finite() && h.b2.is_finite());
            // Needles may be hit, and so may the collinear triangle (its
            // projection is a sliver after rounding); triangles with a
            // repeated vertex and non-finite primitives never.
            let input = order[h.prim as usize] as usize;
            assert!(matches!(input, 0 | 3 | 4 | 9), "hit primitive {input}");
            if input == 9 {
                assert!((h.t - 1.0).abs() < 1e-6);
            }
            assert!(accel.occluded(o, d, f32::INFINITY));
        }
    }

    #[test]
    fn bad_rays_hit_nothing() {
        let (accel, _) = Accel::build(
            &[
                Primitive::Triangle([-Vec3::X, Vec3::X, Vec3::Y]),
                Primitive::Sphere(Vec3::Z, 0.5),
            ],
            BuildQuality::Medium,
        );
        let (o, d) = (Vec3::new(0.0, 0.2, -1.0), Vec3::Z);
        assert!(accel.intersect(o, d, f32::INFINITY).is_some());
        for (o, d, tmax) in [
            (Vec3::NAN, d, f32::INFINITY),
            (o, Vec3::NAN, f32::INFINITY),
            (o, Vec3::ZERO, f32::INFINITY),
            (Vec3::INFINITY, -Vec3::ONE, f32::INFINITY),
            (o, d, f32::NAN),
            (o, d, 0.0),
            (o, d, -1.0),
        ] {
            assert_eq!(accel.intersect(o, d, tmax), None, "{o} {d} {tmax}");
            assert!(!accel.occluded(o, d, tmax), "{o} {d} {tmax}");
        }
    }

    /// A plane of `n`×`n` axis-aligned squares of side ½ at z = 0, two
    /// triangles each: edges and vertices shared everywhere.
    pub(super) fn tiles(n: i32) -> Vec<Primitive> {
        let mut prims = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let p = |di: i32, dj: i32| Vec3::new((i + di) as f32, (j + dj) as f32, 0.0) * 0.5;
                prims.push(Primitive::Triangle([p(0, 0), p(1, 0), p(1, 1)]));
                prims.push(Primitive::Triangle([p(0, 0), p(1, 1), p(0, 1)]));
            }
        }
        prims
    }

    #[test]
    fn axis_aligned_rays_find_flat_tiles_at_shared_edges() {
        // A plane of axis-aligned unit squares (flat boxes in every node);
        // rays straight down (two direction components zero) at every tile
        // corner and edge midpoint must hit, whatever the BVH looks like.
        let n = 12;
        let (accel, _) = Accel::build(&tiles(n), BuildQuality::Medium);
        for i in 0..=2 * n {
            for j in 0..=2 * n {
                let o = Vec3::new(i as f32, j as f32, 4.0) * Vec3::new(0.25, 0.25, 1.0);
                for d in [
                    -Vec3::Z,
                    Vec3::new(0.0, 1e-3, -1.0),
                    Vec3::new(-1e-3, 0.0, -1.0),
                ] {
                    let target = o + d * 4.0 / -d.z;
                    let inside = target.x >= 0.0
                        && target.y >= 0.0
                        && target.x <= 0.5 * n as f32
                        && target.y <= 0.5 * n as f32;
                    if inside {
                        let hit = accel.intersect(o, d, f32::INFINITY);
                        assert!(
                            hit.is_some(),
                            "ray down at ({}, {}) along {d} leaked",
                            o.x,
                            o.y
                        );
                        assert!(accel.occluded(o, d, f32::INFINITY));
                    }
                }
            }
        }
    }

    #[test]
    fn coincident_primitives_build_a_usable_hierarchy() {
        // Thousands of identical triangles give the builder nothing to
        // split; traversal must stay within its stack and find them.
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let mut prims = vec![Primitive::Triangle(tri); 5000];
        prims.push(Primitive::Triangle(tri.map(|v| v + Vec3::Z)));
        let (accel, order) = Accel::build(&prims, BuildQuality::High);
        let hit = accel.intersect(Vec3::new(0.2, 0.2, 2.0), -Vec3::Z, f32::INFINITY);
        assert_eq!(
            hit.map(|h| (h.t, order[h.prim as usize])),
            Some((1.0, 5000))
        );
        let hit = accel.intersect(Vec3::new(0.2, 0.2, 0.5), -Vec3::Z, f32::INFINITY);
        assert_eq!(hit.map(|h| h.t), Some(0.5));
        assert!(accel.occluded(Vec3::new(0.2, 0.2, 0.5), -Vec3::Z, 1.0));
        assert!(!accel.occluded(Vec3::new(0.2, 0.2, 0.5), Vec3::Z, 0.4));
    }

    /// Random triangles and spheres around the origin, in object space.
    pub(super) fn object(seed: u64, n: usize) -> Vec<Primitive> {
        let mut s = seed;
        (0..n)
            .map(|i| {
                let c = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 2.0 - 1.0;
                if i % 7 == 6 {
                    Primitive::Sphere(c, 0.05 + 0.1 * lcg(&mut s))
                } else {
                    let mut v =
                        || c + (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5) * 0.5;
                    Primitive::Triangle([v(), v(), v()])
                }
            })
            .collect()
    }

    /// `prims` moved to render space by `m` (spheres by a similarity).
    pub(super) fn placed(prims: &[Primitive], m: glam::DMat4) -> Vec<Primitive> {
        let p = |v: Vec3| m.transform_point3(v.as_dvec3()).as_vec3();
        let scale = m.transform_vector3(glam::DVec3::X).length() as f32;
        prims
            .iter()
            .map(|prim| match *prim {
                Primitive::Triangle(v) => Primitive::Triangle(v.map(p)),
                Primitive::Sphere(c, r) => Primitive::Sphere(p(c), r * scale),
            })
            .collect()
    }

    /// Similarity transforms for instances (spheres stay spheres).
    pub(super) fn placements(seed: u64, n: usize) -> Vec<glam::DMat4> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                let axis = (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5)
                    .normalize()
                    .as_dvec3();
                glam::DMat4::from_scale_rotation_translation(
                    glam::DVec3::splat(0.5 + f64::from(lcg(&mut s))),
                    glam::DQuat::from_axis_angle(axis, f64::from(lcg(&mut s)) * 6.0),
                    (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 12.0 - 6.0).as_dvec3(),
                )
            })
            .collect()
    }

    /// Bottom levels and instances: `statics` in render space (instance 0
    /// of level 0), `shape` placed by each of `places` (level 1).
    pub(super) fn two_levels(
        statics: &[Primitive],
        shape: &[Primitive],
        places: &[glam::DMat4],
    ) -> (Vec<Blas>, Vec<Instance>) {
        let blases = vec![
            Blas::build(statics, None, BuildQuality::Medium),
            Blas::build(shape, None, BuildQuality::Medium),
        ];
        let mut instances = vec![Instance {
            blas: 0,
            place: Place::Identity,
        }];
        instances.extend(places.iter().map(|m| Instance {
            blas: 1,
            place: Place::Fixed(Placement::new(*m).expect("invertible")),
        }));
        (blases, instances)
    }

    #[test]
    fn two_levels_find_the_hits_of_one() {
        // Two shapes: one static in render space, one instanced five times.
        let statics = object(1, 300);
        let shape = object(2, 200);
        let places = placements(3, 5);
        let mut flat = statics.clone();
        for m in &places {
            flat.extend(placed(&shape, *m));
        }
        let (one, order) = Accel::build(&flat, BuildQuality::Medium);
        let (blases, instances) = two_levels(&statics, &shape, &places);
        let two = Accel::new(blases, instances, BuildQuality::Medium);
        assert!(!two.direct);
        // The flat soup's primitive `i` as (instance, primitive of its shape).
        let identity = |i: usize| {
            if i < statics.len() {
                (0, i)
            } else {
                let k = i - statics.len();
                (1 + k / shape.len(), k % shape.len())
            }
        };
        let mut s = 9;
        let mut hits = 0;
        for _ in 0..20_000 {
            let o = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 20.0 - 10.0;
            let target = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 12.0 - 6.0;
            let d = (target - o).normalize();
            let a = one.intersect(o, d, f32::INFINITY);
            let b = two.intersect(o, d, f32::INFINITY);
            match (a, b) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    hits += 1;
                    // Instances see the ray through a transform: equal up to
                    // its rounding.
                    assert!(
                        (a.t - b.t).abs() <= 1e-4 * a.t.max(1.0),
                        "t {} vs {}",
                        a.t,
                        b.t
                    );
                    let (inst, local) = identity(order[a.prim as usize] as usize);
                    let blas = two.instances[b.inst as usize].blas as usize;
                    let got = two.blases[blas].order()[(b.prim - two.bases[blas]) as usize];
                    if (b.inst as usize, got as usize) != (inst, local) {
                        assert!((a.t - b.t).abs() <= 1e-4 * a.t.max(1.0));
                    }
                }
                // A graze at an edge may go either way after a transform.
                (a, b) => {
                    let t = a.or(b).map_or(0.0, |h| h.t);
                    assert!(
                        one.occluded(o, d, t * 1.001) && !one.occluded(o, d, t * 0.999)
                            || two.occluded(o, d, t * 1.001),
                        "one and two levels disagree: {a:?} vs {b:?}"
                    );
                }
            }
            let tmax = lcg(&mut s) * 10.0;
            if one.occluded(o, d, tmax * 0.999) {
                assert!(two.occluded(o, d, tmax), "shadow ray leaked");
            }
        }
        assert!(hits > 2000, "only {hits} rays hit");
    }

    /// A motion over the shutter: moved, turned and grown.
    pub(super) fn swing() -> Motion {
        Motion {
            outer: glam::DMat4::from_translation(glam::DVec3::new(0.0, 0.0, -3.0)),
            open: crate::world::Trs::IDENTITY,
            close: crate::world::Trs {
                translate: glam::DVec3::new(2.0, 0.5, 0.0),
                rotate: glam::DQuat::from_rotation_y(2.5),
                scale: glam::DVec3::splat(1.5),
            },
            inner: glam::DMat4::from_translation(glam::DVec3::new(0.5, 0.0, 0.0)),
        }
    }

    #[test]
    fn a_moving_instance_is_hit_where_it_is_at_the_ray_time() {
        let shape = object(4, 150);
        let motion = swing();
        let moving = Accel::new(
            vec![Blas::build(&shape, None, BuildQuality::Medium)],
            vec![Instance {
                blas: 0,
                place: Place::Moving(Box::new(motion)),
            }],
            BuildQuality::Medium,
        );
        let mut s = 21;
        let mut hits = 0;
        for _ in 0..4000 {
            let tau = lcg(&mut s);
            let fixed = Accel::new(
                vec![Blas::build(&shape, None, BuildQuality::Medium)],
                vec![Instance {
                    blas: 0,
                    place: Place::Fixed(motion.at(tau).expect("invertible")),
                }],
                BuildQuality::Medium,
            );
            let o = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 8.0 - 4.0;
            let target =
                Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 4.0 - Vec3::new(1.0, 2.0, 5.0);
            let d = (target - o).normalize();
            let a = moving.intersect_at(o, d, f32::INFINITY, tau);
            let b = fixed.intersect(o, d, f32::INFINITY);
            assert_eq!(
                a.map(|h| (h.t, h.prim)),
                b.map(|h| (h.t, h.prim)),
                "τ {tau}"
            );
            assert_eq!(
                moving.occluded_at(o, d, 5.0, tau),
                fixed.occluded(o, d, 5.0),
                "τ {tau}"
            );
            hits += usize::from(a.is_some());
        }
        assert!(hits > 300, "only {hits} rays hit");
    }

    #[test]
    fn the_top_level_follows_moved_instances() {
        let shape = object(5, 100);
        let start = placements(6, 40);
        let end = placements(7, 40);
        let build = |ms: &[glam::DMat4]| {
            Accel::new(
                vec![Blas::build(&shape, None, BuildQuality::Medium)],
                ms.iter()
                    .map(|m| Instance {
                        blas: 0,
                        place: Place::Fixed(Placement::new(*m).expect("invertible")),
                    })
                    .collect(),
                BuildQuality::Medium,
            )
        };
        let fresh = build(&end);
        for rebuild_above in [f32::INFINITY, 0.0] {
            let mut moved = build(&start);
            for (inst, m) in moved.instances_mut().iter_mut().zip(&end) {
                inst.place = Place::Fixed(Placement::new(*m).expect("invertible"));
            }
            let update = moved.update_top_level(UpdatePolicy { rebuild_above });
            assert_eq!(update.rebuilt, rebuild_above == 0.0);
            let mut s = 33;
            for _ in 0..5000 {
                let o = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 20.0 - 10.0;
                let d = (Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) - 0.5).normalize();
                let key = |h: Option<Hit>| h.map(|h| (h.t, h.inst, h.prim));
                assert_eq!(
                    key(moved.intersect(o, d, f32::INFINITY)),
                    key(fresh.intersect(o, d, f32::INFINITY))
                );
            }
        }
    }
}

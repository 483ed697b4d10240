//! Keyframe tracks and their interpolation.
//!
//! A [`Track`] holds keys at strictly increasing times (seconds) and
//! evaluates to a value at any time: `step` holds a key's value until the
//! next key, `linear` interpolates straight (rotations by shortest-path
//! slerp), `smooth` follows a Catmull–Rom spline (cubic Hermite segments
//! whose tangents are the finite differences of the neighbouring keys).
//! Before the first key and after the last, a track holds the end key's
//! value. The scene loader builds tracks from `keyframes:` in YAML; the
//! animation systems ([`super::systems`]) evaluate them each frame.

use glam::{DMat4, DQuat, DVec3};

/// How a track moves from one key to the next.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Interpolation {
    /// The key's value until the next key.
    Step,
    /// Straight lines between keys (shortest-path slerp for rotations).
    #[default]
    Linear,
    /// A Catmull–Rom spline through the keys.
    Smooth,
}

impl Interpolation {
    /// The names the scene file uses.
    pub const NAMES: &'static [&'static str] = &["step", "linear", "smooth"];

    /// The interpolation called `name` in the scene file.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "step" => Some(Self::Step),
            "linear" => Some(Self::Linear),
            "smooth" => Some(Self::Smooth),
            _ => None,
        }
    }
}

/// A value that keys can hold and tracks can blend.
pub trait Keyable: Clone + PartialEq {
    /// The value a fraction `s` in [0, 1] of the way from `a` to `b`.
    fn lerp(a: &Self, b: &Self, s: f64) -> Self;

    /// The cubic Hermite segment from `a` (tangent `ta`·`dt`) to `b`
    /// (tangent `tb`·`dt`) at fraction `s`, where the tangents are given by
    /// the neighbouring keys: `prev` before `a` (at relative time `-da`)
    /// and `next` after `b` (at `1 + db`), both in units of the segment's
    /// length. The default is the linear blend.
    fn hermite(prev: &Self, a: &Self, b: &Self, next: &Self, (da, db): (f64, f64), s: f64) -> Self {
        let _ = (prev, next, da, db);
        Self::lerp(a, b, s)
    }
}

/// Catmull–Rom tangents of a segment [a, b] of unit length, with `prev` at
/// relative time −`da` and `next` at 1 + `db`: m = (p₊ − p₋)/(t₊ − t₋),
/// one-sided where a neighbour is the segment's own end (`da` or `db` 0).
fn tangents(prev: f64, a: f64, b: f64, next: f64, da: f64, db: f64) -> (f64, f64) {
    let ma = (b - prev) / (1.0 + da);
    let mb = (next - a) / (1.0 + db);
    (ma, mb)
}

/// The cubic Hermite blend of `a` and `b` with tangents `ma` and `mb` (per
/// segment length) at `s`.
fn hermite(a: f64, b: f64, ma: f64, mb: f64, s: f64) -> f64 {
    let s2 = s * s;
    let s3 = s2 * s;
    (2.0 * s3 - 3.0 * s2 + 1.0) * a
        + (s3 - 2.0 * s2 + s) * ma
        + (-2.0 * s3 + 3.0 * s2) * b
        + (s3 - s2) * mb
}

impl Keyable for f64 {
    fn lerp(a: &Self, b: &Self, s: f64) -> Self {
        a + (b - a) * s
    }

    fn hermite(prev: &Self, a: &Self, b: &Self, next: &Self, (da, db): (f64, f64), s: f64) -> Self {
        let (ma, mb) = tangents(*prev, *a, *b, *next, da, db);
        hermite(*a, *b, ma, mb, s)
    }
}

impl Keyable for DVec3 {
    fn lerp(a: &Self, b: &Self, s: f64) -> Self {
        a.lerp(*b, s)
    }

    fn hermite(prev: &Self, a: &Self, b: &Self, next: &Self, d: (f64, f64), s: f64) -> Self {
        let c = |i: usize| f64::hermite(&prev[i], &a[i], &b[i], &next[i], d, s);
        DVec3::new(c(0), c(1), c(2))
    }
}

/// Lists of numbers (module parameters: a number, a colour, a point).
impl Keyable for Vec<f64> {
    fn lerp(a: &Self, b: &Self, s: f64) -> Self {
        a.iter().zip(b).map(|(a, b)| f64::lerp(a, b, s)).collect()
    }

    fn hermite(prev: &Self, a: &Self, b: &Self, next: &Self, d: (f64, f64), s: f64) -> Self {
        (0..a.len())
            .map(|i| f64::hermite(&prev[i], &a[i], &b[i], &next[i], d, s))
            .collect()
    }
}

impl Keyable for DQuat {
    /// Shortest-path slerp: `b` or `−b`, whichever is nearer to `a`.
    fn lerp(a: &Self, b: &Self, s: f64) -> Self {
        slerp(*a, *b, s)
    }

    /// The Hermite spline on the quaternions' components, each key's sign
    /// chosen nearest to the one before it, then normalised: smooth, and
    /// through every key.
    fn hermite(prev: &Self, a: &Self, b: &Self, next: &Self, d: (f64, f64), s: f64) -> Self {
        let near = |q: DQuat, to: DQuat| if q.dot(to) < 0.0 { -q } else { q };
        let prev = near(*prev, *a);
        let b = near(*b, *a);
        let next = near(*next, b);
        let c = |f: fn(&DQuat) -> f64| f64::hermite(&f(&prev), &f(a), &f(&b), &f(&next), d, s);
        DQuat::from_xyzw(c(|q| q.x), c(|q| q.y), c(|q| q.z), c(|q| q.w)).normalize()
    }
}

/// Spherical linear interpolation along the shorter arc between unit
/// quaternions `a` and `b` (which may differ in sign: q and −q are the
/// same rotation).
pub fn slerp(a: DQuat, b: DQuat, s: f64) -> DQuat {
    let mut cos = a.dot(b);
    let b = if cos < 0.0 {
        cos = -cos;
        -b
    } else {
        b
    };
    if cos > 1.0 - 1e-12 {
        // Nearly the same rotation: the chord is the arc.
        return (a + (b - a) * s).normalize();
    }
    let angle = cos.clamp(-1.0, 1.0).acos();
    let sin = angle.sin();
    let wa = ((1.0 - s) * angle).sin() / sin;
    let wb = (s * angle).sin() / sin;
    (a * wa + b * wb).normalize()
}

/// One key of a track: a time in seconds and the value there.
#[derive(Debug, Clone, PartialEq)]
pub struct Key<T> {
    /// Seconds.
    pub time: f64,
    /// The value at `time`.
    pub value: T,
}

/// Why keys do not make a track.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TrackError {
    /// No keys at all.
    #[error("a track needs at least one key")]
    Empty,
    /// Key `index` is not after the key before it.
    #[error(
        "keys must be in strictly increasing time order: key {index} (time {time} s) is not after the key before it (time {before} s)"
    )]
    OutOfOrder {
        /// The offending key, counted from 0.
        index: usize,
        /// Its time.
        time: String,
        /// The time of the key before it.
        before: String,
    },
    /// A key's time is not finite.
    #[error("key {0}'s time is not a finite number")]
    NonFinite(usize),
}

/// Keys at strictly increasing times and how to move between them.
#[derive(Debug, Clone, PartialEq)]
pub struct Track<T> {
    keys: Vec<Key<T>>,
    interpolation: Interpolation,
}

impl<T: Keyable> Track<T> {
    /// A track through `keys`; the times must be finite and strictly
    /// increasing.
    pub fn new(keys: Vec<Key<T>>, interpolation: Interpolation) -> Result<Self, TrackError> {
        if keys.is_empty() {
            return Err(TrackError::Empty);
        }
        for (i, k) in keys.iter().enumerate() {
            if !k.time.is_finite() {
                return Err(TrackError::NonFinite(i));
            }
            if i > 0 && k.time <= keys[i - 1].time {
                return Err(TrackError::OutOfOrder {
                    index: i,
                    time: k.time.to_string(),
                    before: keys[i - 1].time.to_string(),
                });
            }
        }
        Ok(Self {
            keys,
            interpolation,
        })
    }

    /// A track that always has `value`.
    pub fn constant(value: T) -> Self {
        Self {
            keys: vec![Key { time: 0.0, value }],
            interpolation: Interpolation::Step,
        }
    }

    /// The keys.
    pub fn keys(&self) -> &[Key<T>] {
        &self.keys
    }

    /// Whether the value never changes.
    pub fn is_constant(&self) -> bool {
        self.keys.windows(2).all(|w| w[0].value == w[1].value)
    }

    /// The value at `time` seconds.
    pub fn at(&self, time: f64) -> T {
        let keys = &self.keys;
        // The first key after `time`.
        let next = keys.partition_point(|k| k.time <= time);
        if next == 0 {
            return keys[0].value.clone();
        }
        if next == keys.len() {
            return keys[keys.len() - 1].value.clone();
        }
        let (a, b) = (&keys[next - 1], &keys[next]);
        let span = b.time - a.time;
        let s = ((time - a.time) / span).clamp(0.0, 1.0);
        match self.interpolation {
            Interpolation::Step => a.value.clone(),
            Interpolation::Linear => T::lerp(&a.value, &b.value, s),
            Interpolation::Smooth => {
                // Neighbours: the keys around the segment, or its own ends
                // (a one-sided tangent) at the track's ends.
                let (prev, da) = match next.checked_sub(2) {
                    Some(p) => (&keys[p].value, (a.time - keys[p].time) / span),
                    None => (&a.value, 0.0),
                };
                let (after, db) = match keys.get(next + 1) {
                    Some(n) => (&n.value, (n.time - b.time) / span),
                    None => (&b.value, 0.0),
                };
                T::hermite(prev, &a.value, &b.value, after, (da, db), s)
            }
        }
    }
}

/// A rigid-body-and-scale pose: scale, then rotation, then translation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trs {
    /// Translation.
    pub translate: DVec3,
    /// Rotation (unit quaternion).
    pub rotate: DQuat,
    /// Scale per axis.
    pub scale: DVec3,
}

impl Trs {
    /// No change.
    pub const IDENTITY: Trs = Trs {
        translate: DVec3::ZERO,
        rotate: DQuat::IDENTITY,
        scale: DVec3::ONE,
    };

    /// The matrix T·R·S.
    pub fn matrix(&self) -> DMat4 {
        DMat4::from_scale_rotation_translation(self.scale, self.rotate, self.translate)
    }

    /// The pose a fraction `s` of the way from `a` to `b`: translation and
    /// scale linearly, rotation by shortest-path slerp (as motion blur
    /// moves an instance between shutter open and close).
    pub fn lerp(a: &Trs, b: &Trs, s: f64) -> Trs {
        Trs {
            translate: a.translate.lerp(b.translate, s),
            rotate: slerp(a.rotate, b.rotate, s),
            scale: a.scale.lerp(b.scale, s),
        }
    }
}

/// The translation, rotation and scale tracks of an entity (`animation:`
/// on a shape, light or camera); a missing track is the identity.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TransformTracks {
    /// Translation track.
    pub translate: Option<Track<DVec3>>,
    /// Rotation track.
    pub rotate: Option<Track<DQuat>>,
    /// Scale track.
    pub scale: Option<Track<DVec3>>,
}

impl TransformTracks {
    /// The pose at `time` seconds.
    pub fn at(&self, time: f64) -> Trs {
        Trs {
            translate: self.translate.as_ref().map_or(DVec3::ZERO, |t| t.at(time)),
            rotate: self.rotate.as_ref().map_or(DQuat::IDENTITY, |t| t.at(time)),
            scale: self.scale.as_ref().map_or(DVec3::ONE, |t| t.at(time)),
        }
    }

    /// Whether the pose never changes.
    pub fn is_constant(&self) -> bool {
        self.translate.as_ref().is_none_or(Track::is_constant)
            && self.rotate.as_ref().is_none_or(Track::is_constant)
            && self.scale.as_ref().is_none_or(Track::is_constant)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track(keys: &[(f64, f64)], i: Interpolation) -> Track<f64> {
        let keys = keys
            .iter()
            .map(|&(time, value)| Key { time, value })
            .collect();
        Track::new(keys, i).expect("valid keys")
    }

    #[test]
    fn keys_must_be_strictly_increasing() {
        let k = |time| Key { time, value: 1.0 };
        assert_eq!(
            Track::<f64>::new(vec![], Interpolation::Linear),
            Err(TrackError::Empty)
        );
        for bad in [vec![k(0.0), k(0.0)], vec![k(1.0), k(0.5)]] {
            assert!(matches!(
                Track::new(bad, Interpolation::Linear),
                Err(TrackError::OutOfOrder { index: 1, .. })
            ));
        }
        assert_eq!(
            Track::new(vec![k(0.0), k(f64::NAN)], Interpolation::Step),
            Err(TrackError::NonFinite(1))
        );
    }

    #[test]
    fn values_at_and_between_keys() {
        let keys = [(0.0, 1.0), (1.0, 3.0), (3.0, -1.0)];
        let step = track(&keys, Interpolation::Step);
        let linear = track(&keys, Interpolation::Linear);
        let smooth = track(&keys, Interpolation::Smooth);
        for t in [&step, &linear, &smooth] {
            // At the keys, every interpolation gives the key's value.
            for &(time, value) in &keys {
                assert!((t.at(time) - value).abs() < 1e-12, "{t:?} at {time}");
            }
            // Held before the first key and after the last.
            assert_eq!(t.at(-5.0), 1.0);
            assert_eq!(t.at(10.0), -1.0);
        }
        assert_eq!(step.at(0.999), 1.0);
        assert_eq!(step.at(2.0), 3.0);
        assert!((linear.at(0.25) - 1.5).abs() < 1e-12);
        assert!((linear.at(2.0) - 1.0).abs() < 1e-12);
        // Catmull–Rom: the tangent at key 1 is (−1 − 1)/(3 − 0) per second,
        // so on [0, 1] (tangents 2 and −2/3 per unit segment) the midpoint
        // is (1 + 3)/2 + (2 + 2/3)/8.
        let mid = 2.0 + (2.0 + 2.0 / 3.0) / 8.0;
        assert!((smooth.at(0.5) - mid).abs() < 1e-12, "{}", smooth.at(0.5));
        // Continuous in value and slope across key 1.
        let h = 1e-7;
        let slope = |t: f64| (smooth.at(t + h) - smooth.at(t - h)) / (2.0 * h);
        assert!((slope(1.0 - 1e-5) - slope(1.0 + 1e-5)).abs() < 1e-3);
        assert!((slope(1.0) - (-2.0 / 3.0)).abs() < 1e-4, "{}", slope(1.0));
    }

    #[test]
    fn a_single_key_is_constant() {
        let t = track(&[(2.0, 5.0)], Interpolation::Smooth);
        assert!(t.is_constant());
        assert_eq!((t.at(0.0), t.at(2.0), t.at(9.0)), (5.0, 5.0, 5.0));
        assert!(!track(&[(0.0, 1.0), (1.0, 2.0)], Interpolation::Step).is_constant());
    }

    #[test]
    fn slerp_takes_the_short_way_across_the_sign_flip() {
        let a = DQuat::from_rotation_y(170f64.to_radians());
        // −190° is the same rotation as 170° + 20°; its quaternion has the
        // opposite sign of the nearest representative.
        let b = DQuat::from_rotation_y(-170f64.to_radians());
        assert!(a.dot(b) < 0.0);
        let mid = slerp(a, b, 0.5);
        // Halfway along the short arc is 180°, not 0°.
        let angle = mid.angle_between(DQuat::from_rotation_y(std::f64::consts::PI));
        assert!(angle < 1e-9, "{angle}");
        // Constant angular speed: a quarter of the way is 175°.
        let quarter = slerp(a, b, 0.25);
        assert!(quarter.angle_between(DQuat::from_rotation_y(175f64.to_radians())) < 1e-9);
        // Identical and opposite-sign identical rotations.
        assert!(slerp(a, a, 0.3).angle_between(a) < 1e-9);
        assert!(slerp(a, -a, 0.3).angle_between(a) < 1e-9);
    }

    #[test]
    fn rotation_tracks_interpolate_on_the_sphere() {
        let keys = vec![
            Key {
                time: 0.0,
                value: DQuat::IDENTITY,
            },
            Key {
                time: 1.0,
                value: -DQuat::from_rotation_z(90f64.to_radians()),
            },
            Key {
                time: 2.0,
                value: DQuat::from_rotation_z(180f64.to_radians()),
            },
        ];
        let linear = Track::new(keys.clone(), Interpolation::Linear).expect("valid");
        let smooth = Track::new(keys, Interpolation::Smooth).expect("valid");
        let z45 = DQuat::from_rotation_z(45f64.to_radians());
        assert!(linear.at(0.5).angle_between(z45) < 1e-9);
        for t in [0.0f64, 1.0, 2.0] {
            let expected = DQuat::from_rotation_z((90.0 * t).to_radians());
            assert!(smooth.at(t).angle_between(expected) < 1e-9, "t {t}");
        }
        // Evenly spaced keys on one axis: the spline stays on the axis and
        // near the uniform rotation.
        let q = smooth.at(0.5);
        assert!(q.is_normalized());
        assert!(q.angle_between(z45) < 2f64.to_radians(), "{q:?}");
    }

    #[test]
    fn trs_lerp_moves_scales_and_turns() {
        let a = Trs::IDENTITY;
        let b = Trs {
            translate: DVec3::new(2.0, 0.0, 0.0),
            rotate: DQuat::from_rotation_y(90f64.to_radians()),
            scale: DVec3::splat(3.0),
        };
        let m = Trs::lerp(&a, &b, 0.5);
        assert_eq!(m.translate, DVec3::new(1.0, 0.0, 0.0));
        assert_eq!(m.scale, DVec3::splat(2.0));
        assert!(
            m.rotate
                .angle_between(DQuat::from_rotation_y(45f64.to_radians()))
                < 1e-12
        );
        let p = b.matrix().transform_point3(DVec3::X);
        assert!((p - DVec3::new(2.0, 0.0, -3.0)).length() < 1e-12, "{p}");
    }
}

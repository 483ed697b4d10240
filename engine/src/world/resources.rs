//! What a scene holds besides its entities: settings, the modules that are
//! not attached to an entity (filter, sampler, named textures and
//! materials) and the timeline of its frames.

use super::ModuleSpec;
use crate::settings::RenderSettings;
use hecs::World;
use std::path::PathBuf;

/// The scene's frames and how they map to time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timeline {
    /// Frames per second.
    pub fps: f64,
    /// The first frame.
    pub start: i64,
    /// The last frame.
    pub end: i64,
    /// The camera's shutter, open from `open` to `close` frames after each
    /// frame's time (`camera: {shutter: [open, close]}`); `None`: no
    /// motion blur.
    pub shutter: Option<(f64, f64)>,
}

impl Default for Timeline {
    /// One frame, frame 1, at 24 frames per second, no motion blur.
    fn default() -> Self {
        Self {
            fps: 24.0,
            start: 1,
            end: 1,
            shutter: None,
        }
    }
}

/// The times at which the systems evaluate a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameTimes {
    /// The frame number.
    pub frame: i64,
    /// The frame's time in seconds (the middle of the exposure where there
    /// is a shutter): everything that does not blur is evaluated here.
    pub time: f64,
    /// Shutter open and close in seconds, where there is a shutter.
    pub shutter: Option<(f64, f64)>,
}

impl Timeline {
    /// The time of frame `frame` in seconds.
    pub fn time(&self, frame: f64) -> f64 {
        frame / self.fps
    }

    /// The times of frame `frame`: with a shutter, the frame's time is
    /// the middle of the exposure, where everything that does not blur
    /// (lights, materials, the camera's parameters) is evaluated.
    pub fn times(&self, frame: i64) -> FrameTimes {
        let f = frame as f64;
        match self.shutter {
            None => FrameTimes {
                frame,
                time: self.time(f),
                shutter: None,
            },
            Some((open, close)) => FrameTimes {
                frame,
                time: self.time(f + 0.5 * (open + close)),
                shutter: Some((self.time(f + open), self.time(f + close))),
            },
        }
    }

    /// Whether `frame` is one of the scene's frames.
    pub fn contains(&self, frame: i64) -> bool {
        (self.start..=self.end).contains(&frame)
    }

    /// The number of frames.
    pub fn len(&self) -> u64 {
        (self.end - self.start + 1).max(0) as u64
    }

    /// Whether the scene has no frames (never: a timeline has at least
    /// its start frame).
    pub fn is_empty(&self) -> bool {
        self.end < self.start
    }
}

/// A loaded scene: the world plus the settings and module definitions that
/// are not entities.
pub struct Scene {
    /// The scene file.
    pub file: PathBuf,
    /// The folder relative paths are resolved against.
    pub dir: PathBuf,
    /// Shapes, lights and the camera.
    pub world: World,
    /// Integrator, film and sampler settings.
    pub settings: RenderSettings,
    /// The integrator module (its `type` and own keys; the keys every
    /// integrator shares are in `settings`).
    pub integrator: ModuleSpec,
    /// The frames and the shutter.
    pub timeline: Timeline,
    /// The frame the systems last moved the world to
    /// ([`animate`](super::systems::animate)).
    pub frame: i64,
    /// The pixel filter.
    pub filter: ModuleSpec,
    /// The sampler.
    pub sampler: ModuleSpec,
    /// Named textures, in file order.
    pub textures: Vec<(String, ModuleSpec)>,
    /// Materials (shaders), indexed by [`MaterialRef`](super::MaterialRef).
    pub materials: Vec<(String, ModuleSpec)>,
    /// Participating media and the shapes' interfaces between them.
    pub media: crate::scene::media::SceneMedia,
}

//! An outside integrator: `directions` shows each camera ray's direction
//! as a colour, 0.5·(d + 1) per axis — the smallest tile integrator, a
//! template for your own (`integrator: {type: directions}`).
//!
//! It belongs to the image-tile family: the engine's driver hands each
//! thread a [`DirectionsWorker`] and calls it with batches (a pixel
//! rectangle and a range of sample indices); the worker draws its sample
//! values from the scene's sampler by pixel and sample index (so images do
//! not depend on the thread count) and adds every sample to the tile's
//! film, ending each block of sample indices as the film's exact sums ask.

use radiant::core::glam::{Vec2, Vec3};
use radiant::core::{CameraRays, ModuleInfo, Params, Registry, Rgb, SampleId};
use radiant::film::Reconstruction;
use radiant::film::exact::BLOCK;
use radiant::integrators::{
    Batch, Family, Integrator, TileContext, TileIntegrator, TileOutput, TileWorker,
};
use serde::Deserialize;

/// The `directions` integrator.
#[derive(Debug, Clone, Copy, Default)]
pub struct Directions;

impl Integrator for Directions {
    fn family(&self) -> Family<'_> {
        Family::Tiles(self)
    }
}

impl TileIntegrator for Directions {
    fn worker(&self) -> Box<dyn TileWorker + '_> {
        Box::<DirectionsWorker>::default()
    }
}

/// One thread's buffers, reused from batch to batch.
#[derive(Default)]
pub struct DirectionsWorker {
    ids: Vec<SampleId>,
    film: Vec<Vec2>,
    lens: Vec<Vec2>,
    origins: Vec<Vec3>,
    directions: Vec<Vec3>,
    weights: Vec<f32>,
    rays: u64,
}

impl TileWorker for DirectionsWorker {
    fn render(&mut self, ctx: &TileContext<'_>, b: Batch, mut out: TileOutput<'_>) {
        let width = ctx.scene.settings.width;
        // Sample-major: every pixel's sample i, then sample i + 1, so that
        // blocks of sample indices end in order.
        self.ids.clear();
        for index in b.first_sample..b.first_sample + b.samples {
            for y in b.y0..b.y1 {
                for x in b.x0..b.x1 {
                    self.ids.push(SampleId {
                        pixel: y * width + x,
                        index,
                    });
                }
            }
        }
        let n = self.ids.len();
        for v in [&mut self.film, &mut self.lens] {
            v.resize(n, Vec2::ZERO);
        }
        for v in [&mut self.origins, &mut self.directions] {
            v.resize(n, Vec3::ZERO);
        }
        self.weights.resize(n, 0.0);
        ctx.scene.sampler.fill_2d(&self.ids, 0, &mut self.film);
        ctx.scene.sampler.fill_2d(&self.ids, 2, &mut self.lens);
        for (f, id) in self.film.iter_mut().zip(&self.ids) {
            *f += Vec2::new((id.pixel % width) as f32, (id.pixel / width) as f32);
        }
        ctx.scene.camera.generate(
            &self.film,
            &self.lens,
            CameraRays {
                origins: &mut self.origins,
                directions: &mut self.directions,
                weights: &mut self.weights,
            },
        );
        let per_index = ((b.x1 - b.x0) * (b.y1 - b.y0)) as usize;
        for (k, index) in (b.first_sample..b.first_sample + b.samples).enumerate() {
            for i in k * per_index..(k + 1) * per_index {
                let value: Rgb = (self.directions[i] + Vec3::ONE) * 0.5;
                let pixel = self.ids[i].pixel;
                match ctx.reconstruction {
                    Reconstruction::Splat(table) => out.film.splat(self.film[i], value, table),
                    // Filter importance sampling would draw the offset from
                    // the filter; this example adds to the pixel alone.
                    Reconstruction::Importance(_) => {
                        out.film.add(pixel % width, pixel / width, value, 1.0)
                    }
                }
                if let Some(add) = out.samples.as_mut() {
                    add(pixel, value);
                }
            }
            if (index + 1) % BLOCK == 0 {
                out.film.end_block();
            }
        }
        self.rays += n as u64;
    }

    fn rays(&self) -> u64 {
        self.rays
    }
}

/// `directions` has no keys of its own.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DirectionsParams {}

/// Registers the `directions` integrator.
pub fn register(registry: &mut Registry) {
    registry.register::<dyn Integrator>(
        ModuleInfo {
            type_name: "directions",
            summary: "Camera ray directions as colours, 0.5·(d + 1) (an example outside integrator).",
            params: &[],
        },
        |params: &Params, _| {
            let DirectionsParams {} = params.parse()?;
            Ok(Box::new(Directions) as Box<dyn Integrator>)
        },
    );
}

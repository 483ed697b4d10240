//! The GPU backend: the frame's path tracer as a wgpu compute kernel.
//!
//! Per frame, [`GpuBackend::render`] gathers the modules' GPU sides
//! ([`modules`]), lays out the geometry ([`upload`], [`bvh`]), assembles
//! the kernel from exactly what the frame uses ([`kernel`]), compiles it
//! (or reuses the pipeline of an identical kernel: animation frames
//! recompile nothing), uploads the frame's buffers, and renders the
//! samples in dispatches small enough for OS watchdogs. One invocation
//! traces one path (a megakernel), or with [`GpuKernel::Wavefront`] paths
//! pass through separate stages with queues between them ([`wavefront`]);
//! either way each path owns its film or splat entry, so accumulation
//! needs no atomics and a render is deterministic for a given seed and
//! adapter. With [`GpuOptions::stats`] every pass is timed where the
//! adapter has timestamp queries ([`timing`]). (Buffers are made anew each frame; keeping them, and
//! the bottom levels that did not change, is left to do.)

mod bvh;
mod cwbvh;
mod device;
pub mod error;
pub mod kernel;
mod light_selection;
mod media;
pub mod modules;
pub mod probe;
pub mod timing;
pub mod trace;
pub mod upload;
pub mod wavefront;

pub use super::gpu_options::{BvhLayout, GpuKernel, GpuOptions};
pub use error::GpuError;
pub use timing::{Stage, StageTimes};

use super::cpu::Pass;
use super::{Progress, Rendered};
use crate::extract::RenderScene;
use crate::film::Film;
use crate::integrators::path::UNLIMITED_DEPTH_CAP;
use kernel::{Features, Kernel};
use modules::Modules;
use std::time::Instant;
use timing::StageTimer;
use upload::{Geometry, LevelCache};
use wgpu::util::DeviceExt;

/// Paths (pixels × samples) one dispatch renders at most, so that each
/// stays far below OS watchdog limits (a few seconds) on a slow adapter.
const PATHS_PER_DISPATCH: u64 = 1 << 21;

/// Paths of the dispatches submitted together (between two reads of the
/// counters, which must not overflow 32 bits: about 10 rays per path).
const PATHS_PER_SUBMIT: u64 = 1 << 24;

/// Film layers at most: a dispatch renders up to this many samples of
/// each pixel, one invocation each, into separate layers (small frames
/// then still fill the GPU).
const MAX_LAYERS: u32 = 16;

/// Bytes between the dispatches' uniforms (the dynamic-offset alignment
/// every adapter accepts).
const UNIFORM_STRIDE: u64 = 256;

/// One dispatch: samples [first, first + samples) of rows [y0, y0 + rows).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Dispatch {
    first: u32,
    samples: u32,
    y0: u32,
    rows: u32,
}

/// The frame's dispatches, in order, for `layers` film layers.
fn dispatches(width: u32, height: u32, spp: u32, layers: u32) -> Vec<Dispatch> {
    let rows = (PATHS_PER_DISPATCH / (width as u64 * layers as u64)).clamp(1, height as u64) as u32;
    let mut out = Vec::new();
    let mut first = 0;
    while first < spp {
        let samples = layers.min(spp - first);
        let mut y0 = 0;
        while y0 < height {
            out.push(Dispatch {
                first,
                samples,
                y0,
                rows: rows.min(height - y0),
            });
            y0 += rows;
        }
        first += samples;
    }
    out
}

/// Rows of the workgroup grid (8 × 8 pixels per workgroup).
const WORKGROUP: u32 = 8;

/// What a frame compiles to, before any GPU work: for `radiant info` and
/// `--dump-wgsl`.
pub struct Plan {
    /// The modules' parameters and types.
    pub modules: Modules,
    /// The geometry.
    pub geometry: Geometry,
    /// The kernel.
    pub kernel: Kernel,
}

impl Plan {
    /// Whether `scene` can render on the GPU, without laying out its
    /// geometry: fails, naming it, on a module without GPU code (the only
    /// way planning fails).
    pub fn check(scene: &RenderScene) -> Result<(), GpuError> {
        Modules::new(scene).map(drop)
    }

    /// Plans `scene` for the GPU: fails, naming it, on a module without
    /// GPU code.
    pub fn new(scene: &RenderScene) -> Result<Self, GpuError> {
        Self::with_bvh(scene, BvhLayout::default())
    }

    /// This plan with the kernel that renders with `kernel` (the
    /// wavefront's stages compiled in), counting traversal work where
    /// `stats`.
    pub fn for_kernel(mut self, kernel: GpuKernel, stats: bool) -> Self {
        let wavefront = kernel == GpuKernel::Wavefront;
        if stats || wavefront {
            let features = Features {
                stats,
                wavefront,
                ..self.kernel.features
            };
            self.kernel = Kernel::assemble(&self.modules, features);
        }
        self
    }

    /// [`Plan::new`] with hierarchies of `layout`.
    pub fn with_bvh(scene: &RenderScene, layout: BvhLayout) -> Result<Self, GpuError> {
        Self::with_levels(scene, layout, &mut LevelCache::default())
    }

    /// [`Plan::with_bvh`], taking the bottom levels that did not change
    /// since the last frame from `levels`.
    pub fn with_levels(
        scene: &RenderScene,
        layout: BvhLayout,
        levels: &mut LevelCache,
    ) -> Result<Self, GpuError> {
        let mut modules = Modules::new(scene)?;
        let geometry = Geometry::with_cache(scene, layout, levels)?;
        modules.locate(&geometry);
        let features = Features::of(scene, &geometry, &modules);
        let kernel = Kernel::assemble(&modules, features);
        Ok(Self {
            modules,
            geometry,
            kernel,
        })
    }
}

/// A compiled kernel, kept while frames assemble the same source.
struct Pipeline {
    source: String,
    overrides: (u32, u32),
    pipeline: wgpu::ComputePipeline,
    /// The gather pass of filter splatting, where the kernel splats.
    gather: Option<wgpu::ComputePipeline>,
    /// The wavefront's stages, where the kernel has them.
    wavefront: Option<wavefront::Stages>,
}

/// The kernel's bindings (`wgsl/path.wgsl`): the dispatch's uniform, five
/// read-only storage buffers, the film, the counters and the splats.
fn bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let entry = |binding: u32, ty: wgpu::BufferBindingType| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let read = wgpu::BufferBindingType::Storage { read_only: true };
    let write = wgpu::BufferBindingType::Storage { read_only: false };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("frame"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(32),
                },
                count: None,
            },
            entry(1, read),
            entry(2, read),
            entry(3, read),
            entry(4, read),
            entry(5, read),
            entry(6, write),
            entry(7, write),
            entry(8, write),
        ],
    })
}

/// What the last render counted beyond [`Rendered`]: shadow rays apart,
/// and with [`GpuOptions::stats`] the traversal work.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GpuStats {
    /// Camera paths (one camera ray each).
    pub camera_rays: u64,
    /// Continuation rays after the camera rays.
    pub bounce_rays: u64,
    /// Shadow rays of next-event estimation.
    pub shadow_rays: u64,
    /// BVH nodes visited (both levels; zero without `stats`).
    pub nodes: u64,
    /// Primitives tested (zero without `stats`).
    pub prims: u64,
    /// GPU time per stage kind (zero without `stats` or where the adapter
    /// has no timestamp queries).
    pub stages: StageTimes,
}

/// What the kernel of one call of [`GpuBackend::render_samples`] binds,
/// kept while it runs.
struct FrameBuffers {
    /// Σ w·L and Σ w per pixel and film layer.
    film: wgpu::Buffer,
    /// Counts the kernel adds to (see [`GpuBackend::dispatch`]).
    counters: wgpu::Buffer,
    /// Every binding of the kernel (the bind group keeps its buffers).
    bind: wgpu::BindGroup,
    /// Layers of `film`.
    film_layers: usize,
    /// The filter's reach in pixels (the gather pass's border).
    reach: u32,
}

/// The geometry buffers on the device, with the bytes they hold (to tell
/// whether the next frame's geometry is the same).
struct ResidentGeometry {
    nodes: wgpu::Buffer,
    prims: wgpu::Buffer,
    shading: wgpu::Buffer,
    instances: wgpu::Buffer,
    bytes: [Vec<u8>; 4],
}

/// The GPU backend: a device and what it keeps between frames.
pub struct GpuBackend {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    limits: wgpu::Limits,
    pipeline: Option<Pipeline>,
    /// The last frame's geometry buffers.
    geometry: Option<ResidentGeometry>,
    /// The last frame's bottom levels in the GPU's layout.
    levels: LevelCache,
    /// Geometry uploads so far (a frame whose geometry is the last one's
    /// uploads none).
    uploads: u64,
    layout: wgpu::BindGroupLayout,
    errors: device::ErrorSink,
    stats: bool,
    /// The hierarchy layout of the frames' geometry.
    bvh: BvhLayout,
    /// Which kernel renders.
    kernel: GpuKernel,
    /// Path slots of the wavefront's pool, if not its default.
    wavefront_paths: Option<u32>,
    /// Timestamps of the passes (with `stats`, where the adapter has them).
    timer: Option<StageTimer>,
    last: GpuStats,
}

/// Uploads `data` (at least 16 bytes, so that empty arrays bind).
fn storage(device: &wgpu::Device, label: &str, data: &[u8], writable: bool) -> wgpu::Buffer {
    let mut usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
    if writable {
        usage |= wgpu::BufferUsages::COPY_SRC;
    }
    let padded;
    let contents = if data.len() < 16 {
        padded = [data, &[0u8; 16][data.len()..]].concat();
        &padded[..]
    } else {
        data
    };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage,
    })
}

/// The buffers of `g` on `device`: the last frame's (`kept`) where its
/// geometry is the same (a still scene's frames, a camera move,
/// progressive passes), else uploaded anew (counted in `uploads`) and kept
/// for the next.
fn resident<'a>(
    device: &wgpu::Device,
    kept: &'a mut Option<ResidentGeometry>,
    uploads: &mut u64,
    g: &Geometry,
) -> &'a ResidentGeometry {
    let arrays: [&[u8]; 4] = [
        bytemuck::cast_slice(&g.nodes),
        bytemuck::cast_slice(&g.prims),
        bytemuck::cast_slice(&g.shading),
        bytemuck::cast_slice(&g.instances),
    ];
    let same = kept
        .as_ref()
        .is_some_and(|r| r.bytes.iter().zip(&arrays).all(|(a, b)| a == b));
    if !same {
        let d = device;
        *kept = Some(ResidentGeometry {
            nodes: storage(d, "nodes", arrays[0], false),
            prims: storage(d, "prims", arrays[1], false),
            shading: storage(d, "shading", arrays[2], false),
            instances: storage(d, "instances", arrays[3], false),
            bytes: arrays.map(<[u8]>::to_vec),
        });
        *uploads += 1;
    }
    kept.as_ref().expect("made above")
}

impl GpuBackend {
    /// Opens an adapter as `options` say.
    pub fn new(options: &GpuOptions) -> Result<Self, GpuError> {
        let (device, queue, info, limits, errors) = device::open(options)?;
        let buffers = limits.max_storage_buffers_per_shader_stage;
        if options.kernel == GpuKernel::Wavefront && buffers < wavefront::STORAGE_BUFFERS {
            return Err(GpuError::Limit {
                adapter: info.name,
                limit: "max_storage_buffers_per_shader_stage",
                needed: wavefront::STORAGE_BUFFERS.into(),
                allowed: buffers.into(),
            });
        }
        let layout = bind_group_layout(&device);
        let timer = options
            .stats
            .then(|| StageTimer::new(&device, &queue))
            .flatten();
        Ok(Self {
            stats: options.stats,
            bvh: options.bvh,
            kernel: options.kernel,
            wavefront_paths: options.wavefront_paths,
            timer,
            last: GpuStats::default(),
            layout,
            device,
            queue,
            info,
            limits,
            pipeline: None,
            geometry: None,
            levels: LevelCache::default(),
            uploads: 0,
            errors,
        })
    }

    /// The adapter's description, as `auto` reports it.
    pub fn adapter(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }

    /// How many times a frame's geometry was uploaded: frames whose
    /// geometry is the same as the last one's reuse its buffers.
    pub fn geometry_uploads(&self) -> u64 {
        self.uploads
    }

    /// How many bottom levels were laid out for the GPU: a frame lays out
    /// only those that changed since the last frame (or moved in the
    /// arrays), and reuses the rest.
    pub fn levels_built(&self) -> u64 {
        self.levels.built()
    }

    /// What the last render counted.
    pub fn last_stats(&self) -> GpuStats {
        self.last
    }

    /// Which kernel renders.
    pub fn kernel(&self) -> GpuKernel {
        self.kernel
    }

    /// Whether renders time their passes (`stats` on an adapter with
    /// timestamp queries).
    pub fn times_stages(&self) -> bool {
        self.timer.is_some()
    }

    /// Whether the adapter is a software rasteriser on the CPU (lavapipe).
    pub fn is_software(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// The pipeline for `kernel` with the frame's overrides, compiled
    /// unless the last frame's is the same.
    fn pipeline(&mut self, kernel: &Kernel, overrides: (u32, u32)) -> Result<(), GpuError> {
        if let Some(p) = &self.pipeline
            && p.source == kernel.source
            && p.overrides == overrides
        {
            return Ok(());
        }
        device::validate(kernel)?;
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("radiant path kernel"),
                source: wgpu::ShaderSource::Wgsl(kernel.source.as_str().into()),
            });
        let constants = [
            ("MAX_DEPTH", overrides.0 as f64),
            ("RR_DEPTH", overrides.1 as f64),
        ];
        let layout = self
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("radiant path kernel"),
                bind_group_layouts: &[Some(&self.layout)],
                immediate_size: 0,
            });
        let entry = |name: &str| {
            self.device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(name),
                    layout: Some(&layout),
                    module: &module,
                    entry_point: Some(name),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &constants,
                        ..Default::default()
                    },
                    cache: None,
                })
        };
        let pipeline = entry("render");
        let gather = kernel.features.splat.then(|| entry("gather"));
        let wavefront = kernel
            .features
            .wavefront
            .then(|| wavefront::Stages::new(&self.device, &module, &self.layout, &constants));
        self.errors.check()?;
        self.pipeline = Some(Pipeline {
            source: kernel.source.clone(),
            overrides,
            pipeline,
            gather,
            wavefront,
        });
        Ok(())
    }

    /// Fails where a buffer of `bytes` exceeds the adapter's limits.
    fn fits(&self, what: &'static str, bytes: usize) -> Result<(), GpuError> {
        let allowed = self
            .limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size);
        if bytes as u64 > allowed {
            return Err(GpuError::TooLarge {
                what,
                needed: bytes as u64,
                allowed,
            });
        }
        Ok(())
    }

    /// Renders `scene` (all its samples) and develops the image.
    pub fn render(
        &mut self,
        scene: &RenderScene,
        progress: &Progress<'_>,
    ) -> Result<Rendered, GpuError> {
        let s = &scene.settings;
        let mut film =
            Film::try_new(s.width, s.height).map_err(|e| GpuError::Render(e.to_string()))?;
        let pass = self.render_samples(scene, &mut film, 0..s.spp, progress)?;
        let image = film
            .try_develop()
            .map_err(|e| GpuError::Render(e.to_string()))?;
        Ok(Rendered {
            image,
            time: pass.time,
            samples: pass.samples,
            rays: pass.rays,
            invalid_samples: film.invalid_samples,
        })
    }

    /// Progressive rendering, as [`cpu::render_samples`](crate::backend::cpu::render_samples)
    /// does it: renders the sample indices `samples` of every pixel and
    /// adds them to `film`, so consecutive ranges accumulate the image of
    /// one render of all of them.
    pub fn render_samples(
        &mut self,
        scene: &RenderScene,
        film: &mut Film,
        samples: std::ops::Range<u32>,
        progress: &Progress<'_>,
    ) -> Result<Pass, GpuError> {
        let spp = samples.len() as u32;
        if spp == 0 {
            return Ok(Pass {
                time: std::time::Duration::ZERO,
                samples: 0,
                rays: 0,
            });
        }
        let plan = self.compile(scene)?;
        let s = &scene.settings;
        let (w, h) = (s.width, s.height);
        let pixels = w as usize * h as usize;
        let layers = ((1u64 << 20) / pixels as u64).clamp(1, MAX_LAYERS.min(spp) as u64) as u32;
        let work = dispatches(w, h, spp, layers);
        let total = pixels as u64 * spp as u64;
        if let Some(timer) = &mut self.timer {
            timer.times = StageTimes::default();
        }
        let (counts, (sums, time)) = match self.kernel {
            GpuKernel::Megakernel => {
                let frame = self.upload(&plan, (w, h), layers, samples.start, &work, 0)?;
                let start = Instant::now();
                let counts = self.dispatch(&frame, &work, (w, h), total, progress)?;
                (counts, self.read_film(&frame, pixels, start)?)
            }
            GpuKernel::Wavefront => {
                // The batches' uniforms follow the bands' (which the
                // gather passes use).
                let batches = wavefront::batches(&work, h);
                let pool =
                    wavefront::pool_size(pixels as u64 * layers as u64, self.wavefront_paths);
                let slots = [&work[..], &batches].concat();
                let frame = self.upload(&plan, (w, h), layers, samples.start, &slots, pool)?;
                let start = Instant::now();
                let counts =
                    self.dispatch_wavefront(&frame, &work, &batches, pool, (w, h), progress)?;
                (counts, self.read_film(&frame, pixels, start)?)
            }
        };
        self.last = GpuStats {
            camera_rays: total,
            bounce_rays: counts[1].saturating_sub(total),
            shadow_rays: counts[2],
            nodes: counts[3],
            prims: counts[4],
            stages: self.timer.as_ref().map(|t| t.times).unwrap_or_default(),
        };
        film.add_layers(&sums, counts[0]);
        Ok(Pass {
            time,
            samples: total,
            rays: counts[1] + counts[2],
        })
    }

    /// Reads the film layers of `frame` back, with the time since `start`.
    fn read_film(
        &self,
        frame: &FrameBuffers,
        pixels: usize,
        start: Instant,
    ) -> Result<(Vec<f32>, std::time::Duration), GpuError> {
        let sums = device::read_f32s(
            &self.device,
            &self.queue,
            &frame.film,
            pixels * frame.film_layers * 4,
            &self.errors,
        )?;
        Ok((sums, start.elapsed()))
    }

    /// Plans `scene` (with the traversal counters where asked) and makes
    /// sure its pipeline is compiled.
    fn compile(&mut self, scene: &RenderScene) -> Result<Plan, GpuError> {
        let plan = Plan::with_levels(scene, self.bvh, &mut self.levels)?
            .for_kernel(self.kernel, self.stats);
        if self.kernel == GpuKernel::Wavefront && plan.kernel.features.media {
            // Its stages keep no medium state per slot.
            return Err(GpuError::Unsupported {
                kernel: "wavefront",
                what: "participating media or `null` boundaries".into(),
            });
        }
        let s = &scene.settings;
        let max_depth = if s.max_depth < 0 {
            UNLIMITED_DEPTH_CAP
        } else {
            s.max_depth as u32
        };
        self.pipeline(&plan.kernel, (max_depth, s.rr_depth))?;
        Ok(plan)
    }

    /// The frame's buffers: `plan`'s parameters and geometry, the film
    /// (one layer when splatting, `layers` otherwise), the splatted samples
    /// (`layers` layers), the counters, and one uniform slot per dispatch
    /// of `work` (sample indices from `first_sample` on; the wavefront's
    /// pool of `pool` path slots).
    fn upload(
        &mut self,
        plan: &Plan,
        (w, h): (u32, u32),
        layers: u32,
        first_sample: u32,
        work: &[Dispatch],
        pool: u32,
    ) -> Result<FrameBuffers, GpuError> {
        let pixels = w as usize * h as usize;
        let splat = plan.kernel.features.splat;
        let film_layers = if splat { 1 } else { layers as usize };
        let splat_bytes = if splat {
            pixels * layers as usize * 16
        } else {
            16
        };
        let g = &plan.geometry;
        self.fits("the splatted samples", splat_bytes)?;
        self.fits("the film", pixels * film_layers * 16)?;
        self.fits("the BVH nodes", g.nodes.len() * 16)?;
        self.fits("the primitives", g.prims.len() * 16)?;
        self.fits("the shading data", g.shading.len() * 16)?;
        self.fits("the module parameters", plan.modules.params.len() * 4)?;
        let d = &self.device;
        let reach = plan.modules.params[16];
        let mut slots = vec![0u32; work.len() * UNIFORM_STRIDE as usize / 4];
        for (k, job) in work.iter().enumerate() {
            let at = k * UNIFORM_STRIDE as usize / 4;
            slots[at..at + 8].copy_from_slice(&[
                w,
                h,
                first_sample + job.first,
                job.samples,
                job.y0,
                job.rows,
                job.y0.saturating_sub(reach),
                pool,
            ]);
        }
        let uniform = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("dispatches"),
            contents: bytemuck::cast_slice(&slots),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let empty = |label, size: usize, usage| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size as u64,
                usage: wgpu::BufferUsages::STORAGE | usage,
                mapped_at_creation: false,
            })
        };
        let params = storage(
            d,
            "params",
            bytemuck::cast_slice(&plan.modules.params),
            false,
        );
        let resident = resident(&self.device, &mut self.geometry, &mut self.uploads, g);
        let read_only = [
            &params,
            &resident.nodes,
            &resident.prims,
            &resident.shading,
            &resident.instances,
        ];
        let film = empty(
            "film",
            pixels * film_layers * 16,
            wgpu::BufferUsages::COPY_SRC,
        );
        let counters = storage(d, "counters", &[0u8; 32], true);
        let splats = empty("splats", splat_bytes, wgpu::BufferUsages::empty());
        let mut entries = vec![wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &uniform,
                offset: 0,
                size: wgpu::BufferSize::new(32),
            }),
        }];
        for (binding, buffer) in (1..).zip(read_only.into_iter().chain([&film, &counters, &splats]))
        {
            entries.push(wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            });
        }
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("frame"),
            layout: &self.layout,
            entries: &entries,
        });
        self.errors.check()?;
        Ok(FrameBuffers {
            film,
            counters,
            bind,
            film_layers,
            reach,
        })
    }

    /// Runs `work` in submissions of at most [`PATHS_PER_SUBMIT`] paths,
    /// reading the counters after each (invalid samples, camera and
    /// continuation rays, shadow rays, nodes, primitives) and reporting
    /// progress towards `total` paths.
    fn dispatch(
        &mut self,
        frame: &FrameBuffers,
        work: &[Dispatch],
        (w, h): (u32, u32),
        total: u64,
        progress: &Progress<'_>,
    ) -> Result<[u64; 5], GpuError> {
        let compiled = self.pipeline.as_ref().expect("compiled before dispatching");
        // Traversal counts reach 32 bits sooner than ray counts.
        let per_submit = if self.stats {
            PATHS_PER_SUBMIT >> 4
        } else {
            PATHS_PER_SUBMIT
        };
        let (mut counts, mut done, mut k) = ([0u64; 5], 0u64, 0);
        while k < work.len() {
            let mut enc = self.device.create_command_encoder(&Default::default());
            let mut paths = 0u64;
            while let Some(job) = work.get(k) {
                let n = w as u64 * job.rows as u64 * job.samples as u64;
                if paths > 0 && paths + n > per_submit {
                    break;
                }
                {
                    let mut pass =
                        StageTimer::pass(self.timer.as_mut(), &mut enc, Stage::Megakernel);
                    pass.set_pipeline(&compiled.pipeline);
                    pass.set_bind_group(0, &frame.bind, &[(k as u64 * UNIFORM_STRIDE) as u32]);
                    pass.dispatch_workgroups(
                        w.div_ceil(WORKGROUP),
                        job.rows.div_ceil(WORKGROUP),
                        job.samples,
                    );
                }
                if let Some(gather) = &compiled.gather {
                    let mut pass = StageTimer::pass(self.timer.as_mut(), &mut enc, Stage::Gather);
                    encode_gather(&mut pass, gather, frame, k, job, (w, h));
                }
                paths += n;
                k += 1;
            }
            submit_counted(
                (&self.device, &self.queue, &self.errors),
                self.timer.as_mut(),
                enc,
                &frame.counters,
                &mut counts,
            )?;
            done += paths;
            progress.report(done, total);
        }
        Ok(counts)
    }
}

/// Encodes the splat gather of dispatch `k` (`job`): the band's rows and
/// the filter's reach around them.
fn encode_gather(
    pass: &mut wgpu::ComputePass<'_>,
    gather: &wgpu::ComputePipeline,
    frame: &FrameBuffers,
    k: usize,
    job: &Dispatch,
    (w, h): (u32, u32),
) {
    let top = job.y0.saturating_sub(frame.reach);
    let bottom = (job.y0 + job.rows + frame.reach).min(h);
    pass.set_pipeline(gather);
    pass.set_bind_group(0, &frame.bind, &[(k as u64 * UNIFORM_STRIDE) as u32]);
    pass.dispatch_workgroups(w.div_ceil(WORKGROUP), (bottom - top).div_ceil(WORKGROUP), 1);
}

/// Submits `encoder` on the device `(device, queue, errors)` (timing its
/// passes where there is a `timer`), then adds the `counters` it counted
/// to `counts` and zeroes them for the next submission.
fn submit_counted(
    (device, queue, errors): (&wgpu::Device, &wgpu::Queue, &device::ErrorSink),
    timer: Option<&mut StageTimer>,
    encoder: wgpu::CommandEncoder,
    counters: &wgpu::Buffer,
    counts: &mut [u64; 5],
) -> Result<(), GpuError> {
    timing::submit(device, queue, errors, timer, encoder)?;
    let c = device::read_words(device, queue, counters, 5, errors)?;
    for (sum, c) in counts.iter_mut().zip(c) {
        *sum += u64::from(c);
    }
    queue.write_buffer(counters, 0, &[0u8; 32]);
    Ok(())
}

//! The wavefront variant of the GPU path tracer (`--gpu-kernel
//! wavefront`), next to the megakernel: the same estimator split into
//! stages (`wgsl/wavefront.wgsl`: generate, extend, shade, connect,
//! accumulate) that pass paths through queues, as seed 001 §1.3–1.5
//! describes.
//!
//! Data flow of one call of [`GpuBackend::render_samples`](super::GpuBackend::render_samples):
//! the frame's dispatches (bands of rows × film layers) are grouped into
//! batches, one per set of sample indices ([`batches`]); a batch's work
//! items (pixel, sample) fill a pool of at most [`POOL`] path slots whose
//! state lives in one buffer (structure of arrays) and whose queues (two
//! ray queues used in turn, the retired paths, the free slots) live in
//! another. Each iteration plans the dispatch sizes from the queue
//! counters on the GPU (`plan_extend`, `plan_connect`, one invocation
//! each) and runs every stage as an indirect dispatch of exactly the
//! queued work: shade appends survivors compacted to the next ray queue,
//! and finished paths free their slots, which the next iteration refills
//! from the work items (regeneration), so the pool stays full until the
//! batch runs out of items. The host records [`ITERATIONS_PER_SUBMIT`]
//! iterations per submission and reads the queue header after each to
//! know when the batch is done; then the splat gather runs over the
//! batch's bands exactly as after the megakernel. Paths are not sorted by
//! material.

use super::timing::{self, Stage, StageTimer};
use super::{Dispatch, FrameBuffers, GpuBackend, GpuError, UNIFORM_STRIDE, device};
use crate::backend::Progress;
use wgpu::util::DeviceExt;

/// Path slots of the pool at most (twice what an H200 keeps resident at
/// 64 registers per invocation, so that every stage fills the GPU).
const POOL: u32 = 1 << 19;

/// `vec4` rows per path slot: six of path state, three of its shadow
/// record (`wgsl/wavefront.wgsl`).
const ROWS_PER_SLOT: u64 = 9;

/// Words of the queue header.
const HEADER_WORDS: usize = 16;

/// Header words the host sets and reads (`Q_*` in the WGSL).
const Q_LIVE: usize = 0;
const Q_FREE: usize = 4;
const Q_NEXT_ITEM: usize = 5;
const Q_ITEMS: usize = 6;

/// Iterations (bounces of the pool) recorded per submission, between two
/// reads of the queue header; iterations after a batch ends dispatch
/// nothing.
const ITERATIONS_PER_SUBMIT: usize = 16;

/// Storage buffers one stage binds: the megakernel's eight, the path
/// state and the queues.
pub(super) const STORAGE_BUFFERS: u32 = 10;

/// Byte offsets of the indirect dispatch sizes, as `set_dispatch` writes
/// them.
const GENERATE_ARGS: u64 = 0;
const EXTEND_ARGS: u64 = 12;
const CONNECT_ARGS: u64 = 24;
const ACCUMULATE_ARGS: u64 = 36;

/// The compiled stages and the layouts of their bindings.
pub(super) struct Stages {
    plan_extend: wgpu::ComputePipeline,
    generate: wgpu::ComputePipeline,
    extend: wgpu::ComputePipeline,
    shade: wgpu::ComputePipeline,
    plan_connect: wgpu::ComputePipeline,
    connect: wgpu::ComputePipeline,
    accumulate: wgpu::ComputePipeline,
    /// Group 1: path state and queues.
    queues_layout: wgpu::BindGroupLayout,
    /// Group 2 of the planning passes: the indirect dispatch sizes.
    indirect_layout: wgpu::BindGroupLayout,
    /// Group 0 of the planning passes, which bind no frame data.
    no_frame: wgpu::BindGroup,
}

/// A bind group layout of read-write storage buffers at 0, 1, ….
fn storage_layout(device: &wgpu::Device, label: &str, count: u32) -> wgpu::BindGroupLayout {
    let entries: Vec<_> = (0..count)
        .map(|binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

impl Stages {
    /// The stages' pipelines from `module` (a kernel assembled with the
    /// wavefront feature), binding `frame` as group 0.
    pub(super) fn new(
        device: &wgpu::Device,
        module: &wgpu::ShaderModule,
        frame: &wgpu::BindGroupLayout,
        constants: &[(&str, f64)],
    ) -> Self {
        let queues_layout = storage_layout(device, "wavefront queues", 2);
        let indirect_layout = storage_layout(device, "wavefront dispatch sizes", 1);
        let empty = storage_layout(device, "no frame", 0);
        let no_frame = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("no frame"),
            layout: &empty,
            entries: &[],
        });
        let layout = |groups: &[Option<&wgpu::BindGroupLayout>]| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("wavefront"),
                bind_group_layouts: groups,
                immediate_size: 0,
            })
        };
        let stage_layout = layout(&[Some(frame), Some(&queues_layout)]);
        let plan_layout = layout(&[Some(&empty), Some(&queues_layout), Some(&indirect_layout)]);
        let entry = |name: &str, layout: &wgpu::PipelineLayout| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(name),
                layout: Some(layout),
                module,
                entry_point: Some(name),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    ..Default::default()
                },
                cache: None,
            })
        };
        Self {
            plan_extend: entry("plan_extend", &plan_layout),
            generate: entry("generate", &stage_layout),
            extend: entry("extend", &stage_layout),
            shade: entry("shade", &stage_layout),
            plan_connect: entry("plan_connect", &plan_layout),
            connect: entry("connect", &stage_layout),
            accumulate: entry("accumulate", &stage_layout),
            queues_layout,
            indirect_layout,
            no_frame,
        }
    }
}

/// One batch per set of sample indices of `work` (its bands merged into
/// the whole frame of `height` rows): the wavefront's unit of
/// regeneration, since the splats of one set must be gathered before the
/// next overwrites them.
pub(super) fn batches(work: &[Dispatch], height: u32) -> Vec<Dispatch> {
    let mut out: Vec<Dispatch> = Vec::new();
    for job in work {
        if out.last().is_none_or(|b| b.first != job.first) {
            out.push(Dispatch {
                first: job.first,
                samples: job.samples,
                y0: 0,
                rows: height,
            });
        }
    }
    out
}

/// Path slots for batches of at most `items` work items: `asked` (at
/// least one) or [`POOL`], no more than there are items.
pub(super) fn pool_size(items: u64, asked: Option<u32>) -> u32 {
    items.min(u64::from(asked.unwrap_or(POOL).max(1))) as u32
}

/// The buffers of the path pool.
struct PoolBuffers {
    /// Header, ray queues, retired queue, free stack.
    queues: wgpu::Buffer,
    /// Group 1 of every stage.
    state: wgpu::BindGroup,
    /// Group 2 of the planning passes.
    sizes: wgpu::BindGroup,
    /// The stages' indirect dispatch sizes.
    indirect: wgpu::Buffer,
}

impl GpuBackend {
    /// Makes the buffers of a pool of `pool` path slots: all slots free.
    fn pool_buffers(&self, stages: &Stages, pool: u32) -> Result<PoolBuffers, GpuError> {
        let d = &self.device;
        let state_bytes = u64::from(pool) * ROWS_PER_SLOT * 16;
        self.fits("the wavefront's path state", state_bytes as usize)?;
        let paths = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("wavefront path state"),
            size: state_bytes,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let mut words = vec![0u32; HEADER_WORDS + 4 * pool as usize];
        let free = HEADER_WORDS + 3 * pool as usize;
        for (slot, w) in (0..pool).zip(&mut words[free..]) {
            *w = slot;
        }
        let queues = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("wavefront queues"),
            contents: bytemuck::cast_slice(&words),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        });
        let indirect = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("wavefront dispatch sizes"),
            size: ACCUMULATE_ARGS + 12,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
            mapped_at_creation: false,
        });
        let state = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wavefront queues"),
            layout: &stages.queues_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: paths.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: queues.as_entire_binding(),
                },
            ],
        });
        let sizes = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wavefront dispatch sizes"),
            layout: &stages.indirect_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: indirect.as_entire_binding(),
            }],
        });
        Ok(PoolBuffers {
            queues,
            state,
            sizes,
            indirect,
        })
    }

    /// Renders `work` with the wavefront stages: each of `batches` (whose
    /// uniforms follow `work`'s) in a pool of `pool` path slots until all
    /// its items are done, then the splat gather over its bands. Returns
    /// the counters as [`GpuBackend::dispatch`] does.
    pub(super) fn dispatch_wavefront(
        &mut self,
        frame: &FrameBuffers,
        work: &[Dispatch],
        batches: &[Dispatch],
        pool: u32,
        (w, h): (u32, u32),
        progress: &Progress<'_>,
    ) -> Result<[u64; 5], GpuError> {
        let compiled = self.pipeline.as_ref().expect("compiled before dispatching");
        let stages = compiled
            .wavefront
            .as_ref()
            .expect("a wavefront kernel has its stages");
        let buffers = self.pool_buffers(stages, pool)?;
        let total: u64 = batches
            .iter()
            .map(|b| u64::from(w) * u64::from(h) * u64::from(b.samples))
            .sum();
        let (mut counts, mut done) = ([0u64; 5], 0u64);
        for (b, batch) in batches.iter().enumerate() {
            let offset = ((work.len() + b) as u64 * UNIFORM_STRIDE) as u32;
            let items = w * h * batch.samples;
            let mut header = [0u32; HEADER_WORDS];
            header[Q_FREE] = pool;
            header[Q_ITEMS] = items;
            self.queue
                .write_buffer(&buffers.queues, 0, bytemuck::cast_slice(&header));
            loop {
                let mut enc = self.device.create_command_encoder(&Default::default());
                for _ in 0..ITERATIONS_PER_SUBMIT {
                    let mut timer = self.timer.as_mut();
                    let mut stage = |kind, pipeline, plan: bool, args: Option<u64>| {
                        let mut pass = StageTimer::pass(timer.as_deref_mut(), &mut enc, kind);
                        pass.set_pipeline(pipeline);
                        if plan {
                            pass.set_bind_group(0, &stages.no_frame, &[]);
                            pass.set_bind_group(2, &buffers.sizes, &[]);
                        } else {
                            pass.set_bind_group(0, &frame.bind, &[offset]);
                        }
                        pass.set_bind_group(1, &buffers.state, &[]);
                        match args {
                            Some(at) => pass.dispatch_workgroups_indirect(&buffers.indirect, at),
                            None => pass.dispatch_workgroups(1, 1, 1),
                        }
                    };
                    stage(Stage::Queues, &stages.plan_extend, true, None);
                    stage(
                        Stage::Generate,
                        &stages.generate,
                        false,
                        Some(GENERATE_ARGS),
                    );
                    stage(Stage::Extend, &stages.extend, false, Some(EXTEND_ARGS));
                    stage(Stage::Shade, &stages.shade, false, Some(EXTEND_ARGS));
                    stage(Stage::Queues, &stages.plan_connect, true, None);
                    stage(Stage::Connect, &stages.connect, false, Some(CONNECT_ARGS));
                    stage(
                        Stage::Accumulate,
                        &stages.accumulate,
                        false,
                        Some(ACCUMULATE_ARGS),
                    );
                }
                super::submit_counted(
                    (&self.device, &self.queue, &self.errors),
                    self.timer.as_mut(),
                    enc,
                    &frame.counters,
                    &mut counts,
                )?;
                let header = device::read_words(
                    &self.device,
                    &self.queue,
                    &buffers.queues,
                    HEADER_WORDS,
                    &self.errors,
                )?;
                progress.report(done + u64::from(header[Q_NEXT_ITEM]), total);
                if header[Q_LIVE] == 0 && header[Q_NEXT_ITEM] == items {
                    break;
                }
            }
            done += u64::from(items);
            if let Some(gather) = &compiled.gather {
                let mut enc = self.device.create_command_encoder(&Default::default());
                for (k, job) in work
                    .iter()
                    .enumerate()
                    .filter(|(_, j)| j.first == batch.first)
                {
                    let mut pass = StageTimer::pass(self.timer.as_mut(), &mut enc, Stage::Gather);
                    super::encode_gather(&mut pass, gather, frame, k, job, (w, h));
                }
                timing::submit(
                    &self.device,
                    &self.queue,
                    &self.errors,
                    self.timer.as_mut(),
                    enc,
                )?;
            }
        }
        Ok(counts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_batch_per_sample_set_covers_the_whole_frame() {
        let work = super::super::dispatches(1000, 3000, 20, 16);
        let b = batches(&work, 3000);
        assert_eq!(b.len(), 2);
        assert_eq!((b[0].first, b[0].samples, b[0].rows), (0, 16, 3000));
        assert_eq!((b[1].first, b[1].samples, b[1].y0), (16, 4, 0));
    }
}

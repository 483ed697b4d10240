//! GPU time per stage: each compute pass of a render is one stage kind
//! (the megakernel, the wavefront's generate, extend, shade, connect,
//! accumulate and queue planning, the splat gather); where the device
//! has timestamp queries (`wgpu::Features::TIMESTAMP_QUERY`) every pass
//! writes one at its beginning and its end, and after each submission the
//! differences are summed per kind into [`StageTimes`]. Without the
//! feature passes run untimed and the sums stay zero.

use super::device;
use super::error::GpuError;

/// The kinds of compute pass a render runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// The megakernel: whole paths per invocation.
    Megakernel,
    /// Wavefront: camera rays of new work items into free path slots.
    Generate,
    /// Wavefront: closest hits of the ray queue.
    Extend,
    /// Wavefront: emission, light sampling, BSDF sampling, roulette, and
    /// the compacting appends to the next queues.
    Shade,
    /// Wavefront: occlusion of the shadow queue.
    Connect,
    /// Wavefront: finished paths to the film or splats.
    Accumulate,
    /// Wavefront: the single-invocation passes that size the next
    /// stages' indirect dispatches from the queue counters (with the
    /// appends in shade, the cost of compaction and regeneration).
    Queues,
    /// The splat gather of filter splatting.
    Gather,
}

impl Stage {
    /// Every kind, in the order [`StageTimes`] holds them.
    pub const ALL: [Stage; 8] = [
        Stage::Megakernel,
        Stage::Generate,
        Stage::Extend,
        Stage::Shade,
        Stage::Connect,
        Stage::Accumulate,
        Stage::Queues,
        Stage::Gather,
    ];

    /// The kind's name, as `--gpu-stats` prints it.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Megakernel => "megakernel",
            Stage::Generate => "generate",
            Stage::Extend => "extend",
            Stage::Shade => "shade",
            Stage::Connect => "connect",
            Stage::Accumulate => "accumulate",
            Stage::Queues => "queues",
            Stage::Gather => "gather",
        }
    }
}

/// GPU nanoseconds per stage kind (indexed by `Stage as usize`, the
/// order of [`Stage::ALL`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StageTimes(pub [u64; Stage::ALL.len()]);

impl StageTimes {
    /// The kinds that ran, with their milliseconds.
    pub fn millis(&self) -> Vec<(&'static str, f64)> {
        Stage::ALL
            .iter()
            .zip(self.0)
            .filter(|(_, ns)| *ns > 0)
            .map(|(s, ns)| (s.name(), ns as f64 * 1e-6))
            .collect()
    }
}

/// Passes one submission may time (two queries each; wgpu allows 4096
/// queries per set). Passes beyond it run untimed.
const PASSES: u32 = 1024;

/// Timestamp queries of the passes of one submission.
pub(super) struct StageTimer {
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    /// The kind of each timed pass since the last [`StageTimer::collect`].
    passes: Vec<Stage>,
    /// Nanoseconds per timestamp tick.
    period: f64,
    /// The GPU time of the passes collected so far.
    pub(super) times: StageTimes,
}

impl StageTimer {
    /// A timer where `device` has timestamp queries, else `None`.
    pub(super) fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Self> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        let queries = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("stage timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count: 2 * PASSES,
        });
        let resolved = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("stage timestamps"),
            size: 2 * PASSES as u64 * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Some(Self {
            queries,
            resolved,
            passes: Vec::new(),
            period: f64::from(queue.get_timestamp_period()),
            times: StageTimes::default(),
        })
    }

    /// Begins a compute pass of kind `stage` on `encoder`, timed where
    /// there is a timer with room.
    pub(super) fn pass<'e>(
        timer: Option<&mut Self>,
        encoder: &'e mut wgpu::CommandEncoder,
        stage: Stage,
    ) -> wgpu::ComputePass<'e> {
        let timestamp_writes = timer.and_then(|t| {
            let k = t.passes.len() as u32;
            (k < PASSES).then(|| {
                t.passes.push(stage);
                wgpu::ComputePassTimestampWrites {
                    query_set: &t.queries,
                    beginning_of_pass_write_index: Some(2 * k),
                    end_of_pass_write_index: Some(2 * k + 1),
                }
            })
        });
        encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(stage.name()),
            timestamp_writes,
        })
    }

    /// Resolves the timed passes' queries at the end of `encoder` (before
    /// it is submitted).
    fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        let n = 2 * self.passes.len() as u32;
        if n > 0 {
            encoder.resolve_query_set(&self.queries, 0..n, &self.resolved, 0);
        }
    }

    /// Adds the submitted passes' durations to `times` and starts over.
    fn collect(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        errors: &device::ErrorSink,
    ) -> Result<(), GpuError> {
        if self.passes.is_empty() {
            return Ok(());
        }
        let words =
            device::read_words(device, queue, &self.resolved, 4 * self.passes.len(), errors)?;
        for (stage, pair) in self.passes.drain(..).zip(words.chunks_exact(4)) {
            let begin = u64::from(pair[0]) | u64::from(pair[1]) << 32;
            let end = u64::from(pair[2]) | u64::from(pair[3]) << 32;
            self.times.0[stage as usize] += (end.saturating_sub(begin) as f64 * self.period) as u64;
        }
        Ok(())
    }
}

/// Submits `encoder` (resolving its timed passes' queries first) and adds
/// their GPU times to the timer's.
pub(super) fn submit(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    errors: &device::ErrorSink,
    timer: Option<&mut StageTimer>,
    mut encoder: wgpu::CommandEncoder,
) -> Result<(), GpuError> {
    match timer {
        Some(t) => {
            t.resolve(&mut encoder);
            queue.submit([encoder.finish()]);
            t.collect(device, queue, errors)
        }
        None => {
            queue.submit([encoder.finish()]);
            Ok(())
        }
    }
}

//! Opening an adapter and talking to it: the limits the backend needs,
//! errors captured rather than panicking (wgpu's default), validation of a
//! kernel with naga so that a compile error names the module its line is
//! in, and reading buffers back.

use super::GpuOptions;
use super::error::GpuError;
use super::kernel::Kernel;
use std::sync::{Arc, Mutex};

/// Errors the device reported outside a call (validation, out of memory,
/// device loss), kept until [`ErrorSink::check`] turns them into a
/// [`GpuError`].
#[derive(Clone, Default)]
pub(super) struct ErrorSink {
    errors: Arc<Mutex<Vec<String>>>,
}

impl ErrorSink {
    fn push(&self, message: String) {
        if let Ok(mut e) = self.errors.lock() {
            e.push(message);
        }
    }

    /// The first error reported since the last check, if any.
    pub(super) fn check(&self) -> Result<(), GpuError> {
        let mut e = self
            .errors
            .lock()
            .map_err(|_| GpuError::Render("error log poisoned".into()))?;
        match e.drain(..).next() {
            Some(message) => Err(GpuError::Render(message)),
            None => Ok(()),
        }
    }
}

/// The limits the backend needs beyond wgpu's defaults: the adapter's own
/// (so large scenes can bind large buffers), checked against the minimum
/// the frame needs.
fn limits_for(adapter: &wgpu::Adapter, options: &GpuOptions) -> Result<wgpu::Limits, GpuError> {
    let limits = adapter.limits();
    let name = adapter.get_info().name;
    let checks = [
        (
            "max_storage_buffers_per_shader_stage",
            8,
            u64::from(limits.max_storage_buffers_per_shader_stage),
        ),
        (
            "max_compute_invocations_per_workgroup",
            64,
            u64::from(limits.max_compute_invocations_per_workgroup),
        ),
        (
            "max_storage_buffer_binding_size",
            options.storage_buffer_bytes.unwrap_or(0),
            limits.max_storage_buffer_binding_size,
        ),
    ];
    for (limit, needed, allowed) in checks {
        if allowed < needed {
            return Err(GpuError::Limit {
                adapter: name,
                limit,
                needed,
                allowed,
            });
        }
    }
    Ok(limits)
}

/// Opens the preferred adapter (`WGPU_BACKEND` and `WGPU_ADAPTER_NAME`
/// choose among several).
pub(super) fn open(
    options: &GpuOptions,
) -> Result<
    (
        wgpu::Device,
        wgpu::Queue,
        wgpu::AdapterInfo,
        wgpu::Limits,
        ErrorSink,
    ),
    GpuError,
> {
    // Compute needs no OpenGL: the primary backends unless WGPU_BACKEND
    // says otherwise (probing GL would also print display-server noise).
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    descriptor.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
    let instance = wgpu::Instance::new(descriptor);
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    }))
    .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
    let info = adapter.get_info();
    let limits = limits_for(&adapter, options)?;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("radiant"),
        required_limits: limits.clone(),
        // Pass timing (`--gpu-stats`) where the adapter has it.
        required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
        ..Default::default()
    }))
    .map_err(|e| GpuError::Device {
        adapter: info.name.clone(),
        message: e.to_string(),
    })?;
    let errors = ErrorSink::default();
    let sink = errors.clone();
    device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| sink.push(e.to_string())));
    let sink = errors.clone();
    device.set_device_lost_callback(move |reason, message| {
        sink.push(format!("the device was lost ({reason:?}): {message}"));
    });
    Ok((device, queue, info, limits, errors))
}

/// Parses and validates `kernel` with naga; an error names the part of the
/// kernel (a module, a library, the integrator) its first line falls in.
pub(super) fn validate(kernel: &Kernel) -> Result<(), GpuError> {
    let source = &kernel.source;
    let located = |line: Option<u32>, message: String| GpuError::Compile {
        module: line
            .and_then(|l| kernel.part_at(l.saturating_sub(1) as usize))
            .map(str::to_string),
        message,
    };
    let module = naga::front::wgsl::parse_str(source).map_err(|e| {
        located(
            e.location(source).map(|l| l.line_number),
            e.emit_to_string(source),
        )
    })?;
    let mut validator = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    );
    validator.validate(&module).map_err(|e| {
        located(
            e.location(source).map(|l| l.line_number),
            e.emit_to_string(source),
        )
    })?;
    Ok(())
}

/// Copies the first `count` words of `buffer` back.
pub(super) fn read_words(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    count: usize,
    errors: &ErrorSink,
) -> Result<Vec<u32>, GpuError> {
    let bytes = (count * 4) as u64;
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
    queue.submit([enc.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    staging
        .slice(..)
        .map_async(wgpu::MapMode::Read, move |r| drop(tx.send(r)));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Render(e.to_string()))?;
    errors.check()?;
    rx.recv()
        .map_err(|e| GpuError::Render(e.to_string()))?
        .map_err(|e| GpuError::Render(e.to_string()))?;
    let view = staging
        .slice(..)
        .get_mapped_range()
        .map_err(|e| GpuError::Render(e.to_string()))?;
    let words = bytemuck::cast_slice(&view).to_vec();
    Ok(words)
}

/// Reads `count` words of `buffer` as floats.
pub(super) fn read_f32s(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    count: usize,
    errors: &ErrorSink,
) -> Result<Vec<f32>, GpuError> {
    Ok(read_words(device, queue, buffer, count, errors)?
        .into_iter()
        .map(f32::from_bits)
        .collect())
}

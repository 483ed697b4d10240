//! Probes: a module's WGSL run on given inputs, for tests that hold every
//! module's GPU side to its Rust implementation (same inputs through
//! both; the tolerance is float precision, not noise).
//!
//! A probe kernel holds the module's code, the texture dispatcher over the
//! given texture table, and an entry point that runs a test-supplied WGSL
//! body once per input record. The body reads its inputs with
//! `input(i, k)` (record `i`, float `k`), writes results with
//! `output(i, k, value)`, and finds the module's parameters at offset `P`.

use super::GpuBackend;
use super::device;
use super::error::GpuError;
use super::kernel::Kernel;
use super::modules::Modules;
use radiant_core::{GpuModule, TextureTable};
use wgpu::util::DeviceExt;

/// The kind whose signature the probed module implements.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProbeKind {
    /// `camera_ray_T`.
    Camera,
    /// `sample_1d_T`.
    Sampler,
    /// `bsdf_sample_T`, `bsdf_eval_T`.
    Shader,
    /// `light_sample_T`, `light_hit_T`, `light_escaped_T`.
    Light,
    /// `texture_T`.
    Texture,
}

/// What a probe runs: a module, its kind, and the body run per record.
#[derive(Clone)]
pub struct Probe<'a> {
    /// The module instance.
    pub module: GpuModule,
    /// Its kind.
    pub kind: ProbeKind,
    /// The scene's textures (shaders read theirs through `texture_eval`).
    pub textures: &'a TextureTable,
    /// The WGSL run for record `i` (see the module docs).
    pub body: &'a str,
    /// Floats per input record.
    pub inputs_per_record: usize,
    /// Floats per output record.
    pub outputs_per_record: usize,
}

impl GpuBackend {
    /// Runs `probe` on `inputs` (records of `inputs_per_record` floats)
    /// and returns the outputs (records of `outputs_per_record` floats).
    pub fn probe(&mut self, probe: &Probe<'_>, inputs: &[f32]) -> Result<Vec<f32>, GpuError> {
        let (modules, at) = Modules::for_probe(probe.textures, &probe.module, probe.kind)?;
        let records = inputs.len() / probe.inputs_per_record.max(1);
        let body = format!(
            "const P: u32 = {at}u;\n\
             fn input(i: u32, k: u32) -> f32 {{ return probe_in[i * {ni}u + k]; }}\n\
             fn output(i: u32, k: u32, v: f32) {{ probe_out[i * {no}u + k] = v; }}\n\
             @compute @workgroup_size(64)\n\
             fn probe(@builtin(global_invocation_id) g: vec3u) {{\n\
             let i = g.x;\n\
             if i >= {records}u {{ return; }}\n\
             {body}\n\
             }}\n",
            ni = probe.inputs_per_record,
            no = probe.outputs_per_record,
            body = probe.body,
        );
        let kernel = Kernel::assemble_probe(&modules, &body);
        device::validate(&kernel)?;
        let d = &self.device;
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("probe"),
            source: wgpu::ShaderSource::Wgsl(kernel.source.as_str().into()),
        });
        // An explicit layout: a body need not read every binding.
        let entry = |binding: u32, read_only: bool| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("probe"),
            entries: &[entry(0, true), entry(1, true), entry(2, false)],
        });
        let pipeline_layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("probe"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("probe"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("probe"),
            compilation_options: Default::default(),
            cache: None,
        });
        let buffer = |label, data: &[u8], usage| {
            let padded = [data, &[0u8; 16]].concat();
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &padded,
                usage,
            })
        };
        let read = wgpu::BufferUsages::STORAGE;
        let params = buffer("params", bytemuck::cast_slice(&modules.params), read);
        let input = buffer("inputs", bytemuck::cast_slice(inputs), read);
        let out_len = records * probe.outputs_per_record;
        let output = buffer(
            "outputs",
            &vec![0u8; out_len * 4],
            read | wgpu::BufferUsages::COPY_SRC,
        );
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probe"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: input.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: output.as_entire_binding(),
                },
            ],
        });
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups((records as u32).div_ceil(64).max(1), 1, 1);
        }
        self.queue.submit([enc.finish()]);
        self.errors.check()?;
        device::read_f32s(d, &self.queue, &output, out_len, &self.errors)
    }
}

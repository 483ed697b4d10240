//! Rays traced on the GPU alone, for tests of the WGSL traversal against
//! the CPU's BVH: closest hits and occlusion of given rays through a
//! frame's geometry, in either hierarchy layout.

use super::BvhLayout;
use super::GpuBackend;
use super::device;
use super::error::GpuError;
use super::kernel::{Features, Kernel};
use super::upload::Geometry;
use crate::extract::RenderScene;
use glam::Vec3;
use wgpu::util::DeviceExt;

/// What the GPU found along one ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TracedRay {
    /// Distance to the closest hit (`f32::MAX` for none).
    pub t: f32,
    /// The primitive hit (the CPU's numbering), `u32::MAX` for none.
    pub prim: u32,
    /// Whether anything lies within the ray's `tmax`.
    pub occluded: bool,
}

impl GpuBackend {
    /// Traces `rays` (origin, direction, tmax for the occlusion query,
    /// time in the shutter) through `scene`'s geometry laid out in
    /// `layout`.
    pub fn trace_rays(
        &mut self,
        scene: &RenderScene,
        rays: &[(Vec3, Vec3, f32, f32)],
        layout: BvhLayout,
    ) -> Result<Vec<TracedRay>, GpuError> {
        let g = Geometry::new(scene, layout)?;
        let features = Features {
            instances: g.instanced,
            spheres: g.spheres,
            tangent_frames: g.tangent_frames,
            motion: g.motion,
            wide_bvh: layout == BvhLayout::Wide,
            ..Features::default()
        };
        let kernel = Kernel::assemble_trace(features);
        device::validate(&kernel)?;
        let d = &self.device;
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("trace"),
            source: wgpu::ShaderSource::Wgsl(kernel.source.as_str().into()),
        });
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("trace"),
            layout: None,
            module: &module,
            entry_point: Some("trace"),
            compilation_options: Default::default(),
            cache: None,
        });
        let packed: Vec<[f32; 4]> = rays
            .iter()
            .flat_map(|(o, dir, tmax, tau)| [[o.x, o.y, o.z, *tmax], [dir.x, dir.y, dir.z, *tau]])
            .collect();
        let buffer = |label, data: &[u8], usage| {
            let padded = [data, &[0u8; 16]].concat();
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &padded,
                usage,
            })
        };
        let read = wgpu::BufferUsages::STORAGE;
        let header = [g.root, 0, 0, 0];
        let buffers = [
            buffer("header", bytemuck::cast_slice(&header), read),
            buffer("nodes", bytemuck::cast_slice(&g.nodes), read),
            buffer("prims", bytemuck::cast_slice(&g.prims), read),
            buffer("shading", bytemuck::cast_slice(&g.shading), read),
            buffer("instances", bytemuck::cast_slice(&g.instances), read),
            d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("rays"),
                contents: bytemuck::cast_slice(&packed),
                usage: read,
            }),
            buffer(
                "hits",
                &vec![0u8; rays.len() * 16],
                read | wgpu::BufferUsages::COPY_SRC,
            ),
        ];
        let layout = pipeline.get_bind_group_layout(0);
        // Bindings the traversal does not read are left out of the
        // derived layout; bind what it kept.
        let entries: Vec<wgpu::BindGroupEntry> = buffers
            .iter()
            .enumerate()
            .filter(|(i, _)| kernel_uses(&kernel, *i))
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: b.as_entire_binding(),
            })
            .collect();
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("trace"),
            layout: &layout,
            entries: &entries,
        });
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups((rays.len() as u32).div_ceil(64).max(1), 1, 1);
        }
        self.queue.submit([enc.finish()]);
        self.errors.check()?;
        let out = device::read_f32s(d, &self.queue, &buffers[6], rays.len() * 4, &self.errors)?;
        Ok(out
            .chunks_exact(4)
            .map(|h| TracedRay {
                t: h[0],
                prim: h[1].to_bits(),
                occluded: h[2] != 0.0,
            })
            .collect())
    }
}

/// Whether the trace kernel reads binding `i` (the shading data and the
/// instances only where the features use them).
fn kernel_uses(kernel: &Kernel, i: usize) -> bool {
    match i {
        3 => false,
        4 => kernel.features.instances,
        _ => true,
    }
}

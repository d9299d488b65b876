//! Batches of shadow rays answered on the GPU: one compute invocation per ray over
//! the casters' BVH. For a host that wants exact visibility at points of its own,
//! and for the tests that hold the GPU tracer to the CPU reference.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

use super::{GROUP, GpuBvh, Traversal};
use crate::{Gpu, RenderError, readback};
use gnomon_scene::settings::Tracer;

/// A segment to test: from `origin` along the unit `direction`, up to `length`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowRay {
    /// Where the ray starts, already moved off its surface if it leaves one.
    pub origin: Vec3,
    /// Unit direction toward the light.
    pub direction: Vec3,
    /// How far to look: the light's distance, or the scene's size for a sun.
    pub length: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct RayGpu {
    pub(crate) origin: [f32; 3],
    pub(crate) length: f32,
    pub(crate) direction: [f32; 3],
    pub(crate) _pad: f32,
}

/// Threads per workgroup of the query shader (`QUERY_WORKGROUP` there).
const WORKGROUP: u32 = 64;

/// The query pass's WGSL for `traversal`, linked.
pub(crate) fn query_wgsl(traversal: Traversal) -> String {
    crate::passes::compose_wgsl(&[
        &format!("const QUERY_WORKGROUP: u32 = {WORKGROUP}u;"),
        &super::trace_wgsl(GROUP, traversal),
        include_str!("query.wgsl"),
    ])
}

/// A scene's casters on the GPU, ready to answer shadow rays.
pub struct ShadowRays {
    gpu: Gpu,
    bvh: GpuBvh,
    traversal: Traversal,
    pipeline: wgpu::ComputePipeline,
    io_layout: wgpu::BindGroupLayout,
}

impl ShadowRays {
    /// Builds and uploads the BVH of `scene`'s shadow casters, and on a GPU with ray
    /// queries, its acceleration structures (`Tracer::Auto`).
    pub fn new(gpu: &Gpu, scene: &gnomon_scene::Scene) -> Result<Self, RenderError> {
        Self::with_tracer(gpu, scene, Tracer::Auto)
    }

    /// As [`ShadowRays::new`], tracing as `tracer` asks. Ray queries asked for by
    /// name on a device that has none, or that cannot take the scene, are refused
    /// ([`RenderError::RayQueriesUnavailable`]): a batch has no frame to report a
    /// fallback in.
    pub fn with_tracer(gpu: &Gpu, scene: &gnomon_scene::Scene, tracer: Tracer) -> Result<Self, RenderError> {
        scene.validate()?;
        let device = &gpu.device;
        let (traversal, unavailable) = Traversal::resolve(tracer, gpu);
        if let Some(why) = unavailable {
            return Err(why.into());
        }
        let layouts = super::layouts(device);
        let bvh = GpuBvh::upload(gpu, scene, layouts.get(Traversal::Shader))?;
        let traversal = match (traversal, tracer) {
            (Traversal::Shader, _) => Traversal::Shader,
            (Traversal::RayQuery, _) => match bvh.build_accel(gpu, layouts.get(Traversal::RayQuery))? {
                Ok(()) => Traversal::RayQuery,
                Err(why) if tracer == Tracer::RayQuery => return Err(why.into()),
                Err(_) => Traversal::Shader,
            },
        };
        let rays_layout = layouts.get(traversal);
        let io_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow ray query"),
            entries: &[
                crate::passes::compute_storage_entry(0, crate::passes::StorageAccess::Read),
                crate::passes::compute_storage_entry(1, crate::passes::StorageAccess::ReadWrite),
            ],
        });
        let pipeline = gpu.checked("building the shadow ray query", || {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("shadow ray query"),
                bind_group_layouts: &[Some(&io_layout), None, None, Some(rays_layout)],
                immediate_size: 0,
            });
            let source = query_wgsl(traversal);
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("shadow ray query"),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("shadow ray query"),
                layout: Some(&layout),
                module: &module,
                entry_point: Some("cs_query"),
                compilation_options: Default::default(),
                cache: None,
            })
        })?;
        Ok(Self { gpu: Gpu::clone(gpu), bvh, traversal, pipeline, io_layout })
    }

    /// How the rays traverse the casters.
    pub fn traversal(&self) -> Traversal {
        self.traversal
    }

    /// Follows instances that moved: `scene`, the one these rays were made for, holds
    /// the new transforms of the instances numbered in `moved`. The tree is refitted,
    /// not rebuilt ([`crate::Renderer::move_instances`] says more). An index out of
    /// range or a non-finite transform is refused, naming it, before anything changes.
    pub fn move_instances(
        &mut self,
        scene: &gnomon_scene::Scene,
        moved: &[usize],
    ) -> Result<(), RenderError> {
        crate::gpu_scene::check_moved(scene, self.bvh.instance_count(), moved)?;
        self.bvh.refit(&self.gpu, scene, moved)
    }

    /// Triangles in the tree: every shadow-casting instance's.
    pub fn triangle_count(&self) -> usize {
        self.bvh.triangles
    }

    /// For each ray, whether a caster blocks it.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn occluded(&self, rays: &[ShadowRay]) -> Result<Vec<bool>, RenderError> {
        pollster::block_on(self.occluded_async(rays))
    }

    /// [`ShadowRays::occluded`], for a caller that cannot block (a browser).
    pub async fn occluded_async(&self, rays: &[ShadowRay]) -> Result<Vec<bool>, RenderError> {
        if rays.is_empty() {
            return Ok(Vec::new());
        }
        let device = &self.gpu.device;
        let data: Vec<RayGpu> = rays
            .iter()
            .map(|r| RayGpu {
                origin: r.origin.to_array(),
                length: r.length,
                direction: r.direction.to_array(),
                _pad: 0.0,
            })
            .collect();
        let answers = self.gpu.checked("tracing shadow rays", || {
            let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("shadow rays"),
                contents: bytemuck::cast_slice(&data),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let output = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("shadow ray answers"),
                size: 4 * rays.len() as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let io = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("shadow ray query"),
                layout: &self.io_layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: input.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
                ],
            });
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &io, &[]);
                pass.set_bind_group(GROUP, self.bvh.group(self.traversal), &[]);
                let groups = (rays.len() as u32).div_ceil(WORKGROUP);
                // Workgroups in two dimensions: one dimension alone stops at 65,535.
                let per_row = groups.min(device.limits().max_compute_workgroups_per_dimension);
                pass.dispatch_workgroups(per_row, groups.div_ceil(per_row), 1);
            }
            let staging = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("shadow ray answers, read back"),
                size: output.size(),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            encoder.copy_buffer_to_buffer(&output, 0, &staging, 0, output.size());
            self.gpu.queue.submit([encoder.finish()]);
            staging
        })?;
        let words: Vec<u32> = readback::read_buffer(&self.gpu, &answers).await?;
        Ok(words.into_iter().take(rays.len()).map(|w| w != 0).collect())
    }
}

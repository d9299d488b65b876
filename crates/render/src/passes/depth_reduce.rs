//! The sample-distribution pass of SDSM: a depth-only prepass from the camera and a
//! compute reduction of its depth buffer to the view depths actually seen, which the
//! cascades then split instead of the frustum's intersection with the scene bounds.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

/// The reduction pipeline and its bind group layout.
pub(crate) struct DepthReducePass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

/// The depth-range readback, waiting on the submission.
pub(crate) struct PendingDepthRange {
    buffer: wgpu::Buffer,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Planes {
    near: f32,
    far: f32,
    _pad: [f32; 2],
}

impl DepthReducePass {
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth reduction"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: false },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("depth_reduce.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("depth_reduce.wgsl").into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth reduction"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("depth reduction"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("reduce"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self { layout, pipeline }
    }

    /// Records the reduction of `depth` (a camera depth buffer with planes `near`,
    /// `far`) and the copy of its result out.
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        depth: &wgpu::Texture,
        near: f32,
        far: f32,
    ) -> PendingDepthRange {
        let range = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("depth range"),
            contents: bytemuck::cast_slice(&[u32::MAX, 0u32]),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        });
        let planes = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("camera planes"),
            contents: bytemuck::bytes_of(&Planes { near, far, _pad: [0.0; 2] }),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view = depth.create_view(&Default::default());
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("depth reduction"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) },
                wgpu::BindGroupEntry { binding: 1, resource: range.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: planes.as_entire_binding() },
            ],
        });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("depth reduction"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(depth.width().div_ceil(16), depth.height().div_ceil(16), 1);
        }
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("depth range readback"),
            size: 8,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        encoder.copy_buffer_to_buffer(&range, 0, &buffer, 0, 8);
        PendingDepthRange { buffer }
    }
}

impl PendingDepthRange {
    /// The (nearest, farthest) view depth seen, after the submission; None when the
    /// camera sees no surface.
    pub fn read(self, gpu: &crate::Gpu) -> Result<Option<(f32, f32)>, crate::RenderError> {
        let bits: Vec<u32> = crate::readback::read_buffer(gpu, &self.buffer)?;
        let (near, far) = (f32::from_bits(bits[0]), f32::from_bits(bits[1]));
        Ok((bits[0] != u32::MAX && near <= far).then_some((near, far)))
    }
}

//! The shadow-map preview: a live frame's depth map, every layer (cascade, cube face)
//! side by side in grayscale, as a colour texture a UI can show.

use bytemuck::{Pod, Zeroable};
use glam::Vec4;
use gnomon_math::{LightProjection, ProjectionKind};
use wgpu::util::DeviceExt;

use crate::gpu_types::MAX_CASCADES;

/// The preview's texel format: plain 8-bit, shown as is.
pub(crate) const PREVIEW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// See `map_preview.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct PreviewParams {
    tile: Vec4,
    layers: [Vec4; MAX_CASCADES],
}

pub(crate) struct MapPreviewPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

impl MapPreviewPass {
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("map preview"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                    count: None,
                },
                super::uniform_entry(1, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("map preview"),
            source: wgpu::ShaderSource::Wgsl(include_str!("map_preview.wgsl").into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("map preview"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("map preview"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_fullscreen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_preview"),
                compilation_options: Default::default(),
                targets: &[Some(PREVIEW_FORMAT.into())],
            }),
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        Self { layout, pipeline }
    }

    /// Draws the layers of `map` (described by `projections`), each `tile` pixels
    /// square, into a new texture.
    pub fn draw(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        map: &wgpu::Texture,
        projections: &[LightProjection],
        tile: u32,
    ) -> wgpu::Texture {
        let count = (map.depth_or_array_layers() as usize).min(MAX_CASCADES);
        let mut layers = [Vec4::ZERO; MAX_CASCADES];
        for (slot, projection) in layers.iter_mut().zip(projections) {
            let perspective = matches!(projection.kind, ProjectionKind::Perspective { .. });
            *slot = Vec4::new(perspective as u8 as f32, projection.near, projection.far, 0.0);
        }
        let params =
            PreviewParams { tile: Vec4::new(tile as f32, count as f32, map.width() as f32, 0.0), layers };
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("map preview"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view = map.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            aspect: wgpu::TextureAspect::DepthOnly,
            ..Default::default()
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("map preview"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) },
                wgpu::BindGroupEntry { binding: 1, resource: buffer.as_entire_binding() },
            ],
        });
        let target = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("map preview"),
            size: wgpu::Extent3d { width: tile * count as u32, height: tile, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: PREVIEW_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let target_view = target.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("map preview"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.draw(0..3, 0..1);
        }
        queue.submit([encoder.finish()]);
        target
    }
}

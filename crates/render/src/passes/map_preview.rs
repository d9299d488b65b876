//! The shadow-map preview: a live frame's depth map, every layer (cascade, cube face)
//! side by side in grayscale, as a colour texture a UI can show.

use bytemuck::{Pod, Zeroable};
use gnomon_math::{LightProjection, ProjectionKind};

use crate::{
    Gpu,
    pool::{Binding, Pool, ViewKey},
    uniforms::MAX_CASCADES,
};

/// The preview's texel format: plain 8-bit, shown as is.
pub(crate) const PREVIEW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// One layer of the preview (`PreviewLayer` in `map_preview.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Default, Pod, Zeroable)]
pub(crate) struct PreviewLayer {
    /// 1 for a perspective layer, whose depth is linearized first.
    pub perspective: u32,
    pub near: f32,
    pub far: f32,
    pub _pad: f32,
}

/// The preview's uniform (`Preview` in `map_preview.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct PreviewParams {
    /// Tile side in pixels.
    pub tile: f32,
    pub layer_count: u32,
    /// The map's texels per side.
    pub resolution: f32,
    pub _pad: f32,
    pub layers: [PreviewLayer; MAX_CASCADES],
}

pub(crate) struct MapPreviewPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

impl MapPreviewPass {
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("map preview"),
            source: wgpu::ShaderSource::Wgsl(preview_wgsl().into()),
        });
        let (layout, pipeline_layout) =
            super::depth_reader_layouts(device, "map preview", wgpu::TextureViewDimension::D2Array);
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
        gpu: &Gpu,
        pool: &mut Pool,
        map: &wgpu::Texture,
        projections: &[LightProjection],
        tile: u32,
    ) -> wgpu::Texture {
        let device = &gpu.device;
        let count = (map.depth_or_array_layers() as usize).min(MAX_CASCADES);
        let mut layers = [PreviewLayer::default(); MAX_CASCADES];
        for (slot, projection) in layers.iter_mut().zip(projections) {
            let perspective = matches!(projection.kind, ProjectionKind::Perspective { .. });
            *slot = PreviewLayer {
                perspective: perspective.into(),
                near: projection.near,
                far: projection.far,
                _pad: 0.0,
            };
        }
        let params = PreviewParams {
            tile: tile as f32,
            layer_count: count as u32,
            resolution: map.width() as f32,
            _pad: 0.0,
            layers,
        };
        let buffer = pool.uniform(&gpu.queue, "map preview", &params);
        let view = pool.view(map, ViewKey::whole(wgpu::TextureViewDimension::D2Array));
        let group =
            pool.bind_group("map preview", &self.layout, &[Binding::View(view), Binding::Buffer(buffer)]);
        let target = pool.texture(
            "map preview",
            wgpu::Extent3d { width: tile * count as u32, height: tile, depth_or_array_layers: 1 },
            PREVIEW_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        );
        let target_view = pool.view(&target, ViewKey::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        super::draw_fullscreen(&mut encoder, "map preview", &target_view, &self.pipeline, &group);
        gpu.queue.submit([encoder.finish()]);
        target
    }
}

/// `map_preview.wgsl`, composed.
pub(crate) fn preview_wgsl() -> String {
    super::compose_wgsl(&[super::FULLSCREEN_WGSL, include_str!("map_preview.wgsl")])
}

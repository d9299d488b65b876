//! Scrolling a kept shadow-map layer by whole texels (`map_scroll.wgsl`): a cascade
//! whose window moved by whole texels keeps what it drew, moved, and draws only the
//! strips it newly covers (`frame/map_cache.rs`).

use bytemuck::{Pod, Zeroable};

use super::SHADOW_FORMAT;
use crate::pool::{Binding, Pool};

/// The scroll's uniform (`Scroll` in `map_scroll.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct ScrollParams {
    /// Where a target texel's depth comes from, relative to it, in texels.
    pub(crate) offset: [i32; 2],
    /// The layer's texels per side.
    pub(crate) size: [i32; 2],
}

pub(crate) struct MapScrollPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

impl MapScrollPass {
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("map scroll"),
            source: wgpu::ShaderSource::Wgsl(scroll_wgsl().into()),
        });
        let (layout, pipeline_layout) =
            super::depth_reader_layouts(device, "map scroll", wgpu::TextureViewDimension::D2);
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("map scroll"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_fullscreen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_scroll"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            primitive: Default::default(),
            // Every texel is written, whatever it held.
            depth_stencil: Some(wgpu::DepthStencilState {
                format: SHADOW_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        Self { layout, pipeline }
    }

    /// Records into `target` (a layer of `size` texels per side) the layer `source`
    /// moved so that target texel p holds source texel p + `offset`, and the far plane
    /// where that lies outside it.
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        pool: &mut Pool,
        encoder: &mut wgpu::CommandEncoder,
        layer: ScrolledLayer,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites>,
    ) {
        let params = ScrollParams { offset: layer.offset, size: [layer.size as i32; 2] };
        let buffer = pool.uniform(queue, "map scroll", &params);
        let group = pool.bind_group(
            "map scroll",
            &self.layout,
            &[Binding::View(layer.source.clone()), Binding::Buffer(buffer)],
        );
        let mut pass = super::begin_depth_pass(
            encoder,
            "map scroll",
            layer.target,
            wgpu::LoadOp::Clear(1.0),
            timestamp_writes,
        );
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// One scroll: from a copy of the kept layer into the layer itself.
pub(crate) struct ScrolledLayer<'a> {
    pub source: &'a wgpu::TextureView,
    pub target: &'a wgpu::TextureView,
    pub offset: [i32; 2],
    pub size: u32,
}

/// `map_scroll.wgsl`, composed.
pub(crate) fn scroll_wgsl() -> String {
    super::compose_wgsl(&[super::FULLSCREEN_WGSL, include_str!("map_scroll.wgsl")])
}

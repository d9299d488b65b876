//! The copy of Gnomon's colour image into a host's texture ([`crate::Renderer::render_into`]):
//! a full-screen triangle per target format, so that any renderable colour format
//! will do, where a texture copy would need the same format.

use std::collections::HashMap;

use super::compose_wgsl;
use crate::pool::{Binding, Pool, ViewKey};

/// The blit's WGSL, composed.
pub(crate) fn blit_wgsl() -> String {
    compose_wgsl(&[super::FULLSCREEN_WGSL, include_str!("blit.wgsl")])
}

/// A host's colour target for [`crate::Renderer::render_into`]: a view, its format
/// (any renderable colour format) and its size, which the image takes.
#[derive(Clone, Copy, Debug)]
pub struct HostTarget<'a> {
    /// Where the image goes (a texture made with `RENDER_ATTACHMENT` usage).
    pub view: &'a wgpu::TextureView,
    /// The view's format.
    pub format: wgpu::TextureFormat,
    /// Its width in pixels.
    pub width: u32,
    /// Its height in pixels.
    pub height: u32,
}

impl<'a> HostTarget<'a> {
    /// The target `view` of `texture` (a whole-texture view of its own format).
    pub fn new(texture: &wgpu::Texture, view: &'a wgpu::TextureView) -> Self {
        Self { view, format: texture.format(), width: texture.width(), height: texture.height() }
    }
}

pub(crate) struct BlitPass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    module: wgpu::ShaderModule,
    /// One pipeline per target format, built on first use.
    pipelines: HashMap<wgpu::TextureFormat, wgpu::RenderPipeline>,
}

impl BlitPass {
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("blit"),
            entries: &[super::unfilterable_texture_entry(0)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("blit"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("blit"),
            source: wgpu::ShaderSource::Wgsl(blit_wgsl().into()),
        });
        Self { layout, pipeline_layout, module, pipelines: HashMap::new() }
    }

    /// Records the copy of `image` into `target`, of the same size.
    pub fn record(
        &mut self,
        device: &wgpu::Device,
        pool: &mut Pool,
        encoder: &mut wgpu::CommandEncoder,
        image: &wgpu::Texture,
        target: &HostTarget,
    ) {
        let HostTarget { view: target_view, format, .. } = *target;
        let source = pool.view(image, ViewKey::default());
        let group = pool.bind_group("blit", &self.layout, &[Binding::View(source)]);
        let Self { pipeline_layout, module, pipelines, .. } = self;
        let pipeline = pipelines.entry(format).or_insert_with(|| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("blit"),
                layout: Some(pipeline_layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_fullscreen"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_blit"),
                    compilation_options: Default::default(),
                    targets: &[Some(format.into())],
                }),
                primitive: Default::default(),
                depth_stencil: None,
                multisample: Default::default(),
                multiview_mask: None,
                cache: None,
            })
        });
        super::draw_fullscreen(encoder, "blit", target_view, pipeline, &group);
    }
}

//! The lighting pass: every instance shaded from the camera with the selected
//! technique's shadow lookup, writing the colour image and the per-pixel outputs.

use std::collections::HashMap;

use gnomon_scene::settings::Technique;

use super::{LIGHT_WGSL, Layouts, SCENE_COMMON_WGSL, compose_wgsl};
use crate::{gpu_types::VertexGpu, techniques};

pub(crate) const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub(crate) const VISIBILITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
pub(crate) const POSITION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub(crate) const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub(crate) const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The colour attachments, in location order.
pub(crate) const TARGETS: [wgpu::TextureFormat; 5] =
    [COLOR_FORMAT, VISIBILITY_FORMAT, POSITION_FORMAT, NORMAL_FORMAT, ID_FORMAT];

/// Bytes per pixel of all colour attachments together (checked against the device).
pub(crate) fn target_bytes_per_pixel() -> u32 {
    TARGETS.iter().map(|f| f.block_copy_size(None).unwrap_or(16)).sum()
}

/// Lighting pipelines, one per technique, built on first use.
pub(crate) struct LightingPass {
    layout: wgpu::PipelineLayout,
    pipelines: HashMap<Technique, wgpu::RenderPipeline>,
}

impl LightingPass {
    pub fn new(device: &wgpu::Device, layouts: &Layouts) -> Self {
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lighting"),
            bind_group_layouts: &[
                Some(&layouts.scene),
                Some(&layouts.camera),
                Some(&layouts.shadow),
                Some(&layouts.material),
            ],
            immediate_size: 0,
        });
        Self { layout, pipelines: HashMap::new() }
    }

    pub fn pipeline(&mut self, device: &wgpu::Device, technique: Technique) -> &wgpu::RenderPipeline {
        let layout = &self.layout;
        self.pipelines.entry(technique).or_insert_with(|| {
            let mut parts: Vec<String> = vec![LIGHT_WGSL.to_owned(), SCENE_COMMON_WGSL.to_owned()];
            parts.extend(techniques::shared_wgsl());
            parts.extend(techniques::lookup(technique).wgsl().iter().map(|s| s.to_string()));
            parts.push(include_str!("lighting.wgsl").to_owned());
            let refs: Vec<&str> = parts.iter().map(String::as_str).collect();
            let source = compose_wgsl(&refs);
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(technique.name()),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
            let targets = TARGETS.map(|format| Some(wgpu::ColorTargetState::from(format)));
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("lighting"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(VertexGpu::layout())],
                },
                // Both sides are drawn, as a ray tracer sees them; the shader flips the
                // normal of back faces.
                primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        })
    }
}

//! The shadow pass: casters drawn depth-only from the light into a Depth32Float map,
//! with the rasterizer's constant and slope-scaled depth bias and a chosen cull mode.

use std::collections::HashMap;

use gnomon_scene::settings::{BiasSettings, CullMode};

use super::{Layouts, SCENE_COMMON_WGSL, SHADOW_FORMAT, compose_wgsl};
use crate::gpu_types::VertexGpu;

/// What makes two shadow pipelines differ.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
struct ShadowPipelineKey {
    cull: CullMode,
    depth_bias: i32,
    slope_bias_bits: u32,
}

/// Shadow-pass pipelines, built on first use for each bias and cull combination.
pub(crate) struct ShadowPass {
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    pipelines: HashMap<ShadowPipelineKey, wgpu::RenderPipeline>,
}

impl ShadowPass {
    pub fn new(device: &wgpu::Device, layouts: &Layouts) -> Self {
        let source = compose_wgsl(&[SCENE_COMMON_WGSL, include_str!("shadow_depth.wgsl")]);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("shadow depth"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow depth"),
            bind_group_layouts: &[Some(&layouts.scene)],
            immediate_size: 0,
        });
        Self { module, layout, pipelines: HashMap::new() }
    }

    pub fn pipeline(&mut self, device: &wgpu::Device, bias: &BiasSettings) -> &wgpu::RenderPipeline {
        let key = ShadowPipelineKey {
            cull: bias.cull,
            depth_bias: bias.depth_bias,
            slope_bias_bits: bias.slope_bias.to_bits(),
        };
        let (module, layout) = (&self.module, &self.layout);
        self.pipelines.entry(key).or_insert_with(|| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("shadow depth"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_shadow"),
                    compilation_options: Default::default(),
                    buffers: &[Some(VertexGpu::layout())],
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode: match key.cull {
                        CullMode::Back => Some(wgpu::Face::Back),
                        CullMode::Front => Some(wgpu::Face::Front),
                        CullMode::None => None,
                    },
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: SHADOW_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::LessEqual),
                    stencil: Default::default(),
                    // The clamp stays 0: wgpu 30 does not enable the Vulkan feature
                    // (depthBiasClamp) that a non-zero clamp needs.
                    bias: wgpu::DepthBiasState {
                        constant: key.depth_bias,
                        slope_scale: f32::from_bits(key.slope_bias_bits),
                        clamp: 0.0,
                    },
                }),
                multisample: Default::default(),
                fragment: None,
                multiview_mask: None,
                cache: None,
            })
        })
    }
}

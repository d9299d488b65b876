//! The shadow pass: casters drawn depth-only from the light into a Depth32Float map,
//! with the rasterizer's constant and slope-scaled depth bias and a chosen cull mode.
//! A point light's cube faces write distance over range instead, with the same bias
//! applied in the fragment stage (`shadow_depth.wgsl`), and flip their winding: the
//! face views are mirrored (`gnomon_math::omni`).

use std::collections::HashMap;

use gnomon_scene::settings::{BiasSettings, CullMode};

use super::{LIGHT_WGSL, Layouts, SCENE_COMMON_WGSL, SHADOW_FORMAT, compose_wgsl};
use crate::gpu_types::VertexGpu;

/// What makes two shadow pipelines differ.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
struct ShadowPipelineKey {
    cull: CullMode,
    depth_bias: i32,
    slope_bias_bits: u32,
    masked: bool,
    unclipped: bool,
    target: DepthTarget,
}

/// What a shadow pass stores in its depth attachment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum DepthTarget {
    /// The projection's own depth, biased by the rasterizer: suns and spots.
    Projected,
    /// Distance over range, through a cube face's mirrored view.
    CubeFace,
    /// Distance over range, through a dual-paraboloid hemisphere (mirrored too).
    Paraboloid,
}

/// Shadow-pass pipelines, built on first use for each bias, cull and alpha-test
/// combination. Opaque casters use a vertex-only pipeline; alpha-masked casters add a
/// fragment stage that discards cut-out texels.
pub(crate) struct ShadowPass {
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    masked_layout: wgpu::PipelineLayout,
    pipelines: HashMap<ShadowPipelineKey, wgpu::RenderPipeline>,
}

/// The shadow pass's position-only vertex stream: opaque casters into a projected map
/// read nothing else, and a third of the bytes fetched is a third of the bandwidth.
const POSITIONS: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 12,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &[wgpu::VertexAttribute {
        format: wgpu::VertexFormat::Float32x3,
        offset: 0,
        shader_location: 0,
    }],
};

impl ShadowPass {
    /// Whether this pipeline reads the position-only stream
    /// ([`crate::GpuScene`]'s `positions`) rather than the full vertices.
    pub fn reads_positions_only(masked: bool, target: DepthTarget) -> bool {
        !masked && target == DepthTarget::Projected
    }

    pub fn new(device: &wgpu::Device, layouts: &Layouts) -> Self {
        let source = compose_wgsl(&[LIGHT_WGSL, SCENE_COMMON_WGSL, include_str!("shadow_depth.wgsl")]);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("shadow depth"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow depth"),
            bind_group_layouts: &[Some(&layouts.scene)],
            immediate_size: 0,
        });
        let masked_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow depth, alpha-masked"),
            bind_group_layouts: &[Some(&layouts.scene), Some(&layouts.material)],
            immediate_size: 0,
        });
        Self { module, layout, masked_layout, pipelines: HashMap::new() }
    }

    /// The pipeline for casters with these bias settings; `double_sided` casters are
    /// never culled, `masked` ones run the alpha test, and `unclipped` clamps depth
    /// instead of clipping it (pancaking; needs `Features::DEPTH_CLIP_CONTROL`), and
    /// `target` says what the pass stores.
    pub fn pipeline(
        &mut self,
        device: &wgpu::Device,
        bias: &BiasSettings,
        double_sided: bool,
        masked: bool,
        unclipped: bool,
        target: DepthTarget,
    ) -> &wgpu::RenderPipeline {
        let key = ShadowPipelineKey {
            cull: if double_sided { CullMode::None } else { bias.cull },
            depth_bias: bias.depth_bias,
            slope_bias_bits: bias.slope_bias.to_bits(),
            masked,
            unclipped,
            target,
        };
        let writes_distance = target != DepthTarget::Projected;
        let module = &self.module;
        let layout = if masked { &self.masked_layout } else { &self.layout };
        self.pipelines.entry(key).or_insert_with(|| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(match (target, masked) {
                    (DepthTarget::CubeFace, _) => "shadow distance (cube face)",
                    (DepthTarget::Paraboloid, _) => "shadow distance (paraboloid)",
                    (DepthTarget::Projected, true) => "shadow depth, alpha-masked",
                    (DepthTarget::Projected, false) => "shadow depth",
                }),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some(match (target, masked) {
                        (DepthTarget::CubeFace, _) => "vs_shadow_distance",
                        (DepthTarget::Paraboloid, _) => "vs_shadow_paraboloid",
                        (DepthTarget::Projected, true) => "vs_shadow_masked",
                        (DepthTarget::Projected, false) => "vs_shadow",
                    }),
                    compilation_options: Default::default(),
                    buffers: &[Some(if Self::reads_positions_only(masked, target) {
                        POSITIONS
                    } else {
                        VertexGpu::layout()
                    })],
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode: match key.cull {
                        CullMode::Back => Some(wgpu::Face::Back),
                        CullMode::Front => Some(wgpu::Face::Front),
                        CullMode::None => None,
                    },
                    unclipped_depth: key.unclipped,
                    front_face: if writes_distance { wgpu::FrontFace::Cw } else { wgpu::FrontFace::Ccw },
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: SHADOW_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::LessEqual),
                    stencil: Default::default(),
                    // The clamp stays 0: wgpu 30 does not enable the Vulkan feature
                    // (depthBiasClamp) that a non-zero clamp needs. A cube face biases
                    // the depth it writes itself (the rasterizer's bias does not reach
                    // a written depth).
                    bias: if writes_distance {
                        wgpu::DepthBiasState::default()
                    } else {
                        wgpu::DepthBiasState {
                            constant: key.depth_bias,
                            slope_scale: f32::from_bits(key.slope_bias_bits),
                            clamp: 0.0,
                        }
                    },
                }),
                multisample: Default::default(),
                fragment: (masked || writes_distance).then_some(wgpu::FragmentState {
                    module,
                    entry_point: Some(match (target, masked) {
                        (DepthTarget::CubeFace, true) => "fs_shadow_distance_masked",
                        (DepthTarget::CubeFace, false) => "fs_shadow_distance",
                        (DepthTarget::Paraboloid, true) => "fs_shadow_paraboloid_masked",
                        (DepthTarget::Paraboloid, false) => "fs_shadow_paraboloid",
                        (DepthTarget::Projected, _) => "fs_shadow_masked",
                    }),
                    compilation_options: Default::default(),
                    targets: &[],
                }),
                multiview_mask: None,
                cache: None,
            })
        })
    }
}

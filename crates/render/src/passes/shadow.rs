//! The shadow pass: casters drawn depth-only from the light into a Depth32Float map,
//! with the rasterizer's constant and slope-scaled depth bias and a chosen cull mode.
//! A point light's cube faces write distance over range instead, with the same bias
//! applied in the fragment stage (`shadow_depth.wgsl`), and flip their winding: the
//! face views are mirrored (`gnomon_math::omni`).
//!
//! Opaque casters into a projected map take the cheapest path a rasterizer has: no
//! fragment stage, a 12-byte position stream, the instance's matrix as a per-instance
//! attribute, and no storage buffer read. [`ShadowPipelineShape`] states each
//! pipeline's shape as data, and the tests below hold the opaque one to that, so that
//! the pass stays within reach of the depth-only baseline (`depth_baseline`).

/// What a shadow map's texel that no caster covers holds: the depth pass clears to
/// the far plane. The penumbra classification and the map's pyramid leave such texels
/// out (depth_pyramid.wgsl, penumbra_classify.wgsl: `MAP_CLEARED`).
pub(crate) const MAP_CLEARED_DEPTH: f32 = 1.0;

use std::collections::HashMap;

use gnomon_scene::{
    Instance, Scene,
    settings::{BiasSettings, CullMode},
};

use super::{LIGHT_WGSL, Layouts, SCENE_COMMON_WGSL, SHADOW_FORMAT, compose_wgsl};
use crate::gpu_types::VertexStream;

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

impl DepthTarget {
    /// The winding its pipelines call front: a cube face's and a paraboloid's views
    /// are mirrored (`gnomon_math::omni`).
    pub fn front_face(self) -> wgpu::FrontFace {
        match self {
            DepthTarget::Projected => wgpu::FrontFace::Ccw,
            DepthTarget::CubeFace | DepthTarget::Paraboloid => wgpu::FrontFace::Cw,
        }
    }
}

/// Whether a caster's surface is cut by its texture's alpha.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Coverage {
    Opaque,
    /// Alpha-masked: the fragment stage discards cut-out texels.
    Masked,
}

/// What depth outside the projection's near and far planes does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum DepthRange {
    Clipped,
    /// Clamped onto the range (pancaking); needs `Features::DEPTH_CLIP_CONTROL`.
    Clamped,
}

impl DepthRange {
    pub fn clamped_if(clamp: bool) -> Self {
        if clamp { DepthRange::Clamped } else { DepthRange::Clipped }
    }
}

/// Everything that makes two shadow pipelines differ.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct ShadowPipelineKey {
    /// The faces the rasterizer culls, once `cull auto` is resolved for the casters.
    pub cull: Option<wgpu::Face>,
    pub depth_bias: i32,
    slope_bias_bits: u32,
    pub coverage: Coverage,
    pub depth_range: DepthRange,
    pub target: DepthTarget,
}

impl ShadowPipelineKey {
    /// The key for casters of `sides` drawn with `bias` (its cull mode as
    /// [`Sides::culled_face`] resolves it).
    pub fn new(
        bias: &BiasSettings,
        sides: Sides,
        coverage: Coverage,
        depth_range: DepthRange,
        target: DepthTarget,
    ) -> Self {
        Self {
            cull: sides.culled_face(bias.cull),
            depth_bias: bias.depth_bias,
            slope_bias_bits: bias.slope_bias.to_bits(),
            coverage,
            depth_range,
            target,
        }
    }

    pub fn slope_bias(&self) -> f32 {
        f32::from_bits(self.slope_bias_bits)
    }
}

/// Which faces of a batch of casters can block light, from its material and mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum Sides {
    /// A glTF double-sided material: both faces cast, whatever the cull setting.
    Double,
    /// A single-sided material on a closed mesh: every ray into it crosses a front
    /// face and a back face, so culling either loses no blocker.
    Closed,
    /// A single-sided material on an open mesh (a wall, a roof, a drape): `cull auto`
    /// draws both faces.
    Open,
}

impl Sides {
    /// The faces the shadow pass culls on casters of these sides under `mode`:
    /// double-sided casters are never culled, and `cull auto` culls back faces of
    /// closed meshes only.
    pub fn culled_face(self, mode: CullMode) -> Option<wgpu::Face> {
        match (self, mode) {
            (Sides::Double, _)
            | (Sides::Open | Sides::Closed, CullMode::None)
            | (Sides::Open, CullMode::Auto) => None,
            (Sides::Closed, CullMode::Auto) | (Sides::Open | Sides::Closed, CullMode::Back) => {
                Some(wgpu::Face::Back)
            }
            (Sides::Open | Sides::Closed, CullMode::Front) => Some(wgpu::Face::Front),
        }
    }

    /// The faces of `instance` that can block light; `closed` says per mesh whether
    /// it is closed ([`Scene::closed_meshes`]).
    pub fn of(scene: &Scene, instance: &Instance, closed: &[bool]) -> Sides {
        match (scene.materials[instance.material].double_sided, closed[instance.mesh]) {
            (true, _) => Sides::Double,
            (false, true) => Sides::Closed,
            (false, false) => Sides::Open,
        }
    }
}

/// A shadow pipeline's shape: its entry points, what it reads and how it rasterizes.
/// The pipeline is built from this and nothing else, so a test can inspect it without
/// a device.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ShadowPipelineShape {
    pub label: &'static str,
    pub vertex_entry: &'static str,
    /// None: depth only, the rasterizer's fixed-function path.
    pub fragment_entry: Option<&'static str>,
    pub stream: VertexStream,
    pub front_face: wgpu::FrontFace,
    pub cull_mode: Option<wgpu::Face>,
    pub unclipped_depth: bool,
    pub bias: wgpu::DepthBiasState,
}

impl ShadowPipelineShape {
    pub fn of(key: &ShadowPipelineKey) -> Self {
        use {Coverage::*, DepthTarget::*};
        let (label, vertex_entry, fragment_entry) = match (key.target, key.coverage) {
            (Projected, Opaque) => ("shadow depth", "vs_shadow", None),
            (Projected, Masked) => {
                ("shadow depth, alpha-masked", "vs_shadow_masked", Some("fs_shadow_masked"))
            }
            (CubeFace, Opaque) => {
                ("shadow distance (cube face)", "vs_shadow_distance", Some("fs_shadow_distance"))
            }
            (CubeFace, Masked) => {
                ("shadow distance (cube face)", "vs_shadow_distance", Some("fs_shadow_distance_masked"))
            }
            (Paraboloid, Opaque) => {
                ("shadow distance (paraboloid)", "vs_shadow_paraboloid", Some("fs_shadow_paraboloid"))
            }
            (Paraboloid, Masked) => {
                ("shadow distance (paraboloid)", "vs_shadow_paraboloid", Some("fs_shadow_paraboloid_masked"))
            }
        };
        let writes_distance = key.target != Projected;
        Self {
            label,
            vertex_entry,
            fragment_entry,
            // Only opaque casters into a projected map need nothing but the position.
            stream: if key.coverage == Opaque && !writes_distance {
                VertexStream::PositionsOnly
            } else {
                VertexStream::Full
            },
            front_face: key.target.front_face(),
            cull_mode: key.cull,
            unclipped_depth: key.depth_range == DepthRange::Clamped,
            // The clamp stays 0: wgpu 30 does not enable the Vulkan feature
            // (depthBiasClamp) that a non-zero clamp needs. A distance pass biases the
            // depth it writes itself (the rasterizer's bias does not reach a written
            // depth).
            bias: if writes_distance {
                wgpu::DepthBiasState::default()
            } else {
                wgpu::DepthBiasState { constant: key.depth_bias, slope_scale: key.slope_bias(), clamp: 0.0 }
            },
        }
    }
}

/// Shadow-pass pipelines, built on first use for each key.
pub(crate) struct ShadowPass {
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    masked_layout: wgpu::PipelineLayout,
    pipelines: HashMap<ShadowPipelineKey, wgpu::RenderPipeline>,
}

/// The shadow pass's WGSL, composed.
pub(crate) fn shadow_wgsl() -> String {
    let light = super::light_binding_wgsl(super::OWN_LIGHT_BINDING);
    // The alpha-masked casters' texture is the depth pass's group 1.
    let material = super::material_bindings_wgsl(super::BindingPlace { group: 1, binding: 0 });
    compose_wgsl(&[LIGHT_WGSL, SCENE_COMMON_WGSL, &light, &material, include_str!("shadow_depth.wgsl")])
}

impl ShadowPass {
    pub fn new(device: &wgpu::Device, layouts: &Layouts) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("shadow depth"),
            source: wgpu::ShaderSource::Wgsl(shadow_wgsl().into()),
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

    /// The pipeline for `key`, built from its [`ShadowPipelineShape`].
    pub fn pipeline(&mut self, device: &wgpu::Device, key: &ShadowPipelineKey) -> &wgpu::RenderPipeline {
        let module = &self.module;
        let layout = match key.coverage {
            Coverage::Opaque => &self.layout,
            Coverage::Masked => &self.masked_layout,
        };
        self.pipelines.entry(*key).or_insert_with(|| {
            let shape = ShadowPipelineShape::of(key);
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(shape.label),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some(shape.vertex_entry),
                    compilation_options: Default::default(),
                    buffers: &shape.stream.buffers(),
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode: shape.cull_mode,
                    unclipped_depth: shape.unclipped_depth,
                    front_face: shape.front_face,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: SHADOW_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::LessEqual),
                    stencil: Default::default(),
                    bias: shape.bias,
                }),
                multisample: Default::default(),
                fragment: shape.fragment_entry.map(|entry| wgpu::FragmentState {
                    module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets: &[],
                }),
                multiview_mask: None,
                cache: None,
            })
        })
    }
}

#[cfg(test)]
#[path = "shadow_tests.rs"]
mod tests;

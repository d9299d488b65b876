//! The depth-only baseline that the shadow pass is measured against: the same casters,
//! pre-transformed to world space in one vertex buffer (positions only) and drawn with
//! one draw call per cull state into the same layers at the same resolution, with a
//! vertex-only pipeline that reads one matrix and rasterizes as the shadow pass does
//! (cull mode, winding, depth clamp and bias). No instance data, no culling work, no
//! state changes: what any shadow pass must at least cost.

use std::{collections::BTreeMap, ops::Range};

use glam::{Mat4, Vec3};
use gnomon_scene::{Scene, settings::BiasSettings};
use wgpu::util::DeviceExt;

use super::{
    SHADOW_FORMAT,
    shadow::{Coverage, DepthRange, DepthTarget, ShadowPipelineKey, ShadowPipelineShape, Sides},
};
use crate::{
    Gpu, RenderError,
    pool::{Binding, Pool},
};

/// The casters of a scene, flattened for the depth-only baseline pass.
pub struct DepthBaselineScene {
    positions: wgpu::Buffer,
    indices: wgpu::Buffer,
    /// Index ranges of the casters of each kind of [`Sides`], drawn with its own cull.
    ranges: Vec<(Sides, Range<u32>)>,
    /// Triangles it draws per layer.
    pub triangles: usize,
}

impl DepthBaselineScene {
    /// Flattens every shadow-casting instance of `scene` into world space, grouped by
    /// the faces that can block light (as the shadow pass's batches are). Alpha-masked
    /// casters are drawn solid: the baseline has no texture to test.
    pub fn upload(gpu: &Gpu, scene: &Scene) -> Result<Self, RenderError> {
        let closed = scene.closed_meshes();
        let mut positions: Vec<Vec3> = Vec::new();
        let mut by_sides: BTreeMap<Sides, Vec<u32>> = BTreeMap::new();
        for instance in scene.instances.iter().filter(|i| i.casts_shadow) {
            let mesh = &scene.meshes[instance.mesh];
            let base = positions.len() as u32;
            positions.extend(mesh.positions.iter().map(|&p| instance.world_from_object.transform_point3(p)));
            let sides = by_sides.entry(Sides::of(scene, instance, &closed)).or_default();
            sides.extend(mesh.indices.iter().map(|&i| base + i));
        }
        let mut indices = Vec::new();
        let mut ranges = Vec::new();
        for (sides, list) in by_sides {
            let start = indices.len() as u32;
            indices.extend(list);
            ranges.push((sides, start..indices.len() as u32));
        }
        if indices.is_empty() {
            return Err(RenderError::EmptyScene(scene.name.clone()));
        }
        let triangles = indices.len() / 3;
        let device = &gpu.device;
        gpu.checked("uploading the depth-only baseline", || Self {
            positions: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("baseline positions"),
                contents: bytemuck::cast_slice(&positions),
                usage: wgpu::BufferUsages::VERTEX,
            }),
            indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("baseline indices"),
                contents: bytemuck::cast_slice(&indices),
                usage: wgpu::BufferUsages::INDEX,
            }),
            ranges,
            triangles,
        })
    }
}

/// The baseline's pipelines, one per shadow-pipeline key it stands in for.
pub(crate) struct DepthBaselinePass {
    module: wgpu::ShaderModule,
    group_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    pipelines: std::collections::HashMap<ShadowPipelineKey, wgpu::RenderPipeline>,
}

/// One layer the baseline draws.
pub(crate) struct BaselineLayer<'a> {
    pub clip_from_world: Mat4,
    pub raster: BaselineRaster<'a>,
    pub target: &'a wgpu::TextureView,
}

/// How the shadow pass would rasterize a layer: the baseline rasterizes the same way,
/// so that the two draw the same depth map.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BaselineRaster<'a> {
    pub bias: &'a BiasSettings,
    pub depth_range: DepthRange,
    pub target: DepthTarget,
}

impl BaselineRaster<'_> {
    fn key(&self, sides: Sides) -> ShadowPipelineKey {
        ShadowPipelineKey::new(self.bias, sides, Coverage::Opaque, self.depth_range, self.target)
    }
}

/// The baseline's WGSL, linked.
pub(crate) fn baseline_wgsl() -> String {
    super::compose_wgsl(&[include_str!("depth_baseline.wgsl")])
}

impl DepthBaselinePass {
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("depth-only baseline"),
            source: wgpu::ShaderSource::Wgsl(baseline_wgsl().into()),
        });
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("depth-only baseline"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("depth-only baseline"),
            bind_group_layouts: &[Some(&group_layout)],
            immediate_size: 0,
        });
        Self { module, group_layout, layout, pipelines: Default::default() }
    }

    /// The pipeline standing in for the shadow pipeline of `key`: its own vertex stage
    /// and no fragment stage, with the shadow pipeline's culling, winding, depth range
    /// and bias ([`ShadowPipelineShape`]). A distance map's bias is written by its
    /// fragment stage, so the baseline of a cube face or paraboloid has none.
    fn pipeline(&mut self, device: &wgpu::Device, key: ShadowPipelineKey) -> &wgpu::RenderPipeline {
        let (module, layout) = (&self.module, &self.layout);
        self.pipelines.entry(key).or_insert_with(|| {
            let shape = ShadowPipelineShape::of(&key);
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("depth-only baseline"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_baseline"),
                    compilation_options: Default::default(),
                    buffers: &[Some(wgpu::VertexBufferLayout {
                        array_stride: 12,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &wgpu::vertex_attr_array![0 => Float32x3],
                    })],
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
                fragment: None,
                multiview_mask: None,
                cache: None,
            })
        })
    }

    /// Builds the pipelines that `scene` needs under `raster`, before a pass
    /// borrows them.
    pub fn prepare(&mut self, device: &wgpu::Device, scene: &DepthBaselineScene, raster: BaselineRaster<'_>) {
        for (sides, _) in &scene.ranges {
            self.pipeline(device, raster.key(*sides));
        }
    }

    /// The bind group of one matrix, from `pool`.
    pub fn matrix_group(&self, gpu: &Gpu, pool: &mut Pool, clip_from_world: Mat4) -> wgpu::BindGroup {
        let matrix = pool.uniform(&gpu.queue, "baseline clip_from_world", &clip_from_world);
        pool.bind_group("depth-only baseline", &self.group_layout, &[Binding::Buffer(matrix)])
    }

    /// Draws `scene` into the open `pass` through `group`'s matrix, with the
    /// pipelines [`DepthBaselinePass::prepare`] built for `raster`.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene: &DepthBaselineScene,
        raster: BaselineRaster<'_>,
        group: &wgpu::BindGroup,
    ) {
        pass.set_bind_group(0, group, &[]);
        pass.set_vertex_buffer(0, scene.positions.slice(..));
        pass.set_index_buffer(scene.indices.slice(..), wgpu::IndexFormat::Uint32);
        for (sides, range) in &scene.ranges {
            if !range.is_empty() {
                pass.set_pipeline(&self.pipelines[&raster.key(*sides)]);
                pass.draw_indexed(range.clone(), 0, 0..1);
            }
        }
    }

    /// Records the baseline's depth pass into `layer.target` through
    /// `layer.clip_from_world`, rasterized as `layer.raster` says the shadow pass would.
    pub fn record(
        &mut self,
        gpu: &Gpu,
        pool: &mut Pool,
        encoder: &mut wgpu::CommandEncoder,
        scene: &DepthBaselineScene,
        layer: BaselineLayer<'_>,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites>,
    ) {
        let BaselineLayer { clip_from_world, raster, target } = layer;
        let group = self.matrix_group(gpu, pool, clip_from_world);
        self.prepare(&gpu.device, scene, raster);
        // The same pass set-up (attachment, load and store) as the shadow pass's.
        let mut pass = super::begin_depth_pass(
            encoder,
            "depth-only baseline",
            target,
            wgpu::LoadOp::Clear(1.0),
            timestamp_writes,
        );
        self.draw(&mut pass, scene, raster, &group);
    }
}

//! One depth-only pass with the shadow pipelines (a shadow-map layer, its strips, or
//! SDSM's camera prepass), and how its draws are submitted (`DrawSubmission`):
//! culled on the GPU, each bucket of the shadow items one multi-draw whose count the
//! culler wrote; or culled on the CPU and bucketed by the state they share (scissor,
//! pipeline, material), each bucket one multi-draw from a buffer of draw arguments,
//! or its draws one by one. Depth-only draws may go in any order: the nearest depth
//! wins whichever comes first, so the map is the same either way.

use gnomon_scene::{Motion, Settings, settings::DrawSubmission};

use super::{
    Renderer,
    bindings::{argument_slots, scene_group},
    recording::DrawStats,
};
use crate::{
    GpuScene,
    gpu_scene::{
        CullView, DrawArgs, Granularity, IndexOrder, Run, Visible,
        shadow_items::{BucketClass, ShadowItems},
    },
    gpu_types::VertexStream,
    passes::{
        begin_depth_pass,
        gpu_cull::{CullTarget, CulledDraws},
        shadow::{Coverage, DepthRange, DepthTarget, ShadowPass, ShadowPipelineKey, ShadowPipelineShape},
    },
    uniforms::LightGpu,
};

/// One depth-only pass: a shadow-map layer, or SDSM's camera prepass.
#[derive(Clone)]
pub(super) struct DepthPass<'a> {
    pub settings: &'a Settings,
    /// The uniform whose `clip_from_world` projects the geometry.
    pub light: &'a LightGpu,
    pub target_view: &'a wgpu::TextureView,
    pub visible: &'a Visible,
    pub target: DepthTarget,
    /// Clamp depth instead of clipping it.
    pub unclipped: bool,
    /// What the pass starts from.
    pub start: DepthStart,
    /// Where it draws.
    pub area: DepthArea,
    /// What a shadow layer's pass culls against, for the GPU culler; None for a pass
    /// that draws only what the CPU culled (SDSM's prepass).
    pub culling: Option<LayerCulling>,
}

/// What a shadow layer's pass draws, for the GPU culler to find.
#[derive(Clone, Copy, Debug)]
pub(super) struct LayerCulling {
    /// The layer (or the strip of it drawn) its casters are culled against.
    pub view: CullView,
    pub casters: Casters,
}

/// Which of a layer's casters a pass draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Casters {
    All,
    /// Those that stay: what a kept layer holds.
    Still,
    /// Those that move: drawn over a kept layer's copy.
    Moving,
}

impl Casters {
    /// Whether casters of `motion` are among these.
    pub fn take(self, motion: Motion) -> bool {
        match self {
            Casters::All => true,
            Casters::Still => motion == Motion::Static,
            Casters::Moving => motion == Motion::Dynamic,
        }
    }

    /// The runs of `visible` these casters are.
    pub fn of(self, uploaded: &GpuScene, visible: &Visible) -> Visible {
        let runs = visible
            .runs
            .iter()
            .filter(|r| self.take(uploaded.batches[r.batch as usize].motion))
            .cloned()
            .collect();
        Visible { runs }
    }
}

/// Where a depth pass draws.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum DepthArea {
    /// The whole target.
    Whole,
    /// These rectangles of it only: every run is drawn once into each.
    Strips(Vec<ScissorRect>),
    /// This rectangle as if it were the whole target: the viewport and the scissor
    /// (a virtual map's page in its tile of the pool).
    Tile(ScissorRect),
}

/// A rectangle of a target, in texels from its top-left corner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ScissorRect {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl ScissorRect {
    /// The projection of the part of a `resolution`² target that this rectangle
    /// covers, widened by a texel each way, when the whole is `clip_from_world`: its
    /// clip volume is the rectangle's, for culling what it may draw.
    pub fn clip_from_world(&self, clip_from_world: glam::Mat4, resolution: u32) -> glam::Mat4 {
        let r = resolution as f32;
        // NDC x runs with texel columns; NDC y against texel rows.
        let (x0, x1) = (self.x as f32 - 1.0, (self.x + self.width) as f32 + 1.0);
        let (y0, y1) = (self.y as f32 - 1.0, (self.y + self.height) as f32 + 1.0);
        let (left, right) = (2.0 * x0 / r - 1.0, 2.0 * x1 / r - 1.0);
        let (bottom, top) = (1.0 - 2.0 * y1 / r, 1.0 - 2.0 * y0 / r);
        let (cx, cy) = (0.5 * (left + right), 0.5 * (bottom + top));
        let (hx, hy) = (0.5 * (right - left), 0.5 * (top - bottom));
        // x' = (x − cx·w) / hx, y' = (y − cy·w) / hy: the rectangle's NDC onto [−1, 1].
        let onto = glam::Mat4::from_cols(
            glam::Vec4::new(1.0 / hx, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, 1.0 / hy, 0.0, 0.0),
            glam::Vec4::Z,
            glam::Vec4::new(-cx / hx, -cy / hy, 0.0, 1.0),
        );
        onto * clip_from_world
    }
}

/// What a depth pass starts from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum DepthStart {
    /// Cleared to the far plane.
    Clear,
    /// What the target holds: a copy of a kept layer, to draw moving casters over.
    Keep,
}

impl DepthStart {
    pub(super) fn load(self) -> wgpu::LoadOp<f32> {
        match self {
            DepthStart::Clear => wgpu::LoadOp::Clear(crate::passes::shadow::MAP_CLEARED_DEPTH),
            DepthStart::Keep => wgpu::LoadOp::Load,
        }
    }
}

/// What a run of draws in a depth pass shares: the scissor, the pipeline and, for
/// alpha-masked casters, the material texture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct DrawState {
    rect: Option<ScissorRect>,
    key: ShadowPipelineKey,
    /// The material group an alpha-masked caster samples; None for opaque ones.
    material: Option<usize>,
}

impl DrawState {
    /// The state of draws of `class` in `depth`'s pass, within `rect`.
    fn of(depth: &DepthPass, rect: Option<ScissorRect>, class: &BucketClass) -> Self {
        let coverage = if class.masked { Coverage::Masked } else { Coverage::Opaque };
        let key = ShadowPipelineKey::new(
            &depth.settings.shadow.bias,
            class.sides,
            coverage,
            DepthRange::clamped_if(depth.unclipped),
            depth.target,
        );
        DrawState { rect, key, material: class.material }
    }
}

impl DepthArea {
    /// The scissor rectangles it draws in: None for the whole target.
    fn rects(&self) -> Vec<Option<ScissorRect>> {
        match self {
            DepthArea::Whole => vec![None],
            DepthArea::Strips(strips) => strips.iter().copied().map(Some).collect(),
            DepthArea::Tile(tile) => vec![Some(*tile)],
        }
    }
}

/// Sets what each draw of a depth pass needs as it changes: the scissor, the
/// pipeline with its vertex stream, and an alpha-masked caster's material.
#[derive(Default)]
pub(super) struct StateChanges {
    current: Option<DrawState>,
    stream: Option<VertexStream>,
}

impl StateChanges {
    /// Forgets the pipeline, scissor and material set, as after a draw with another
    /// pipeline: the next [`StateChanges::apply`] sets them all. (Vertex buffers stay
    /// bound across pipelines.)
    pub(super) fn forget_state(&mut self) {
        self.current = None;
    }

    /// Moves `pass` to `state`, counting the changes in `stats`.
    pub(super) fn apply(
        &mut self,
        pass: &mut wgpu::RenderPass<'_>,
        pipelines: (&mut ShadowPass, &wgpu::Device),
        uploaded: &GpuScene,
        state: &DrawState,
        stats: &mut DrawStats,
    ) {
        let current = self.current;
        if let Some(rect) = state.rect.filter(|_| current.map(|c| c.rect) != Some(state.rect)) {
            pass.set_scissor_rect(rect.x, rect.y, rect.width, rect.height);
        }
        if current.map(|c| c.key) != Some(state.key) {
            let wanted = ShadowPipelineShape::of(&state.key).stream;
            match self.stream {
                None => uploaded.bind_geometry(pass, wanted, IndexOrder::Clusters),
                Some(bound) if bound != wanted => uploaded.bind_stream(pass, wanted),
                Some(_) => {}
            }
            self.stream = Some(wanted);
            let (shadow, device) = pipelines;
            pass.set_pipeline(shadow.pipeline(device, &state.key));
            stats.pipeline_changes += 1;
        }
        if let Some(material) = state.material.filter(|&m| current.and_then(|c| c.material) != Some(m)) {
            pass.set_bind_group(1, &uploaded.material_groups[material], &[]);
            stats.bind_group_changes += 1;
        }
        self.current = Some(*state);
    }
}

/// A pass's draws bucketed by their state, buckets in order of first appearance
/// (within each scissor rectangle, in the order of the rectangles).
pub(super) fn buckets<'a>(uploaded: &GpuScene, depth: &'a DepthPass) -> Vec<(DrawState, Vec<&'a Run>)> {
    let mut buckets: Vec<(DrawState, Vec<&Run>)> = Vec::new();
    for rect in depth.area.rects() {
        for run in &depth.visible.runs {
            let batch = &uploaded.batches[run.batch as usize];
            let state = DrawState::of(depth, rect, &BucketClass::of(batch));
            match buckets.iter_mut().find(|(s, _)| *s == state) {
                Some((_, runs)) => runs.push(run),
                None => buckets.push((state, vec![run])),
            }
        }
    }
    buckets
}

/// Begins `depth`'s render pass with its scene group (instances and light) bound.
fn open_depth_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    depth: &DepthPass,
    group: &wgpu::BindGroup,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites>,
    stats: &mut DrawStats,
) -> wgpu::RenderPass<'e> {
    let mut pass =
        begin_depth_pass(encoder, "shadow", depth.target_view, depth.start.load(), timestamp_writes);
    if let DepthArea::Tile(tile) = depth.area {
        let (x, y, size) = (tile.x as f32, tile.y as f32, (tile.width as f32, tile.height as f32));
        pass.set_viewport(x, y, size.0, size.1, 0.0, 1.0);
    }
    pass.set_bind_group(0, group, &[]);
    stats.bind_group_changes += 1;
    pass
}

impl Renderer {
    /// Records a depth-only pass with the shadow pipelines, drawing the runs
    /// `depth.visible` holds (a shadow-map layer's casters, or what the camera sees for
    /// SDSM's prepass), or, for a layer culled on the GPU, what the culler keeps.
    /// Returns the stats of what it recorded.
    pub(super) fn record_depth_pass(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        depth: &DepthPass,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites>,
    ) -> DrawStats {
        let gpu = self.gpu.clone();
        // The GPU culls cluster by cluster: a pass asked to cull whole instances (the
        // baseline clusters are measured against) is culled on the CPU.
        let culled_on_gpu = match (depth.settings.shadow.map.draw_submission, &depth.culling) {
            (DrawSubmission::GpuCulled, Some(culling))
                if gpu.indirect_count && matches!(culling.view.granularity, Granularity::Clusters { .. }) =>
            {
                uploaded.uploaded_shadow_items().map(|items| (items, culling))
            }
            (DrawSubmission::GpuCulled | DrawSubmission::Indirect | DrawSubmission::Direct, _) => None,
        };
        let light_buffer = self.pool.uniform(&gpu.queue, "light", depth.light);
        let group = scene_group(&mut self.pool, &self.layouts, uploaded, &light_buffer);
        let mut stats = match culled_on_gpu {
            Some((items, culling)) => {
                self.record_gpu_culled(encoder, uploaded, depth, (items, culling), (&group, timestamp_writes))
            }
            None => self.record_cpu_culled(encoder, uploaded, depth, &group, timestamp_writes),
        };
        // What the CPU culled, which the GPU culler keeps too (`render/tests/gpu/gpu_culling.rs`
        // holds their maps equal): the counts of a layer culled on the GPU stay on it.
        stats.shadow_draws = depth.visible.runs.len() as u32 * depth.area.rects().len() as u32;
        stats.shadow_instances = depth.visible.instances();
        stats.shadow_triangles = depth.visible.triangles();
        stats
    }

    /// The pass's draws as the CPU culled them: each bucket one multi-draw from
    /// uploaded arguments, or its draws one by one.
    fn record_cpu_culled(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        depth: &DepthPass,
        group: &wgpu::BindGroup,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites>,
    ) -> DrawStats {
        let gpu = self.gpu.clone();
        let buckets = buckets(uploaded, depth);
        let draws: usize = buckets.iter().map(|(_, runs)| runs.len()).sum();
        // Every bucket's arguments, one after another, in one buffer.
        let indirect = match depth.settings.shadow.map.draw_submission {
            DrawSubmission::GpuCulled | DrawSubmission::Indirect => gpu.indirect_draws && draws > 0,
            DrawSubmission::Direct => false,
        };
        let arguments = indirect.then(|| {
            let mut args: Vec<DrawArgs> = buckets
                .iter()
                .flat_map(|(_, runs)| {
                    runs.iter().map(|run| DrawArgs::of(&uploaded.batches[run.batch as usize], run))
                })
                .collect();
            args.resize(argument_slots(args.len()), DrawArgs::default());
            self.pool.storage(&gpu.queue, "draw arguments", &args, wgpu::BufferUsages::INDIRECT)
        });
        let mut stats = DrawStats::default();
        let mut pass = open_depth_pass(encoder, depth, group, timestamp_writes, &mut stats);
        let mut changes = StateChanges::default();
        let mut first_argument = 0u64;
        for (state, runs) in &buckets {
            changes.apply(&mut pass, (&mut self.passes.shadow, &gpu.device), uploaded, state, &mut stats);
            match &arguments {
                Some(buffer) => {
                    let offset = first_argument * DrawArgs::SIZE;
                    pass.multi_draw_indexed_indirect(buffer, offset, runs.len() as u32);
                    first_argument += runs.len() as u64;
                    stats.shadow_commands += 1;
                }
                None => {
                    for run in runs {
                        GpuScene::draw_run(&mut pass, &uploaded.batches[run.batch as usize], run);
                    }
                    stats.shadow_commands += runs.len() as u32;
                }
            }
        }
        stats
    }

    /// The pass's draws as the GPU culler keeps them: one dispatch culls every
    /// shadow item for the layer, then each bucket of the casters drawn is one
    /// multi-draw whose count the dispatch wrote.
    fn record_gpu_culled(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        depth: &DepthPass,
        (items, culling): (&ShadowItems, &LayerCulling),
        (group, timestamp_writes): (&wgpu::BindGroup, Option<wgpu::RenderPassTimestampWrites>),
    ) -> DrawStats {
        let gpu = self.gpu.clone();
        let target = CullTarget {
            frustum: &culling.view.frustum,
            near: culling.view.near,
            faces: match culling.view.granularity {
                Granularity::Clusters { faces } => faces,
                // Not culled here (`record_depth_pass`).
                Granularity::Instances => None,
            },
        };
        // The layer's time runs from the dispatch's start to the draws' end.
        let (cull_writes, draw_writes) = match timestamp_writes {
            Some(w) => (
                Some(wgpu::ComputePassTimestampWrites {
                    query_set: w.query_set,
                    beginning_of_pass_write_index: w.beginning_of_pass_write_index,
                    end_of_pass_write_index: None,
                }),
                Some(wgpu::RenderPassTimestampWrites {
                    query_set: w.query_set,
                    beginning_of_pass_write_index: None,
                    end_of_pass_write_index: w.end_of_pass_write_index,
                }),
            ),
            None => (None, None),
        };
        let culled = self.passes.gpu_cull.record(&gpu, &mut self.pool, encoder, items, &target, cull_writes);
        let mut stats = DrawStats::default();
        let mut pass = open_depth_pass(encoder, depth, group, draw_writes, &mut stats);
        let mut changes = StateChanges::default();
        for rect in depth.area.rects() {
            for (index, bucket) in items.buckets.iter().enumerate() {
                if !culling.casters.take(bucket.class.motion) {
                    continue;
                }
                let state = DrawState::of(depth, rect, &bucket.class);
                changes.apply(
                    &mut pass,
                    (&mut self.passes.shadow, &gpu.device),
                    uploaded,
                    &state,
                    &mut stats,
                );
                pass.multi_draw_indexed_indirect_count(
                    &culled.draws,
                    CulledDraws::draw_offset(bucket.first_slot),
                    &culled.counts,
                    CulledDraws::count_offset(index),
                    bucket.capacity,
                );
                stats.shadow_commands += 1;
            }
        }
        stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn argument_buffers_come_in_few_sizes() {
        assert_eq!(argument_slots(1), 64);
        assert_eq!(argument_slots(64), 64);
        assert_eq!(argument_slots(65), 128);
        assert_eq!(argument_slots(2639), 4096);
    }
}

//! One depth-only pass with the shadow pipelines (a shadow-map layer, its strips, or
//! SDSM's camera prepass), and how its draws are submitted: bucketed by the state they
//! share (scissor, pipeline, material), each bucket one multi-draw from a buffer of
//! draw arguments, or its draws one by one (`DrawSubmission`). Depth-only draws may
//! go in any order: the nearest depth wins whichever comes first, so the map is the
//! same either way.

use gnomon_scene::{Settings, settings::DrawSubmission};

use super::{Renderer, bindings::scene_group, outputs::DrawStats};
use crate::{
    GpuScene,
    gpu_scene::{DrawArgs, IndexOrder, Run, Visible},
    gpu_types::VertexStream,
    passes::{
        begin_depth_pass,
        shadow::{Coverage, DepthRange, DepthTarget, ShadowPipelineKey, ShadowPipelineShape},
    },
    uniforms::LightGpu,
};

/// One depth-only pass: a shadow-map layer, or SDSM's camera prepass.
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
}

/// Where a depth pass draws.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum DepthArea {
    /// The whole target.
    Whole,
    /// These rectangles of it only: every run is drawn once into each.
    Strips(Vec<ScissorRect>),
}

/// A rectangle of a target, in texels from its top-left corner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct ScissorRect {
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

/// What a run of draws in a depth pass shares: the scissor, the pipeline and, for
/// alpha-masked casters, the material texture.
#[derive(Clone, Copy, Debug, PartialEq)]
struct DrawState {
    rect: Option<ScissorRect>,
    key: ShadowPipelineKey,
    /// The material group an alpha-masked caster samples; None for opaque ones.
    material: Option<usize>,
}

/// A pass's draws bucketed by their state, buckets in order of first appearance
/// (within each scissor rectangle, in the order of the rectangles).
fn buckets<'a>(uploaded: &GpuScene, depth: &'a DepthPass) -> Vec<(DrawState, Vec<&'a Run>)> {
    let bias = &depth.settings.shadow.bias;
    let rects: Vec<Option<ScissorRect>> = match &depth.area {
        DepthArea::Whole => vec![None],
        DepthArea::Strips(strips) => strips.iter().copied().map(Some).collect(),
    };
    let mut buckets: Vec<(DrawState, Vec<&Run>)> = Vec::new();
    for rect in rects {
        for run in &depth.visible.runs {
            let batch = &uploaded.batches[run.batch as usize];
            let coverage = if batch.masked { Coverage::Masked } else { Coverage::Opaque };
            let key = ShadowPipelineKey::new(
                bias,
                batch.sides,
                coverage,
                DepthRange::clamped_if(depth.unclipped),
                depth.target,
            );
            let material = batch.masked.then_some(batch.material_group);
            let state = DrawState { rect, key, material };
            match buckets.iter_mut().find(|(s, _)| *s == state) {
                Some((_, runs)) => runs.push(run),
                None => buckets.push((state, vec![run])),
            }
        }
    }
    buckets
}

/// How many draw arguments an arguments buffer holds for `draws`: the next power of
/// two (at least 64), so that the pool keeps reusing a buffer while the count moves.
fn argument_slots(draws: usize) -> usize {
    draws.next_power_of_two().max(64)
}

impl Renderer {
    /// Records a depth-only pass with the shadow pipelines, drawing the runs
    /// `depth.visible` holds: a shadow-map layer's casters, or what the camera sees for
    /// SDSM's prepass. Returns the stats of what it recorded.
    pub(super) fn record_depth_pass(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        depth: &DepthPass,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites>,
    ) -> DrawStats {
        let gpu = self.gpu.clone();
        let light_buffer = self.pool.uniform(&gpu.queue, "light", depth.light);
        let group = scene_group(&mut self.pool, &self.layouts, uploaded, &light_buffer);
        let buckets = buckets(uploaded, depth);
        let draws: usize = buckets.iter().map(|(_, runs)| runs.len()).sum();
        // Every bucket's arguments, one after another, in one buffer.
        let indirect = match depth.settings.shadow.map.draw_submission {
            DrawSubmission::Indirect => gpu.indirect_draws && draws > 0,
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
        let load = match depth.start {
            DepthStart::Clear => wgpu::LoadOp::Clear(1.0),
            DepthStart::Keep => wgpu::LoadOp::Load,
        };
        let mut pass = begin_depth_pass(encoder, "shadow", depth.target_view, load, timestamp_writes);
        pass.set_bind_group(0, &group, &[]);
        stats.bind_group_changes += 1;
        let mut current: Option<DrawState> = None;
        let mut stream: Option<VertexStream> = None;
        let mut first_argument = 0u64;
        for (state, runs) in &buckets {
            if let Some(rect) = state.rect.filter(|_| current.map(|c| c.rect) != Some(state.rect)) {
                pass.set_scissor_rect(rect.x, rect.y, rect.width, rect.height);
            }
            if current.map(|c| c.key) != Some(state.key) {
                let wanted = ShadowPipelineShape::of(&state.key).stream;
                match stream {
                    None => uploaded.bind_geometry(&mut pass, wanted, IndexOrder::Clusters),
                    Some(bound) if bound != wanted => uploaded.bind_stream(&mut pass, wanted),
                    Some(_) => {}
                }
                stream = Some(wanted);
                pass.set_pipeline(self.passes.shadow.pipeline(&gpu.device, &state.key));
                stats.pipeline_changes += 1;
            }
            if let Some(material) = state.material.filter(|&m| current.and_then(|c| c.material) != Some(m)) {
                pass.set_bind_group(1, &uploaded.material_groups[material], &[]);
                stats.bind_group_changes += 1;
            }
            current = Some(*state);
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
            stats.shadow_draws += runs.len() as u32;
        }
        stats.shadow_instances = depth.visible.instances();
        stats.shadow_triangles = depth.visible.triangles();
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

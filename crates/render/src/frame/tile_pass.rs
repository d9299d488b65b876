//! Many tiles of one depth target drawn in one render pass (a virtual map's runs of
//! pages in one layer of its pool): each tile its own projection (its own scene
//! group), viewport and scissor, and the casters the CPU culled against it, each
//! bucket of them one multi-draw from one buffer of arguments for every tile. One
//! pass instead of one per tile: a pass and a culling dispatch per page cost a GPU
//! tens of microseconds each, more than a page's draws.

use gnomon_scene::settings::DrawSubmission;

use super::{
    Renderer,
    bindings::{argument_slots, scene_group},
    depth_pass::{DepthArea, DepthPass, DrawState, ScissorRect, StateChanges, buckets},
    recording::DrawStats,
};
use crate::{
    GpuScene,
    gpu_scene::{DrawArgs, Run, Visible},
    passes::begin_depth_pass,
    uniforms::LightGpu,
};

/// One tile of a [`TilePass`]: where it lies, its projection and its casters.
pub(super) struct Tile<'a> {
    pub rect: ScissorRect,
    /// The uniform whose `clip_from_world` projects the geometry onto the tile.
    pub light: LightGpu,
    pub visible: &'a Visible,
}

/// Tiles of one target drawn in one pass, over what the target holds or over the
/// far plane (`like.start`).
pub(super) struct TilePass<'a> {
    /// Each tile's draws are those of this pass with the tile's light, casters and
    /// area (`DepthArea::Tile`).
    pub like: DepthPass<'a>,
    pub tiles: Vec<Tile<'a>>,
    /// Where set, each tile is first cleared to the far plane by one draw of this
    /// pipeline (a triangle over its viewport at depth 1, `page_clear.wgsl`): a pass
    /// can clear only its whole target, and the rest of the target is kept.
    pub clear_tiles: Option<&'a wgpu::RenderPipeline>,
}

impl Renderer {
    /// Records `tiles` as one render pass; returns the stats of what it recorded.
    pub(super) fn record_tile_pass(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        tiles: &TilePass,
    ) -> DrawStats {
        let gpu = self.gpu.clone();
        let passes: Vec<DepthPass> = tiles
            .tiles
            .iter()
            .map(|tile| DepthPass {
                light: &tile.light,
                visible: tile.visible,
                area: DepthArea::Tile(tile.rect),
                ..tiles.like.clone()
            })
            .collect();
        let tile_buckets: Vec<Vec<(DrawState, Vec<&Run>)>> =
            passes.iter().map(|p| buckets(uploaded, p)).collect();
        let groups: Vec<wgpu::BindGroup> = tiles
            .tiles
            .iter()
            .map(|tile| {
                let light = self.pool.uniform(&gpu.queue, "light", &tile.light);
                scene_group(&mut self.pool, &self.layouts, uploaded, &light)
            })
            .collect();
        let draws: usize = tile_buckets.iter().flatten().map(|(_, runs)| runs.len()).sum();
        let indirect = match tiles.like.settings.shadow.map.draw_submission {
            DrawSubmission::GpuCulled | DrawSubmission::Indirect => gpu.indirect_draws && draws > 0,
            DrawSubmission::Direct => false,
        };
        let arguments = indirect.then(|| {
            let mut args: Vec<DrawArgs> = tile_buckets
                .iter()
                .flatten()
                .flat_map(|(_, runs)| {
                    runs.iter().map(|run| DrawArgs::of(&uploaded.batches[run.batch as usize], run))
                })
                .collect();
            args.resize(argument_slots(args.len()), DrawArgs::default());
            self.pool.storage(&gpu.queue, "tile draw arguments", &args, wgpu::BufferUsages::INDIRECT)
        });
        let mut stats = DrawStats::default();
        let mut pass =
            begin_depth_pass(encoder, "shadow tiles", tiles.like.target_view, tiles.like.start.load(), None);
        let mut changes = StateChanges::default();
        let mut first_argument = 0u64;
        for ((tile, group), buckets) in tiles.tiles.iter().zip(&groups).zip(&tile_buckets) {
            let r = tile.rect;
            pass.set_viewport(r.x as f32, r.y as f32, r.width as f32, r.height as f32, 0.0, 1.0);
            if let Some(clear) = tiles.clear_tiles {
                pass.set_scissor_rect(r.x, r.y, r.width, r.height);
                pass.set_pipeline(clear);
                pass.draw(0..3, 0..1);
                stats.pipeline_changes += 1;
                // The casters' pipeline (and scissor) must be set again.
                changes.forget_state();
            }
            pass.set_bind_group(0, group, &[]);
            stats.bind_group_changes += 1;
            for (state, runs) in buckets {
                changes.apply(&mut pass, (&mut self.passes.shadow, &gpu.device), uploaded, state, &mut stats);
                match &arguments {
                    Some(buffer) => {
                        pass.multi_draw_indexed_indirect(
                            buffer,
                            first_argument * DrawArgs::SIZE,
                            runs.len() as u32,
                        );
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
            stats.shadow_draws += tile.visible.runs.len() as u32;
            stats.shadow_instances += tile.visible.instances();
            stats.shadow_triangles += tile.visible.triangles();
        }
        stats
    }
}

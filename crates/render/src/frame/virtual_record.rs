//! Recording a sun's virtual map (`--partition virtual`): clearing and drawing the
//! pages [`super::virtual_pages`] planned, neighbours in runs drawn as one
//! ([`gnomon_math::virtual_map::runs`]), and the buffers its sampling passes bind.

use super::{
    Renderer,
    bindings::VirtualBuffers,
    cull::layer_view,
    depth_pass::{DepthArea, DepthPass, DepthStart, ScissorRect},
    plan::LightPlan,
    recording::{LayerWork, Recording},
    shadow_maps::bracket,
    tile_pass::{Tile, TilePass},
    virtual_pages::VirtualPlan,
};
use crate::{
    GpuScene,
    pool::{Pool, ViewKey},
    rays::RefineLists,
    timing::{PassKind, SlotPart},
    uniforms::LightGpu,
    virtual_map::EdgeTarget,
};

impl Renderer {
    /// Clears and draws the pages of a virtual light's pool that are new or stale
    /// this frame, timed as its one layer; returns the pool's texture, its map.
    ///
    /// Neighbouring pages in neighbouring tiles are drawn as one run (a frame laid
    /// out anew, `PagePool::pack`, is mostly long runs), one render pass for each
    /// layer of the pool that holds a run. A frame that keeps no page clears those
    /// layers by their passes' loads; one that keeps some clears each run's tiles
    /// by a draw before its casters.
    pub(super) fn record_virtual_pages(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        light: &LightPlan,
        plan: &VirtualPlan,
        light_index: u32,
    ) -> wgpu::Texture {
        let gpu = self.gpu.clone();
        let pages = self.virtual_lights.pages(light_index as usize);
        let (texture, size, clear) = (pages.texture().clone(), pages.size(), pages.clear_pipeline().clone());
        if plan.runs.is_empty() {
            return texture;
        }
        let slot = rec.clock.begin(&gpu, rec.encoder, PassKind::Shadow, Some(light_index), Some(0));
        bracket(rec, slot, SlotPart::Opening);
        let projections: Vec<_> =
            plan.runs.iter().map(|run| plan.clipmap.run_clip_from_world(run.first.page, run.len)).collect();
        let views: Vec<_> =
            projections.iter().map(|&clip_from_world| layer_view(light, clip_from_world)).collect();
        // Culled on the CPU, cluster by cluster where the settings say so, against
        // each run alone: one pass for every run needs every run's draws before it.
        let seen = uploaded.cull(&views);
        let start = if plan.clear_layers { DepthStart::Clear } else { DepthStart::Keep };
        let mut work = LayerWork::default();
        for layer in 0..size.layers() {
            let in_layer: Vec<usize> = (0..plan.runs.len())
                .filter(|&r| size.tile(plan.runs[r].first.physical).layer == layer)
                .collect();
            let Some(&first) = in_layer.first() else { continue };
            let view = self.pool.view(&texture, ViewKey::layer(layer));
            let like = DepthPass {
                settings: &light.settings,
                light: &light.light_gpu,
                target_view: &view,
                visible: &seen[first],
                target: light.depth_target(),
                unclipped: light.layout.depth_clamp,
                start,
                area: DepthArea::Whole,
                culling: None,
            };
            let tiles = in_layer
                .iter()
                .map(|&r| {
                    let (run, tile) = (&plan.runs[r], size.tile(plan.runs[r].first.physical));
                    let (width, height) = (size.page_size * run.len, size.page_size);
                    Tile {
                        rect: ScissorRect { x: tile.x, y: tile.y, width, height },
                        light: LightGpu { clip_from_world: projections[r], ..light.light_gpu },
                        visible: &seen[r],
                    }
                })
                .collect();
            let clear_tiles = match start {
                DepthStart::Clear => None,
                DepthStart::Keep => Some(&clear),
            };
            let stats = self.record_tile_pass(rec.encoder, uploaded, &TilePass { like, tiles, clear_tiles });
            rec.stats.add(&stats);
            work.commands += stats.shadow_commands;
            // The texels cleared or drawn: a whole layer where it was cleared whole.
            work.texels += match start {
                DepthStart::Clear => size.layer_texels(),
                DepthStart::Keep => in_layer
                    .iter()
                    .map(|&r| u64::from(plan.runs[r].len) * u64::from(size.page_size).pow(2))
                    .sum(),
            };
        }
        rec.layer_commands.add(light_index as usize, 0, work);
        bracket(rec, slot, SlotPart::Closing);
        rec.clock.end(&gpu, rec.encoder, slot);
        texture
    }

    /// After light `index`'s trace pass, where it asks for pages along shadow
    /// edges: the pass that turns its list of traced pixels (`list`: group 1 of
    /// the trace pass; `counters`: every light's) into requests for the pages one
    /// level finer round them, read by the next frame (`virtual_map/edges.rs`).
    pub(super) fn record_edge_requests(
        &mut self,
        rec: &mut Recording,
        plan: &VirtualPlan,
        list: EdgeList<'_>,
        index: u32,
    ) {
        let Some(params) = plan.edge_params else { return };
        let Some((pass, feedback)) = self.virtual_lights.edge_pass(index as usize) else { return };
        let target = EdgeTarget {
            params,
            clipmap: &plan.clipmap,
            screen: list.screen,
            counters: list.counters,
            counter_offset: RefineLists::counter_offset(index),
            feedback,
        };
        pass.record(&self.gpu, rec.encoder, target);
    }

    /// A virtual light's uniform and page table for the sampling passes.
    pub(super) fn virtual_buffers(
        pool: &mut Pool,
        queue: &wgpu::Queue,
        plan: &VirtualPlan,
    ) -> VirtualBuffers {
        VirtualBuffers {
            uniform: pool.uniform(queue, "virtual map", &plan.uniform),
            page_table: pool.storage(queue, "page table", &plan.table, wgpu::BufferUsages::empty()),
        }
    }
}

/// A light's list of traced pixels, as the trace pass binds it.
pub(super) struct EdgeList<'a> {
    /// Group 1 of the trace pass: the camera, the prepass, the list and the counters.
    pub screen: &'a wgpu::BindGroup,
    /// Every light's counters.
    pub counters: &'a wgpu::Buffer,
}

//! Recording a sun's virtual map (`--partition virtual`): clearing and drawing the
//! pages [`super::virtual_pages`] planned, and the buffers its sampling passes bind.

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
    timing::{PassKind, SlotPart},
    uniforms::LightGpu,
};

impl Renderer {
    /// Clears and draws the pages of a virtual light's pool that are new or stale
    /// this frame, timed as its one layer; returns the pool's texture, its map.
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
        let texture = pages.texture().clone();
        let drawn: Vec<_> = plan.allocation.to_draw().copied().collect();
        if drawn.is_empty() {
            return texture;
        }
        let page_size = pages.size().page_size;
        let tiles: Vec<ScissorRect> = drawn
            .iter()
            .map(|grant| {
                let (x, y) = pages.tile_origin(grant.physical);
                ScissorRect { x, y, width: page_size, height: page_size }
            })
            .collect();
        let slot = rec.clock.begin(&gpu, rec.encoder, PassKind::Shadow, Some(light_index), Some(0));
        bracket(rec, slot, SlotPart::Opening);
        let view = self.pool.view(&texture, ViewKey::default());
        // A frame that keeps no page (the light turned) clears the pool whole, by its
        // pass's load: a texture cleared so lets the GPU reject hidden fragments
        // early, where one cleared tile by tile by a draw may not.
        let start = if plan.clear_whole {
            DepthStart::Clear
        } else {
            self.virtual_lights.pages(light_index as usize).record_tile_clears(rec.encoder, &view, &tiles);
            DepthStart::Keep
        };
        let views: Vec<_> = drawn
            .iter()
            .map(|grant| layer_view(light, plan.clipmap.page_clip_from_world(grant.page)))
            .collect();
        // Culled on the CPU, cluster by cluster where the settings say so, against
        // each page alone: one pass for every page needs every page's draws before it.
        let seen = uploaded.cull(&views);
        let like = DepthPass {
            settings: &light.settings,
            light: &light.light_gpu,
            target_view: &view,
            visible: &seen[0],
            target: light.depth_target(),
            unclipped: light.layout.depth_clamp,
            start,
            area: DepthArea::Whole,
            culling: None,
        };
        let page_tiles = drawn
            .iter()
            .zip(&tiles)
            .zip(&seen)
            .map(|((grant, rect), visible)| Tile {
                rect: *rect,
                light: LightGpu {
                    clip_from_world: plan.clipmap.page_clip_from_world(grant.page),
                    ..light.light_gpu
                },
                visible,
            })
            .collect();
        let stats = self.record_tile_pass(rec.encoder, uploaded, &TilePass { like, tiles: page_tiles });
        rec.stats.add(&stats);
        // The texels cleared or drawn: the whole pool where it was cleared whole.
        let texels = match start {
            DepthStart::Clear => u64::from(texture.width()) * u64::from(texture.height()),
            DepthStart::Keep => drawn.len() as u64 * u64::from(page_size) * u64::from(page_size),
        };
        let work = LayerWork { commands: stats.shadow_commands, texels };
        rec.layer_commands.add(light_index as usize, 0, work);
        bracket(rec, slot, SlotPart::Closing);
        rec.clock.end(&gpu, rec.encoder, slot);
        texture
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

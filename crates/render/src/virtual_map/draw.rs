//! Drawing a virtual shadow map's pages: one depth texture of `pages_per_side`² page
//! tiles (the physical pool), the [`PagePool`] that says which virtual page each tile
//! holds, and a frame that draws only the pages new or dirty this frame, each through
//! its own projection ([`Clipmap::page_clip_from_world`]) into its tile. Here casters
//! are drawn as the depth-only baseline draws them (`passes/depth_baseline.rs`: every
//! caster pre-transformed, one draw per cull state), each page drawing every caster;
//! the frame draws its pages with the shadow pass instead, culled per page
//! (`frame/virtual_record.rs`).

use gnomon_math::virtual_map::{
    Clipmap, PageKey,
    pages::{FrameAllocation, PagePool, TableEntry},
};
use gnomon_scene::settings::BiasSettings;

use crate::{
    DepthBaselineScene, Gpu, RenderError,
    passes::{
        SHADOW_FORMAT, begin_depth_pass,
        depth_baseline::{BaselineRaster, DepthBaselinePass},
        shadow::{DepthRange, DepthTarget},
    },
    pool::{Pool, ViewKey},
};

/// Rows of page tiles in one layer of the pool's texture. The pool is an array of
/// layers because a render pass can clear only whole layers by its load, and a layer
/// cleared so lets a GPU reject hidden fragments early, where tiles cleared by draws
/// do not (on an H200, Sponza's moving sun took 3.2 ms of shadow passes with the pool
/// cleared whole, 5.1 ms with each run of tiles cleared by a draw), while clearing a
/// whole pool costs in proportion to its texels (the tree's took 1.08 ms against
/// 0.55). Layers of a few rows let a frame clear only the layers its pages use.
pub const POOL_LAYER_ROWS: u32 = 4;

/// How large a virtual map's physical pool is, and how its tiles are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PoolSize {
    /// Texels per side of a page (the clipmap's page size).
    pub page_size: u32,
    /// Page tiles per row of the pool, and rows in all: `pages_per_side`² physical
    /// pages.
    pub pages_per_side: u32,
    /// Rows of tiles in each layer of the pool's texture (the last layer may hold
    /// fewer).
    pub rows_per_layer: u32,
}

/// Where a slot's tile lies in the pool's texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PoolTile {
    /// Its layer.
    pub layer: u32,
    /// Its first column of texels in the layer.
    pub x: u32,
    /// Its first row of texels in the layer.
    pub y: u32,
}

impl PoolSize {
    /// A pool of `pages_per_side`² pages of `page_size`² texels, in layers of
    /// [`POOL_LAYER_ROWS`] rows.
    pub fn new(page_size: u32, pages_per_side: u32) -> PoolSize {
        PoolSize { page_size, pages_per_side, rows_per_layer: pages_per_side.clamp(1, POOL_LAYER_ROWS) }
    }

    /// Texels per row of the pool's texture.
    pub fn texels_per_side(&self) -> u64 {
        u64::from(self.page_size) * u64::from(self.pages_per_side)
    }

    /// Layers of the pool's texture.
    pub fn layers(&self) -> u32 {
        self.pages_per_side.div_ceil(self.rows_per_layer.max(1))
    }

    /// Texels in one layer.
    pub fn layer_texels(&self) -> u64 {
        self.texels_per_side() * u64::from(self.page_size) * u64::from(self.rows_per_layer)
    }

    /// The tile of slot `slot`: slots run along rows, rows down the layers.
    pub fn tile(&self, slot: u32) -> PoolTile {
        let (column, row) = (slot % self.pages_per_side, slot / self.pages_per_side);
        PoolTile {
            layer: row / self.rows_per_layer,
            x: column * self.page_size,
            y: (row % self.rows_per_layer) * self.page_size,
        }
    }
}

/// A virtual map's physical pages and what they hold, kept across frames.
pub struct VirtualPages {
    size: PoolSize,
    texture: wgpu::Texture,
    pages: PagePool,
    clear: wgpu::RenderPipeline,
    baseline: DepthBaselinePass,
    pool: Pool,
    bias: BiasSettings,
    /// The lookup probe's pass, built on the first probe (`probe.rs`).
    pub(super) probe: Option<super::probe::ProbePass>,
}

impl VirtualPages {
    /// A pool of `size` on `gpu`, every page free. Refuses a pool larger than the
    /// device's largest 2D texture, before allocating it.
    pub fn new(gpu: &Gpu, size: PoolSize) -> Result<VirtualPages, RenderError> {
        // Its layers (at most 64 / POOL_LAYER_ROWS) are within any WebGPU device's 256.
        let (max, side) = (gpu.device.limits().max_texture_dimension_2d, size.texels_per_side());
        if side == 0 || side > u64::from(max) {
            return Err(RenderError::PagePoolTooLarge {
                pages_per_side: size.pages_per_side,
                texels: side,
                max,
                adapter: gpu.info.adapter.clone(),
            });
        }
        let device = &gpu.device;
        gpu.checked("creating a virtual map's page pool", || {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("virtual page pool"),
                size: wgpu::Extent3d {
                    width: side as u32,
                    height: size.page_size * size.rows_per_layer,
                    depth_or_array_layers: size.layers(),
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: SHADOW_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
            VirtualPages {
                size,
                texture,
                pages: PagePool::new(size.pages_per_side * size.pages_per_side),
                clear: clear_pipeline(device),
                baseline: DepthBaselinePass::new(device),
                pool: Pool::new(device),
                bias: BiasSettings::default(),
                probe: None,
            }
        })
    }

    /// Pages resident in the pool.
    pub fn resident(&self) -> usize {
        self.pages.resident()
    }

    /// The pool's pages: which page each slot holds.
    pub fn pages(&self) -> &PagePool {
        &self.pages
    }

    /// The pool's size.
    pub fn size(&self) -> PoolSize {
        self.size
    }

    /// The pool of transient resources, its frame begun, for sampling the map.
    pub(super) fn frame_pool(&mut self) -> &mut Pool {
        self.pool.end_frame();
        &mut self.pool
    }

    /// The pool's depth texture: page tile `slot` at [`PoolSize::tile`].
    pub fn texture(&self) -> &wgpu::Texture {
        &self.texture
    }

    /// Every page drawn so far is stale: the light turned, or the clipmap's levels
    /// changed.
    pub fn invalidate_all(&mut self) {
        self.pages.invalidate_all();
    }

    /// Marks stale the resident pages for which `overlaps` holds (under a moved
    /// caster's shadow, where it was and where it is); returns how many.
    pub fn invalidate(&mut self, overlaps: impl Fn(PageKey) -> bool) -> u32 {
        self.pages.invalidate(overlaps)
    }

    /// The page table for `clipmap` as the pool now stands.
    pub fn page_table(&self, clipmap: &Clipmap) -> Vec<TableEntry> {
        self.pages.page_table(clipmap)
    }

    /// Grants this frame's `requests` their tiles (the frame draws those new or
    /// stale itself: `frame/virtual_pages.rs`).
    pub(crate) fn allocate(&mut self, requests: &[PageKey]) -> FrameAllocation {
        self.pages.allocate(requests)
    }

    /// Lays `allocation` out anew for drawing in runs if it keeps no page
    /// ([`PagePool::pack`]); returns whether it did, and so whether the whole pool
    /// may be cleared before its draws.
    pub(crate) fn pack(&mut self, allocation: &mut FrameAllocation) -> bool {
        self.pages.pack(allocation)
    }

    /// The pipeline that clears a tile to the far plane: one triangle over the
    /// viewport at depth 1 (`page_clear.wgsl`).
    pub(crate) fn clear_pipeline(&self) -> &wgpu::RenderPipeline {
        &self.clear
    }

    /// Grants this frame's `requests` their pages and draws, into their tiles, the
    /// casters of `casters` over every page new or dirty this frame; submits the
    /// draws and returns the allocation (what was drawn, kept and refused).
    pub fn draw(
        &mut self,
        gpu: &Gpu,
        casters: &DepthBaselineScene,
        clipmap: &Clipmap,
        requests: &[PageKey],
    ) -> FrameAllocation {
        self.pool.end_frame();
        let allocation = self.pages.allocate(requests);
        let raster = BaselineRaster {
            bias: &self.bias,
            depth_range: DepthRange::Clipped,
            target: DepthTarget::Projected,
        };
        self.baseline.prepare(&gpu.device, casters, raster);
        let drawn: Vec<_> = allocation.to_draw().copied().collect();
        if drawn.is_empty() {
            return allocation;
        }
        let groups: Vec<wgpu::BindGroup> = drawn
            .iter()
            .map(|grant| {
                self.baseline.matrix_group(gpu, &mut self.pool, clipmap.page_clip_from_world(grant.page))
            })
            .collect();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        for layer in 0..self.size.layers() {
            let view = self.pool.view(&self.texture, ViewKey::layer(layer));
            let mut pass = begin_depth_pass(&mut encoder, "virtual pages", &view, wgpu::LoadOp::Load, None);
            let size = self.size.page_size;
            for (grant, group) in drawn.iter().zip(&groups) {
                let tile = self.size.tile(grant.physical);
                if tile.layer != layer {
                    continue;
                }
                pass.set_viewport(tile.x as f32, tile.y as f32, size as f32, size as f32, 0.0, 1.0);
                pass.set_scissor_rect(tile.x, tile.y, size, size);
                pass.set_pipeline(&self.clear);
                pass.draw(0..3, 0..1);
                self.baseline.draw(&mut pass, casters, raster, group);
            }
        }
        gpu.queue.submit([encoder.finish()]);
        allocation
    }
}

/// The pipeline that clears a page's tile to the far plane (`page_clear.wgsl`).
fn clear_pipeline(device: &wgpu::Device) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("page_clear.wgsl"),
        source: wgpu::ShaderSource::Wgsl(page_clear_wgsl().into()),
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("virtual page clear"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_page_clear"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: SHADOW_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: None,
        multiview_mask: None,
        cache: None,
    })
}

/// `page_clear.wgsl`, composed.
pub(crate) fn page_clear_wgsl() -> String {
    crate::passes::compose_wgsl(&[include_str!("page_clear.wgsl")])
}

#[cfg(test)]
pub(crate) mod tests;

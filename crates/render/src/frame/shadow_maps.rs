//! Recording a light's shadow map: one depth pass per layer (cascade, cube face),
//! drawn from scratch (`--map-cache off`), or through the light's kept map
//! (`map_cache.rs`): a layer draws its still casters only when its cache is stale,
//! scrolls it by whole texels when its window moved by whole texels, and draws the
//! casters that move over a copy of it.

use gnomon_scene::{
    Motion,
    settings::{MapCache as MapCacheSetting, RayUse},
};

use super::{
    Renderer,
    cull::layer_view,
    depth_pass::{Casters, DepthArea, DepthPass, DepthStart, LayerCulling, ScissorRect},
    map_cache::{LayerKey, LayerPlan},
    plan::LightPlan,
    recording::{LayerWork, Recording},
};
use crate::{
    GpuScene,
    gpu_scene::{CullView, Visible},
    passes::{SHADOW_FORMAT, map_scroll::ScrolledLayer},
    pool::ViewKey,
    timing::{PassKind, Slot, SlotPart},
};

/// The timestamps a pass writes: `part` of the clock's `slot`.
#[derive(Clone, Copy)]
struct Timestamps {
    slot: Slot,
    part: SlotPart,
}

/// One layer's pass of a light's map.
struct LayerPass<'a> {
    light: &'a LightPlan,
    /// The light's index in the frame.
    light_index: usize,
    layer: usize,
    visible: &'a Visible,
    /// What `visible` was culled against: the layer, or the strip of it drawn.
    culled_for: CullView,
    casters: Casters,
    view: &'a wgpu::TextureView,
    start: DepthStart,
    area: DepthArea,
}

impl Renderer {
    /// Draws a light's shadow map, one depth pass per layer (cascade or cube face),
    /// each drawing the casters culled for that layer (`layers`), each timed alone;
    /// with `--map-cache still-casters`, through the light's kept map. Returns the map.
    pub(super) fn record_shadow_maps(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        light: &LightPlan,
        layers: &[Visible],
        light_index: u32,
    ) -> wgpu::Texture {
        debug_assert_eq!(layers.len() as u32, light.layers(), "one culled set per layer");
        if let Some(plan) = &light.virtual_map {
            // Its pool of pages, kept by `virtual_pages.rs`, is its map.
            self.map_cache.bypass(light_index as usize, layers.len());
            return self.record_virtual_pages(rec, uploaded, light, plan, light_index);
        }
        // A technique that reads no map (`techniques/raytraced.rs`): no pass clears it.
        let reads_map = light.technique.rays() == RayUse::AsSettingsSay;
        if reads_map && light.settings.shadow.map.cache == MapCacheSetting::StillCasters {
            return self.record_cached_maps(rec, uploaded, light, layers, light_index);
        }
        self.map_cache.bypass(light_index as usize, layers.len());
        let map = self.shadow_map_texture(light);
        if !reads_map {
            return map;
        }
        for (layer, visible) in layers.iter().enumerate() {
            let view = self.pool.view(&map, ViewKey::layer(layer as u32));
            let slot = rec.clock.begin(
                &self.gpu,
                rec.encoder,
                PassKind::Shadow,
                Some(light_index),
                Some(layer as u32),
            );
            let pass = LayerPass {
                light,
                light_index: light_index as usize,
                layer,
                visible,
                culled_for: whole_layer(light, layer),
                casters: Casters::All,
                view: &view,
                start: DepthStart::Clear,
                area: DepthArea::Whole,
            };
            self.record_layer(rec, uploaded, &pass, Some(Timestamps { slot, part: SlotPart::Whole }));
            rec.clock.end(&self.gpu, rec.encoder, slot);
        }
        map
    }

    /// A light's map through its kept map. Each layer, timed from an empty pass
    /// before its first command to one after its last: its still casters drawn into
    /// the cache where it is stale, or the cache scrolled and the strips it newly
    /// covers drawn; then, where casters move, the layer copied out of the cache and
    /// they drawn over the copy. Where none moves, the cache is the map, and a kept
    /// layer records nothing.
    fn record_cached_maps(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        light: &LightPlan,
        layers: &[Visible],
        light_index: u32,
    ) -> wgpu::Texture {
        let keys = (0..layers.len()).map(|l| LayerKey::of(light, l, uploaded.still_generation)).collect();
        let size = light.map_size();
        let (cache, plans) = self.map_cache.take(&self.gpu.device, light_index as usize, size, keys);
        let moves =
            |v: &Visible| v.runs.iter().any(|r| uploaded.batches[r.batch as usize].motion == Motion::Dynamic);
        let moving = layers.iter().any(moves);
        let map = if moving { self.shadow_map_texture(light) } else { cache.clone() };
        if !moving && plans.iter().all(|p| *p == LayerPlan::Keep) {
            self.map_cache.mark_kept_whole(light_index as usize);
        }
        for (layer, visible) in layers.iter().enumerate() {
            if plans[layer] == LayerPlan::Keep && !moving {
                continue;
            }
            let gpu = self.gpu.clone();
            let slot =
                rec.clock.begin(&gpu, rec.encoder, PassKind::Shadow, Some(light_index), Some(layer as u32));
            bracket(rec, slot, SlotPart::Opening);
            let cache_view = self.pool.view(&cache, ViewKey::layer(layer as u32));
            let still = |start, area| LayerPass {
                light,
                light_index: light_index as usize,
                layer,
                visible,
                culled_for: whole_layer(light, layer),
                casters: Casters::Still,
                view: &cache_view,
                start,
                area,
            };
            match plans[layer] {
                LayerPlan::Draw => {
                    self.record_layer(rec, uploaded, &still(DepthStart::Clear, DepthArea::Whole), None)
                }
                LayerPlan::Keep => {}
                LayerPlan::Scroll(offset) => {
                    self.scroll_layer(rec, &cache, layer, offset);
                    // Each strip draws the casters culled against its own part of
                    // the layer, a sliver of it.
                    let clip_from_world = light.light_gpu.for_layer(layer).clip_from_world;
                    for strip in exposed_strips(offset, size.width) {
                        let view = layer_view(light, strip.clip_from_world(clip_from_world, size.width));
                        let seen = uploaded.cull(&[view]).pop().unwrap_or_default();
                        let pass = LayerPass {
                            visible: &seen,
                            culled_for: view,
                            ..still(DepthStart::Keep, DepthArea::Strips(vec![strip]))
                        };
                        self.record_layer(rec, uploaded, &pass, None);
                    }
                }
            }
            if moving {
                copy_layer(rec.encoder, &cache, &map, layer as u32, size);
                let map_view = self.pool.view(&map, ViewKey::layer(layer as u32));
                let pass = LayerPass {
                    light,
                    light_index: light_index as usize,
                    layer,
                    visible,
                    culled_for: whole_layer(light, layer),
                    casters: Casters::Moving,
                    view: &map_view,
                    start: DepthStart::Keep,
                    area: DepthArea::Whole,
                };
                self.record_layer(rec, uploaded, &pass, None);
            }
            bracket(rec, slot, SlotPart::Closing);
            rec.clock.end(&gpu, rec.encoder, slot);
        }
        map
    }

    /// Moves layer `layer` of `cache` so that each texel takes the depth of the texel
    /// `offset` away (the far plane where that is off the map), through a copy.
    fn scroll_layer(&mut self, rec: &mut Recording, cache: &wgpu::Texture, layer: usize, offset: [i32; 2]) {
        let size = cache.size();
        let one_layer = wgpu::Extent3d { depth_or_array_layers: 1, ..size };
        let usage = wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::TEXTURE_BINDING;
        let copy = self.pool.texture("shadow map scroll", one_layer, SHADOW_FORMAT, usage);
        rec.encoder.copy_texture_to_texture(texel_copy(cache, layer as u32), texel_copy(&copy, 0), one_layer);
        let source = self.pool.view(&copy, ViewKey::default());
        let target = self.pool.view(cache, ViewKey::layer(layer as u32));
        let scrolled = ScrolledLayer { source: &source, target: &target, offset, size: size.width };
        self.passes.map_scroll.record(&self.gpu.queue, &mut self.pool, rec.encoder, scrolled, None);
    }

    /// A light's map for this frame, from the pool.
    fn shadow_map_texture(&mut self, light: &LightPlan) -> wgpu::Texture {
        self.pool.texture(
            "shadow map",
            light.map_size(),
            SHADOW_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
        )
    }

    /// Records one layer's depth pass, with the timestamps `timed` where given,
    /// adding what it drew to the frame's counts.
    fn record_layer(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        layer: &LayerPass,
        timed: Option<Timestamps>,
    ) {
        let layer_light = layer.light.light_gpu.for_layer(layer.layer);
        let visible = layer.casters.of(uploaded, layer.visible);
        let pass = DepthPass {
            settings: &layer.light.settings,
            light: &layer_light,
            target_view: layer.view,
            visible: &visible,
            target: layer.light.depth_target(),
            unclipped: layer.light.layout.depth_clamp,
            start: layer.start,
            area: layer.area.clone(),
            culling: Some(LayerCulling { view: layer.culled_for, casters: layer.casters }),
        };
        let writes = timed.and_then(|t| rec.clock.render_part(t.slot, t.part));
        let drawn = self.record_depth_pass(rec.encoder, uploaded, &pass, writes);
        rec.stats.add(&drawn);
        let resolution = u64::from(layer.light.map_resolution());
        let area = match &layer.area {
            DepthArea::Whole => resolution * resolution,
            DepthArea::Strips(strips) => {
                strips.iter().map(|s| u64::from(s.width) * u64::from(s.height)).sum()
            }
            DepthArea::Tile(tile) => u64::from(tile.width) * u64::from(tile.height),
        };
        // A pass that neither clears nor draws leaves its texels alone.
        let touched = drawn.shadow_commands > 0 || layer.start == DepthStart::Clear;
        let work = LayerWork { commands: drawn.shadow_commands, texels: if touched { area } else { 0 } };
        rec.layer_commands.add(layer.light_index, layer.layer, work);
    }
}

/// What layer `layer` of `light` culls its casters against, whole (as `cull.rs` culls
/// it for the frame).
fn whole_layer(light: &LightPlan, layer: usize) -> CullView {
    layer_view(light, light.layout.projections[layer].clip_from_world())
}

/// An empty pass that writes `part` of `slot`'s timestamps: it brackets a layer's
/// commands, copies included, so that the clock times them together.
pub(super) fn bracket(rec: &mut Recording, slot: Slot, part: SlotPart) {
    rec.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("shadow layer timing"),
        timestamp_writes: rec.clock.compute_part(slot, part),
    });
}

/// Layer `layer` of `texture`, whole, as a copy's source or destination.
fn texel_copy(texture: &wgpu::Texture, layer: u32) -> wgpu::TexelCopyTextureInfo<'_> {
    wgpu::TexelCopyTextureInfo {
        texture,
        mip_level: 0,
        origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
        aspect: wgpu::TextureAspect::All,
    }
}

/// Copies layer `layer` of `from` into the same layer of `to`.
fn copy_layer(
    encoder: &mut wgpu::CommandEncoder,
    from: &wgpu::Texture,
    to: &wgpu::Texture,
    layer: u32,
    size: wgpu::Extent3d,
) {
    let one_layer = wgpu::Extent3d { depth_or_array_layers: 1, ..size };
    encoder.copy_texture_to_texture(texel_copy(from, layer), texel_copy(to, layer), one_layer);
}

/// The texels of a `resolution`² layer scrolled by `offset` that no texel of the
/// kept layer covers (those whose source, texel + offset, is off the map): a band
/// of columns and a band of rows, as scissor rectangles.
pub(super) fn exposed_strips(offset: [i32; 2], resolution: u32) -> Vec<ScissorRect> {
    // The band of `k` texels at the far end (k > 0) or the near end (k < 0).
    let band = |k: i32| match k.signum() {
        1 => Some((resolution - k as u32, k as u32)),
        -1 => Some((0, k.unsigned_abs())),
        _ => None,
    };
    let columns = band(offset[0]).map(|(x, width)| ScissorRect { x, y: 0, width, height: resolution });
    let rows = band(offset[1]).map(|(y, height)| ScissorRect { x: 0, y, width: resolution, height });
    columns.into_iter().chain(rows).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_exposed_strips_are_where_the_source_is_off_the_map() {
        let r = 8;
        for offset in [[2, 0], [-3, 0], [0, 1], [0, -2], [1, -1], [-2, 3]] {
            let strips = exposed_strips(offset, r);
            for y in 0..r {
                for x in 0..r {
                    let (sx, sy) = (x as i32 + offset[0], y as i32 + offset[1]);
                    let off_map = !(0..r as i32).contains(&sx) || !(0..r as i32).contains(&sy);
                    let in_strip = strips
                        .iter()
                        .any(|s| (s.x..s.x + s.width).contains(&x) && (s.y..s.y + s.height).contains(&y));
                    assert_eq!(off_map, in_strip, "offset {offset:?}, texel ({x}, {y})");
                }
            }
        }
        assert!(exposed_strips([0, 0], r).is_empty());
    }

    #[test]
    fn a_strips_projection_maps_the_strip_onto_the_clip_volume() {
        let clip_from_world = glam::Mat4::from_scale(glam::Vec3::new(0.5, 0.25, 1.0));
        let strip = ScissorRect { x: 6, y: 0, width: 2, height: 8 };
        let onto = strip.clip_from_world(clip_from_world, 8);
        // Texel column 7's centre (NDC x = 0.875) is inside; column 4's (0.125) is not.
        let world = |ndc_x: f32, ndc_y: f32| glam::Vec4::new(ndc_x / 0.5, ndc_y / 0.25, 0.5, 1.0);
        let inside = onto * world(0.875, 0.3);
        let outside = onto * world(0.125, 0.3);
        assert!(inside.x.abs() <= inside.w && inside.y.abs() <= inside.w, "{inside}");
        assert!(outside.x.abs() > outside.w, "{outside}");
    }
}

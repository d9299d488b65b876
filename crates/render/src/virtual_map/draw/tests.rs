//! The pages drawn into the pool hold the depth a full-resolution map of their level
//! holds at the same texels, a still scene draws no page, and a lookup through the
//! page table reads each tap from its page or the coarser page standing in for it.

use glam::Vec3;
use gnomon_math::virtual_map::{
    Clipmap, ClipmapShape, PageKey,
    pages::{PageState, TableEntry},
};

use super::*;
use crate::{
    OutputRequest, Renderer,
    passes::depth_baseline::BaselineLayer,
    readback,
    virtual_map::{PageRequests, PixelReach, VirtualProbe},
};

/// Depth of a `Depth32Float` texture, row-major, top row first, layer after layer.
pub(crate) fn depth_of(gpu: &Gpu, texture: &wgpu::Texture) -> Vec<f32> {
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let pending =
        readback::record(&mut Pool::new(&gpu.device), &mut encoder, texture, wgpu::TextureAspect::DepthOnly);
    gpu.queue.submit([encoder.finish()]);
    pollster::block_on(pending.read(gpu)).expect("read back")
}

/// The spheres at 192×128, the pages their pixels ask for in a small clipmap
/// (1024² levels in 128² pages, so that a whole level fits one reference map), and
/// the scene's casters for the depth-only drawing.
struct Setup {
    gpu: Gpu,
    clipmap: Clipmap,
    requests: Vec<PageKey>,
    casters: DepthBaselineScene,
    /// Every surface point the frame saw, with its pixel's footprint.
    surfaces: Vec<(Vec3, f32)>,
}

fn setup() -> Setup {
    let gpu = Gpu::new_headless().expect("a GPU adapter (install mesa-vulkan-drivers for lavapipe)");
    let scene = gnomon_scene::builtin::spheres();
    let mut settings = gnomon_scene::Settings::default();
    (settings.image.width, settings.image.height) = (192, 128);
    let frame = Renderer::new(&gpu).unwrap().render(&scene, &settings, &OutputRequest::default()).unwrap();
    let shape = ClipmapShape { virtual_resolution: 1024, page_size: 128, levels: 6 };
    let reach = PixelReach {
        footprint_per_depth: 2.0 * (0.5 * frame.camera.fov_y_degrees.to_radians()).tan() / 128.0,
        reach_texels: 2.0,
        area_search: None,
        cone: None,
    };
    let travel = Vec3::new(0.3, -1.0, 0.2);
    let bounds = scene.bounds();
    let farthest = bounds.corners().iter().map(|c| c.distance(frame.camera.eye)).fold(0.0, f32::max);
    let clipmap =
        Clipmap::new(shape, travel, frame.camera.eye, &bounds, farthest * reach.footprint_per_depth);
    let requests =
        pollster::block_on(PageRequests::new(&gpu).unwrap().request_for_frame(&gpu, &frame, &clipmap, reach))
            .expect("requests");
    let levels: std::collections::BTreeSet<u32> = requests.iter().map(|p| p.level).collect();
    assert!(requests.len() >= 10 && levels.len() >= 2, "{requests:?}");
    let casters = DepthBaselineScene::upload(&gpu, &scene).unwrap();
    let surfaces = frame
        .position
        .iter()
        .zip(&frame.depth)
        .filter(|(p, d)| p.is_finite() && d.is_finite())
        .map(|(p, d)| (*p, d * reach.footprint_per_depth))
        .collect();
    Setup { gpu, clipmap, requests, casters, surfaces }
}

/// A full-resolution map's depth, row-major, top row first: what a page's texels
/// must equal.
pub(crate) struct FullMap<'a> {
    pub depth: &'a [f32],
    pub width: usize,
    pub height: usize,
}

impl FullMap<'_> {
    /// Whether `got` is texel (`r`, `c`)'s depth, to within 10⁻⁶ and a 64th of the
    /// depth's change to the neighbouring texels: two projections of the same texels
    /// round a vertex differently before the rasterizer snaps it to its sub-texel
    /// grid (1/256 of a texel, lavapipe and GPUs alike), which moves a sloped
    /// surface's depth by a fraction of that change.
    pub fn agrees(&self, r: usize, c: usize, got: f32) -> bool {
        let want = self.depth[r * self.width + c];
        let slope = [(0, 1), (2, 1), (1, 0), (1, 2)]
            .iter()
            .filter_map(|&(dr, dc)| {
                let (rr, cc) = ((r + dr).checked_sub(1)?, (c + dc).checked_sub(1)?);
                (rr < self.height && cc < self.width).then(|| self.depth[rr * self.width + cc])
            })
            .filter(|n| *n < 1.0)
            .map(|n| (n - want).abs())
            .fold(0.0f32, f32::max);
        (want - got).abs() <= 1e-6 + slope / 64.0
    }

    /// Whether texel (`r`, `c`) lies where the surface is not one plane (a crease or
    /// a silhouette: a second difference across it beyond [`FullMap::agrees`]'s
    /// rounding) and `got` lies within the depths of its 5×5 neighbourhood: there
    /// the texel's centre may lie within a rounding of an edge, and two projections
    /// of the same texels may give it to either triangle, or to a sliver thinner
    /// than a texel whose other texels are two away (Sponza has many).
    pub fn edge_flip(&self, r: usize, c: usize, got: f32) -> bool {
        if r < 2 || c < 2 || r + 2 >= self.height || c + 2 >= self.width {
            return false;
        }
        let d = |r: usize, c: usize| self.depth[r * self.width + c];
        let here = d(r, c);
        let across = [(d(r, c - 1), d(r, c + 1)), (d(r - 1, c), d(r + 1, c))];
        let slope =
            across.iter().map(|&(a, b)| (a - here).abs().max((b - here).abs())).fold(0.0f32, f32::max);
        let bent = across.iter().any(|&(a, b)| (a + b - 2.0 * here).abs() > 1e-6 + slope / 64.0);
        let around = (r - 2..=r + 2).flat_map(|rr| (c - 2..=c + 2).map(move |cc| (rr, cc)));
        let (low, high) =
            around.map(|(rr, cc)| d(rr, cc)).fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(v), h.max(v)));
        bent && (low - 1e-6..=high + 1e-6).contains(&got)
    }
}

#[test]
fn pages_hold_the_full_resolution_depth_and_a_still_scene_draws_none() {
    let Setup { gpu, clipmap, requests, casters, .. } = setup();
    let shape = clipmap.shape;
    // 8 rows of tiles in layers of 4: pages in both layers.
    let size = PoolSize::new(128, 8);
    assert_eq!(size.layers(), 2);
    let mut pages = VirtualPages::new(&gpu, size).unwrap();
    let first = pages.draw(&gpu, &casters, &clipmap, &requests);
    assert!(first.refused.is_empty() && first.granted.iter().all(|g| g.state == PageState::New), "{first:?}");
    let pool = depth_of(&gpu, pages.texture());
    let pool_side = 8 * 128;
    let layer_texels = size.layer_texels() as usize;

    // Each level's full-resolution map, drawn as the pages are.
    let mut baseline = DepthBaselinePass::new(&gpu.device);
    let mut texture_pool = Pool::new(&gpu.device);
    let bias = BiasSettings::default();
    let raster =
        BaselineRaster { bias: &bias, depth_range: DepthRange::Clipped, target: DepthTarget::Projected };
    let mut compared = 0usize;
    let mut differ = 0usize;
    let mut covered = 0usize;
    for level in 0..shape.levels {
        let granted: Vec<_> = first.granted.iter().filter(|g| g.page.level == level).collect();
        if granted.is_empty() {
            continue;
        }
        let full = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("full-resolution level"),
            size: wgpu::Extent3d { width: 1024, height: 1024, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: SHADOW_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = full.create_view(&Default::default());
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let layer =
            BaselineLayer { clip_from_world: clipmap.level_clip_from_world(level), raster, target: &view };
        baseline.record(&gpu, &mut texture_pool, &mut encoder, &casters, layer, None);
        gpu.queue.submit([encoder.finish()]);
        let reference = depth_of(&gpu, &full);
        let origin = clipmap.origins[level as usize];
        for grant in granted {
            let PageKey { x, y, .. } = grant.page;
            let (column, row) = ((x - origin.x) as usize * 128, (origin.y + 7 - y) as usize * 128);
            let tile = size.tile(grant.physical);
            let (tx, ty, first) = (tile.x, tile.y, tile.layer as usize * layer_texels);
            for j in 0..128 {
                for i in 0..128 {
                    let (r, c) = (row + j, column + i);
                    let got = pool[first + (ty as usize + j) * pool_side + tx as usize + i];
                    let full = FullMap { depth: &reference, width: 1024, height: 1024 };
                    compared += 1;
                    covered += usize::from(full.depth[r * 1024 + c] < 1.0);
                    differ += usize::from(!full.agrees(r, c, got));
                }
            }
        }
    }
    assert!(covered > compared / 10, "the pages hold casters: {covered} of {compared}");
    // Every texel: the same depth, to within 10⁻⁶ and a 64th of a texel's slope (a
    // rasterizer snaps vertices to 1/256 of a texel, lavapipe and GPUs alike).
    assert_eq!(differ, 0, "{differ} of {compared} texels differ from the full-resolution map");

    // Nothing moved: nothing is drawn, every page is kept.
    let second = pages.draw(&gpu, &casters, &clipmap, &requests);
    assert_eq!(second.to_draw().count(), 0, "{second:?}");
    assert_eq!(second.granted.len(), first.granted.len());
    // The light turned: every page is drawn again, into the same tile.
    pages.invalidate_all();
    let third = pages.draw(&gpu, &casters, &clipmap, &requests);
    assert!(third.granted.iter().all(|g| g.state == PageState::Dirty));
    assert_eq!(depth_of(&gpu, pages.texture()), pool, "redrawn pages hold the same depth");
}

/// `virtual_texel_depth` of `page_lookup.wgsl`, on the CPU: the depth of texel
/// `texel` of `level` through `table`, from the pool's texels `pool`.
fn texel_depth(map: &Lookup, level: u32, texel: glam::IVec2) -> f32 {
    let size = map.clipmap.shape.page_size as i32;
    let side = map.clipmap.shape.pages_per_side() as i32;
    let page = glam::IVec2::new(texel.x.div_euclid(size), texel.y.div_euclid(size));
    let relative = page - map.clipmap.origins[level as usize];
    if relative.min_element() < 0 || relative.max_element() >= side {
        return 1.0;
    }
    let entry =
        map.table[level as usize * (side * side) as usize + (relative.y * side + relative.x) as usize];
    let Some((slot, coarser)) = entry.get() else { return 1.0 };
    let read = glam::IVec2::new(texel.x.div_euclid(1 << coarser), texel.y.div_euclid(1 << coarser));
    let within = glam::IVec2::new(read.x.rem_euclid(size), read.y.rem_euclid(size));
    let tile = map.size.tile(slot);
    let (x, y) = (tile.x as i32 + within.x, tile.y as i32 + size - 1 - within.y);
    let row = map.size.texels_per_side() as i32;
    map.pool[tile.layer as usize * map.size.layer_texels() as usize + (y * row + x) as usize]
}

/// What the CPU's lookup reads.
struct Lookup<'a> {
    clipmap: &'a Clipmap,
    table: Vec<TableEntry>,
    pool: Vec<f32>,
    size: PoolSize,
}

/// `virtual_pcf2x2` on the CPU; None where a tap's depth is within 10⁻⁵ of the
/// receiver's, where the two sides' rounding may compare differently.
fn pcf2x2(map: &Lookup, world: Vec3, level: u32) -> Option<f32> {
    let c = map.clipmap;
    let light = c.light_from_world.transform_point3(world);
    let depth = (-light.z - c.near) / (c.far - c.near);
    let continuous = light.truncate() / c.texel_size(level) - glam::Vec2::splat(0.5);
    let base = continuous.floor().as_ivec2();
    let weight = continuous - continuous.floor();
    let mut lit = [0.0f32; 4];
    for (k, offset) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
        let stored = texel_depth(map, level, base + glam::IVec2::from(offset));
        if (stored - depth).abs() < 1e-5 {
            return None;
        }
        lit[k] = if depth <= stored { 1.0 } else { 0.0 };
    }
    let bottom = lit[0] + (lit[1] - lit[0]) * weight.x;
    let top = lit[2] + (lit[3] - lit[2]) * weight.x;
    Some(bottom + (top - bottom) * weight.y)
}

#[test]
fn lookups_through_the_page_table_read_every_tap_from_its_own_page_or_its_fallback() {
    let Setup { gpu, clipmap, requests, casters, surfaces } = setup();
    // A pool of 9 pages for more requests: the finest are refused, and their pixels
    // read the coarser pages over them. One row of tiles to a layer: the lookups
    // find each tile's layer.
    let size = PoolSize { rows_per_layer: 1, ..PoolSize::new(128, 3) };
    let mut pages = VirtualPages::new(&gpu, size).unwrap();
    let allocation = pages.draw(&gpu, &casters, &clipmap, &requests);
    assert!(!allocation.refused.is_empty(), "the pool must overflow: {allocation:?}");
    let lookup = Lookup {
        clipmap: &clipmap,
        table: pages.page_table(&clipmap),
        pool: depth_of(&gpu, pages.texture()),
        size,
    };
    // Receivers a little toward the light from the surfaces the frame saw, each at
    // its pixel's level, every 7th pixel.
    let toward_light = -(clipmap.light_from_world.inverse().transform_vector3(Vec3::NEG_Z)) * 0.02;
    let probes: Vec<(Vec3, u32)> = surfaces
        .iter()
        .step_by(7)
        .map(|&(p, footprint)| (p + toward_light, clipmap.level_for_footprint(footprint)))
        .collect();
    let asked: Vec<VirtualProbe> =
        probes.iter().map(|&(p, level)| VirtualProbe { world: p.to_array(), level }).collect();
    let gpu_visibility = pollster::block_on(pages.visibility(&gpu, &clipmap, &asked)).expect("sampled");
    let mut compared = 0;
    let mut fallbacks = 0;
    let mut shadowed = 0;
    for (k, &(p, level)) in probes.iter().enumerate() {
        let Some(expected) = pcf2x2(&lookup, p, level) else { continue };
        compared += 1;
        shadowed += usize::from(expected < 0.5);
        let page = clipmap.page_at(level, clipmap.map_xy(p)).expect("in the window");
        fallbacks += usize::from(allocation.refused.contains(&page));
        assert!(
            (gpu_visibility[k] - expected).abs() < 1e-4,
            "probe {k} at {p} level {level}: GPU {} CPU {expected}",
            gpu_visibility[k]
        );
    }
    assert!(compared * 10 >= probes.len() * 9, "{compared} of {}", probes.len());
    assert!(fallbacks > 50 && shadowed > 50, "{fallbacks} fallbacks, {shadowed} shadowed of {compared}");
}

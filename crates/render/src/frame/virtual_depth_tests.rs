//! The frame's own pages (laid out anew, drawn in runs into the pool's layers with
//! the shadow pass's pipelines, culled per run) hold the depth that a full-resolution
//! map of their level holds at every texel: the same pass over the bounding rectangle
//! of the level's pages (of a point light's face's), drawn whole. On the spheres
//! under a sun, a spot and a point light, and on Sponza where the shared scenes are
//! present.

use std::collections::BTreeMap;

use glam::IVec2;
use gnomon_math::virtual_map::{PageKey, PageRect};
use gnomon_scene::{
    Scene, Settings, builtin,
    settings::{LightKind, Partition, Refine},
};

use super::{
    Renderer,
    cull::layer_view,
    depth_pass::{DepthArea, DepthPass, DepthStart, ScissorRect},
    tile_pass::{Tile, TilePass},
};
use crate::{
    Gpu, OutputRequest,
    passes::SHADOW_FORMAT,
    pool::ViewKey,
    uniforms::LightGpu,
    virtual_map::draw::tests::{FullMap, depth_of},
};

/// What the comparison saw.
#[derive(Debug, Default)]
struct Compared {
    texels: usize,
    /// Texels under a caster in the full map.
    covered: usize,
    /// Texels the two projections gave to different triangles at an edge
    /// ([`FullMap::edge_flip`]).
    edge_flips: usize,
    /// Texels that differ otherwise.
    differ: usize,
}

/// Renders `scene` with `settings` (a virtual sun), then draws each level's
/// full-resolution map over its resident pages and compares every texel.
fn compare_pages(scene: &Scene, settings: &Settings) -> Compared {
    let gpu = Gpu::new_headless().expect("a GPU adapter (install mesa-vulkan-drivers for lavapipe)");
    let mut renderer = Renderer::new(&gpu).unwrap();
    let uploaded = renderer.upload(scene).unwrap();
    let frame = renderer.render_uploaded(&uploaded, scene, settings, &OutputRequest::default()).unwrap();
    let stats = frame.lights[0].pages.expect("a virtual light reports its pages");
    assert!(stats.drawn > 8 && stats.refused == 0 && stats.runs < stats.drawn, "{stats:?}");
    // Planned again: the same clipmap, every page kept.
    let plan = pollster::block_on(renderer.plan_frame(&uploaded, scene, settings, None)).unwrap();
    let light = &plan.lights[0];
    let clipmap = &light.virtual_map.as_ref().expect("a virtual plan").clipmap;
    let pages = renderer.virtual_lights.pages(0);
    let (size, pool_texture) = (pages.size(), pages.texture().clone());
    // The pages of each layer (a level, or a point light's face of one): one
    // projection draws them.
    let layers = clipmap.layers();
    let mut grouped: BTreeMap<usize, Vec<(PageKey, u32)>> = BTreeMap::new();
    for (page, slot) in pages.pages().resident_pages() {
        let layer = layers.iter().position(|l| l.contains(page)).expect("every page lies in a layer");
        grouped.entry(layer).or_default().push((page, slot));
    }
    assert_eq!(grouped.values().map(Vec::len).sum::<usize>(), stats.drawn as usize);
    let pool = depth_of(&gpu, &pool_texture);
    let page = size.page_size as usize;
    let row_texels = size.texels_per_side() as usize;
    let mut seen = Compared::default();
    for (&layer, resident) in &grouped {
        let level = layers[layer].level;
        let min = resident.iter().fold(IVec2::MAX, |m, (p, _)| m.min(IVec2::new(p.x, p.y)));
        let max = resident.iter().fold(IVec2::MIN, |m, (p, _)| m.max(IVec2::new(p.x, p.y)));
        let rect = PageRect { level, min, max };
        let pages_across = (max - min + IVec2::ONE).as_uvec2();
        let (width, height) = (pages_across.x * size.page_size, pages_across.y * size.page_size);
        let clip_from_world = clipmap.rect_clip_from_world(&rect);
        let extent = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let texture = renderer.pool.texture("full-resolution level", extent, SHADOW_FORMAT, usage);
        let view = renderer.pool.view(&texture, ViewKey::default());
        let visible = uploaded.cull(&[layer_view(light, clip_from_world)]);
        let light_gpu = LightGpu { clip_from_world, ..light.light_gpu };
        let like = DepthPass {
            settings: &light.settings,
            light: &light_gpu,
            target_view: &view,
            visible: &visible[0],
            target: light.depth_target(),
            unclipped: light.layout.depth_clamp,
            start: DepthStart::Clear,
            area: DepthArea::Whole,
            culling: None,
        };
        let whole =
            Tile { rect: ScissorRect { x: 0, y: 0, width, height }, light: light_gpu, visible: &visible[0] };
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        renderer.record_tile_pass(
            &mut encoder,
            &uploaded,
            &TilePass { like, tiles: vec![whole], clear_tiles: None },
        );
        gpu.queue.submit([encoder.finish()]);
        let reference = depth_of(&gpu, &texture);
        let full = FullMap { depth: &reference, width: width as usize, height: height as usize };
        for &(key, slot) in resident {
            // The page's texels in the full map (rows run down, light-space y up) and
            // in the pool.
            let (column, row) = ((key.x - min.x) as usize * page, (max.y - key.y) as usize * page);
            let tile = size.tile(slot);
            let first = tile.layer as usize * size.layer_texels() as usize;
            for j in 0..page {
                for i in 0..page {
                    let got = pool[first + (tile.y as usize + j) * row_texels + tile.x as usize + i];
                    let (r, c) = (row + j, column + i);
                    seen.texels += 1;
                    seen.covered += usize::from(full.depth[r * full.width + c] < 1.0);
                    if !full.agrees(r, c, got) {
                        match full.edge_flip(r, c, got) {
                            true => seen.edge_flips += 1,
                            false => seen.differ += 1,
                        }
                    }
                }
            }
        }
    }
    seen
}

/// Every texel equals the full map's, or lies on an edge that rounding may move
/// (rare: one texel in 10,000 at most).
fn assert_holds(seen: &Compared) {
    assert_eq!(seen.differ, 0, "texels differ from the full-resolution map: {seen:?}");
    assert!(seen.edge_flips * 10_000 <= seen.texels, "too many edges moved: {seen:?}");
    eprintln!("figure: virtual pages against a full map: {seen:?}");
}

fn virtual_sun(width: u32, height: u32) -> Settings {
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (width, height);
    s.shadow.partition = Partition::Virtual;
    s.screen.refine = Refine::Off;
    s
}

#[test]
fn the_frames_pages_hold_a_full_resolution_maps_depth_on_the_spheres() {
    let seen = compare_pages(&builtin::spheres(), &virtual_sun(320, 180));
    assert!(seen.covered > seen.texels / 10, "the pages hold casters: {seen:?}");
    assert_holds(&seen);
}

/// A spot's pages: drawn with its perspective projection, each run's window scaled
/// onto its tiles, as the full map of their level is.
#[test]
fn the_frames_pages_hold_a_full_resolution_maps_depth_under_a_spot() {
    let mut s = virtual_sun(320, 180);
    s.light.kind = LightKind::Spot;
    let seen = compare_pages(&builtin::spheres(), &s);
    assert!(seen.covered > seen.texels / 10, "the pages hold casters: {seen:?}");
    assert_holds(&seen);
}

/// A point light's pages: each face's drawn through its own view, as the full map
/// of the face's pages of a level is; none crossing a face's slot.
#[test]
fn the_frames_pages_hold_a_full_resolution_maps_depth_under_a_point_light() {
    let mut s = virtual_sun(320, 180);
    s.light.kind = LightKind::Point;
    let seen = compare_pages(&builtin::spheres(), &s);
    assert!(seen.covered > seen.texels / 10, "the pages hold casters: {seen:?}");
    assert_holds(&seen);
}

/// `shared/scenes/…` beside the checkout (or in `GNOMON_SHARED_SCENES`); None, saying
/// so, where it is missing, unless `GNOMON_REQUIRE_SHARED=1` (as `.ci/run` sets).
fn shared_scene(relative: &str) -> Option<std::path::PathBuf> {
    let root = match std::env::var_os("GNOMON_SHARED_SCENES") {
        Some(dir) => std::path::PathBuf::from(dir),
        None => std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"),
    };
    let path = root.join(relative);
    if path.is_file() {
        return Some(path);
    }
    assert!(
        std::env::var_os("GNOMON_REQUIRE_SHARED").is_none_or(|v| v != "1"),
        "{} is missing: GNOMON_REQUIRE_SHARED=1 requires the shared scenes",
        path.display()
    );
    eprintln!("skipped: {} is not beside this checkout (`.ci/run` has it)", path.display());
    None
}

#[test]
fn the_frames_pages_hold_a_full_resolution_maps_depth_on_sponza() {
    let Some(path) = shared_scene("sponza/sponza_geometry.glb") else { return };
    let (scene, _) = gnomon_scene::gltf_loader::load(&path).expect("Sponza loads");
    // The view of the comparison with Bevy, at a quarter of its pixels a side.
    let mut s = virtual_sun(320, 180);
    s.camera.eye = Some(glam::Vec3::new(-85.0, 12.0, -4.0));
    s.camera.target = Some(glam::Vec3::new(60.0, 30.0, -4.0));
    s.camera.fov_y_degrees = Some(60.0);
    (s.light.sun_elevation, s.light.sun_azimuth) = (Some(70.17), Some(303.69));
    let seen = compare_pages(&scene, &s);
    assert!(seen.covered > seen.texels / 2, "the pages hold casters: {seen:?}");
    assert_holds(&seen);
}

//! The viewer's path: a live frame (left on the GPU) shows the same image as a read-back
//! frame, and the shadow-map preview shows every layer's depth in grayscale.

use crate::support;

use gnomon_render::{OutputRequest, Renderer, read_texture};
use gnomon_scene::{Settings, builtin, settings::Partition};

fn small() -> Settings {
    let mut s = Settings::default();
    s.image.width = 160;
    s.image.height = 96;
    s.shadow.map.resolution = 256;
    s
}

#[test]
fn a_live_frame_is_the_frame_that_is_read_back() {
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::spheres();
    let uploaded = renderer.upload(&scene).unwrap();
    let mut settings = small();
    // Both frames draw their maps, so that they draw the same things (a kept map
    // would draw none the second time; `map_cache.rs` tests that).
    settings.shadow.map.cache = gnomon_scene::settings::MapCache::Off;
    let frame = renderer.render_uploaded(&uploaded, &scene, &settings, &OutputRequest::default()).unwrap();
    let live = renderer.render_live(&uploaded, &scene, &settings).unwrap();
    assert_eq!((live.color.width(), live.color.height()), (160, 96));
    let color: Vec<u8> = read_texture(gpu, &live.color).unwrap();
    let differing = color.iter().zip(&frame.color).filter(|(a, b)| a.abs_diff(**b) > 2).count();
    assert_eq!(differing, 0, "the live image differs from the read-back one in {differing} channels");
    assert_eq!(live.layout.projections.len(), frame.cascades.len());
    assert_eq!(live.stats, frame.stats);
}

#[test]
fn the_map_preview_shows_every_cascade_in_gray_side_by_side() {
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::columns();
    let uploaded = renderer.upload(&scene).unwrap();
    let mut settings = small();
    settings.shadow.partition = Partition::Cascades;
    settings.shadow.cascades.count = 3;
    let live = renderer.render_live(&uploaded, &scene, &settings).unwrap();
    let tile = 64;
    let preview = renderer.preview_shadow_map(&live, tile).unwrap();
    assert_eq!((preview.width(), preview.height()), (3 * tile, tile), "three cascades side by side");
    let texels: Vec<u8> = read_texture(gpu, &preview).unwrap();
    // Every cascade sees the ground and some columns: a spread of grays, with the
    // columns' tops (nearest the sun) darker than the ground around them.
    for layer in 0..3 {
        let grays: Vec<u8> = (0..tile)
            .flat_map(|y| (2..tile).map(move |x| (y, layer * tile + x)))
            .map(|(y, x)| texels[((y * 3 * tile + x) * 4) as usize])
            .collect();
        let (min, max) = (grays.iter().min().unwrap(), grays.iter().max().unwrap());
        assert!(max - min > 20, "cascade {layer}: grays only span {min}..{max}");
        let channels = &texels[((tile / 2 * 3 * tile + layer * tile + tile / 2) * 4) as usize..][..4];
        assert!(channels[0] == channels[1] && channels[1] == channels[2], "not gray: {channels:?}");
    }
    // The seam between cascades is marked.
    let seam = &texels[((tile / 2 * 3 * tile + tile) * 4) as usize..][..3];
    assert!(seam[0] > seam[1] + 40, "no seam colour at the second cascade's edge: {seam:?}");
}

/// Live frames do not wait for their own timestamps: each reports the previous
/// frame's pass times, and the first reports none.
#[test]
fn live_frames_report_the_previous_frames_times() {
    let gpu = crate::support::gpu();
    if gpu.timestamp_period_ns.is_none() {
        support::figures::skipped("live frame timings", "the adapter has no timestamp queries");
        return;
    }
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::spheres();
    let uploaded = renderer.upload(&scene).unwrap();
    let mut settings = small();
    // Every frame draws its shadow passes, to have their times: a kept map would
    // draw none after the first (`map_cache.rs` tests that).
    settings.shadow.map.cache = gnomon_scene::settings::MapCache::Off;
    let first = renderer.render_live(&uploaded, &scene, &settings).unwrap();
    assert!(first.timings.is_none(), "the first live frame has no earlier frame to report");
    for _ in 0..4 {
        let live = renderer.render_live(&uploaded, &scene, &settings).unwrap();
        let timings = live.timings.expect("the previous frame's times");
        assert_eq!(live.timings_age, 1);
        assert!(timings.shadow_ms > 0.0 && timings.lighting_ms > 0.0, "{timings:?}");
        assert!(timings.frame_ms >= timings.shadow_ms, "{timings:?}");
        let light = &live.lights[0];
        assert!(light.shadow_ms.is_some() && !light.layer_ms.is_empty(), "{light:?}");
    }
}

//! The light list (issue 26): one lighting pass that sums every light over a tiled
//! list shades what one pass per light does, draws the scene once, and its scissored
//! mask passes lose no light: checked against the forward path's per-light passes,
//! which look every light's shadow up inline over the whole screen.

use crate::support;

use gnomon_render::Frame;
use gnomon_scene::{
    Scene, Settings, builtin,
    settings::{LightKind, Lighting, Refine, ShadowPath},
};
use support::figures::figure;

fn settings(path: ShadowPath, lighting: Lighting) -> Settings {
    let mut s = Settings::default();
    s.image.width = 192;
    s.image.height = 108;
    s.light.kind = LightKind::All;
    s.screen.shadow_path = path;
    s.screen.lighting = lighting;
    // Rays answer differently on the two paths (per pixel in the mask pass, per
    // fragment forward); the maps' answers are the same.
    s.screen.refine = Refine::Off;
    s
}

/// The largest difference of any channel of any pixel, in 8-bit sRGB steps, and the
/// mean over all channels.
fn colour_difference(a: &Frame, b: &Frame) -> (u8, f64) {
    let diffs: Vec<u8> = a.color.iter().zip(&b.color).map(|(x, y)| x.abs_diff(*y)).collect();
    let mean = diffs.iter().map(|&d| d as f64).sum::<f64>() / diffs.len() as f64;
    (diffs.into_iter().max().unwrap_or(0), mean)
}

/// Renders `scene` lit from the light list on the mask path and one pass per light
/// forward, and checks that they agree within the per-light passes' rounding.
fn agrees_with_per_light_passes(scene: &Scene) {
    let listed = support::render(scene, &settings(ShadowPath::Mask, Lighting::LightList));
    let forward = support::render(scene, &settings(ShadowPath::Forward, Lighting::PerLight));
    let lights = scene.listed_lights().count();
    assert!(listed.shadow_mask && !forward.shadow_mask);
    assert_eq!(listed.object_id, forward.object_id, "{}: the same surfaces", scene.name);
    // The mask pass looks the shadow up where it rebuilds the point from the
    // prepass's depth, not at the fragment's own position: the same answer to 1e-3
    // (as `alpha.rs` in gnomon-reference holds the two paths).
    let worst = listed
        .visibility
        .iter()
        .zip(&forward.visibility)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(worst <= 1e-3, "{}: the reported light's visibility differs by {worst}", scene.name);
    // Each per-light pass rounds the sum to 8 bits once more (sRGB blending decodes,
    // adds and encodes again): at most half a step each, and the list's one rounding.
    let (max, mean) = colour_difference(&listed, &forward);
    let bound = (lights + 1).div_ceil(2) as u8;
    figure(&format!("{}: light list against per-light passes, largest step", scene.name), max, bound);
    assert!(max <= bound, "{}: colours differ by up to {max} steps (bound {bound})", scene.name);
    assert!(mean < 0.5, "{}: colours differ by {mean:.3} steps on average", scene.name);
    // One draw of the scene for every light.
    assert_eq!(listed.stats.lighting_draws * lights as u32, forward.stats.lighting_draws, "{}", scene.name);
}

#[test]
fn the_light_list_shades_every_kind_of_light_as_per_light_passes_do() {
    // A sun with cascades, spots and point lights of four techniques.
    agrees_with_per_light_passes(&builtin::lamps());
}

#[test]
fn the_light_list_shades_a_grid_of_lamps_as_per_light_passes_do() {
    // Lamps whose ranges cover parts of the screen: scissored mask passes.
    agrees_with_per_light_passes(&builtin::build("lamps:12").unwrap());
}

#[test]
fn auto_takes_the_light_list_for_several_lights_and_per_light_asks_for_its_passes() {
    let scene = builtin::build("lamps:3").unwrap();
    let mut s = settings(ShadowPath::Auto, Lighting::LightList);
    let listed = support::render(&scene, &s);
    assert!(listed.shadow_mask, "several lights under auto take the mask path for the list");
    assert_eq!(listed.stats.lighting_draws, listed.stats.prepass_draws, "one draw of the scene");
    s.screen.lighting = Lighting::PerLight;
    let per_light = support::render(&scene, &s);
    assert!(!per_light.shadow_mask, "per-light lighting without rays stays forward");
    assert_eq!(per_light.stats.lighting_draws, 3 * listed.stats.lighting_draws);
}

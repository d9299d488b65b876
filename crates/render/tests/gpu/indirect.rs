//! Indirect submission (issue 26): a shadow layer's draws go out as one multi-draw
//! per pipeline state from a buffer of draw arguments (`DrawSubmission::Indirect`),
//! or one by one (`Direct`, the fallback for a device without first instances in
//! indirect draws). Both draw the same map, texel for texel, for every light kind,
//! and the indirect one records a handful of commands however many meshes it draws.
//! The camera's passes (prepass, lighting) draw each texture's runs as one multi-draw
//! too, unless `direct`: the images are identical, byte for byte.

use crate::support;

use gnomon_render::{Frame, OutputRequest, Renderer};
use gnomon_scene::{
    Scene, Settings, builtin, geometry,
    settings::{DrawSubmission, LightKind, MapCache, OmniMap, Partition, Refine, ShadowPath},
};
use support::figures::{figure, skipped};

fn drawn(scene: &Scene, settings: &Settings, submission: DrawSubmission) -> Frame {
    let mut s = settings.clone();
    s.shadow.map.draw_submission = submission;
    let mut renderer = Renderer::new(support::gpu()).expect("renderer");
    renderer.render(scene, &s, &OutputRequest { shadow_map: true, ..Default::default() }).expect("render")
}

fn settings(light: LightKind) -> Settings {
    let mut s = Settings::default();
    s.screen.refine = Refine::Off;
    s.image.width = 160;
    s.image.height = 90;
    s.shadow.map.resolution = 512;
    s.shadow.map.cache = MapCache::Off;
    s.light.kind = light;
    s
}

/// Draws `scene` both ways and checks the reported light's maps are identical and
/// the draws the same; returns the two frames (indirect, direct).
fn same_maps(name: &str, scene: &Scene, settings: &Settings) -> (Frame, Frame) {
    let indirect = drawn(scene, settings, DrawSubmission::Indirect);
    let direct = drawn(scene, settings, DrawSubmission::Direct);
    let (a, b) = (indirect.shadow_map.as_ref().expect("map"), direct.shadow_map.as_ref().expect("map"));
    assert_eq!((a.resolution, a.layers), (b.resolution, b.layers));
    let differing = a.depth.iter().zip(&b.depth).filter(|(x, y)| x.to_bits() != y.to_bits()).count();
    assert_eq!(differing, 0, "{name}: {differing} of {} texels differ", a.depth.len());
    assert_eq!(indirect.stats.shadow_draws, direct.stats.shadow_draws, "{name}: the same draws");
    // The camera's passes draw the same runs in the same order: the same image.
    let other_colour = indirect.color.iter().zip(&direct.color).filter(|(a, b)| a != b).count();
    assert_eq!(other_colour, 0, "{name}: the camera's passes drew another image");
    let other_surface = indirect.object_id.iter().zip(&direct.object_id).filter(|(a, b)| a != b).count();
    assert_eq!(other_surface, 0, "{name}: the camera's passes saw other surfaces");
    assert_eq!(indirect.stats.lighting_draws, direct.stats.lighting_draws, "{name}");
    assert_eq!(direct.stats.shadow_commands, direct.stats.shadow_draws, "{name}: one command a draw");
    for light in &direct.lights {
        assert_eq!(light.layer_commands, light.layer_draws, "{name}: {}", light.name);
    }
    (indirect, direct)
}

#[test]
fn indirect_and_direct_draws_give_the_same_map_for_every_light_kind() {
    if !support::gpu().indirect_draws {
        skipped("indirect draws", "the device has no first instance in indirect draws");
        return;
    }
    let spheres = builtin::spheres();
    let mut cascades = settings(LightKind::Sun);
    cascades.shadow.partition = Partition::Cascades;
    let mut paraboloid = settings(LightKind::Point);
    paraboloid.shadow.map.omni = OmniMap::Paraboloid;
    let cases = [
        ("sun, cascades", cascades),
        ("spot", settings(LightKind::Spot)),
        ("point, cube", settings(LightKind::Point)),
        ("point, paraboloids", paraboloid),
    ];
    for (name, s) in &cases {
        let (indirect, _) = same_maps(name, &spheres, s);
        assert!(indirect.stats.shadow_commands <= indirect.stats.shadow_draws, "{name}");
    }
    // Three lamps lit from the light list: the mask path, whose prepass draws too.
    let mut lamps = settings(LightKind::All);
    lamps.screen.shadow_path = ShadowPath::Mask;
    let (listed, _) = same_maps("lamps:3, mask path", &builtin::build("lamps:3").expect("lamps"), &lamps);
    assert!(listed.stats.prepass_draws > 0, "{:?}", listed.stats);
}

/// A ground and `count` boxes, each its own mesh (as a glTF file's nodes often are:
/// Florence has 2,639), in a square grid, each box a little different in size.
fn many_meshes(count: usize) -> Scene {
    let mut scene = support::ground_scene("many meshes", 60.0);
    let side = (count as f32).sqrt().ceil() as usize;
    for i in 0..count {
        let (x, z) = ((i % side) as f32, (i / side) as f32);
        let half = glam::Vec3::new(0.3, 0.4 + 0.01 * (i % 7) as f32, 0.3);
        let at = glam::Vec3::new(2.0 * x - side as f32, half.y, 2.0 * z - side as f32);
        support::add(
            &mut scene,
            &format!("box {i}"),
            geometry::cuboid(half),
            glam::Mat4::from_translation(at),
        );
    }
    scene
}

#[test]
fn a_layer_of_many_meshes_is_a_few_commands() {
    if !support::gpu().indirect_draws {
        skipped("indirect draws", "the device has no first instance in indirect draws");
        return;
    }
    let scene = many_meshes(400);
    let (indirect, direct) = same_maps("400 meshes", &scene, &settings(LightKind::Sun));
    let layer_draws = indirect.lights[0].layer_draws[0];
    let layer_commands = indirect.lights[0].layer_commands[0];
    figure(&format!("400 meshes: commands for the sun's {layer_draws} draws"), layer_commands, "2");
    assert!(layer_draws > 200, "{layer_draws} draws: too few to show anything");
    // One command per pipeline state: the closed boxes and the open ground.
    assert!(layer_commands <= 2, "{layer_commands} commands for {layer_draws} draws");
    assert_eq!(direct.lights[0].layer_commands[0], layer_draws);
}

//! Issue 7: many shadowed lights at once. The built-in `lamps` lists eight lights of
//! every type, each with its own technique and map resolution; with `--light all`
//! each gets its own map and lighting pass, and each light's shadows agree with the
//! reference for that light alone.

use crate::common;

use common::{compare, figures::figure, reference, render};
use gnomon_scene::{
    Light, Settings, builtin,
    settings::{LightKind, ShadowPath, Technique},
};

/// Each light's mismatch bound over its light-facing pixels (those inside its cone and
/// range that face it), about 1.7× what was measured on lavapipe with the default
/// normal offset of 0.3 texels (in %): sun 0.150, spots 0.086, 0.114, 0.224, point
/// lights 0.281, 0.346, 0.381, 0.476. The all-surface rate, on which the earlier
/// bounds were set, is reported beside it.
const MISMATCH_BOUNDS: [f64; 8] = [0.0025, 0.0015, 0.002, 0.004, 0.005, 0.006, 0.0065, 0.008];
/// The earlier bounds over all surfaces (`surface_mismatch_rate`), still held: about
/// 1.7× what was measured when they were set (sun 0.151 %, spots 0.055, 0.047,
/// 0.143 %, point lights 0.327, 0.511, 0.394, 0.454 %).
const SURFACE_MISMATCH_BOUNDS: [f64; 8] = [0.0025, 0.001, 0.001, 0.0025, 0.0055, 0.0085, 0.0065, 0.0075];

fn all_lights(index: usize) -> Settings {
    let mut s = Settings::default();
    s.light.kind = LightKind::All;
    s.light.light_index = index;
    s.image.width = 480;
    s.image.height = 270;
    s.reference.samples = 64;
    s
}

#[test]
fn eight_mixed_lights_each_match_the_reference() {
    let scene = builtin::lamps();
    assert_eq!(scene.listed_lights().count(), 8);
    for (index, bound) in MISMATCH_BOUNDS.into_iter().enumerate() {
        let s = all_lights(index);
        let frame = render(&scene, &s);
        // Every light drew its own map, with its own settings.
        assert_eq!(frame.lights.len(), 8);
        let kinds: Vec<&str> = frame.lights.iter().map(|l| l.kind).collect();
        assert_eq!(kinds, ["sun", "spot", "spot", "spot", "point", "point", "point", "point"]);
        assert_eq!(frame.lights[0].layer_draws.len(), 4, "the sun's cascades");
        for l in &frame.lights[4..] {
            assert_eq!((l.layer_draws.len(), l.resolution), (6, 512), "{l:?}");
        }
        assert_eq!(frame.lights[1].resolution, 1024);
        assert_eq!(frame.lights[2].technique, Technique::PCSS);
        assert!(frame.lights.iter().all(|l| l.shadow_draws() > 0), "{:?}", frame.lights);
        assert_eq!(
            frame.light,
            scene.listed_lights().nth(index).unwrap().light,
            "the frame reports the light asked for"
        );

        let truth = reference(&scene, &s);
        let m = compare(&frame, &truth);
        let light = scene.listed_lights().nth(index).unwrap();
        eprintln!(
            "lamps, light {index} `{}` ({}, {}): mismatch {:.3}% of light-facing pixels, {:.3}% of all surfaces, MAE {:.4}",
            light.name,
            light.light.type_name(),
            frame.lights[index].technique.name(),
            100.0 * m.mismatch_rate,
            100.0 * m.surface_mismatch_rate,
            m.mae
        );
        assert!(m.surface() > frame.pixel_count() / 2);
        assert!(m.compared > 0, "light {index} lights nothing in view");
        figure(
            &format!(
                "lamps, light {index} ({}): mismatch over light-facing pixels (all surfaces)",
                light.light.type_name()
            ),
            format!("{:.3}% ({:.3}%)", 100.0 * m.mismatch_rate, 100.0 * m.surface_mismatch_rate),
            format!("{:.2}%", 100.0 * bound),
        );
        assert!(m.mismatch_rate < bound, "light {index}: {m:?}");
        assert!(m.surface_mismatch_rate < SURFACE_MISMATCH_BOUNDS[index], "light {index}: {m:?}");

        // The light's shadows do not depend on the other seven: alone in the
        // scene, with the same settings, it shades the same. The eight take the mask
        // path (the default refines the hard ones by rays); a light with an area,
        // alone, would take the forward one, so alone it is given the mask too.
        let mut alone = scene.clone();
        alone.replace_listed_lights([light.clone()]);
        let mut alone_settings = all_lights(0);
        alone_settings.screen.shadow_path = ShadowPath::Mask;
        let single = render(&alone, &alone_settings);
        let differing =
            frame.visibility.iter().zip(&single.visibility).filter(|(a, b)| (*a - *b).abs() > 1e-5).count();
        assert_eq!(differing, 0, "light {index}: {differing} pixels differ from the light rendered alone");
    }
}

#[test]
fn every_light_adds_to_the_image() {
    // Each light's pass adds light where it reaches: the eight-light image is
    // brighter than the first light alone, and background pixels keep the sky.
    let scene = builtin::lamps();
    let s = all_lights(0);
    let all = render(&scene, &s);
    let mut alone = scene.clone();
    alone.replace_listed_lights(scene.listed_lights().take(1).cloned());
    let one = render(&alone, &s);
    let brightness = |c: &[u8]| c.iter().map(|&v| v as u64).sum::<u64>();
    assert!(brightness(&all.color) > brightness(&one.color) * 11 / 10);
    for (i, id) in all.object_id.iter().enumerate() {
        if *id == 0 {
            assert_eq!(all.color[4 * i..4 * i + 4], one.color[4 * i..4 * i + 4], "sky at pixel {i}");
        }
    }
    assert!(matches!(all.light, Light::Directional(_)));
}

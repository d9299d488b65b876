//! A street canyon under a low sun (issue 76, item 3): `builtin::canyon`, judged at
//! the frame's own surfaces, every light-facing pixel counted. An outside tracer
//! found a virtual map alone (`--partition virtual --refine off`) lighting a wedge
//! by a tall box's base in such a street, 1.46 % of the pixels against a single
//! map's 0.055 %. Here the virtual map alone must be no worse than a single map of
//! the same memory (the pool's texels in one square map), and the defaults exact.

use crate::{common, one_surface::drawn_metrics};
use common::{
    figures::{figure, percent},
    render,
};
use gnomon_reference::drawn::DrawnMetrics;
use gnomon_scene::{
    Settings, builtin,
    settings::{PAGE_TEXELS, Partition, Refine},
};

/// Issue 76's bound at the defaults: 0.02 % of light-facing pixels wrong.
const DEFAULTS_MISMATCH: f64 = 0.0002;

/// How much more of the view the virtual map alone may get wrong than the single
/// map of its memory: a handful of pixels (0.01 % is 14 of the view's 144,000
/// light-facing pixels at 640×360). Its far levels hold coarser texels than a single
/// map fitted to the view, so along the far buildings' edges each gets a few pixels
/// the other gets right; over 33 suns 10–20° up, it measured at most 0.009 % more,
/// and up to 0.23 % less (docs/hard-cases.md, "A street canyon"). The leak the issue
/// saw was 1.4 % more.
const FEW_PIXELS: f64 = 0.0001;

fn view(elevation: f32, azimuth: f32) -> Settings {
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (640, 360);
    s.light.sun_elevation = Some(elevation);
    s.light.sun_azimuth = Some(azimuth);
    s
}

fn measured(scene: &gnomon_scene::Scene, s: &Settings) -> DrawnMetrics {
    drawn_metrics(scene, s, &render(scene, s))
}

#[test]
fn a_virtual_map_alone_lights_no_more_of_a_street_canyon_than_a_single_map_of_its_memory() {
    let scene = builtin::canyon();
    // The canyon's own sun, and two that light the street along its length, where
    // the maps alone are most wrong.
    for (elevation, azimuth) in [(15.0, 20.0), (10.0, 0.0), (20.0, 340.0)] {
        let defaults = view(elevation, azimuth);
        let mut single = defaults.clone();
        single.screen.refine = Refine::Off;
        single.shadow.map.resolution = defaults.shadow.virtual_map.pool_side * PAGE_TEXELS;
        let mut virtual_map = defaults.clone();
        virtual_map.screen.refine = Refine::Off;
        virtual_map.shadow.partition = Partition::Virtual;
        let name = format!("canyon, sun {elevation}° up at {azimuth}°");
        let exact = measured(&scene, &defaults);
        let single = measured(&scene, &single);
        let paged = measured(&scene, &virtual_map);
        figure(
            &format!("{name}: the defaults, mismatch"),
            percent(exact.mismatch_rate),
            percent(DEFAULTS_MISMATCH),
        );
        figure(
            &format!("{name}: the virtual map alone, falsely lit (the single map of its memory)"),
            format!("{} ({})", percent(paged.false_lit_rate), percent(single.false_lit_rate)),
            format!("≤ the single map's + {}", percent(FEW_PIXELS)),
        );
        assert!(exact.compared > 100_000, "{name}: {exact:?}");
        assert!(exact.mismatch_rate <= DEFAULTS_MISMATCH, "{name}: {exact:?}");
        assert!(
            paged.false_lit_rate <= single.false_lit_rate + FEW_PIXELS,
            "{name}: {paged:?} against {single:?}"
        );
        assert!(
            paged.mismatch_rate <= single.mismatch_rate + FEW_PIXELS,
            "{name}: {paged:?} against {single:?}"
        );
    }
}

//! Casters thinner than a texel (issue 76): `builtin::wires`' wires, railing and
//! poles, 4 mm thick, which a 2048² map fitted to the view stores in broken dashes
//! or not at all: the map's rasterization keeps a caster only where it covers a
//! texel's centre, so the footprint test saw light alone around the ones it lost,
//! and traced no ray. The map's touched layer (`rays/touched.rs`), drawn
//! conservatively, holds every caster that touches a texel; the footprint test reads
//! it, and the defaults trace those shadows. Judged at the frame's own surfaces,
//! every light-facing pixel counted, close and far, under the sun and the spot.

use crate::{common, one_surface::drawn_metrics};
use common::{
    figures::{figure, percent},
    render,
};
use gnomon_scene::{
    Settings, builtin,
    settings::{LightKind, Refine},
};

/// Issue 76's bound at the defaults: 0.02 % of light-facing pixels wrong.
const DEFAULTS_MISMATCH: f64 = 0.0002;

/// The map alone misses the thin casters' shadows: measured 0.21 % to 0.47 % here
/// (docs/thin-casters.md); more than this shows that the scene still tests what it
/// is for. The defaults measured 0.000 % to 0.013 %, and before the touched layer
/// 0.003 % to 0.170 %.
const MAP_ALONE_MISSES: f64 = 0.001;

fn view(kind: LightKind, eye: Option<[f32; 3]>) -> Settings {
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (640, 360);
    s.light.kind = kind;
    if let Some(eye) = eye {
        s.camera.eye = Some(glam::Vec3::from(eye));
        s.camera.target = Some(glam::Vec3::new(0.5, 0.0, -0.5));
    }
    s
}

#[test]
fn casters_thinner_than_a_texel_are_traced_at_the_defaults() {
    let scene = builtin::wires();
    for (name, defaults) in [
        ("sun, close", view(LightKind::Sun, None)),
        ("sun, far", view(LightKind::Sun, Some([-2.0, 9.0, 14.0]))),
        ("spot, close", view(LightKind::Spot, None)),
    ] {
        let mut alone = defaults.clone();
        alone.screen.refine = Refine::Off;
        let refined = drawn_metrics(&scene, &defaults, &render(&scene, &defaults));
        let map = drawn_metrics(&scene, &alone, &render(&scene, &alone));
        figure(&format!("wires, {name}: the map alone, mismatch"), percent(map.mismatch_rate), "> 0.1 %");
        figure(
            &format!("wires, {name}: the defaults, mismatch"),
            percent(refined.mismatch_rate),
            percent(DEFAULTS_MISMATCH),
        );
        assert!(refined.compared > 100_000, "{name}: {refined:?}");
        assert!(map.mismatch_rate > MAP_ALONE_MISSES, "{name}: the map alone should miss the wires: {map:?}");
        assert!(refined.mismatch_rate <= DEFAULTS_MISMATCH, "{name}: {refined:?}");
    }
}

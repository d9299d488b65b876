//! The depth-only baseline draws what the shadow pass draws, so that the ratio of
//! their times compares pipelines, not workloads.

use gnomon_render::{Gpu, OutputRequest, Renderer, timing::ClockChoice};
use gnomon_scene::{
    Settings, builtin,
    settings::{BiasSettings, LightKind, Partition},
};

fn unbiased() -> Settings {
    let mut s = Settings::default();
    s.image.width = 160;
    s.image.height = 90;
    s.shadow.map.resolution = 512;
    s.shadow.bias = BiasSettings { cull: s.shadow.bias.cull, ..BiasSettings::none() };
    s
}

#[test]
fn the_baseline_draws_the_same_depth_map_as_the_shadow_pass() {
    let gpu = Gpu::new_headless().unwrap();
    let mut renderer = Renderer::new(&gpu).unwrap();
    let mut cascaded = unbiased();
    cascaded.shadow.partition = Partition::Cascades;
    let mut spot = unbiased();
    spot.light.kind = LightKind::Spot;
    let mut point = unbiased();
    point.light.kind = LightKind::Point;
    for (scene, settings) in [
        (builtin::spheres(), unbiased()),
        (builtin::spheres(), cascaded),
        (builtin::contact(), spot),
        (builtin::spheres(), point),
    ] {
        let uploaded = renderer.upload(&scene).unwrap();
        let baseline = renderer.upload_depth_baseline(&scene).unwrap();
        let ours = renderer
            .render_uploaded(
                &uploaded,
                &scene,
                &settings,
                &OutputRequest { shadow_map: true, ..Default::default() },
            )
            .unwrap()
            .shadow_map
            .unwrap()
            .depth;
        let theirs = renderer.depth_baseline_map(&baseline, &uploaded, &scene, &settings).unwrap();
        assert_eq!(ours.len(), theirs.len());
        let covered = ours.iter().filter(|&&d| d < 1.0).count();
        assert!(covered > ours.len() / 20, "{}: the map holds casters ({covered} texels)", scene.name);
        if settings.light.kind == LightKind::Point {
            // A cube face stores distance over range, the baseline projected depth:
            // the same texels are covered, the values differ.
            let differ = ours.iter().zip(&theirs).filter(|(a, b)| (**a < 1.0) != (**b < 1.0)).count();
            assert!(differ * 1000 < ours.len(), "{}: coverage differs in {differ} texels", scene.name);
            continue;
        }
        let differ = ours.iter().zip(&theirs).filter(|(a, b)| (**a - **b).abs() > 1e-5).count();
        assert!(differ * 1000 < ours.len(), "{}: {differ} of {} texels differ", scene.name, ours.len());
        let times =
            renderer.time_depth_baseline(&baseline, &uploaded, &scene, &settings, ClockChoice::Auto).unwrap();
        assert!(times.iter().all(|t| t.is_some_and(|ms| ms > 0.0)), "{times:?}");
    }
}

//! Shadows refined by GPU rays (`--refine`) against the reference: exact where the
//! map alone is not, on the built-in scenes and on casters thinner than a texel, and
//! after casters move; and the view that shows which pixels rays decided.

use crate::common;

use common::{
    compare,
    figures::{figure, percent},
    reference, render,
};
use glam::{Mat4, Vec3};
use gnomon_render::{Frame, OutputRequest, Renderer};
use gnomon_scene::{
    Settings, builtin,
    settings::{DebugView, Refine, Technique},
};

/// Issue 25's bound for `--refine rays` over `pcf2x2` on a single map: 0.02 % of
/// light-facing pixels wrong.
const REFINED_MISMATCH: f64 = 0.0002;

/// Issue 25's bound for every pixel traced: two independent tracers agree on all but
/// 0.01 % of light-facing pixels.
const TRACED_MISMATCH: f64 = 0.0001;

fn settings(refine: Refine) -> Settings {
    let mut s = Settings::default();
    s.image.width = 640;
    s.image.height = 360;
    s.shadow.filter.technique = Technique::PCF2X2;
    s.screen.refine = refine;
    s
}

#[test]
fn refined_and_traced_shadows_match_the_reference_on_the_built_in_scenes() {
    for scene in [builtin::spheres(), builtin::contact(), builtin::columns(), builtin::grazing()] {
        let truth = reference(&scene, &settings(Refine::Off));
        let map = compare(&render(&scene, &settings(Refine::Off)), &truth);
        let refined_frame = render(&scene, &settings(Refine::Rays));
        let traced_frame = render(&scene, &settings(Refine::EveryPixel));
        let refined = compare(&refined_frame, &truth);
        let traced = compare(&traced_frame, &truth);
        // The pixels each frame says it traced: every light-facing one (the compared
        // ones but for a few where the two normals' N·L differ in sign at grazing
        // light), or a small share of them.
        let rays = refined_frame.lights[0].traced_pixels.expect("a refined frame reports its rays");
        let every = traced_frame.lights[0].traced_pixels.expect("a traced frame reports its rays");
        figure(
            &format!("{}, pixels traced by rays (of every light-facing one)", scene.name),
            format!("{rays} of {every}"),
            "traced: every light-facing pixel; refined: under a fifth of them",
        );
        assert!(
            every as f64 >= 0.99 * traced.compared as f64 && every as usize <= traced_frame.pixel_count(),
            "{every} listed, {} compared",
            traced.compared
        );
        assert!(rays > 0 && rays < every / 5, "{rays} of {every}");
        figure(
            &format!(
                "{}, pcf2x2 refined by rays: mismatch (the map alone: {})",
                scene.name,
                percent(map.mismatch_rate)
            ),
            percent(refined.mismatch_rate),
            percent(REFINED_MISMATCH),
        );
        figure(
            &format!("{}, every pixel traced: mismatch", scene.name),
            percent(traced.mismatch_rate),
            percent(TRACED_MISMATCH),
        );
        assert!(refined.mismatch_rate <= REFINED_MISMATCH, "{}: {refined:?}", scene.name);
        assert!(traced.mismatch_rate <= TRACED_MISMATCH, "{}: {traced:?}", scene.name);
        assert!(refined.compared > 50_000, "{}: {refined:?}", scene.name);
    }
}

/// A receiver nearly edge-on to the light is unsure only where a texel lies farther
/// behind its surface than its own bias, as a fold's crest does
/// (`FootprintBounds::grazing`): a flat ground under a sun 3° up (N·L = 0.05) traces
/// its shadows' edges, not itself whole, and stays exact. (Measured against the plane
/// of the lookup's point, which the default normal offset moves 0.3 texels toward the
/// light, 6 texels of depth in front of the ground at N·L = 0.05, it traced 84 % of
/// its light-facing pixels.)
#[test]
fn a_ground_edge_on_to_the_sun_traces_its_shadow_edges_not_itself() {
    let scene = builtin::grazing();
    let mut s = settings(Refine::Off);
    s.light.sun_elevation = Some(3.0);
    let truth = reference(&scene, &s);
    let refined_frame = render(&scene, &Settings { screen: settings(Refine::Rays).screen, ..s.clone() });
    let refined = compare(&refined_frame, &truth);
    let rays = refined_frame.lights[0].traced_pixels.expect("a refined frame reports its rays") as usize;
    figure(
        "grazing, sun 3° up: pixels traced by rays (of the light-facing ones)",
        format!("{rays} of {}", refined.compared),
        "under a fifth",
    );
    figure(
        "grazing, sun 3° up, refined by rays: mismatch",
        percent(refined.mismatch_rate),
        percent(REFINED_MISMATCH),
    );
    assert!(refined.compared > 50_000, "{refined:?}");
    assert!(rays > 0 && rays < refined.compared / 5, "{rays} of {}", refined.compared);
    assert!(refined.mismatch_rate <= REFINED_MISMATCH, "{refined:?}");
}

#[test]
fn casters_thinner_than_a_texel_are_shadowed_exactly_only_with_rays() {
    let scene = common::thin_bars();
    let mut coarse = settings(Refine::Off);
    coarse.shadow.map.resolution = 512;
    let truth = reference(&scene, &coarse);
    let map = compare(&render(&scene, &coarse), &truth);
    let refined = compare(
        &render(&scene, &Settings { screen: settings(Refine::Rays).screen, ..coarse.clone() }),
        &truth,
    );
    figure("thin bars (a third of a texel), pcf2x2 on 512²: mismatch", percent(map.mismatch_rate), "> 0.5%");
    figure("thin bars, refined by rays: mismatch", percent(refined.mismatch_rate), percent(REFINED_MISMATCH));
    assert!(map.mismatch_rate > 0.005, "the map alone should miss sub-texel bars: {map:?}");
    assert!(refined.mismatch_rate <= REFINED_MISMATCH, "{refined:?}");
}

/// Suzanne under a sun 70° up, at its default view (`gnomon compare
/// pmndrs/suzi.glb --sun-elevation 70 --refine rays`). Past the folds of her brows
/// and ears she shades herself, and the caster there is seen almost edge-on from the
/// light: its slope-scaled bias stores it behind the receiver it shadows, so the
/// lookup reads light, and a footprint test that trusted the stored depths was sure
/// of it. Measured on lavapipe: the map alone 0.401 %; refined, 0.056 % while the
/// footprint test took the bilinear texels at their stored depths, 0.021 % once it
/// took the receiver's own bias off them (`FootprintBounds::own_bias` in
/// refine_footprint.wgsl), 0.012 % since a receiver nearly edge-on to the light is
/// judged against its own surface, not the plane of the lookup's point that the
/// normal offset moved, and is unsure where a texel lies farther behind it than its
/// own bias (`FootprintBounds::grazing`). The bound is issue 25's 0.02 %, which both former
/// tests fail. Needs `../shared`.
const SUZANNE_FOLDS_REFINED: f64 = REFINED_MISMATCH;

#[test]
fn folds_where_a_model_shades_itself_are_traced() {
    let path = common::shipped_scene("pmndrs/suzi.glb");
    let (scene, _) = gnomon_scene::gltf_loader::load(&path).unwrap();
    let mut s = settings(Refine::Off);
    s.image.width = 1280;
    s.image.height = 720;
    s.light.sun_elevation = Some(70.0);
    let truth = reference(&scene, &s);
    let map = compare(&render(&scene, &s), &truth);
    let refined =
        compare(&render(&scene, &Settings { screen: settings(Refine::Rays).screen, ..s.clone() }), &truth);
    figure("Suzanne, sun 70° up, pcf2x2: mismatch", percent(map.mismatch_rate), "> 0.2%");
    figure(
        "Suzanne, sun 70° up, refined by rays: mismatch",
        percent(refined.mismatch_rate),
        percent(SUZANNE_FOLDS_REFINED),
    );
    assert!(map.mismatch_rate > 0.002, "the map alone should be wrong past the folds: {map:?}");
    assert!(refined.compared > 200_000, "{refined:?}");
    assert!(refined.mismatch_rate <= SUZANNE_FOLDS_REFINED, "{refined:?}");
}

#[test]
fn moved_casters_are_traced_where_they_now_stand() {
    // Issue 25: "the BVH refit follows a moved instance". One column is laid across
    // the aisle in view, another moved behind the camera, past the scene's old
    // bounds; the uploaded scene follows them by a refit (`Renderer::move_instances`),
    // and its refined and traced frames must match the reference of the moved scene
    // as closely as a fresh upload's do.
    let mut scene = builtin::columns();
    let mut renderer = Renderer::new(common::gpu()).unwrap();
    let mut uploaded = renderer.upload(&scene).unwrap();
    let request = OutputRequest::default();
    let before =
        renderer.render_uploaded(&uploaded, &scene, &settings(Refine::EveryPixel), &request).unwrap();
    let index = |name: &str| scene.instances.iter().position(|i| i.name == name).unwrap();
    let (laid, behind) = (index("column L1"), index("column R0"));
    scene.instances[laid].world_from_object = Mat4::from_translation(Vec3::new(3.0, 0.6, -11.0))
        * Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2);
    scene.instances[behind].world_from_object = Mat4::from_translation(Vec3::new(2.0, 0.0, 30.0));
    renderer.move_instances(&mut uploaded, &scene, &[laid, behind]).unwrap();
    let truth = reference(&scene, &settings(Refine::Off));
    let stale = compare(&before, &truth);
    for (refine, bound) in [(Refine::EveryPixel, TRACED_MISMATCH), (Refine::Rays, REFINED_MISMATCH)] {
        let frame = renderer.render_uploaded(&uploaded, &scene, &settings(refine), &request).unwrap();
        let moved = compare(&frame, &truth);
        figure(
            &format!(
                "columns, two columns moved, {refine:?} after a refit: mismatch (before the move: {})",
                percent(stale.mismatch_rate)
            ),
            percent(moved.mismatch_rate),
            percent(bound),
        );
        assert!(moved.mismatch_rate <= bound, "{refine:?}: {moved:?}");
    }
    assert!(stale.mismatch_rate > 0.005, "the move should change the shadows: {stale:?}");
    // The map alone (moved transforms, refitted culling trees and bounds) draws what a
    // fresh upload of the moved scene draws.
    let unrefined = renderer.render_uploaded(&uploaded, &scene, &settings(Refine::Off), &request).unwrap();
    let fresh = render(&scene, &settings(Refine::Off));
    let differing =
        unrefined.visibility.iter().zip(&fresh.visibility).filter(|(a, b)| (*a - *b).abs() > 0.01).count();
    assert!(
        differing as f64 <= 1e-4 * fresh.pixel_count() as f64,
        "{differing} pixels differ from a fresh upload"
    );
    // A bad move is refused before anything changes.
    let e = renderer.move_instances(&mut uploaded, &scene, &[scene.instances.len()]).unwrap_err().to_string();
    assert!(e.contains(&format!("no instance {}", scene.instances.len())), "{e}");
    scene.instances[laid].world_from_object.x_axis.y = f32::INFINITY;
    let e = renderer.move_instances(&mut uploaded, &scene, &[laid]).unwrap_err().to_string();
    assert!(e.contains("column L1") && e.contains("non-finite"), "{e}");
}

#[test]
fn the_traced_view_tints_the_pixels_rays_decided_and_changes_no_shadow() {
    // `--debug-view traced` marks each pixel rays decided, in the mask's layer: the
    // image turns magenta there, and nowhere else, while the visibility stays as it
    // was. A light whose shadow no ray decides tints nothing.
    let scene = builtin::columns();
    let plain = render(&scene, &settings(Refine::Rays));
    let mut s = settings(Refine::Rays);
    s.image.debug_view = DebugView::Traced;
    let tinted = render(&scene, &s);
    let traced = tinted.lights[0].traced_pixels.expect("a refined frame reports its rays") as usize;
    let changed = |a: &Frame, b: &Frame| {
        a.color
            .chunks(4)
            .zip(b.color.chunks(4))
            .filter(|(p, q)| p.iter().zip(*q).any(|(x, y)| x.abs_diff(*y) > 2))
            .count()
    };
    let magenta = changed(&plain, &tinted);
    figure(
        "columns, traced view: pixels tinted (of those rays decided)",
        format!("{magenta} of {traced}"),
        "within 2 %",
    );
    assert!(traced > 1000 && magenta.abs_diff(traced) * 50 <= traced, "{magenta} tinted, {traced} traced");
    let moved =
        plain.visibility.iter().zip(&tinted.visibility).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
    assert_eq!(moved, 0, "the view must not change a shadow");
    s.screen.refine = Refine::Off;
    assert_eq!(changed(&render(&scene, &settings(Refine::Off)), &render(&scene, &s)), 0);
}

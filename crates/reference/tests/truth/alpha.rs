//! Alpha-masked casters: a quad with a checkerboard alpha texture casts a checkerboard
//! shadow, in the rasterizer and in the reference, where the analytic projection puts
//! it; and on the `tree` scene the two agree.

use crate::common;

use common::{
    compare,
    figures::{figure, percent},
    reference, render,
};
use glam::{Mat4, Vec2, Vec3};
use gnomon_scene::{
    AlphaMode, DirectionalLight, Instance, Material, Scene, Settings, Texture, Wrap, builtin, geometry,
    settings::{Refine, ScreenSpaceSettings, Technique, value_name},
};

const CELLS: u32 = 8;
const HALF: f32 = 1.0;
const HEIGHT: f32 = 1.2;
const QUAD_CENTER: Vec3 = Vec3::new(0.3, HEIGHT, -0.2);

/// Alpha of checker cell (i, j): opaque when i + j is even.
fn opaque_cell(i: i32, j: i32) -> bool {
    (i + j).rem_euclid(2) == 0
}

fn checker_scene() -> Scene {
    let mut scene = builtin::spheres();
    scene.name = "checker".into();
    scene.meshes = vec![geometry::plane(12.0, 12.0), geometry::plane(2.0 * HALF, 2.0 * HALF)];
    let rgba8 = (0..CELLS as i32)
        .flat_map(|j| {
            (0..CELLS as i32).flat_map(move |i| [200, 180, 60, if opaque_cell(i, j) { 255 } else { 0 }])
        })
        .collect();
    scene.textures = vec![Texture {
        name: "checker".into(),
        width: CELLS,
        height: CELLS,
        rgba8,
        wrap_u: Wrap::ClampToEdge,
        wrap_v: Wrap::ClampToEdge,
        nearest: true,
    }];
    let mut cutout = Material::new("cut-out", Vec3::ONE);
    cutout.base_color_texture = Some(0);
    cutout.alpha_mode = AlphaMode::Mask { cutoff: 0.5 };
    cutout.double_sided = true;
    scene.materials = vec![Material::new("ground", Vec3::splat(0.7)), cutout];
    scene.instances = vec![
        Instance {
            name: "ground".into(),
            mesh: 0,
            material: 0,
            world_from_object: Mat4::IDENTITY,
            casts_shadow: true,
            motion: gnomon_scene::Motion::Static,
        },
        Instance {
            name: "checker".into(),
            mesh: 1,
            material: 1,
            world_from_object: Mat4::from_translation(QUAD_CENTER),
            casts_shadow: true,
            motion: gnomon_scene::Motion::Static,
        },
    ];
    scene.light_mut::<DirectionalLight>().unwrap().direction = -gnomon_scene::sun_direction(60.0, 20.0);
    // Seen from beyond the shadow, so that the quad hides as little of it as possible.
    let shadow = shadow_offset(scene.light::<DirectionalLight>().unwrap().direction)
        + Vec2::new(QUAD_CENTER.x, QUAD_CENTER.z);
    scene.camera.eye = Vec3::new(shadow.x - 1.0, 6.0, shadow.y - 5.0);
    scene.camera.target = Vec3::new(shadow.x, 0.0, shadow.y);
    scene
}

/// Where on the ground (xz) the quad's shadow is shifted, relative to the quad.
fn shadow_offset(direction: Vec3) -> Vec2 {
    Vec2::new(direction.x, direction.z) * (HEIGHT / -direction.y)
}

/// Analytic truth for a ground point: (shadowed, distance to the nearest cell edge,
/// which is where the shadow's state can change).
fn analytic(p: Vec3, direction: Vec3) -> (bool, f32) {
    let q = Vec2::new(p.x, p.z) - shadow_offset(direction) - Vec2::new(QUAD_CENTER.x, QUAD_CENTER.z);
    // The plane's texture runs u along +x and v along +z, from the corner (−h, −h).
    let uv = (q + Vec2::splat(HALF)) / (2.0 * HALF);
    let cell = 2.0 * HALF / CELLS as f32;
    let grid = uv * CELLS as f32;
    let to_line = |g: f32| (g - g.round()).abs() * cell;
    let edge = to_line(grid.x).min(to_line(grid.y));
    let inside = uv.cmpge(Vec2::ZERO).all() && uv.cmplt(Vec2::ONE).all();
    let shadowed = inside && opaque_cell(grid.x.floor() as i32, grid.y.floor() as i32);
    // Outside the quad, the distance to its outline is what matters.
    let outline = if inside { edge } else { (uv.clamp(Vec2::ZERO, Vec2::ONE) - uv).length() * 2.0 * HALF };
    (shadowed, if inside { edge } else { outline })
}

fn settings(technique: Technique) -> Settings {
    let mut s = Settings::default();
    s.image.width = 640;
    s.image.height = 480;
    s.shadow.map.resolution = 2048;
    s.shadow.filter.technique = technique;
    s
}

fn pixel_size(position: &[Vec3], ids: &[u32], w: usize, i: usize) -> f32 {
    [i.wrapping_sub(1), i + 1, i.wrapping_sub(w), i + w]
        .iter()
        .filter(|&&j| j < position.len() && ids[j] == ids[i])
        .map(|&j| position[j].distance(position[i]))
        .fold(0.0, f32::max)
}

#[test]
fn a_checkerboard_alpha_quad_casts_a_checkerboard_shadow() {
    let scene = checker_scene();
    let direction = scene.light::<DirectionalLight>().unwrap().direction;
    for technique in [Technique::HARD, Technique::PCF2X2] {
        let s = settings(technique.clone());
        let frame = render(&scene, &s);
        let texel = frame.light_projection.texel_world_size(2048, 0.0);
        let w = frame.width as usize;
        let (mut cells_seen, mut shadowed, mut worst) = (0, 0, f32::NEG_INFINITY);
        for i in 0..frame.pixel_count() {
            if frame.object_id[i] != 1 {
                continue;
            }
            let (truth, edge) = analytic(frame.position[i], direction);
            cells_seen += usize::from(truth);
            let v = frame.visibility[i] < 0.5;
            shadowed += usize::from(v);
            if v != truth {
                worst = worst.max(edge - texel - pixel_size(&frame.position, &frame.object_id, w, i));
            }
        }
        assert!(
            cells_seen > 3000 && shadowed > 3000,
            "{technique:?}: {cells_seen} truly shadowed, {shadowed} shadowed"
        );
        assert!(
            worst <= 0.0,
            "{technique:?}: a mismatch {worst} beyond one texel and one pixel of a cell edge"
        );
    }
    // The reference: exact to a pixel, with the same alpha lookup.
    let s = settings(Technique::HARD);
    let r = reference(&scene, &s);
    let w = r.width as usize;
    let mut worst = f32::NEG_INFINITY;
    for i in 0..r.pixel_count() {
        if r.object_id[i] != 1 {
            continue;
        }
        let (truth, edge) = analytic(r.position[i], direction);
        if (r.visibility[i] < 0.5) != truth {
            worst = worst.max(edge - pixel_size(&r.position, &r.object_id, w, i));
        }
    }
    assert!(worst <= 0.0, "reference: a mismatch {worst} beyond one pixel of a cell edge");
    // Without the alpha test the whole quad would shadow: make sure the holes exist.
    let lit_under_quad = (0..r.pixel_count())
        .filter(|&i| r.object_id[i] == 1)
        .filter(|&i| {
            let q = Vec2::new(r.position[i].x, r.position[i].z)
                - shadow_offset(direction)
                - Vec2::new(QUAD_CENTER.x, QUAD_CENTER.z);
            q.abs().max_element() < HALF * 0.95 && r.visibility[i] > 0.5
        })
        .count();
    assert!(lit_under_quad > 1000, "the holes let light through ({lit_under_quad} pixels)");
}

/// The tree's leaves are MASK (cutoff 0.5) and double-sided. Needs `../shared`.
///
/// Issue 4 asks for a mismatch under 2 % for `pcf2x2` at 2048² under a directional
/// light, over every surface pixel (the measure of its time, kept as
/// `surface_mismatch_rate`), of the map alone (`--refine off`). Asserted on the view
/// `gnomon compare tree.glb --sun-elevation 55 --sun-azimuth 200 --refine off` uses
/// (the default framing, which fits every vertex in the frame, no ground; every
/// compared pixel is foliage or trunk, so this is leaves shadowing leaves): 1.469 %
/// measured on lavapipe (normal offset 0.3; 1.64 % with 0.6 and the framing of the
/// bounding box). A close view with a ground, where 2 % is not met (2.017 %), is held
/// to a regression bound. The errors are one-texel fringes around each leaf's shadow,
/// so the figure depends on the sun and the framing.
const TREE_FITTED_MISMATCH: f64 = 0.02;
const TREE_CLOSE_MISMATCH: f64 = 0.025;
/// The same two views over the light-facing pixels alone, the measure `compare`
/// reports since issue 22: 2.408 % and 2.141 % measured on lavapipe (a third of the
/// fitted view's pixels are leaves seen from their unlit side, which the all-surface
/// rate counts as trivially right). Regression bounds about 1.25× those.
const TREE_FITTED_LIGHT_FACING: f64 = 0.03;
const TREE_CLOSE_LIGHT_FACING: f64 = 0.027;
/// The same two views with the default's rays where the map is unsure, over the
/// light-facing pixels: 0.016 % and 0.025 % measured on lavapipe, a hundredth of the
/// map's alone (0.017 % and 0.026 % before the footprint test took the receiver's
/// own bias off the bilinear texels). Issue 25's 0.02 % is met on the fitted view,
/// not on the close one. When first measured, against the reference's revision 3,
/// the close view read 0.155 % and 0.135 % with every pixel traced, a disagreement of
/// the two tracers that revision 4 (camera rays from an f64 inverse) is the likely
/// end of; it was not re-measured in between. Regression bounds about 1.5× the
/// measurements.
const TREE_FITTED_REFINED: f64 = 0.00025;
const TREE_CLOSE_REFINED: f64 = 0.0004;

#[test]
fn tree_pcf2x2_agrees_with_the_alpha_aware_reference_with_and_without_rays() {
    let path = common::shipped_scene("tree/tree.glb");
    let (mut scene, extras) = gnomon_scene::gltf_loader::load(&path).unwrap();
    assert!(!extras.has_camera, "the tree ships without a camera: the loader fits one");
    scene.light_mut::<DirectionalLight>().unwrap().direction = -gnomon_scene::sun_direction(55.0, 200.0);
    let mut s = settings(Technique::PCF2X2);
    s.image.width = 1280;
    s.image.height = 720;
    // The map alone, then refined by rays as the default renders, against one reference.
    let measure = |scene: &Scene, what: &str| {
        let truth = reference(scene, &s);
        [Refine::Off, Refine::Auto].map(|refine| {
            let m = compare(&render(scene, &Settings { screen: ScreenSpaceSettings { refine, ..s.screen.clone() }, ..s.clone() }), &truth);
            eprintln!(
                "tree, {what}, pcf2x2, 2048², --refine {}: mismatch {:.3}% (false shadow {:.3}%, false lit {:.3}%) of {} light-facing pixels; {:.3}% of all {} surface pixels",
                value_name(&refine),
                100.0 * m.mismatch_rate,
                100.0 * m.false_shadow_rate,
                100.0 * m.false_lit_rate,
                m.compared,
                100.0 * m.surface_mismatch_rate,
                m.surface(),
            );
            m
        })
    };
    let [fitted, fitted_refined] = measure(&scene, "fitted view");
    figure(
        "tree, fitted view, pcf2x2, map alone: mismatch over light-facing pixels",
        percent(fitted.mismatch_rate),
        percent(TREE_FITTED_LIGHT_FACING),
    );
    figure(
        "tree, fitted view, pcf2x2, map alone: mismatch over all surfaces",
        percent(fitted.surface_mismatch_rate),
        percent(TREE_FITTED_MISMATCH),
    );
    figure(
        "tree, fitted view, pcf2x2, refined by rays: mismatch over light-facing pixels",
        percent(fitted_refined.mismatch_rate),
        percent(TREE_FITTED_REFINED),
    );
    assert!(fitted.surface() > 40_000, "{fitted:?}");
    assert!(fitted.surface_mismatch_rate < TREE_FITTED_MISMATCH, "{fitted:?}");
    assert!(fitted.mismatch_rate < TREE_FITTED_LIGHT_FACING, "{fitted:?}");
    assert!(fitted_refined.mismatch_rate < TREE_FITTED_REFINED, "{fitted_refined:?}");

    // Close to the tree, with a ground three times its width.
    let b = scene.bounds();
    scene.add_ground_plane();
    let (c, r) = (b.center(), b.bounding_radius());
    scene.camera.eye = c + Vec3::new(0.4, 0.9, 1.6) * r;
    scene.camera.target = Vec3::new(c.x, b.min.y + 0.3 * b.extent().y, c.z);
    scene.camera.near = 0.01 * r;
    scene.camera.far = 10.0 * r;
    let [close, close_refined] = measure(&scene, "close view with ground");
    figure(
        "tree, close view with ground, pcf2x2, map alone: mismatch over light-facing pixels",
        percent(close.mismatch_rate),
        percent(TREE_CLOSE_LIGHT_FACING),
    );
    figure(
        "tree, close view with ground, pcf2x2, map alone: mismatch over all surfaces",
        percent(close.surface_mismatch_rate),
        percent(TREE_CLOSE_MISMATCH),
    );
    figure(
        "tree, close view with ground, pcf2x2, refined by rays: mismatch over light-facing pixels",
        percent(close_refined.mismatch_rate),
        percent(TREE_CLOSE_REFINED),
    );
    assert!(close.surface() > 300_000, "{close:?}");
    // Issue 4's 2 % is not met on this view (README); this bound only guards it
    // against getting worse.
    assert!(close.surface_mismatch_rate < TREE_CLOSE_MISMATCH, "{close:?}");
    assert!(close.mismatch_rate < TREE_CLOSE_LIGHT_FACING, "{close:?}");
    assert!(close_refined.mismatch_rate < TREE_CLOSE_REFINED, "{close_refined:?}");
}

#[test]
fn the_mask_paths_prepass_cuts_the_same_holes() {
    // The prepass applies the alpha cut too: through the quad's holes the mask path
    // sees, and shades, the same ground as the forward path.
    let scene = checker_scene();
    let mut s = settings(Technique::PCF2X2);
    // The two paths' map answers: the default's rays refine only the mask path.
    s.screen.refine = Refine::Off;
    s.screen.shadow_path = gnomon_scene::settings::ShadowPath::Forward;
    let forward = render(&scene, &s);
    s.screen.shadow_path = gnomon_scene::settings::ShadowPath::Mask;
    let mask = render(&scene, &s);
    let quad_id = scene.instances.iter().position(|i| i.name == "checker").unwrap() as u32 + 1;
    let seen = forward.object_id.iter().filter(|&&id| id == quad_id).count();
    let holes_differ =
        (0..forward.pixel_count()).filter(|&i| forward.object_id[i] != mask.object_id[i]).count();
    let far_apart = (0..forward.pixel_count())
        .filter(|&i| forward.object_id[i] != 0 && (forward.visibility[i] - mask.visibility[i]).abs() > 1e-3)
        .count();
    eprintln!(
        "checker: {seen} quad pixels; {holes_differ} pixels see another surface, {far_apart} differ by over 1e-3"
    );
    assert!(seen > 5000, "the camera sees the quad: {seen}");
    assert_eq!(holes_differ, 0);
    assert!(far_apart * 5000 <= forward.pixel_count(), "{far_apart}");
}

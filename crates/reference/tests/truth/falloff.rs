//! Lights that fall off with distance as glTF's `KHR_lights_punctual` says
//! (`Falloff::InverseSquare`): a point light over a plane shades it as the inverse
//! square times the cosine and the range window, exactly; and under a spot's disk of
//! such points, the CPU reference and the GPU's penumbra rays both weight each point
//! of the disk by its own falloff, as the integral over the disk does.

use crate::common;

use common::{figures::figure, gpu};
use glam::{Mat4, Vec3};
use gnomon_reference::{ReferenceOptions, TracedScene, reference_visibility};
use gnomon_render::{OutputRequest, Renderer};
use gnomon_scene::{
    Camera, Falloff, Light, Material, Mesh, PointLight, Scene, Settings, SpotLight, geometry,
    settings::{LightKind, Refine, Technique},
};

/// `builtin::spheres` emptied and refilled with `meshes`, in one grey material
/// without a highlight, and no ambient light: the image is the direct light alone.
fn scene_of(meshes: Vec<(Mesh, Mat4)>) -> Scene {
    let mut grey = Material::new("grey", Vec3::splat(ALBEDO));
    grey.specular = 0.0;
    let mut scene = common::scene_of(meshes, grey);
    scene.ambient = Vec3::ZERO;
    scene
}

const ALBEDO: f32 = 0.7;

/// The sRGB transfer function undone (IEC 61966-2-1).
fn linear(encoded: u8) -> f32 {
    let c = f32::from(encoded) / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// The most an 8-bit sRGB code can be off its linear value below 0.6 (where this
/// test's images stay): half a code step, 0.0033 of linear at 0.6, and a little for
/// the rasterizer's interpolation of the position that the shading reads.
const SHADE_TOLERANCE: f32 = 0.004;

/// A point light 2 m over a plane, of 3 cd and range 7: each pixel of the plane
/// shows albedo × 3 × h / d³ × (1 − (d / 7)⁴), the irradiance of the extension's
/// falloff, to within 8-bit rounding. Without the falloff the pixel under the light
/// would be 0.7 × 3, eight times as bright (and clipped); without the window the
/// ring near the range would be lit where it must be black.
#[test]
fn a_point_light_over_a_plane_falls_off_as_the_inverse_square() {
    let (height, intensity, range) = (2.0, 3.0, 7.0);
    let mut scene = scene_of(vec![(geometry::plane(20.0, 20.0), Mat4::IDENTITY)]);
    scene.set_default(PointLight {
        position: Vec3::new(0.0, height, 0.0),
        range,
        color: Vec3::ONE,
        intensity,
        falloff: Falloff::InverseSquare { window: Some(range) },
        radius: 0.0,
    });
    scene.camera = Camera {
        eye: Vec3::new(0.0, 9.0, 7.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_degrees: 70.0,
        near: 0.1,
        far: 50.0,
    };
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (160, 120);
    s.light.kind = LightKind::Point;
    let frame = Renderer::new(gpu()).unwrap().render(&scene, &s, &OutputRequest::default()).unwrap();

    let (mut compared, mut worst, mut beyond_range) = (0usize, 0.0f32, 0usize);
    for (i, p) in frame.position.iter().enumerate() {
        if frame.object_id[i] != 1 {
            continue;
        }
        let d = p.distance(scene.light::<PointLight>().unwrap().position);
        let expected = ALBEDO * intensity * scene.light::<PointLight>().unwrap().falloff.at(d) * (height / d);
        let shown = linear(frame.color[4 * i]);
        // The visibility output is 0 beyond a light's range, 1 within it: no caster.
        assert!(
            frame.visibility[i] == if d < range { 1.0 } else { 0.0 },
            "pixel {i} at {p}: visibility {} with no caster",
            frame.visibility[i]
        );
        worst = worst.max((shown - expected).abs());
        compared += 1;
        beyond_range += usize::from(d >= range);
        assert!(
            (shown - expected).abs() <= SHADE_TOLERANCE,
            "pixel {i} at {p}, {d:.3} m from the light: shows {shown:.4}, the inverse square gives {expected:.4}"
        );
    }
    figure(
        "point light over a plane: worst |shown − inverse square|",
        format!("{worst:.4}"),
        SHADE_TOLERANCE,
    );
    assert!(
        compared > 10_000 && beyond_range > 1000,
        "{compared} plane pixels, {beyond_range} beyond the range"
    );
}

/// A spot's disk of radius 2, 3 m over the ground, half hidden by an occluder 1.5 m
/// up that covers x < 0: a ground point (x, 0, z) sees the disk's points (u, 3, w)
/// with x + u ≥ 0 (the ray crosses the occluder's plane halfway up).
const DISK_RADIUS: f32 = 2.0;
const DISK_HEIGHT: f32 = 3.0;

fn half_hidden_disk() -> (Scene, Settings) {
    let mut scene = scene_of(vec![
        (geometry::plane(40.0, 40.0), Mat4::IDENTITY),
        // Covers x in [−20, 0] at height 1.5.
        (geometry::plane(20.0, 40.0), Mat4::from_translation(Vec3::new(-10.0, 0.5 * DISK_HEIGHT, 0.0))),
    ]);
    scene.set_default(SpotLight {
        position: Vec3::new(0.0, DISK_HEIGHT, 0.0),
        direction: Vec3::NEG_Y,
        inner_angle_degrees: 70.0,
        outer_angle_degrees: 80.0,
        range: 30.0,
        color: Vec3::ONE,
        intensity: 9.0,
        falloff: Falloff::InverseSquare { window: None },
        radius: DISK_RADIUS,
    });
    // Under the occluder's edge, looking down at the penumbra's lit half (x > 0),
    // where nearer points of the disk are the visible ones.
    scene.camera = Camera {
        eye: Vec3::new(1.0, 1.2, 0.0),
        target: Vec3::new(1.0, 0.0, 0.3),
        up: Vec3::Y,
        fov_y_degrees: 60.0,
        near: 0.05,
        far: 50.0,
    };
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (96, 72);
    s.light.kind = LightKind::Spot;
    (scene, s)
}

/// The visible share of the disk from ground point `p`, each point of the disk
/// weighted by `weight` of its distance: a polar quadrature, fine enough (400 × 400)
/// that its own error is far below the tests' bounds.
fn disk_share(p: Vec3, weight: impl Fn(f32) -> f32) -> f32 {
    let n = 400;
    let (mut seen, mut all) = (0.0f64, 0.0f64);
    for i in 0..n {
        let r = DISK_RADIUS * (i as f32 + 0.5) / n as f32;
        for j in 0..n {
            let angle = std::f32::consts::TAU * (j as f32 + 0.5) / n as f32;
            let q = Vec3::new(r * angle.cos(), DISK_HEIGHT, r * angle.sin());
            let w = f64::from(weight(q.distance(p)) * r);
            all += w;
            if p.x + q.x >= 0.0 {
                seen += w;
            }
        }
    }
    (seen / all) as f32
}

/// How a penumbra estimate compares with the weighted integral and with the
/// unweighted share that a light without falloff would give: the mean signed
/// differences over the pixels where the two integrals differ.
struct Against {
    pixels: usize,
    weighted: f64,
    unweighted: f64,
}

fn against_integrals(visibility: &[f32], position: &[Vec3], object_id: &[u32], falloff: Falloff) -> Against {
    let (mut pixels, mut weighted, mut unweighted) = (0usize, 0.0f64, 0.0f64);
    for i in 0..visibility.len() {
        let p = position[i];
        if object_id[i] != 1 || !(0.2..1.8).contains(&p.x) {
            continue;
        }
        pixels += 1;
        weighted += f64::from(visibility[i] - disk_share(p, |d| falloff.at(d)));
        unweighted += f64::from(visibility[i] - disk_share(p, |_| 1.0));
    }
    Against { pixels, weighted: weighted / pixels as f64, unweighted: unweighted / pixels as f64 }
}

/// The mean signed difference allowed from the weighted integral: the estimates'
/// noise averages out over the pixels (256 stratified samples a pixel, standard error
/// about 0.01 each, over some 3,000 pixels), so a bias of 0.005 would be plain.
const MEAN_BIAS: f64 = 0.004;
/// How far the unweighted share lies below the weighted one over these pixels (0.034
/// on average over evenly spaced x in [0.2, 1.8], by the same quadrature): a tracer
/// that ignored the falloff would sit there.
const UNWEIGHTED_GAP: f64 = 0.02;

#[test]
fn the_reference_weights_each_point_of_a_disk_by_its_falloff() {
    let (scene, s) = half_hidden_disk();
    let options = ReferenceOptions { width: s.image.width, height: s.image.height, samples: 256 };
    let light = Light::Spot(*scene.light::<SpotLight>().unwrap());
    let image = reference_visibility(&TracedScene::build(&scene), &scene.camera, &light, &options, &|_| {});
    let found = against_integrals(
        &image.visibility,
        &image.position,
        &image.object_id,
        scene.light::<SpotLight>().unwrap().falloff,
    );
    figure(
        "reference under a disk of inverse-square points: mean − weighted integral (− unweighted)",
        format!("{:+.4} ({:+.4})", found.weighted, found.unweighted),
        format!("±{MEAN_BIAS} (≥ {UNWEIGHTED_GAP})"),
    );
    assert!(found.pixels > 3000, "{} penumbra pixels", found.pixels);
    assert!(
        found.weighted.abs() <= MEAN_BIAS,
        "mean bias {:+.4} against the weighted integral",
        found.weighted
    );
    assert!(found.unweighted >= UNWEIGHTED_GAP, "{:+.4} over the unweighted share", found.unweighted);
}

#[test]
fn penumbra_rays_weight_each_point_of_a_disk_by_its_falloff() {
    let (scene, mut s) = half_hidden_disk();
    s.shadow.filter.technique = Technique::PCSS;
    s.screen.refine = Refine::EveryPixel;
    s.screen.penumbra_rays = 256;
    let frame = Renderer::new(gpu()).unwrap().render(&scene, &s, &OutputRequest::default()).unwrap();
    let found = against_integrals(
        &frame.visibility,
        &frame.position,
        &frame.object_id,
        scene.light::<SpotLight>().unwrap().falloff,
    );
    figure(
        "GPU penumbra rays under a disk of inverse-square points: mean − weighted integral (− unweighted)",
        format!("{:+.4} ({:+.4})", found.weighted, found.unweighted),
        format!("±{MEAN_BIAS} (≥ {UNWEIGHTED_GAP})"),
    );
    assert!(found.pixels > 3000, "{} penumbra pixels", found.pixels);
    assert!(
        found.weighted.abs() <= MEAN_BIAS,
        "mean bias {:+.4} against the weighted integral",
        found.weighted
    );
    assert!(found.unweighted >= UNWEIGHTED_GAP, "{:+.4} over the unweighted share", found.unweighted);
}

/// `Falloff::at` is the extension's formula: the inverse square inside the window,
/// 0 at and past it, and no window when there is none.
#[test]
fn the_falloff_is_the_extensions_formula() {
    let windowed = Falloff::InverseSquare { window: Some(4.0) };
    assert!((windowed.at(2.0) - (1.0 - 0.0625) / 4.0).abs() < 1e-7);
    assert_eq!(windowed.at(4.0), 0.0);
    assert_eq!(windowed.at(5.0), 0.0);
    assert_eq!(Falloff::InverseSquare { window: None }.at(10.0), 0.01);
    assert_eq!(Falloff::Constant.at(123.0), 1.0);
    // A surface touching the light gets a finite irradiance.
    assert!(Falloff::InverseSquare { window: None }.at(0.0).is_finite());
}

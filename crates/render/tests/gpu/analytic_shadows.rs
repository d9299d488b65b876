//! GPU tests against analytic shadows: a square occluder over a plane under a sun
//! and under a spot light. The shadow boundary must be within one shadow texel plus
//! one pixel of the exact projection, for every technique of the foundation.

use crate::support;

use glam::{Vec2, Vec3};
use gnomon_scene::{Light, SpotLight, settings::Technique};
use support::*;

#[derive(Debug)]
struct BoundaryReport {
    compared: usize,
    shadowed: usize,
    mismatched: usize,
    worst_excess: f32,
}

/// Compares the ground pixels of `frame` with an analytic shadow given by
/// `distance_to_shadow_edge` (negative inside the shadow). A mismatch is allowed
/// only within one texel plus one pixel footprint of the exact edge.
fn check_boundary(
    frame: &gnomon_render::Frame,
    distance_to_shadow_edge: impl Fn(Vec3) -> f32,
    texel: impl Fn(Vec3) -> f32,
) -> BoundaryReport {
    let mut r = BoundaryReport { compared: 0, shadowed: 0, mismatched: 0, worst_excess: f32::NEG_INFINITY };
    for i in 0..frame.pixel_count() {
        // Ground only (object id 1), and only where the ground faces up toward the light.
        if frame.object_id[i] != 1 || frame.visibility[i].is_nan() {
            continue;
        }
        let p = frame.position[i];
        let d = distance_to_shadow_edge(p);
        let analytic_shadow = d < 0.0;
        let shadowed = frame.visibility[i] < 0.5;
        r.compared += 1;
        r.shadowed += shadowed as usize;
        if analytic_shadow != shadowed {
            r.mismatched += 1;
            let allowed = texel(p) + pixel_footprint(frame, i);
            r.worst_excess = r.worst_excess.max(d.abs() - allowed);
        }
    }
    r
}

fn techniques() -> Vec<(Technique, u32)> {
    vec![(Technique::HARD, 3), (Technique::PCF2X2, 3), (Technique::PCF, 3), (Technique::PCF, 7)]
}

#[test]
fn square_occluder_under_a_sun_matches_the_analytic_projection() {
    let SquareOccluder { scene, shadow_center, shadow_half: half, .. } = square_under_sun();
    for (technique, kernel) in techniques() {
        let mut s = settings(640, 480, 1024);
        s.shadow.filter.technique = technique.clone();
        s.shadow.filter.pcf_kernel = kernel as f32;
        let frame = render(&scene, &s);
        let texel = frame.light_projection.texel_world_size(1024, 0.0);
        let r =
            check_boundary(&frame, |p| square_distance(Vec2::new(p.x, p.z), shadow_center, half), |_| texel);
        let label = format!("{technique:?} {kernel}");
        // The analytic shadow is 2 × 2 units, several thousand pixels here.
        assert!(r.shadowed > 2000, "{label}: only {} shadowed pixels", r.shadowed);
        assert!(r.compared > 100_000, "{label}: only {} ground pixels", r.compared);
        assert!(
            r.worst_excess <= 0.0,
            "{label}: a mismatch lies {} beyond one texel ({texel}) plus one pixel of the edge ({} of {} pixels mismatched)",
            r.worst_excess,
            r.mismatched,
            r.compared
        );
    }
}

#[test]
fn spot_light_cone_and_shadow_match_the_perspective_projection() {
    let SquareOccluder { scene, shadow_center, shadow_half, .. } = square_under_spot();
    let cone_radius = SPOT_HEIGHT * SPOT_OUTER_DEGREES.to_radians().tan();

    for (technique, kernel) in techniques() {
        let mut s = settings(640, 480, 1024);
        s.light.kind = gnomon_scene::settings::LightKind::Spot;
        s.shadow.filter.technique = technique.clone();
        s.shadow.filter.pcf_kernel = kernel as f32;
        let frame = render(&scene, &s);
        let Light::Spot(spot) = frame.light else { panic!("spot expected") };
        assert_eq!(spot.position, scene.light::<SpotLight>().unwrap().position);
        let label = format!("{technique:?} {kernel}");

        // Outside the cone: no light at all, so visibility 0 and only ambient colour.
        let mut outside = 0;
        for i in 0..frame.pixel_count() {
            if frame.object_id[i] != 1 {
                continue;
            }
            let p = frame.position[i];
            let r = Vec2::new(p.x, p.z).length();
            if r > cone_radius + pixel_footprint(&frame, i) {
                outside += 1;
                assert_eq!(frame.visibility[i], 0.0, "{label}: lit outside the cone at {p}");
                let ambient = srgb_encode(scene.ambient.x * 0.7);
                let c = frame.color[4 * i] as f32;
                assert!(
                    (c - ambient).abs() <= 2.0,
                    "{label}: colour {c} outside the cone, ambient alone is {ambient}"
                );
            }
        }
        assert!(outside > 10_000, "{label}: the view must include ground outside the cone ({outside})");

        // Inside the cone: the occluder's shadow is where the perspective projection puts it.
        let r = check_boundary(
            &frame,
            |p| {
                let in_cone = Vec2::new(p.x, p.z).length() < cone_radius;
                if in_cone { square_distance(Vec2::new(p.x, p.z), shadow_center, shadow_half) } else { -1e9 }
            },
            |p| frame.shadow_texel_world_size(p),
        );
        assert!(r.shadowed > 2000, "{label}: only {} shadowed pixels", r.shadowed);
        assert!(
            r.worst_excess <= 0.0,
            "{label}: a mismatch lies {} beyond one texel plus one pixel of the edge ({} of {} mismatched)",
            r.worst_excess,
            r.mismatched,
            r.compared
        );
    }
}

/// Refined by rays (the default), a shadow's edge is exact: on a 256² map, whose
/// texels span several pixels here, no mismatch lies farther than one pixel from the
/// analytic edge, under a sun or a spot; the same map unrefined misses ten times as
/// many pixels at least.
#[test]
fn rays_put_shadow_edges_within_a_pixel_of_the_exact_projection() {
    use gnomon_scene::settings::{LightKind, Refine};
    let sun = square_under_sun();
    let spot = square_under_spot();
    let cone_radius = SPOT_HEIGHT * SPOT_OUTER_DEGREES.to_radians().tan();
    for (kind, occluder) in [(LightKind::Sun, &sun), (LightKind::Spot, &spot)] {
        let (center, half) = (occluder.shadow_center, occluder.shadow_half);
        let distance = |p: Vec3| {
            let in_cone = kind == LightKind::Sun || Vec2::new(p.x, p.z).length() < cone_radius;
            if in_cone { square_distance(Vec2::new(p.x, p.z), center, half) } else { -1e9 }
        };
        let report = |refine: Refine| {
            let mut s = settings(640, 480, 256);
            s.light.kind = kind;
            s.screen.refine = refine;
            let frame = render(&occluder.scene, &s);
            assert_eq!(frame.shadow_mask, refine != Refine::Off, "{kind:?} {refine:?}: the path");
            let texel = |p: Vec3| frame.shadow_texel_world_size(p);
            (check_boundary(&frame, distance, |_| 0.0), texel(Vec3::new(center.x, 0.0, center.y)))
        };
        let (refined, texel) = report(Refine::Auto);
        let (unrefined, _) = report(Refine::Off);
        eprintln!(
            "{kind:?}, 256² map (texel {texel:.4}): beyond a pixel of the edge, refined {:.4} ({} of {} mismatched), unrefined {:.4} ({} mismatched)",
            refined.worst_excess,
            refined.mismatched,
            refined.compared,
            unrefined.worst_excess,
            unrefined.mismatched
        );
        assert!(refined.shadowed > 1000 && refined.compared > 100_000, "{kind:?}: the shadow is in view");
        assert!(
            refined.worst_excess <= 0.0,
            "{kind:?}: a refined mismatch lies {} beyond a pixel",
            refined.worst_excess
        );
        // The same map unrefined misses ten times as many pixels at least.
        assert!(
            unrefined.mismatched > 10 * refined.mismatched.max(1),
            "{kind:?}: the unrefined map should miss more often ({unrefined:?} against {refined:?})"
        );
    }
}

/// Linear [0, 1] to an 8-bit sRGB value.
fn srgb_encode(linear: f32) -> f32 {
    let s = if linear <= 0.0031308 { 12.92 * linear } else { 1.055 * linear.powf(1.0 / 2.4) - 0.055 };
    255.0 * s
}

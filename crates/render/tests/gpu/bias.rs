//! GPU tests of the bias knobs against ray-traced truth: acne on `grazing` without
//! bias and its absence with the defaults, and no peter-panning at a contact in
//! `contact` with the defaults.

use crate::support;

use glam::{Vec2, Vec3};
use gnomon_render::techniques::TechniqueRegistry;
use gnomon_scene::{
    builtin,
    settings::{BiasSettings, Technique},
};
use support::*;

/// True when the ray-traced visibility changes within `radius` of `p` across the
/// light's direction: `p` is then on a shadow edge, where a map's finite resolution
/// misplaces the boundary by up to a texel whatever the bias. That is aliasing, not
/// acne, so the acne measure leaves those pixels out.
fn near_shadow_edge(
    scene: &gnomon_scene::Scene,
    light: &gnomon_scene::Light,
    p: Vec3,
    n: Vec3,
    radius: f32,
) -> bool {
    let gnomon_scene::Light::Directional(sun) = light else { unreachable!() };
    let d = sun.direction.normalize();
    let a = d.any_orthonormal_vector();
    let b = d.cross(a);
    let lit = ray_traced_lit(scene, light, p, n);
    (0..8).any(|k| {
        let phi = k as f32 * std::f32::consts::FRAC_PI_4;
        // A step of `radius` in light space, slid along the light onto the receiver's
        // tangent plane: the surface point that a shadow texel that far away covers.
        let q = p + radius * (phi.cos() * a + phi.sin() * b);
        let q = q - d * ((q - p).dot(n) / d.dot(n));
        ray_traced_lit(scene, light, q, n) != lit
    })
}

/// Fraction of lit-facing pixels (N·L > 0) that are truly lit but rendered shadowed,
/// away from shadow edges (see [`near_shadow_edge`]).
/// Also returns the fraction of lit-facing pixels wrongly shadowed on shadow edges.
fn acne_fraction(technique: Technique, bias: BiasSettings) -> (f64, f64, usize) {
    let mut s = settings(640, 360, 2048);
    s.shadow.filter.technique = technique;
    s.shadow.bias = bias;
    acne_fraction_with(&s, 0.5)
}

/// Like [`acne_fraction`], counting pixels darker than `threshold` as shadowed.
fn acne_fraction_with(s: &gnomon_scene::Settings, threshold: f32) -> (f64, f64, usize) {
    let scene = builtin::grazing();
    let frame = render(&scene, s);
    let gnomon_scene::Light::Directional(sun) = frame.light else { panic!() };
    let to_light = -sun.direction;
    let (mut facing, mut wrong, mut edge) = (0usize, 0usize, 0usize);
    for i in 0..frame.pixel_count() {
        if frame.object_id[i] == 0 || frame.normal[i].dot(to_light) <= 0.0 {
            continue;
        }
        facing += 1;
        let (p, n) = (frame.position[i], frame.normal[i]);
        if frame.visibility[i] < threshold && ray_traced_lit(&scene, &frame.light, p, n) {
            let texel = frame.light_projection.texel_world_size(2048, 0.0);
            // A filter legitimately greys pixels within its reach of an edge (W/2 for
            // a PCF kernel of width W), as the technique states it.
            let f = &s.shadow.filter;
            let technique = TechniqueRegistry::builtin().get(&f.technique).expect("a built-in technique");
            let reach = technique.filter_reach_texels(f, f.pcf_kernel);
            if !near_shadow_edge(&scene, &frame.light, p, n, (1.5 + reach) * texel) {
                wrong += 1;
            } else {
                edge += 1;
            }
        }
    }
    (wrong as f64 / facing as f64, edge as f64 / facing as f64, facing)
}

#[test]
fn grazing_without_bias_has_acne_and_the_default_bias_removes_it() {
    let (unbiased, _, facing) = acne_fraction(Technique::HARD, BiasSettings::none());
    assert!(facing > 100_000, "the plane fills most of the view ({facing} lit-facing pixels)");
    assert!(
        unbiased > 0.05,
        "zero bias: only {:.3}% wrongly shadowed, expected acne above 5%",
        100.0 * unbiased
    );
    let (biased, edge, _) = acne_fraction(Technique::HARD, BiasSettings::default());
    assert!(biased < 0.001, "default bias: {:.4}% wrongly shadowed, expected under 0.1%", 100.0 * biased);
    // Edge aliasing is excluded above; it must stay a thin band, not a hiding place.
    assert!(edge < 0.005, "default bias: {:.3}% wrongly shadowed along shadow edges", 100.0 * edge);
    eprintln!(
        "grazing, hard: {:.2}% acne without bias; {:.4}% acne and {:.3}% edge aliasing with the default bias",
        100.0 * unbiased,
        100.0 * biased,
        100.0 * edge
    );
}

#[test]
fn default_bias_removes_acne_for_filtered_techniques_too() {
    for technique in [Technique::PCF2X2, Technique::PCF] {
        let (biased, edge, _) = acne_fraction(technique.clone(), BiasSettings::default());
        assert!(
            biased < 0.001,
            "{technique:?}: {:.4}% wrongly shadowed with the default bias",
            100.0 * biased
        );
        assert!(edge < 0.005, "{technique:?}: {:.3}% wrongly shadowed along shadow edges", 100.0 * edge);
    }
}

#[test]
fn receiver_plane_bias_keeps_wide_kernels_off_their_own_receiver() {
    // A 25-texel kernel on `grazing` reaches 12.5 texels from the lookup, where the
    // plane's depth differs by far more than the slope bias allows for one texel:
    // the outer taps shadow the receiver itself, and lit ground greys. Any pixel of
    // truly lit ground below 0.9 counts.
    for technique in [Technique::PCF, Technique::PCF_TENT, Technique::PCF_POISSON] {
        let mut s = settings(640, 360, 2048);
        s.shadow.filter.technique = technique.clone();
        s.shadow.filter.pcf_kernel = 25.0;
        s.shadow.filter.receiver_plane_bias = false;
        let (flat, _, _) = acne_fraction_with(&s, 0.9);
        s.shadow.filter.receiver_plane_bias = true;
        let (tilted, _, _) = acne_fraction_with(&s, 0.9);
        eprintln!(
            "{}: {:.3}% self-shadowed without receiver-plane bias, {:.4}% with it",
            technique.name(),
            100.0 * flat,
            100.0 * tilted
        );
        assert!(flat > 0.01, "{technique:?}: the wide kernel should self-shadow without it ({flat})");
        assert!(
            tilted < 0.001,
            "{technique:?}: {:.4}% self-shadowed with receiver-plane bias",
            100.0 * tilted
        );
    }
}

/// The largest distance from the contact line at which a ground pixel on the
/// shadow's centre line is still lit, in shadow texels, and how many pixels were on
/// that line. The caster is `contact`'s thin wall (0.04 thick, 1.5 high), whose
/// lit face is −z: with back-face culling only that face is in the map, so any bias
/// shows as a gap behind the wall's foot. (The solid box hides bias behind its own
/// thickness: the light leaves it through its top, far above the ground.)
fn contact_detachment(technique: Technique, bias: BiasSettings) -> (f32, usize) {
    let scene = builtin::contact();
    let mut s = settings(960, 720, 2048);
    s.shadow.filter.technique = technique;
    s.shadow.bias = bias;
    let frame = render(&scene, &s);
    let gnomon_scene::Light::Directional(sun) = frame.light else { panic!() };
    let wall = scene.instances.iter().find(|i| i.name == "thin wall").unwrap();
    let bounds = scene.meshes[wall.mesh].bounds().transformed(wall.world_from_object);
    // The shadow runs along the light's horizontal direction, here toward +z.
    let along = Vec2::new(sun.direction.x, sun.direction.z).normalize();
    assert!(along.y > 0.5, "the contact scene's sun casts the wall's shadow toward +z");
    // Start on the foot of the wall's far (+z) face, below its middle.
    let start = Vec2::new(bounds.center().x, bounds.max.z);
    // A ground point s along the line sees the sun over the wall once s·tan(elevation)
    // exceeds the wall's height, measured from the far face's foot.
    let elevation = (-sun.direction.y).asin();
    let shadow_length = bounds.max.y / elevation.tan();
    let texel = frame.light_projection.texel_world_size(2048, 0.0);
    let (mut worst, mut on_line) = (0.0f32, 0usize);
    for i in 0..frame.pixel_count() {
        if frame.object_id[i] != 1 {
            continue;
        }
        let p = frame.position[i];
        let rel = Vec2::new(p.x, p.z) - start;
        let s_along = rel.dot(along);
        let lateral = (rel - s_along * along).length();
        if lateral > 0.5 * pixel_footprint(&frame, i).max(0.01)
            || s_along <= 0.0
            || s_along > 0.8 * shadow_length
        {
            continue;
        }
        // By construction the truth is shadow along the whole stretch; confirm it.
        assert!(!ray_traced_lit(&scene, &frame.light, p, Vec3::Y), "truth is lit at {p}");
        on_line += 1;
        if frame.visibility[i] >= 0.5 {
            worst = worst.max(s_along / texel);
        }
    }
    (worst, on_line)
}

#[test]
fn default_bias_keeps_the_contact_shadow_attached() {
    for technique in [Technique::HARD, Technique::PCF2X2, Technique::PCF] {
        let (detached, on_line) = contact_detachment(technique.clone(), BiasSettings::default());
        eprintln!("contact wall, {}, default bias: detached by {detached:.2} texels", technique.name());
        assert!(on_line > 20, "{technique:?}: only {on_line} pixels on the shadow's centre line");
        assert!(detached <= 2.0, "{technique:?}: shadow detached by {detached:.2} texels at the contact");
    }
    // The measure does detect peter-panning: once the slope bias outgrows the wall's
    // 4 cm thickness the shadow detaches, more with more bias.
    let mut previous = 0.0;
    for slope_bias in [20.0, 40.0, 80.0] {
        let (detached, _) =
            contact_detachment(Technique::HARD, BiasSettings { slope_bias, ..Default::default() });
        eprintln!("contact wall, hard, slope bias {slope_bias}: detached by {detached:.2} texels");
        assert!(detached >= previous, "more bias, no less detachment ({detached:.2} < {previous:.2})");
        if slope_bias == 40.0 {
            assert!(
                detached > 4.0,
                "slope bias 40 should detach the shadow by several texels: {detached:.2}"
            );
        }
        previous = detached;
    }
}

//! Issue 8: screen-space shadows. The mask path (a depth-and-normal prepass, then a
//! full-screen pass per light that resolves its shadow once per pixel) gives the
//! forward path's visibility; contact shadows win back the contact shadows that a
//! large bias detaches, at almost no cost in false shadows.

use crate::common;

use common::{compare, reference, render};
use glam::{Vec2, Vec3};
use gnomon_reference::{
    ReferenceImage,
    metrics::{self, Metrics, PixelClass, RasterView},
};
use gnomon_render::Frame;
use gnomon_scene::{
    Scene, Settings, builtin,
    settings::{LightKind, OmniMap, Partition, Refine, ShadowPath, Technique},
};

/// The default settings at a size, unrefined: these tests compare the two paths'
/// map answers, and contact shadows with the map's, which the default's rays would
/// correct on the mask path alone.
fn settings(width: u32, height: u32) -> Settings {
    let mut s = Settings::default();
    s.screen.refine = Refine::Off;
    s.image.width = width;
    s.image.height = height;
    s
}

/// Per-pixel |forward − mask| over the pixels both frames see the same object at:
/// (largest, mean, pixels over 1e-3, pixels compared).
fn path_difference(forward: &Frame, mask: &Frame) -> (f32, f64, usize, usize) {
    let (mut largest, mut sum, mut over, mut compared) = (0.0f32, 0.0f64, 0usize, 0usize);
    for i in 0..forward.pixel_count() {
        if forward.object_id[i] == 0 || forward.object_id[i] != mask.object_id[i] {
            continue;
        }
        let d = (forward.visibility[i] - mask.visibility[i]).abs();
        largest = largest.max(d);
        sum += d as f64;
        over += (d > 1e-3) as usize;
        compared += 1;
    }
    (largest, sum / compared.max(1) as f64, over, compared)
}

fn both_paths(scene: &Scene, s: &Settings) -> (Frame, Frame) {
    let mut forward = s.clone();
    forward.screen.shadow_path = ShadowPath::Forward;
    let mut mask = s.clone();
    mask.screen.shadow_path = ShadowPath::Mask;
    let (f, m) = (render(scene, &forward), render(scene, &mask));
    assert!(!f.shadow_mask && m.shadow_mask);
    (f, m)
}

/// Changes a case makes to the default settings.
type Configure = Box<dyn Fn(&mut Settings)>;

#[test]
fn the_mask_path_gives_the_forward_visibility() {
    let cases: Vec<(&str, Scene, Configure)> = vec![
        ("spheres, hard", builtin::spheres(), Box::new(|s| s.shadow.filter.technique = Technique::HARD)),
        ("spheres, pcf", builtin::spheres(), Box::new(|s| s.shadow.filter.technique = Technique::PCF)),
        ("spheres, pcss", builtin::spheres(), Box::new(|s| s.shadow.filter.technique = Technique::PCSS)),
        ("spheres, vsm", builtin::spheres(), Box::new(|s| s.shadow.filter.technique = Technique::VSM)),
        (
            "columns, cascades, pcf-poisson",
            builtin::columns(),
            Box::new(|s| {
                s.shadow.partition = Partition::Cascades;
                s.shadow.filter.technique = Technique::PCF_POISSON;
            }),
        ),
        (
            "contact, spot, pcf",
            builtin::contact(),
            Box::new(|s| {
                s.light.kind = LightKind::Spot;
                s.shadow.filter.technique = Technique::PCF;
            }),
        ),
        (
            "spheres, point cube, pcf",
            builtin::spheres(),
            Box::new(|s| {
                s.light.kind = LightKind::Point;
                s.shadow.filter.technique = Technique::PCF;
            }),
        ),
        (
            "lamps, eight lights, reporting the PCSS spot",
            builtin::lamps(),
            Box::new(|s| {
                s.light.kind = LightKind::All;
                s.light.light_index = 2;
            }),
        ),
        (
            "lamps, eight lights, reporting a PCSS point light",
            builtin::lamps(),
            Box::new(|s| {
                s.light.kind = LightKind::All;
                s.light.light_index = 7;
            }),
        ),
        (
            "spheres, point paraboloid, pcf2x2",
            builtin::spheres(),
            Box::new(|s| {
                s.light.kind = LightKind::Point;
                s.shadow.map.omni = OmniMap::Paraboloid;
                s.shadow.filter.technique = Technique::PCF2X2;
            }),
        ),
    ];
    for (name, scene, configure) in cases {
        let mut s = settings(640, 360);
        configure(&mut s);
        let (forward, mask) = both_paths(&scene, &s);
        let (largest, mean, over, compared) = path_difference(&forward, &mask);
        eprintln!(
            "{name}: forward vs mask: largest |Δ| {largest:.2e}, mean {mean:.2e}, {over} of {compared} pixels over 1e-3"
        );
        assert!(compared > forward.pixel_count() / 2, "{name}: {compared}");
        assert_eq!(forward.color.len(), mask.color.len());
        // Both paths look the shadow up at the same point: the mask path reads the
        // point the prepass interpolated from the vertices, as the forward pass does.
        // Under a sun on `spheres` nothing else differs, and the visibility is the
        // same to the bit (a point rebuilt from the prepass's depth differed by up to
        // 1.5e-3 here, and put rays under their own surface on a GPU: docs/gpu.md).
        if name.starts_with("spheres, ") && !name.contains("point") {
            assert_eq!(largest, 0.0, "{name}: the paths shade different points");
        }
        // Elsewhere within 1e-3 but at isolated pixels where the lookup itself is
        // discontinuous and the mask path's screen derivatives, rebuilt on the
        // receiver's plane, round differently from the forward pass's: a receiver
        // as deep as an occluder to float precision (a contact's corner) flips a
        // filter tap, a PCSS blocker-search tap changes the penumbra. At most 1 pixel
        // in 5000 (the worst measured, cascaded Poisson PCF on `columns`: 8 of
        // 138 355); on average the two paths agree to 2e-5.
        assert!(over * 5_000 <= compared, "{name}: {over} pixels over 1e-3");
        assert!(mean < 2e-5, "{name}: mean |Δ| {mean:e}");
    }
}

#[test]
fn the_path_comparison_catches_a_changed_lookup() {
    // The same comparison fails when the mask path's lookup differs: a tenth of a
    // texel more normal offset moves shadow edges by a fraction of a pixel.
    let scene = builtin::spheres();
    let s = settings(640, 360);
    let (forward, _) = both_paths(&scene, &s);
    let mut moved = s.clone();
    moved.screen.shadow_path = ShadowPath::Mask;
    moved.shadow.bias.normal_offset += 0.1;
    let (largest, mean, over, compared) = path_difference(&forward, &render(&scene, &moved));
    eprintln!(
        "normal offset +0.1 on the mask path: largest |Δ| {largest:.2e}, mean {mean:.2e}, {over} over 1e-3"
    );
    assert!(over * 5_000 > compared, "{over} of {compared}, mean {mean:e}");
}

/// Where the scene's objects touch its ground (the plane y = 0): every triangle,
/// edge and vertex of a non-ground instance lying in that plane, as 2D (x, z)
/// triangles (an edge or a vertex is a degenerate one).
fn contacts_with_the_ground(scene: &Scene) -> Vec<[Vec2; 3]> {
    const ON_GROUND: f32 = 1e-4;
    let mut contacts = Vec::new();
    for instance in scene.instances.iter().filter(|i| i.name != "ground") {
        let mesh = &scene.meshes[instance.mesh];
        let world: Vec<Vec3> =
            mesh.positions.iter().map(|&p| instance.world_from_object.transform_point3(p)).collect();
        for t in mesh.indices.chunks_exact(3) {
            let on: Vec<Vec2> = t
                .iter()
                .map(|&i| world[i as usize])
                .filter(|p| p.y.abs() < ON_GROUND)
                .map(|p| Vec2::new(p.x, p.z))
                .collect();
            match on.as_slice() {
                [a, b, c] => contacts.push([*a, *b, *c]),
                [a, b] => contacts.push([*a, *b, *b]),
                [a] => contacts.push([*a, *a, *a]),
                _ => {}
            }
        }
    }
    contacts
}

fn distance_to_segment(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let t =
        if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    p.distance(a + t * ab)
}

/// Distance from `p` to the nearest contact with the ground.
fn distance_to_contact(p: Vec3, contacts: &[[Vec2; 3]]) -> f32 {
    let q = Vec2::new(p.x, p.z);
    let in_plane = contacts
        .iter()
        .map(|&[a, b, c]| {
            let side = |u: Vec2, v: Vec2| (v - u).perp_dot(q - u);
            let (s0, s1, s2) = (side(a, b), side(b, c), side(c, a));
            let inside = (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0);
            let degenerate = (b - a).perp_dot(c - a).abs() < 1e-12;
            if inside && !degenerate {
                0.0
            } else {
                distance_to_segment(q, a, b)
                    .min(distance_to_segment(q, b, c))
                    .min(distance_to_segment(q, c, a))
            }
        })
        .fold(f32::INFINITY, f32::min);
    (in_plane * in_plane + p.y * p.y).sqrt()
}

/// The metrics over the compared pixels whose surface lies within `radius` of a contact.
fn near_contacts(frame: &Frame, truth: &ReferenceImage, scene: &Scene, radius: f32) -> Metrics {
    let contacts = contacts_with_the_ground(scene);
    let raster =
        RasterView { visibility: &frame.visibility, object_id: &frame.object_id, depth: &frame.depth };
    let classes: Vec<PixelClass> = metrics::classify(raster, truth)
        .into_iter()
        .zip(&frame.position)
        .map(|(class, &p)| match class {
            PixelClass::Compared if distance_to_contact(p, &contacts) > radius => PixelClass::Background,
            other => other,
        })
        .collect();
    metrics::measure(raster, truth, &classes)
}

#[test]
fn contact_distance_is_measured_from_where_objects_meet_the_ground() {
    let scene = builtin::contact();
    let contacts = contacts_with_the_ground(&scene);
    // The sphere touches at one point under its centre (0, 1, −2.5).
    assert!(distance_to_contact(Vec3::new(0.0, 0.0, -2.5), &contacts) < 1e-4);
    assert!((distance_to_contact(Vec3::new(0.0, 0.0, -2.0), &contacts) - 0.5).abs() < 1e-3);
    // The box spans x in [−4.5, −2.5], z in [−1, 1]: 0.2 m from its side, 0 under it.
    assert!((distance_to_contact(Vec3::new(-2.3, 0.0, 0.0), &contacts) - 0.2).abs() < 1e-4);
    assert!(distance_to_contact(Vec3::new(-3.5, 0.0, 0.5), &contacts) < 1e-6);
    // Up the box's side, the distance is the height.
    assert!((distance_to_contact(Vec3::new(-2.5, 0.3, 0.0), &contacts) - 0.3).abs() < 1e-4);
    // Far from everything.
    assert!(distance_to_contact(Vec3::new(-7.0, 0.0, 7.0), &contacts) > 3.0);
}

/// The bias that detaches `contact`'s shadows: slope bias 40 (the test in
/// against_raster.rs shows it raises the false-lit rate).
const PETER_PANNING_SLOPE_BIAS: f32 = 40.0;
/// "Near a contact": within this distance of where an object meets the ground.
const NEAR_CONTACT: f32 = 0.3;

/// Near-contact and overall metrics of `s` on `scene`, without and with contact
/// shadows (defaults otherwise).
fn with_and_without_contact(scene: &Scene, s: &Settings, truth: &ReferenceImage) -> [(Metrics, Metrics); 2] {
    let without = render(scene, s);
    let mut on = s.clone();
    on.shadow.contact.contact_shadows = true;
    let with = render(scene, &on);
    assert!(with.shadow_mask && !without.shadow_mask, "contact shadows take the mask path by themselves");
    [without, with].map(|f| (near_contacts(&f, truth, scene, NEAR_CONTACT), compare(&f, truth)))
}

#[test]
fn contact_shadows_reattach_peter_panned_shadows() {
    let scene = builtin::contact();
    let mut s = settings(640, 360);
    s.shadow.bias.slope_bias = PETER_PANNING_SLOPE_BIAS;
    let truth = reference(&scene, &s);
    for technique in [Technique::HARD, Technique::PCF2X2, Technique::PCF, Technique::PCSS] {
        s.shadow.filter.technique = technique.clone();
        let [(near_without, all_without), (near_with, all_with)] =
            with_and_without_contact(&scene, &s, &truth);
        eprintln!(
            "contact, slope bias {PETER_PANNING_SLOPE_BIAS}, {}: near contacts ({} pixels within {NEAR_CONTACT} m) false lit {:.2}% → {:.2}% with contact shadows; everywhere false shadow {:.3}% → {:.3}%, false lit {:.3}% → {:.3}%",
            technique.name(),
            near_without.compared,
            100.0 * near_without.false_lit_rate,
            100.0 * near_with.false_lit_rate,
            100.0 * all_without.false_shadow_rate,
            100.0 * all_with.false_shadow_rate,
            100.0 * all_without.false_lit_rate,
            100.0 * all_with.false_lit_rate,
        );
        // The bias really detaches the shadows near the contacts...
        assert!(near_without.false_lit_rate > 0.02, "{technique:?}: {near_without:?}");
        assert!(near_without.compared > 3000, "{near_without:?}");
        // ...and contact shadows win back at least half of what it lost there,
        assert!(
            near_with.false_lit_rate <= 0.5 * near_without.false_lit_rate,
            "{technique:?}: {near_without:?}\n{near_with:?}"
        );
        // for at most 0.2 percentage points more false shadow over the image.
        assert!(
            all_with.false_shadow_rate <= all_without.false_shadow_rate + 0.002,
            "{technique:?}: {all_without:?}\n{all_with:?}"
        );
    }
}

#[test]
fn contact_shadows_cost_little_where_the_map_is_right() {
    // With the default bias the map keeps its contacts; on a grazing sun, a depth
    // buffer seen at a slant tempts a screen-space ray into shadowing its own
    // surface. Neither may gain more than 0.2 points of false shadow.
    for scene in [builtin::contact(), builtin::grazing(), builtin::columns()] {
        let s = settings(640, 360);
        let truth = reference(&scene, &s);
        let [(_, without), (_, with)] = with_and_without_contact(&scene, &s, &truth);
        eprintln!(
            "{}, default bias: false shadow {:.3}% → {:.3}%, false lit {:.3}% → {:.3}% with contact shadows",
            scene.name,
            100.0 * without.false_shadow_rate,
            100.0 * with.false_shadow_rate,
            100.0 * without.false_lit_rate,
            100.0 * with.false_lit_rate,
        );
        assert!(with.false_shadow_rate <= without.false_shadow_rate + 0.002, "{}: {with:?}", scene.name);
        assert!(with.false_lit_rate <= without.false_lit_rate + 1e-4, "{}: {with:?}", scene.name);
    }
}

#[test]
fn an_over_thick_depth_buffer_is_caught_as_false_shadow() {
    // The metric that bounds contact shadows' false shadows can fail: taking every
    // depth sample as a metre-per-metre-deep occluder with a long ray shadows lit
    // ground behind every object.
    let scene = builtin::contact();
    let s = settings(640, 360);
    let truth = reference(&scene, &s);
    let mut thick = s.clone();
    thick.shadow.contact.contact_shadows = true;
    thick.shadow.contact.contact_thickness = 1.0;
    thick.shadow.contact.contact_length = 3.0;
    let (right, wrong) = (compare(&render(&scene, &s), &truth), compare(&render(&scene, &thick), &truth));
    eprintln!(
        "contact, thickness 1, length 3: false shadow {:.3}% → {:.3}%",
        100.0 * right.false_shadow_rate,
        100.0 * wrong.false_shadow_rate
    );
    assert!(wrong.false_shadow_rate > right.false_shadow_rate + 0.002, "{right:?}\n{wrong:?}");
}

#[test]
fn contact_shadows_fade_out_over_the_last_quarter_of_their_distance() {
    let scene = builtin::contact();
    let mut s = settings(1280, 720);
    s.shadow.bias.slope_bias = PETER_PANNING_SLOPE_BIAS;
    s.screen.shadow_path = ShadowPath::Mask;
    let without = render(&scene, &s);
    s.shadow.contact.contact_shadows = true;
    let full = render(&scene, &s);
    // The pixels contact shadows darken, and the view depths they span.
    let darkened: Vec<usize> =
        (0..full.pixel_count()).filter(|&i| full.visibility[i] < without.visibility[i] - 0.01).collect();
    let mut depths: Vec<f32> = darkened.iter().map(|&i| full.depth[i]).collect();
    depths.sort_by(f32::total_cmp);
    assert!(darkened.len() > 1000, "{} pixels darkened", darkened.len());
    // End the contact shadows where some of those pixels lie beyond the end and some
    // before three quarters of it (they span 9 to 14 m): beyond, the shadows are
    // gone, before, whole, and in between they fade.
    let (nearest, farthest) = (depths[0], depths[depths.len() - 1]);
    assert!(farthest > nearest / 0.75, "depths {nearest} to {farthest}");
    let end = 0.5 * (nearest / 0.75 + farthest);
    s.shadow.contact.contact_distance = end;
    let faded = render(&scene, &s);
    let (mut gone, mut whole, mut between) = (0, 0, 0);
    for &i in &darkened {
        let (v, lo, hi) = (faded.visibility[i], full.visibility[i], without.visibility[i]);
        let z = full.depth[i];
        if z >= end {
            assert!((v - hi).abs() < 1e-6, "pixel {i} at depth {z}: {v} against {hi} without");
            gone += 1;
        } else if z <= 0.75 * end {
            assert!((v - lo).abs() < 1e-6, "pixel {i} at depth {z}: {v} against {lo} in full");
            whole += 1;
        } else {
            assert!(v >= lo - 1e-6 && v <= hi + 1e-6, "pixel {i} at depth {z}: {v} outside [{lo}, {hi}]");
            between += (v > lo + 1e-3 && v < hi - 1e-3) as usize;
        }
    }
    eprintln!("contact shadows ending at {end:.2} m: {gone} pixels gone, {whole} whole, {between} fading");
    assert!(gone > 5 && whole > 100 && between > 10, "{gone} {whole} {between}");
}

#[test]
fn contact_shadows_fade_at_the_screen_edges() {
    // A 640-pixel-wide image with the same vertical field of view and height is the
    // middle of a 1280-pixel one, pixel for pixel. Contact shadows found near the
    // narrow image's left and right edges fade there; well inside, they darken as
    // much in both (not pixel for pixel: the jitter follows pixel coordinates).
    let scene = builtin::contact();
    let mut s = settings(1280, 720);
    s.shadow.bias.slope_bias = PETER_PANNING_SLOPE_BIAS;
    // Fitted to the scene, the map does not change with the framing.
    s.shadow.map.fit = gnomon_scene::settings::Fit::Scene;
    s.screen.shadow_path = ShadowPath::Mask;
    let frames = |s: &Settings| {
        let mut on = s.clone();
        on.shadow.contact.contact_shadows = true;
        (render(&scene, s), render(&scene, &on))
    };
    let wide = frames(&s);
    s.image.width = 640;
    let narrow = frames(&s);
    // Darkening by contact shadows alone (where the map lights the pixel), summed
    // within 6 pixels of the narrow image's edges and beyond 64.
    let (mut edge, mut inside) = ([0.0f64; 2], [0.0f64; 2]);
    for y in 0..720usize {
        for x in 0..640usize {
            let (n, w) = (y * 640 + x, y * 1280 + x + 320);
            assert_eq!(narrow.0.object_id[n], wide.0.object_id[w], "the same surface at ({x}, {y})");
            for (k, (frame, i)) in [(&wide, w), (&narrow, n)].into_iter().enumerate() {
                if frame.0.object_id[i] == 0 || frame.0.visibility[i] < 0.99 {
                    continue;
                }
                let darkening = (frame.0.visibility[i] - frame.1.visibility[i]) as f64;
                match x.min(639 - x) {
                    0..6 => edge[k] += darkening,
                    65.. => inside[k] += darkening,
                    _ => {}
                }
            }
        }
    }
    eprintln!(
        "contact shadows' darkening near the screen edges: {:.1} wide, {:.1} narrow; inside: {:.1} wide, {:.1} narrow",
        edge[0], edge[1], inside[0], inside[1]
    );
    assert!(edge[0] > 20.0 && inside[0] > 500.0, "{edge:?} {inside:?}");
    // Within 1 % of an edge any hit is within 5 % of it (the rays span a few pixels
    // here), where the fade takes most of it.
    assert!(edge[1] <= 0.5 * edge[0], "{edge:?}");
    assert!((inside[1] - inside[0]).abs() <= 0.1 * inside[0], "{inside:?}");
}

//! The touched layer (`rays/touched.rs`) read back from frames and checked against
//! the casters' triangles clipped to each texel's square on the CPU: every texel a
//! triangle touches holds a depth no farther than the triangle's nearest point over
//! the square (the layer is conservative: it never says "nothing here" of a texel a
//! caster touches, however thin), and no texel is marked that no triangle comes
//! near. Slivers a tenth of a texel wide at every angle, and triangles edge-on to the
//! light, under a sun (orthographic) and a spot (perspective). (The layer draws thin
//! triangles alone, `touched.wgsl`: the check mirrors that rule.)

use glam::{DMat4, DVec2, DVec3, DVec4, Mat4, Vec3};
use gnomon_scene::{Instance, Material, Mesh, Motion, Scene, Settings, builtin, settings::LightKind};

use super::Renderer;
use crate::{Gpu, OutputRequest, pool::Pool, rays::bvh::CasterBvh, readback};

fn gpu() -> Gpu {
    Gpu::new_headless().expect("a GPU adapter (install mesa-vulkan-drivers for lavapipe)")
}

/// A 4 × 4 m ground that casts no shadow (so that the layer holds the slivers
/// alone) under slivers: `count` thin triangles at random heights, angles
/// and tilts (0.5 to 6 mm wide, 3 to 30 cm long), and triangles whose plane holds the
/// sun's direction, which the sun's map sees as segments.
fn slivers(count: usize) -> Scene {
    let mut scene = builtin::wires();
    scene.name = "slivers".into();
    scene.materials = vec![Material::new("grey", Vec3::splat(0.7))];
    let gnomon_scene::Light::Directional(sun) = &scene.lights[0].light else {
        panic!("the wires' first light is its sun");
    };
    let toward_sun = -sun.direction;
    // A 64-bit LCG (Knuth's MMIX constants): the same slivers on every run.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = move |low: f32, high: f32| {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        low + (high - low) * ((state >> 40) as f32 / (1u64 << 24) as f32)
    };
    let mut thin = Mesh { name: "slivers".into(), ..Default::default() };
    for k in 0..count {
        let base = Vec3::new(uniform(-1.5, 1.5), uniform(0.3, 1.0), uniform(-1.5, 1.5));
        let angle = uniform(0.0, std::f32::consts::TAU);
        let along = Vec3::new(angle.cos(), uniform(-0.3, 0.3), angle.sin()).normalize() * uniform(0.03, 0.3);
        let across = if k % 8 == 0 {
            // In the plane of the sun's direction: edge-on from the sun.
            toward_sun * uniform(0.01, 0.2)
        } else {
            along.cross(Vec3::Y).normalize() * uniform(0.0005, 0.006)
        };
        let first = thin.positions.len() as u32;
        thin.positions.extend([base, base + along, base + 0.5 * along + across]);
        let normal = along.cross(across).normalize_or_zero();
        thin.normals.extend([normal; 3]);
        thin.uvs.extend([glam::Vec2::ZERO; 3]);
        thin.indices.extend([first, first + 1, first + 2]);
    }
    scene.meshes = vec![gnomon_scene::geometry::plane(4.0, 4.0), thin];
    let instance = |name: &str, mesh, casts_shadow| Instance {
        name: name.into(),
        mesh,
        material: 0,
        world_from_object: Mat4::IDENTITY,
        casts_shadow,
        motion: Motion::Static,
    };
    scene.instances = vec![instance("ground", 0, false), instance("slivers", 1, true)];
    scene.camera.eye = Vec3::new(0.0, 3.0, 3.5);
    scene.camera.target = Vec3::ZERO;
    scene
}

/// The slivers under the sun and under the spot, on a 256² map, one small frame.
fn cases() -> Vec<(Scene, Settings)> {
    [LightKind::Sun, LightKind::Spot]
        .into_iter()
        .map(|kind| {
            let mut s = Settings::default();
            (s.image.width, s.image.height) = (160, 90);
            s.light.kind = kind;
            s.shadow.map.resolution = 256;
            (slivers(120), s)
        })
        .collect()
}

/// A convex polygon in the map's NDC (x, y) with its depth (z), clipped to the
/// half-plane `n · p ≤ w` (Sutherland & Hodgman).
fn clipped(polygon: &[DVec3], n: DVec2, w: f64) -> Vec<DVec3> {
    let inside = |p: &DVec3| n.dot(p.truncate()) <= w;
    let mut out = Vec::new();
    for (i, a) in polygon.iter().enumerate() {
        let b = &polygon[(i + 1) % polygon.len()];
        if inside(a) {
            out.push(*a);
        }
        if inside(a) != inside(b) {
            let (da, db) = (n.dot(a.truncate()) - w, n.dot(b.truncate()) - w);
            out.push(*a + (*b - *a) * (da / (da - db)));
        }
    }
    out
}

/// The nearest depth of `triangle` (NDC) over texel (x, y)'s square of a map
/// `side` texels a side, grown by `grow` texels on each side (negative: shrunk);
/// None where they do not meet.
fn nearest_over_texel(triangle: &[DVec3; 3], x: usize, y: usize, side: usize, grow: f64) -> Option<f64> {
    let texel = 2.0 / side as f64;
    let (left, right) = ((x as f64 - grow) * texel - 1.0, (x as f64 + 1.0 + grow) * texel - 1.0);
    let (top, bottom) = (1.0 - (y as f64 - grow) * texel, 1.0 - (y as f64 + 1.0 + grow) * texel);
    let mut polygon = triangle.to_vec();
    for (n, w) in [
        (DVec2::new(-1.0, 0.0), -left),
        (DVec2::new(1.0, 0.0), right),
        (DVec2::new(0.0, 1.0), top),
        (DVec2::new(0.0, -1.0), -bottom),
    ] {
        polygon = clipped(&polygon, n, w);
        if polygon.is_empty() {
            return None;
        }
    }
    polygon.iter().map(|p| p.z).reduce(f64::min)
}

/// The thin triangles (`projected`), and whether each is checked: those the map
/// cannot hold itself. The list pass leaves out a triangle the map stores (or
/// something nearer) at every texel along its longest edge (`map_holds` in
/// touched_list.wgsl); `may_be_held` says which the pass may have left out, with
/// twice its slack, and those are not checked for conservativeness.
struct Thin {
    all: Vec<[DVec3; 3]>,
    checked: Vec<bool>,
}

/// Whether the list pass may find `p` held by the map `depths` (layer 0, `side` a
/// side, drawn with slope bias `slope_bias`): `map_holds` with twice its slack.
fn may_be_held(p: &[DVec3; 3], depths: &[f32], side: usize, slope_bias: f64) -> bool {
    let texel = 2.0 / side as f64;
    let (u, w) = (p[1] - p[0], p[2] - p[0]);
    let det = u.x * w.y - u.y * w.x;
    if det.abs() < 1e-4 * texel * texel {
        return false;
    }
    let gradient = DVec2::new(u.z * w.y - w.z * u.y, u.x * w.z - w.x * u.z) / det * texel;
    let slack = 2.0 * (slope_bias.max(0.0) + 2.0) * (gradient.x.abs() + gradient.y.abs()) + 1e-5;
    let (a, b) = [(p[0], p[1]), (p[1], p[2]), (p[2], p[0])]
        .into_iter()
        .max_by(|e, f| (e.1 - e.0).truncate().length().total_cmp(&(f.1 - f.0).truncate().length()))
        .unwrap();
    let steps = ((b - a).truncate().length() / texel).ceil().max(1.0) as usize;
    (0..=steps).all(|i| {
        let q = a + (b - a) * (i as f64 / steps as f64);
        let x = (((q.x * 0.5 + 0.5) * side as f64).floor() as usize).min(side - 1);
        let y = (((0.5 - q.y * 0.5) * side as f64).floor() as usize).min(side - 1);
        depths[y * side + x] as f64 <= q.z + slack
    })
}

/// The casters' triangles in the map's NDC of `clip_from_world` (a map `side`
/// texels across), those the touched layer draws: thin (an inscribed circle of
/// radius under 0.75 texels, `THIN_INRADIUS_TEXELS`), not behind the light, and of a
/// closed mesh only those facing it.
fn projected(scene: &Scene, clip_from_world: Mat4, side: usize) -> Vec<[DVec3; 3]> {
    let texel = 2.0 / side as f64;
    let m = clip_from_world.as_dmat4();
    let project = |v: Vec3, m: &DMat4| *m * DVec4::new(v.x as f64, v.y as f64, v.z as f64, 1.0);
    CasterBvh::build(scene)
        .triangles
        .iter()
        .filter_map(|t| {
            let clip = [t.v0, t.v1, t.v2].map(|v| project(Vec3::from(v), &m));
            let p = clip.map(|c| c.truncate() / c.w);
            let area = (p[1] - p[0]).truncate().perp_dot((p[2] - p[0]).truncate());
            let turned_away = t.closed != 0 && area < 0.0;
            let perimeter: f64 = (0..3).map(|k| (p[(k + 1) % 3] - p[k]).truncate().length()).sum();
            let thin = area.abs() / perimeter < 0.75 * texel;
            (clip.iter().all(|c| c.w > 1e-6) && !turned_away && thin).then_some(p)
        })
        .collect()
}

/// The first texel where the layer's `nearness` (1 − depth, layer 0, `side` a
/// side) breaks its promise to the thin `triangles`: a texel a checked triangle
/// touches (its square shrunk by a thousandth of a texel, for rounding) holding a
/// depth farther than the triangle's nearest there, or a texel marked that no thin
/// triangle's square, grown by a thousandth, meets.
fn first_fault(nearness: &[f32], side: usize, triangles: &Thin) -> Option<String> {
    let texel = 2.0 / side as f64;
    let mut nearest = vec![f64::INFINITY; side * side];
    let mut near_any = vec![false; side * side];
    for (triangle, checked) in triangles.all.iter().zip(&triangles.checked) {
        let low = triangle.iter().map(|p| p.truncate()).reduce(DVec2::min).unwrap();
        let high = triangle.iter().map(|p| p.truncate()).reduce(DVec2::max).unwrap();
        let columns = ((low.x + 1.0) / texel - 1.0).max(0.0) as usize
            ..(((high.x + 1.0) / texel + 1.0) as usize).min(side);
        let rows = ((1.0 - high.y) / texel - 1.0).max(0.0) as usize
            ..(((1.0 - low.y) / texel + 1.0) as usize).min(side);
        for y in rows {
            for x in columns.clone() {
                if let Some(z) = nearest_over_texel(triangle, x, y, side, -1e-3).filter(|_| *checked) {
                    nearest[y * side + x] = nearest[y * side + x].min(z.clamp(0.0, 1.0));
                }
                near_any[y * side + x] |= nearest_over_texel(triangle, x, y, side, 1e-3).is_some();
            }
        }
    }
    (0..side * side).find_map(|i| {
        let depth = 1.0 - nearness[i] as f64;
        let (x, y) = (i % side, i / side);
        if nearest[i].is_finite() && depth > nearest[i] + 1e-5 {
            return Some(format!("texel ({x}, {y}): depth {depth}, a caster touches it at {}", nearest[i]));
        }
        (nearness[i] > 0.0 && !near_any[i])
            .then(|| format!("texel ({x}, {y}): marked touched at depth {depth}, no caster near it"))
    })
}

#[test]
fn the_touched_layer_holds_every_caster_that_touches_a_texel_and_no_other() {
    let gpu = gpu();
    for (scene, settings) in cases() {
        let mut renderer = Renderer::new(&gpu).unwrap();
        let request = OutputRequest { shadow_map: true, ..Default::default() };
        let frame = renderer.render(&scene, &settings, &request).unwrap();
        let map = frame.shadow_map.as_ref().expect("the shadow map, read back");
        let uploaded = renderer.upload(&scene).unwrap();
        let plan = pollster::block_on(renderer.plan_frame(&uploaded, &scene, &settings, None)).unwrap();
        let clip_from_world = plan.lights[0].light_gpu.cascade_clip_from_world[0];
        let (touched, layout) = renderer.map_cache.touched.kept(0).expect("the light keeps a touched layer");
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let mut pool = Pool::new(&gpu.device);
        let aspect = wgpu::TextureAspect::DepthOnly;
        let pending = readback::record_level(&mut pool, &mut encoder, &touched.texture, aspect, 0);
        gpu.queue.submit([encoder.finish()]);
        let nearness = pollster::block_on(pending.read::<f32>(&gpu)).expect("read back");
        let side = layout.resolution as usize;
        let all = projected(&scene, clip_from_world, side);
        let slope_bias = f64::from(plan.lights[0].light_gpu.bias.slope);
        let depths = &map.depth[..side * side];
        let checked: Vec<bool> = all.iter().map(|p| !may_be_held(p, depths, side, slope_bias)).collect();
        let count = checked.iter().filter(|&&c| c).count();
        assert!(count > 100, "{:?}: {count} of {} thin triangles checked", settings.light.kind, all.len());
        let triangles = Thin { all, checked };
        let kind = settings.light.kind;
        assert_eq!(first_fault(&nearness, side, &triangles), None, "{kind:?}");
        let marked = nearness.iter().filter(|&&n| n > 0.0).count();
        assert!(marked > 100 && marked < side * side / 4, "{kind:?}: {marked} texels marked");

        // The check sees a layer that lies: one that lost its casters, and one
        // with a caster invented where none is near.
        let lost = vec![0.0; nearness.len()];
        assert!(first_fault(&lost, side, &triangles).is_some(), "{kind:?}: lost casters go unseen");
        let untouched = nearness.iter().position(|&n| n == 0.0).expect("a texel no sliver touches");
        let mut invented = nearness.clone();
        invented[untouched] = 0.5;
        assert!(
            first_fault(&invented, side, &triangles).is_some(),
            "{kind:?}: an invented caster goes unseen"
        );
    }
}

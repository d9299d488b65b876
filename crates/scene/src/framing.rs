//! The default camera for a scene whose file has none: outside the model, framing
//! its bounds, or, for an interior (a courtyard, a room), inside it.
//!
//! Outside, the camera looks at the bounds' centre from 25° above the horizon and 30°
//! round from +z, as close as lets every vertex into the frame: the model itself then
//! reaches the frame's edge, where fitting its bounding sphere leaves an elongated
//! model a third of the frame, and fitting its bounding box leaves a round one (a
//! tree's crown, a sphere) well inside it.
//!
//! A scene is an interior when it is walled in: from points at a third of its height
//! around its centre, most horizontal rays meet, well away, a surface whose front
//! faces them (the inner walls of a courtyard or a room; not the back of a closed
//! model's own shell, not foliage around a tree's centre, not the facades of a city
//! street, nearer than a tenth of the way to the bounds' side). Its camera stands inside, at a third of the height, near one end of
//! the longest horizontal axis, looking down the length.

use glam::{Vec3, Vec3A};

use crate::{Camera, Scene, sun_direction};

/// Vertical field of view of an exterior view, in degrees.
const EXTERIOR_FOV_DEGREES: f32 = 45.0;
/// Vertical field of view of an interior view, in degrees: wider, as rooms are seen.
const INTERIOR_FOV_DEGREES: f32 = 60.0;
/// Share of the frame's half-height (and half-width) the bounds may fill: a margin.
const FILL: f32 = 0.95;
/// Horizontal rays cast from each probe point to decide whether the scene is an interior.
const PROBE_RAYS: usize = 16;
/// Probe points: offsets from the centre, as shares of the bounds' extent in x and z
/// (a 3 × 3 grid, so that one drape or column beside the centre decides nothing).
const PROBE_OFFSETS: [f32; 3] = [-0.2, 0.0, 0.2];
/// Share of all the probe rays that must meet an inward-facing surface far away.
const ENCLOSED_SHARE: f32 = 0.6;
/// "Far": at least this share of the distance to the bounds' side along the ray.
const WALL_DISTANCE: f32 = 0.1;
/// The aspect ratio (width / height) the exterior view frames for: the default image's.
const FRAME_ASPECT: f32 = 16.0 / 9.0;

/// The camera for `scene` when its file brings none: an interior view when the
/// bounds' centre is walled in, else an exterior view framing the bounds. Call it
/// once the scene's instances are placed.
pub fn default_camera(scene: &Scene) -> Camera {
    let triangles = world_triangles(scene);
    let probe = Probe::new(&triangles);
    if is_interior(scene, &probe) {
        interior_camera(scene, &probe)
    } else {
        exterior_camera(scene, &triangles)
    }
}

/// Every instance's triangles in world space (a flat list, in each mesh's index order).
fn world_triangles(scene: &Scene) -> Vec<[Vec3A; 3]> {
    let mut out = Vec::with_capacity(scene.triangle_count());
    for inst in &scene.instances {
        let mesh = &scene.meshes[inst.mesh];
        let world: Vec<Vec3A> =
            mesh.positions.iter().map(|p| inst.world_from_object.transform_point3(*p).into()).collect();
        out.extend(mesh.indices.chunks_exact(3).map(|t| [0, 1, 2].map(|k| world[t[k] as usize])));
    }
    out
}

/// Triangles in each run whose bounds a probe ray tests before the triangles
/// themselves. A mesh's index order keeps neighbours together, so most runs are small
/// and a ray skips nearly all of them: the few hundred probe rays cost Sponza's 279 K
/// triangles about 0.01 s instead of 0.8 s testing every triangle (perf, on this
/// project's 2-core machine), with no tree to build, which would cost more than these
/// rays save.
const PROBE_RUN: usize = 32;

/// The box round one run of [`PROBE_RUN`] triangles.
struct RunBounds {
    min: Vec3A,
    max: Vec3A,
}

/// The scene's triangles for the probe rays, with their runs' bounds.
struct Probe<'a> {
    triangles: &'a [[Vec3A; 3]],
    runs: Vec<RunBounds>,
}

impl<'a> Probe<'a> {
    fn new(triangles: &'a [[Vec3A; 3]]) -> Probe<'a> {
        let runs = triangles
            .chunks(PROBE_RUN)
            .map(|run| {
                let (min, max) =
                    run.iter().flatten().fold(
                        (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
                        |(lo, hi), &p| (lo.min(p), hi.max(p)),
                    );
                // A margin, so that a hit the triangle test accepts at the edge of its
                // tolerance is never lost to the box.
                let pad = Vec3A::splat(1e-4 * (max - min).max_element() + 1e-6);
                RunBounds { min: min - pad, max: max + pad }
            })
            .collect();
        Probe { triangles, runs }
    }

    /// The nearest triangle along a ray: (distance, whether its front face, by its
    /// counter-clockwise winding, faces the ray's origin).
    fn nearest_hit(&self, origin: Vec3A, direction: Vec3A) -> Option<(f32, bool)> {
        let inverse = direction.recip();
        let mut best: Option<(f32, bool)> = None;
        for (run, bounds) in self.triangles.chunks(PROBE_RUN).zip(&self.runs) {
            let within = best.map_or(f32::INFINITY, |(t, _)| t);
            if !ray_meets_box(bounds, origin, inverse, within) {
                continue;
            }
            if let Some(hit) = nearest_hit(run, origin, direction)
                && hit.0 < within
            {
                best = Some(hit);
            }
        }
        best
    }
}

/// Whether a ray from `origin` whose direction's reciprocal is `inverse` meets the box
/// before distance `within` (the slab test, Kay & Kajiya 1986). An axis the ray runs
/// parallel to at the box's very face gives NaN, which the comparisons let through:
/// a box wrongly kept costs a few triangle tests, one wrongly skipped a wall.
fn ray_meets_box(bounds: &RunBounds, origin: Vec3A, inverse: Vec3A, within: f32) -> bool {
    let (t0, t1) = ((bounds.min - origin) * inverse, (bounds.max - origin) * inverse);
    let (near, far) = (t0.min(t1).max_element(), t0.max(t1).min_element());
    let missed = near > far || far < 0.0 || near > within;
    !missed
}

/// The nearest of `triangles` along a ray, as [`Probe::nearest_hit`]: Möller–Trumbore,
/// both faces.
fn nearest_hit(triangles: &[[Vec3A; 3]], origin: Vec3A, direction: Vec3A) -> Option<(f32, bool)> {
    let mut best: Option<(f32, bool)> = None;
    for [a, b, c] in triangles {
        let (e1, e2) = (*b - *a, *c - *a);
        let p = direction.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            continue;
        }
        let s = origin - *a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = direction.dot(q) / det;
        let t = e2.dot(q) / det;
        if u < 0.0 || v < 0.0 || u + v > 1.0 || t <= 0.0 || best.is_some_and(|(bt, _)| bt <= t) {
            continue;
        }
        // The front face's normal is n = e1 × e2, and det = e1 · (d × e2) = −d · n: the
        // front faces the origin (the ray runs against n) when det > 0.
        best = Some((t, det > 0.0));
    }
    best
}

/// Whether the scene is walled in (see the module's documentation).
fn is_interior(scene: &Scene, probe: &Probe) -> bool {
    let bounds = scene.bounds();
    let (min, max, extent) = (Vec3A::from(bounds.min), Vec3A::from(bounds.max), Vec3A::from(bounds.extent()));
    let centre = Vec3A::from(bounds.center());
    let height = min.y + extent.y / 3.0;
    let mut walled = 0;
    for dx in PROBE_OFFSETS {
        for dz in PROBE_OFFSETS {
            let origin = Vec3A::new(centre.x + dx * extent.x, height, centre.z + dz * extent.z);
            walled += (0..PROBE_RAYS)
                .filter(|&k| {
                    let angle = std::f32::consts::TAU * k as f32 / PROBE_RAYS as f32;
                    let direction = Vec3A::new(angle.sin(), 0.0, angle.cos());
                    // The distance to the bounds' side along this direction.
                    let side = |d: f32, lo: f32, hi: f32, at: f32| {
                        if d > 0.0 {
                            (hi - at) / d
                        } else if d < 0.0 {
                            (lo - at) / d
                        } else {
                            f32::INFINITY
                        }
                    };
                    let reach = side(direction.x, min.x, max.x, origin.x).min(side(
                        direction.z,
                        min.z,
                        max.z,
                        origin.z,
                    ));
                    probe
                        .nearest_hit(origin, direction)
                        .is_some_and(|(t, facing)| facing && t >= WALL_DISTANCE * reach)
                })
                .count();
        }
    }
    let rays = PROBE_OFFSETS.len() * PROBE_OFFSETS.len() * PROBE_RAYS;
    walled as f32 >= ENCLOSED_SHARE * rays as f32
}

/// Looking at the bounds' centre from 25° up and 30° round, just far enough for
/// every vertex of `triangles` (the scene's, in world space) to lie in a frame of
/// [`FRAME_ASPECT`].
fn exterior_camera(scene: &Scene, triangles: &[[Vec3A; 3]]) -> Camera {
    let bounds = scene.bounds();
    let centre = bounds.center();
    let radius = bounds.bounding_radius().max(1e-3);
    let back = sun_direction(25.0, 30.0);
    let forward = -back;
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let tan_half = (0.5 * EXTERIOR_FOV_DEGREES.to_radians()).tan() * FILL;
    // A vertex q (from the centre) at eye distance d has view depth d + q·forward; it
    // is in the frame when |q·up| ≤ tan_half · depth and |q·right| ≤ aspect · tan_half · depth.
    let distance = triangles
        .iter()
        .flatten()
        .map(|&p| {
            let q = Vec3::from(p) - centre;
            q.dot(up).abs().max(q.dot(right).abs() / FRAME_ASPECT) / tan_half - q.dot(forward)
        })
        .fold(radius * 1e-3, f32::max);
    Camera {
        eye: centre + back * distance,
        target: centre,
        up: Vec3::Y,
        fov_y_degrees: EXTERIOR_FOV_DEGREES,
        near: (distance - radius).max(distance * 1e-3) * 0.5,
        far: distance + 2.0 * radius,
    }
}

/// Where an interior view may stand: shares of the half-length back from the
/// centre along the longest horizontal axis, and of the height above the floor.
const INTERIOR_EYE_ALONG: [f32; 3] = [0.6, 0.45, 0.3];
const INTERIOR_EYE_HEIGHT: [f32; 3] = [1.0 / 3.0, 0.2, 0.5];
/// Rays over an interior candidate's view (a grid over the central part of its
/// frame) that judge how open the view is.
const VIEW_RAYS: [f32; 3] = [-0.5, 0.0, 0.5];

/// Inside, near one end of the longest horizontal axis, looking down the length
/// and slightly down: of the candidate spots (both ends, a few distances and
/// heights), the one whose view runs freest, never one that sees a back face (a
/// spot inside a column or behind a wall).
fn interior_camera(scene: &Scene, probe: &Probe) -> Camera {
    let bounds = scene.bounds();
    let (centre, extent) = (bounds.center(), bounds.extent());
    let axis = if extent.x >= extent.z { Vec3::X } else { Vec3::Z };
    let half_length = 0.5 * extent.dot(axis);
    let tan_half = (0.5 * INTERIOR_FOV_DEGREES.to_radians()).tan();
    let mut best: Option<(f32, Vec3, Vec3)> = None;
    for side in [1.0f32, -1.0] {
        for along in INTERIOR_EYE_ALONG {
            for height in INTERIOR_EYE_HEIGHT {
                let floor_centre = Vec3::new(centre.x, bounds.min.y, centre.z);
                let eye = floor_centre + Vec3::Y * (height * extent.y) - side * along * half_length * axis;
                let target =
                    floor_centre + Vec3::Y * (0.75 * height * extent.y) + side * 0.5 * half_length * axis;
                let forward = (target - eye).normalize();
                let right = forward.cross(Vec3::Y).normalize();
                let up = right.cross(forward);
                // The median free distance over the view, or none if a ray meets a back face.
                let mut free = Vec::with_capacity(VIEW_RAYS.len() * VIEW_RAYS.len());
                for x in VIEW_RAYS {
                    for y in VIEW_RAYS {
                        let d = (forward + tan_half * (y * up + x * FRAME_ASPECT * right)).normalize();
                        match probe.nearest_hit(eye.into(), d.into()) {
                            Some((_, false)) => free.clear(),
                            Some((t, true)) => free.push(t),
                            None => free.push(2.0 * half_length),
                        }
                        if free.is_empty() {
                            break;
                        }
                    }
                    if free.is_empty() {
                        break;
                    }
                }
                if free.is_empty() {
                    continue;
                }
                free.sort_by(f32::total_cmp);
                let median = free[free.len() / 2];

                if best.is_none_or(|(m, ..)| median > m) {
                    best = Some((median, eye, target));
                }
            }
        }
    }
    let radius = bounds.bounding_radius().max(1e-3);
    // No spot sees only front faces: the probe was wrong, so frame the outside.
    let Some((_, eye, target)) = best else {
        return exterior_camera(scene, probe.triangles);
    };
    Camera {
        eye,
        target,
        up: Vec3::Y,
        fov_y_degrees: INTERIOR_FOV_DEGREES,
        near: radius * 1e-3,
        far: 2.5 * radius,
    }
}

#[cfg(test)]
mod tests {
    use glam::Mat4;

    use super::*;
    use crate::{DirectionalLight, Material, Mesh, geometry};

    fn scene_of(meshes: Vec<(Mesh, Mat4)>) -> Scene {
        let sun = DirectionalLight {
            direction: -Vec3::Y,
            color: Vec3::ONE,
            intensity: 1.0,
            angular_diameter_degrees: 0.0,
        };
        let camera = Camera {
            eye: Vec3::Z,
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_degrees: 45.0,
            near: 0.1,
            far: 10.0,
        };
        let mut scene = Scene::new("framing", camera, sun);
        for (i, (mesh, at)) in meshes.into_iter().enumerate() {
            scene.place(&format!("part {i}"), mesh, Material::new("grey", Vec3::splat(0.5)), at);
        }
        scene
    }

    /// Every vertex lies inside the frame, and the widest reaches near its edge.
    fn assert_frames_tightly(scene: &Scene, camera: &Camera) {
        let clip_from_world = camera.clip_from_world(FRAME_ASPECT);
        let reach = world_triangles(scene)
            .iter()
            .flatten()
            .map(|&p| {
                let clip = clip_from_world * Vec3::from(p).extend(1.0);
                assert!(clip.w > 0.0, "a vertex behind the camera");
                (clip.x / clip.w).abs().max((clip.y / clip.w).abs())
            })
            .fold(0.0f32, f32::max);
        assert!((0.9..=1.0).contains(&reach), "the model reaches {reach} of the half-frame");
    }

    #[test]
    fn an_exterior_view_frames_a_compact_and_an_elongated_model() {
        let cube = scene_of(vec![(geometry::cuboid(Vec3::ONE), Mat4::IDENTITY)]);
        let camera = default_camera(&cube);
        assert_eq!(camera.fov_y_degrees, EXTERIOR_FOV_DEGREES, "a closed box is not an interior");
        assert_frames_tightly(&cube, &camera);
        // The bounding sphere fills most of the frame height.
        let distance = camera.eye.distance(camera.target);
        let sphere_share = (cube.bounds().bounding_radius() / distance).asin() / (0.5 * 45f32.to_radians());
        assert!(sphere_share > 0.8, "{sphere_share}");

        let slab = scene_of(vec![(
            geometry::cuboid(Vec3::new(20.0, 0.5, 3.0)),
            Mat4::from_translation(Vec3::new(100.0, -4.0, 7.0)),
        )]);
        assert_frames_tightly(&slab, &default_camera(&slab));

        // A round model fills the frame too: fitting its bounding box's corners left a
        // sphere at about 0.6 of the half-frame.
        let ball =
            scene_of(vec![(geometry::uv_sphere(2.0, 48, 24), Mat4::from_translation(Vec3::splat(5.0)))]);
        assert_frames_tightly(&ball, &default_camera(&ball));
    }

    /// Four inward-facing walls and a floor: a courtyard, seen from inside; the same
    /// walls facing out (a closed block's shell) are not an interior.
    #[test]
    fn a_walled_courtyard_is_seen_from_inside() {
        let wall = |at: Vec3, turn: f32| {
            // The plane faces +y; a quarter turn about x makes it face +z, then `turn`
            // about y points it where the wall must face.
            let from_plane = Mat4::from_translation(at)
                * Mat4::from_rotation_y(turn)
                * Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2);
            (geometry::plane(40.0, 8.0), from_plane)
        };
        use std::f32::consts::{FRAC_PI_2, PI};
        let inward = vec![
            (geometry::plane(40.0, 40.0), Mat4::IDENTITY),
            wall(Vec3::new(0.0, 4.0, -20.0), 0.0),
            wall(Vec3::new(0.0, 4.0, 20.0), PI),
            wall(Vec3::new(-20.0, 4.0, 0.0), FRAC_PI_2),
            wall(Vec3::new(20.0, 4.0, 0.0), -FRAC_PI_2),
        ];
        let courtyard = scene_of(inward);
        let camera = default_camera(&courtyard);
        assert_eq!(camera.fov_y_degrees, INTERIOR_FOV_DEGREES);
        let b = courtyard.bounds();
        assert!(b.contains(camera.eye) && b.contains(camera.target), "{camera:?}");

        let outward = vec![
            wall(Vec3::new(0.0, 4.0, -20.0), PI),
            wall(Vec3::new(0.0, 4.0, 20.0), 0.0),
            wall(Vec3::new(-20.0, 4.0, 0.0), -FRAC_PI_2),
            wall(Vec3::new(20.0, 4.0, 0.0), FRAC_PI_2),
        ];
        assert_eq!(default_camera(&scene_of(outward)).fov_y_degrees, EXTERIOR_FOV_DEGREES);
    }

    /// The runs' boxes skip only triangles no ray meets first: from a grid of points,
    /// some on the floor's plane and on a wall's face, rays in every direction
    /// (horizontal ones among them, parallel to the floor) find the hit and the face
    /// that testing every triangle finds.
    #[test]
    fn the_probe_finds_what_testing_every_triangle_finds() {
        let scene = scene_of(vec![
            (geometry::plane(40.0, 40.0), Mat4::IDENTITY),
            (geometry::cuboid(Vec3::new(20.0, 4.0, 0.5)), Mat4::from_translation(Vec3::new(0.0, 4.0, -20.0))),
            (geometry::uv_sphere(3.0, 24, 12), Mat4::from_translation(Vec3::new(4.0, 3.0, 2.0))),
            (geometry::cylinder(1.0, 6.0, 16), Mat4::from_translation(Vec3::new(-6.0, 0.0, -5.0))),
        ]);
        let triangles = world_triangles(&scene);
        let probe = Probe::new(&triangles);
        assert!(probe.runs.len() > 10, "{} runs", probe.runs.len());
        let (mut rays, mut hits) = (0, 0);
        for x in [-15.0f32, -3.0, 0.0, 7.5] {
            for y in [0.0f32, 1.0, 3.0, 7.0] {
                for z in [-19.5f32, -8.0, 0.0, 12.0] {
                    // Directions spread over the sphere (a Fibonacci lattice), and the
                    // eight horizontal ones.
                    let lattice = (0..40).map(|k| {
                        let (h, turn) = (1.0 - 2.0 * (k as f32 + 0.5) / 40.0, 2.4 * k as f32);
                        let r = (1.0 - h * h).sqrt();
                        Vec3A::new(r * turn.cos(), h, r * turn.sin())
                    });
                    let level = (0..8).map(|k| {
                        let turn = std::f32::consts::FRAC_PI_4 * k as f32;
                        Vec3A::new(turn.cos(), 0.0, turn.sin())
                    });
                    let origin = Vec3A::new(x, y, z);
                    for direction in lattice.chain(level) {
                        let (found, truth) = (
                            probe.nearest_hit(origin, direction),
                            nearest_hit(&triangles, origin, direction),
                        );
                        assert_eq!(found, truth, "from {origin} along {direction}");
                        rays += 1;
                        hits += usize::from(truth.is_some());
                    }
                }
            }
        }
        assert!(hits > rays / 3 && hits < rays, "{hits} of {rays} rays hit");
    }
}

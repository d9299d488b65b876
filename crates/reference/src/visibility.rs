//! Reference visibility images: one primary ray through each pixel centre with the
//! rasterizer's camera, then shadow rays to the light: one exact ray for a point or
//! directional light, or N stratified samples of an area light.

use glam::{DVec2, DVec4, Vec2, Vec3};
use gnomon_scene::{Camera, Light};
use rayon::prelude::*;

use crate::{
    TracedScene,
    sampling::{cmj, concentric_disk, cone_direction, hash},
    tracer::{RayCone, Receiver, ball_cone, offset_ray_origin},
};

/// How the reference is computed.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceOptions {
    /// Image width in pixels; matches the rasterizer's frame.
    pub width: u32,
    /// Image height in pixels; matches the rasterizer's frame.
    pub height: u32,
    /// Shadow rays per pixel for an area light (ignored for point lights, which need one).
    pub samples: u32,
}

/// The reference, per pixel, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceImage {
    /// Image width in pixels; every per-pixel vector is `width × height` long.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel actually used: 1 for a point or directional light.
    pub samples: u32,
    /// Fraction of the light visible, in [0, 1]; NaN where the primary ray misses.
    /// 0 outside a spot light's cone or range, and where the surface faces away
    /// from the light, as in the rasterizer.
    pub visibility: Vec<f32>,
    /// Whether the surface faces the light (geometric N·L > 0 toward the light's
    /// centre) and lies inside its cone and range: the pixels whose visibility a
    /// shadow decides. False on a miss.
    pub faces_light: Vec<bool>,
    /// Standard error of each pixel's estimate (0 for exact visibility).
    pub std_error: Vec<f32>,
    /// Instance index + 1 of the primary hit; 0 on a miss.
    pub object_id: Vec<u32>,
    /// Triangle index within the hit instance's mesh.
    pub triangle: Vec<u32>,
    /// View-space depth of the primary hit; NaN on a miss.
    pub depth: Vec<f32>,
    /// World position of the primary hit; NaN on a miss.
    pub position: Vec<Vec3>,
    /// Rays traced in all: one primary ray per pixel plus every shadow ray.
    pub rays: u64,
}

impl ReferenceImage {
    /// Number of pixels, `width × height`.
    pub fn pixel_count(&self) -> usize {
        (self.width * self.height) as usize
    }
}

/// Batches of independent stratified patterns a pixel's samples are split into, so
/// that the spread of the batch means gives an honest standard error.
const BATCHES: u32 = 8;

/// The area of a light as the sampler sees it.
enum Emitter {
    /// Parallel rays toward `to_light`; with `half_angle` > 0, a cone of directions.
    Sun { to_light: Vec3, half_angle: f32 },
    /// A disk at `center` of `radius` facing along `axis`; 0 is a point.
    Disk { center: Vec3, axis: Vec3, radius: f32, cos_outer: f32, range: f32 },
    /// A sphere at `center` of `radius` emitting in every direction; 0 is a point.
    Sphere { center: Vec3, radius: f32, range: f32 },
}

impl Emitter {
    fn new(light: &Light) -> Self {
        match light {
            Light::Directional(sun) => Emitter::Sun {
                to_light: -sun.direction.normalize(),
                half_angle: 0.5 * sun.angular_diameter_degrees.to_radians(),
            },
            Light::Spot(spot) => Emitter::Disk {
                center: spot.position,
                axis: spot.direction.normalize(),
                radius: spot.radius,
                cos_outer: spot.outer_angle_degrees.to_radians().cos(),
                range: spot.range,
            },
            Light::Point(point) => {
                Emitter::Sphere { center: point.position, radius: point.radius, range: point.range }
            }
        }
    }

    fn is_point(&self) -> bool {
        match self {
            Emitter::Sun { half_angle, .. } => *half_angle <= 0.0,
            Emitter::Disk { radius, .. } | Emitter::Sphere { radius, .. } => *radius <= 0.0,
        }
    }

    /// Direction to the light's centre, and whether the point receives any light at
    /// all (inside a spot's cone and range).
    fn centre(&self, p: Vec3) -> (Vec3, bool) {
        match *self {
            Emitter::Sun { to_light, .. } => (to_light, true),
            Emitter::Disk { center, axis, cos_outer, range, .. } => {
                let to = center - p;
                let dist = to.length();
                let l = to / dist;
                (l, (-l).dot(axis) >= cos_outer && dist <= range)
            }
            Emitter::Sphere { center, range, .. } => {
                let to = center - p;
                let dist = to.length();
                (to / dist, dist <= range)
            }
        }
    }

    /// Whether light can reach `hit` at all: inside the light's cone and range, on the
    /// side of the surface (the camera-facing geometric normal) that faces the
    /// light's centre, as the rasterizer tests it.
    fn faces(&self, hit: &Hit) -> bool {
        let (centre, receives) = self.centre(hit.position);
        receives && hit.normal.dot(centre) > 0.0
    }

    /// The cone that holds every shadow ray [`Emitter::sample`] can give from `p`:
    /// (unit axis, half-angle, longest ray), each widened by a hair for rounding.
    /// None for a point light, and where `p` is so near the light that the cone
    /// would be too wide to be of use.
    fn bounding_cone(&self, p: Vec3) -> Option<(Vec3, f32, f32)> {
        match *self {
            Emitter::Sun { to_light, half_angle } => {
                (half_angle > 0.0).then_some((to_light, half_angle * (1.0 + 1e-4) + 1e-6, f32::INFINITY))
            }
            // A disk lies within the ball of its radius about its centre, whose
            // farthest point is the centre's distance plus the radius away.
            Emitter::Disk { center, radius, .. } => (radius > 0.0)
                .then(|| ball_cone(p, center, radius))
                .flatten()
                .map(|(axis, half_angle, distance)| (axis, half_angle, (distance + radius) * (1.0 + 1e-4))),
            // Rays end where they enter the sphere, nearer than its centre.
            Emitter::Sphere { center, radius, .. } => (radius > 0.0)
                .then(|| ball_cone(p, center, radius))
                .flatten()
                .map(|(axis, half_angle, distance)| (axis, half_angle, distance * (1.0 + 1e-4))),
        }
    }

    /// A shadow ray toward the light sample `u` from `p`: (direction, length).
    fn sample(&self, p: Vec3, u: Vec2) -> (Vec3, f32) {
        match *self {
            Emitter::Sun { to_light, half_angle } => {
                let d = if half_angle > 0.0 { cone_direction(u, to_light, half_angle) } else { to_light };
                (d, f32::INFINITY)
            }
            Emitter::Disk { center, axis, radius, .. } => {
                let target = if radius > 0.0 {
                    let (a, b) = axis.any_orthonormal_pair();
                    let q = concentric_disk(u) * radius;
                    center + a * q.x + b * q.y
                } else {
                    center
                };
                let to = target - p;
                let len = to.length();
                (to / len, len)
            }
            Emitter::Sphere { center, radius, .. } => {
                let to = center - p;
                let dist = to.length();
                let axis = to / dist;
                if radius <= 0.0 || radius >= dist {
                    return (axis, dist);
                }
                // Uniform over the cone the sphere subtends, which is uniform over its
                // visible area as the receiver sees it (a sphere of uniform radiance);
                // the ray ends where it enters the sphere.
                let d = cone_direction(u, axis, (radius / dist).asin());
                let along = d.dot(to);
                let entry = along - (radius * radius - (dist * dist - along * along)).max(0.0).sqrt();
                (d, entry.max(0.0))
            }
        }
    }
}

/// How an area light's samples are traced at a pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LightSampling {
    /// Every sample's ray, at every pixel: the definition, kept for the test that the
    /// shortcut changes nothing.
    #[cfg_attr(not(test), expect(dead_code, reason = "only the test that compares the two samples this way"))]
    EveryRay,
    /// None where the whole light is provably in sight (`wholly_in_sight`), every
    /// sample's ray elsewhere.
    SkipWhollyInSight,
}

/// Computes the reference visibility of `light` for `camera`, in parallel over rows.
/// `progress` is called with the number of rows finished so far (from any thread).
/// The result depends only on the inputs, not on the thread count or scheduling.
pub fn reference_visibility(
    traced: &TracedScene,
    camera: &Camera,
    light: &Light,
    options: &ReferenceOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> ReferenceImage {
    trace_reference(traced, camera, light, options, progress, LightSampling::SkipWhollyInSight)
}

fn trace_reference(
    traced: &TracedScene,
    camera: &Camera,
    light: &Light,
    options: &ReferenceOptions,
    progress: &(dyn Fn(u64) + Sync),
    sampling: LightSampling,
) -> ReferenceImage {
    let (w, h) = (options.width, options.height);
    let aspect = w as f32 / h as f32;
    // The inverse, in f64, of the very f32 matrix the rasterizer projects with. An f32
    // inverse of a perspective matrix bent the rays by up to 1/25 px at the edges of a
    // 1280-pixel image (Sponza's far-to-near ratio), which flipped the shadow of a pixel
    // whose edge passed that close to its centre.
    let world_from_clip = camera.clip_from_world(aspect).as_dmat4().inverse();
    let view_from_world = camera.view_from_world();
    let emitter = Emitter::new(light);
    let samples = if emitter.is_point() { 1 } else { options.samples.max(BATCHES) };
    let done = std::sync::atomic::AtomicU64::new(0);

    let rows: Vec<Vec<PixelResult>> = (0..h)
        .into_par_iter()
        .map(|y| {
            let row = (0..w)
                .map(|x| {
                    // The same pixel centre and camera as the rasterizer: NDC y up, row 0 at the top.
                    let ndc = DVec2::new(
                        (f64::from(x) + 0.5) / f64::from(w) * 2.0 - 1.0,
                        1.0 - (f64::from(y) + 0.5) / f64::from(h) * 2.0,
                    );
                    let near = world_from_clip * DVec4::new(ndc.x, ndc.y, 0.0, 1.0);
                    let far = world_from_clip * DVec4::new(ndc.x, ndc.y, 1.0, 1.0);
                    let (near, far) = (near.truncate() / near.w, far.truncate() / far.w);
                    let dir = (far - near).normalize().as_vec3();
                    // Start on the near plane and stop at the far one, as the rasterizer clips.
                    let length = (far - near).length() as f32;
                    let Some(hit) = traced.intersect(near.as_vec3(), dir, 0.0, length) else {
                        return PixelResult::MISS;
                    };
                    let pixel_seed = hash(y * w + x);
                    let faces_light = emitter.faces(&hit);
                    let (visibility, std_error, shadow_rays) = if faces_light {
                        shade(traced, &emitter, &hit, samples, pixel_seed, sampling)
                    } else {
                        // Outside a spot's cone, or on a surface turned away from the
                        // light, nothing arrives.
                        (0.0, 0.0, 0)
                    };
                    PixelResult {
                        rays: 1 + shadow_rays,
                        visibility,
                        faces_light,
                        std_error,
                        object_id: hit.object_id,
                        triangle: hit.triangle,
                        depth: -view_from_world.transform_point3(hit.position).z,
                        position: hit.position,
                    }
                })
                .collect();
            let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(n);
            row
        })
        .collect();

    let n = (w * h) as usize;
    let mut image = ReferenceImage {
        width: w,
        height: h,
        samples,
        visibility: Vec::with_capacity(n),
        faces_light: Vec::with_capacity(n),
        std_error: Vec::with_capacity(n),
        object_id: Vec::with_capacity(n),
        triangle: Vec::with_capacity(n),
        depth: Vec::with_capacity(n),
        position: Vec::with_capacity(n),
        rays: 0,
    };
    for p in rows.into_iter().flatten() {
        image.rays += p.rays;
        image.visibility.push(p.visibility);
        image.faces_light.push(p.faces_light);
        image.std_error.push(p.std_error);
        image.object_id.push(p.object_id);
        image.triangle.push(p.triangle);
        image.depth.push(p.depth);
        image.position.push(p.position);
    }
    image
}

struct PixelResult {
    rays: u64,
    visibility: f32,
    faces_light: bool,
    std_error: f32,
    object_id: u32,
    triangle: u32,
    depth: f32,
    position: Vec3,
}

impl PixelResult {
    const MISS: PixelResult = PixelResult {
        rays: 1,
        visibility: f32::NAN,
        faces_light: false,
        std_error: 0.0,
        object_id: 0,
        triangle: 0,
        depth: f32::NAN,
        position: Vec3::NAN,
    };
}

/// Visibility of the light at `hit` (which [faces](Emitter::faces) it), the standard
/// error of the estimate, and the number of shadow rays traced.
fn shade(
    traced: &TracedScene,
    emitter: &Emitter,
    hit: &Hit,
    samples: u32,
    seed: u32,
    sampling: LightSampling,
) -> (f32, f32, u64) {
    let origin = offset_ray_origin(hit.position, hit.normal);
    let rays = std::cell::Cell::new(0u64);
    let visible = |u: Vec2| {
        let (d, len) = emitter.sample(hit.position, u);
        // Light samples below the surface's horizon are blocked by the surface itself.
        if d.dot(hit.normal) <= 0.0 {
            return false;
        }
        rays.set(rays.get() + 1);
        !traced.occluded(origin, d, len)
    };
    if samples == 1 {
        let v = if visible(Vec2::splat(0.5)) { 1.0 } else { 0.0 };
        return (v, 0.0, rays.get());
    }
    if sampling == LightSampling::SkipWhollyInSight && wholly_in_sight(traced, emitter, hit, origin) {
        return (1.0, 0.0, 0);
    }
    // Split the samples into independent stratified batches; the spread of the batch
    // means estimates the standard error of their average.
    let per_batch = samples / BATCHES;
    let means: Vec<f32> = (0..BATCHES)
        .map(|b| {
            let pattern = hash(seed ^ hash(b + 1));
            (0..per_batch).filter(|&s| visible(cmj(s, per_batch, pattern))).count() as f32 / per_batch as f32
        })
        .collect();
    let mean = means.iter().sum::<f32>() / BATCHES as f32;
    let variance = means.iter().map(|m| (m - mean).powi(2)).sum::<f32>() / (BATCHES - 1) as f32;
    (mean, (variance / BATCHES as f32).sqrt(), rays.get())
}

use crate::Hit;

/// Whether every shadow ray the sampler could send from `hit` (leaving from `origin`)
/// arrives: the whole light lies above the surface's horizon, and nothing that could
/// block a ray lies in the cone that holds them all (`TracedScene::cone_is_clear`).
/// Then the estimate is exactly 1 with no spread, as tracing each sample would have
/// found, and no ray is traced: most of a soft-shadow reference's pixels are wholly
/// lit, and each cost `samples` rays before.
fn wholly_in_sight(traced: &TracedScene, emitter: &Emitter, hit: &Hit, origin: Vec3) -> bool {
    let Some((axis, half_angle, length)) = emitter.bounding_cone(hit.position) else {
        return false;
    };
    // Every direction within `half_angle` of `axis` climbs away from the surface.
    if axis.dot(hit.normal) <= half_angle.sin() + 1e-4 {
        return false;
    }
    let cone = RayCone { apex: origin, axis, half_angle, length };
    traced.cone_is_clear(&cone, &Receiver { point: hit.position, normal: hit.normal })
}

#[cfg(test)]
mod tests {
    use super::*;
    use gnomon_scene::{Settings, builtin, settings::LightKind};

    /// The shortcut for pixels that see the whole light changes no pixel of the
    /// reference, bit for bit, under each kind of area light (a sun's disk, a spot's
    /// disk, a point's sphere), over grounds, walls and curved casters; and it does
    /// skip: most rays of these wholly lit grounds are not traced.
    #[test]
    fn skipping_wholly_lit_pixels_changes_no_pixel() {
        let mut sun = Settings::default();
        sun.light.sun_angular_diameter = Some(2.0);
        let mut spot = Settings::default();
        spot.light.kind = LightKind::Spot;
        spot.light.spot_radius = Some(0.5);
        let mut point = Settings::default();
        point.light.kind = LightKind::Point;
        point.light.point_radius = Some(0.25);
        let cases = [
            ("sun 2°, grazing", builtin::grazing(), sun),
            ("spot r 0.5, contact", builtin::contact(), spot.clone()),
            ("spot r 0.5, spheres", builtin::spheres(), spot),
            ("point r 0.25, spheres", builtin::spheres(), point),
        ];
        for (name, scene, s) in cases {
            let traced = TracedScene::build(&scene);
            let camera = s.resolve_camera(&scene).unwrap();
            let light = s.resolve_light(&scene).unwrap();
            let options = ReferenceOptions { width: 160, height: 90, samples: 64 };
            let every = trace_reference(&traced, &camera, &light, &options, &|_| {}, LightSampling::EveryRay);
            let skipping = trace_reference(
                &traced,
                &camera,
                &light,
                &options,
                &|_| {},
                LightSampling::SkipWhollyInSight,
            );
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&every.visibility), bits(&skipping.visibility), "{name}: visibility");
            assert_eq!(bits(&every.std_error), bits(&skipping.std_error), "{name}: standard error");
            let (soft, lit) =
                every.visibility.iter().zip(&every.faces_light).filter(|(_, faces)| **faces).fold(
                    (0, 0),
                    |(soft, lit), (v, _)| {
                        (soft + (*v > 0.0 && *v < 1.0) as usize, lit + (*v == 1.0) as usize)
                    },
                );
            assert!(soft > 50 && lit > 1000, "{name}: a case with penumbrae and lit ground ({soft}, {lit})");
            // The rays of wholly lit pixels, which the shortcut is for: it must save
            // most of them (it cannot save all: a lit pixel near a caster fails the
            // conservative test and is sampled).
            let saved = every.rays - skipping.rays;
            let lit_rays = lit as u64 * u64::from(every.samples);
            eprintln!(
                "{name}: {soft} soft and {lit} wholly lit pixels; {saved} of their {lit_rays} rays skipped"
            );
            assert!(
                2 * saved > lit_rays,
                "{name}: the shortcut skipped {saved} of the wholly lit pixels' {lit_rays} rays"
            );
        }
    }
}

//! Reference visibility images: one primary ray through each pixel centre with the
//! rasterizer's camera, then shadow rays to the light: one exact ray for a point or
//! directional light, or N stratified samples of an area light.

use glam::{DVec2, DVec4, Vec3};
use gnomon_scene::{
    Camera, Light, Scene,
    memory::{self, Charge},
};
use rayon::prelude::*;

use crate::{
    TracedScene,
    emitter::Emitter,
    sampling::hash,
    shade::{BATCHES, LightSampling, shade},
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

/// Refuses a reference of `scene` with `options` that would take more memory than
/// `budget` ([`memory::frame_budget`] for a command): the scene as the tracer holds
/// it and every pixel's result, before any of it is allocated.
pub fn check_memory(
    scene: &Scene,
    options: &ReferenceOptions,
    budget: &memory::FrameBudget,
) -> Result<(), memory::OverBudget> {
    let (width, height) = (options.width, options.height);
    let mut charges = memory::scene_charges(scene);
    charges.push(Charge {
        what: format!("the reference's pixels, {width}×{height}"),
        bytes: memory::pixels(width, height).saturating_mul(memory::BYTES_PER_REFERENCE_PIXEL),
    });
    memory::refuse_over(&charges, budget)
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

#[cfg(test)]
#[test]
fn the_declared_cost_of_a_pixel_covers_what_a_reference_holds() {
    use std::mem::size_of;
    // `ReferenceImage`'s per-pixel vectors, field by field (a new one belongs here).
    let image = size_of::<f32>() * 3 + size_of::<bool>() + size_of::<u32>() * 2 + size_of::<Vec3>();
    let held = (image + size_of::<PixelResult>()) as u64;
    assert!(memory::BYTES_PER_REFERENCE_PIXEL >= held, "a pixel holds {held} bytes");
    assert!(memory::BYTES_PER_REFERENCE_PIXEL < 2 * held, "a pixel holds only {held} bytes");
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

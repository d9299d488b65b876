//! The penumbra classification's depth pyramid and the penumbra history, read back
//! from frames of the built-in scenes under lights with an area: every square of
//! every level bounds the map texels it covers (its range exactly, its plane less
//! its residual from below), so that the classification's "no caster here" is never
//! said of a square that holds one; and the history follows on from the last frame
//! only where nothing it depends on moved.

use gnomon_scene::{Scene, Settings, builtin, settings::LightKind};

use super::Renderer;
use crate::{Gpu, OutputRequest, ShadowMapImage, pool::Pool, rays::PyramidLayout, readback};

fn gpu() -> Gpu {
    Gpu::new_headless().expect("a GPU adapter (install mesa-vulkan-drivers for lavapipe)")
}

/// One frame's settings under a light with an area: `contact` under a spot of radius
/// 0.5, `spheres` under a point light of radius 0.3 (a cube), `grazing` under a 2°
/// sun (on a map 1022 texels a side); small images, one frame a render.
fn cases() -> Vec<(Scene, Settings)> {
    let small = |kind| {
        let mut s = Settings::default();
        (s.image.width, s.image.height) = (160, 90);
        s.light.kind = kind;
        s.screen.penumbra_frames = 1;
        s
    };
    let mut spot = small(LightKind::Spot);
    spot.light.spot_radius = Some(0.5);
    let mut point = small(LightKind::Point);
    point.light.point_radius = Some(0.3);
    point.shadow.map.resolution = 512;
    let mut sun = small(LightKind::Sun);
    sun.light.sun_angular_diameter = Some(2.0);
    // Not a multiple of a first-level square's 4 texels: the squares along the map's
    // far edges are partial (depth_pyramid.wgsl's gathers reach past it).
    sun.shadow.map.resolution = 1022;
    vec![(builtin::contact(), spot), (builtin::spheres(), point), (builtin::grazing(), sun)]
}

/// A pyramid read back: each level's planes (a square's depth at its centre, per map
/// texel along x and y, least residual) and ranges, layer after layer.
struct ReadPyramid {
    layout: PyramidLayout,
    planes: Vec<Vec<[f32; 4]>>,
    ranges: Vec<Vec<[f32; 2]>>,
}

impl ReadPyramid {
    fn read(gpu: &Gpu, renderer: &Renderer, light: usize) -> ReadPyramid {
        let (pyramid, layout) = renderer.map_cache.pyramids.kept(light).expect("the light keeps a pyramid");
        let level = |texture: &wgpu::Texture, level: u32| {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let mut pool = Pool::new(&gpu.device);
            let pending =
                readback::record_level(&mut pool, &mut encoder, texture, wgpu::TextureAspect::All, level);
            gpu.queue.submit([encoder.finish()]);
            pollster::block_on(pending.read::<f32>(gpu)).expect("read back")
        };
        let planes = (0..layout.levels)
            .map(|l| level(&pyramid.planes, l).chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect())
            .collect();
        let ranges = (0..layout.levels)
            .map(|l| level(&pyramid.ranges, l).chunks_exact(2).map(|c| [c[0], c[1]]).collect())
            .collect();
        ReadPyramid { layout, planes, ranges }
    }
}

/// The depths a pyramid holds of `map`: its own, or for a cube face (`cube`: the
/// light's range and the map's near plane) its distance over range made 1 − near /
/// z, z along the face's axis (depth_pyramid.wgsl).
fn pyramid_depths(map: &ShadowMapImage, cube: Option<(f32, f32)>) -> Vec<f32> {
    let n = map.resolution as usize;
    map.depth
        .iter()
        .enumerate()
        .map(|(i, &d)| match cube {
            None => d,
            Some((range, near)) => {
                let (x, y) = ((i % (n * n)) % n, (i % (n * n)) / n);
                let u = (x as f32 + 0.5) / n as f32 * 2.0 - 1.0;
                let v = 1.0 - (y as f32 + 0.5) / n as f32 * 2.0;
                let z = d * range / (1.0 + u * u + v * v).sqrt();
                1.0 - near / z
            }
        })
        .collect()
}

/// A map's depths as its pyramid holds them, and which texels a caster covers.
struct MapDepths {
    depths: Vec<f32>,
    covered: Vec<bool>,
}

impl MapDepths {
    fn of(map: &ShadowMapImage, cube: Option<(f32, f32)>) -> MapDepths {
        let covered = map.depth.iter().map(|&d| d < crate::passes::shadow::MAP_CLEARED_DEPTH).collect();
        MapDepths { depths: pyramid_depths(map, cube), covered }
    }
}

/// Rounding the GPU's arithmetic may differ from the CPU's by, in depth units.
const ROUNDING: f32 = 2e-6;

/// The first square of `pyramid` that does not bound the texels of `depths` (of maps
/// `resolution` a side) it covers: its range not their least and greatest (within
/// `slack`: exactly where the pyramid holds the map's own depths, a cube's made on
/// the GPU round otherwise), or its plane less its residual above one of them that a
/// caster covers (`covered`; the planes leave the others out). None where every
/// square does.
fn first_fault(pyramid: &ReadPyramid, map: &MapDepths, resolution: u32, slack: f32) -> Option<String> {
    let MapDepths { depths, covered } = map;
    let (n, side) = (resolution as usize, pyramid.layout.side as usize);
    for level in 0..pyramid.layout.levels as usize {
        let (span, width) = (4usize << level, (side >> level).max(1));
        for layer in 0..pyramid.layout.layers as usize {
            for (k, (plane, range)) in pyramid.planes[level]
                .iter()
                .zip(&pyramid.ranges[level])
                .skip(layer * width * width)
                .take(width * width)
                .enumerate()
            {
                let (i, j) = (k % width, k / width);
                let centre = [
                    (i * span) as f32 + (span as f32 - 1.0) / 2.0,
                    (j * span) as f32 + (span as f32 - 1.0) / 2.0,
                ];
                let (mut least, mut greatest) = (f32::INFINITY, f32::NEG_INFINITY);
                for y in (j * span).min(n)..((j + 1) * span).min(n) {
                    for x in (i * span).min(n)..((i + 1) * span).min(n) {
                        let d = depths[layer * n * n + y * n + x];
                        (least, greatest) = (least.min(d), greatest.max(d));
                        if !covered[layer * n * n + y * n + x] {
                            continue;
                        }
                        let below = plane[0]
                            + plane[1] * (x as f32 - centre[0])
                            + plane[2] * (y as f32 - centre[1])
                            + plane[3];
                        if below > d + ROUNDING * (1.0 + plane[1].abs() + plane[2].abs()) * span as f32 {
                            return Some(format!(
                                "level {level} layer {layer} square ({i}, {j}): plane less residual {below} above texel ({x}, {y})'s {d}"
                            ));
                        }
                    }
                }
                let exact = if least > greatest {
                    range[0] > range[1]
                } else {
                    (range[0] - least).abs() <= slack && (range[1] - greatest).abs() <= slack
                };
                if !exact {
                    return Some(format!(
                        "level {level} layer {layer} square ({i}, {j}): range {range:?}, its texels {least}..{greatest}"
                    ));
                }
            }
        }
    }
    None
}

/// The classification clears a square where its plane, lowered by its residual,
/// lies behind the receiver's plane everywhere over it (`weigh_square`'s first rule),
/// mirrored here: the receiver's plane of depth `depth` at map position `at`, changing
/// by `gradient` per texel.
fn clears_by_plane(
    plane: [f32; 4],
    centre: [f32; 2],
    half: f32,
    receiver: ([f32; 2], f32, [f32; 2]),
    tolerance: f32,
) -> bool {
    let (at, depth, gradient) = receiver;
    let receiver_at_centre = depth + gradient[0] * (centre[0] - at[0]) + gradient[1] * (centre[1] - at[1]);
    let tilt = (plane[1] - gradient[0]).abs() + (plane[2] - gradient[1]).abs();
    plane[3] + plane[0] - receiver_at_centre - tilt * half >= -tolerance
}

/// A first-level square of layer 0 whose texels a caster covers, every one, holding
/// more than one depth: its index.
fn covered_square(pyramid: &ReadPyramid, depths: &MapDepths, resolution: u32) -> usize {
    let (n, width) = (resolution as usize, pyramid.layout.side as usize);
    (0..width * width)
        .find(|k| {
            let (i, j) = (k % width, k / width);
            (0..16).all(|t| {
                let (x, y) = (4 * i + t % 4, 4 * j + t / 4);
                x < n && y < n && depths.covered[y * n + x]
            }) && pyramid.ranges[0][*k][0] < pyramid.ranges[0][*k][1]
        })
        .expect("a square a caster covers")
}

#[test]
fn every_square_of_the_pyramid_bounds_the_texels_it_covers() {
    let gpu = gpu();
    for (scene, settings) in cases() {
        let mut renderer = Renderer::new(&gpu).unwrap();
        let request = OutputRequest { shadow_map: true, ..Default::default() };
        let frame = renderer.render(&scene, &settings, &request).unwrap();
        let map = frame.shadow_map.as_ref().expect("the shadow map, read back");
        let uploaded = renderer.upload(&scene).unwrap();
        let plan = pollster::block_on(renderer.plan_frame(&uploaded, &scene, &settings, None)).unwrap();
        let light = &plan.lights[0].light_gpu;
        let cube = (settings.light.kind == LightKind::Point).then_some((light.emitter.range, light.map.near));
        let depths = MapDepths::of(map, cube);
        let pyramid = ReadPyramid::read(&gpu, &renderer, 0);
        assert_eq!(pyramid.layout.layers, map.layers, "{}", scene.name);
        let slack = if cube.is_some() { ROUNDING } else { 0.0 };
        assert_eq!(first_fault(&pyramid, &depths, map.resolution, slack), None, "{}", scene.name);

        // The check sees a square that lies: a least depth raised past its least
        // texel, and a residual raised past its lowest texel.
        let occupied = covered_square(&pyramid, &depths, map.resolution);
        let mut raised = ReadPyramid {
            layout: pyramid.layout,
            planes: pyramid.planes.clone(),
            ranges: pyramid.ranges.clone(),
        };
        raised.ranges[0][occupied][0] += 1e-4;
        assert!(
            first_fault(&raised, &depths, map.resolution, slack).is_some(),
            "{}: a raised least depth passed",
            scene.name
        );
        let mut raised = ReadPyramid {
            layout: pyramid.layout,
            planes: pyramid.planes.clone(),
            ranges: pyramid.ranges.clone(),
        };
        raised.planes[0][occupied][3] += 1e-4;
        assert!(
            first_fault(&raised, &depths, map.resolution, slack).is_some(),
            "{}: a raised residual passed",
            scene.name
        );

        // So a square the plane rule clears holds no texel in front of the receiver's
        // plane: tried for planes through every first- and second-level square's
        // texels, tilted as the map's own surfaces are and beyond.
        let n = map.resolution as usize;
        let mut cleared = 0;
        for level in 0..2usize {
            let (span, width) = (4usize << level, (pyramid.layout.side as usize >> level).max(1));
            for (k, plane) in pyramid.planes[level].iter().take(width * width).enumerate().step_by(7) {
                let (i, j) = (k % width, k / width);
                if i * span >= n || j * span >= n {
                    continue;
                }
                let centre = [
                    (i * span) as f32 + (span as f32 - 1.0) / 2.0,
                    (j * span) as f32 + (span as f32 - 1.0) / 2.0,
                ];
                for (tilt, lift) in
                    [([0.0, 0.0], 0.0), ([plane[1], plane[2]], 1e-5), ([2.0 * plane[1], -plane[2]], -1e-5)]
                {
                    let at = [centre[0] + 3.0, centre[1] - 2.0];
                    let depth = plane[0] + plane[1] * 3.0 - plane[2] * 2.0 + lift;
                    let tolerance = 0.5 * (tilt[0].abs() + tilt[1].abs());
                    if !clears_by_plane(*plane, centre, span as f32 / 2.0, (at, depth, tilt), tolerance) {
                        continue;
                    }
                    cleared += 1;
                    for y in j * span..((j + 1) * span).min(n) {
                        for x in i * span..((i + 1) * span).min(n) {
                            let receiver =
                                depth + tilt[0] * (x as f32 - at[0]) + tilt[1] * (y as f32 - at[1]);
                            // A texel no caster covers hides nothing.
                            if !depths.covered[y * n + x] {
                                continue;
                            }
                            let d = depths.depths[y * n + x];
                            assert!(
                                d >= receiver - tolerance - ROUNDING,
                                "{}: level {level} square ({i}, {j}) cleared, but texel ({x}, {y}) at {d} lies in front of the plane's {receiver}",
                                scene.name
                            );
                        }
                    }
                }
            }
        }
        assert!(cleared > 50, "{}: only {cleared} squares cleared to check", scene.name);
    }
}

/// Frames of `contact` under a spot of radius 0.5, each one submission.
fn spot_on_contact() -> (Scene, Settings) {
    let (scene, settings) = cases().swap_remove(0);
    (scene, settings)
}

/// Frames the light's penumbra history held.
fn held(frame: &crate::Frame) -> Option<u32> {
    frame.lights[0].penumbra_frames
}

#[test]
fn the_penumbra_history_follows_on_only_where_nothing_it_depends_on_moved() {
    let gpu = gpu();
    let (mut scene, settings) = spot_on_contact();
    let mut renderer = Renderer::new(&gpu).unwrap();
    let mut uploaded = renderer.upload(&scene).unwrap();
    let render = |renderer: &mut Renderer, uploaded: &crate::GpuScene, scene: &Scene, s: &Settings| {
        renderer.render_uploaded(uploaded, scene, s, &OutputRequest::default()).unwrap()
    };
    let frames: Vec<Option<u32>> =
        (0..3).map(|_| held(&render(&mut renderer, &uploaded, &scene, &settings))).collect();
    assert_eq!(frames, [Some(1), Some(2), Some(3)], "a still view gathers");

    // The light moves: the frame starts afresh, and is the very frame a renderer that
    // never saw the light where it was draws.
    let mut moved = settings.clone();
    moved.light.spot_target = Some(glam::Vec3::new(0.5, 0.0, 0.3));
    let after = render(&mut renderer, &uploaded, &scene, &moved);
    assert_eq!(held(&after), Some(1), "the history outlived the light's move");
    let fresh = Renderer::new(&gpu).unwrap().render(&scene, &moved, &OutputRequest::default()).unwrap();
    let differ =
        after.visibility.iter().zip(&fresh.visibility).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
    assert_eq!(differ, 0, "{differ} pixels differ from a first frame under the moved light");
    assert_eq!(held(&render(&mut renderer, &uploaded, &scene, &moved)), Some(2));

    // The camera moves, a caster moves, a host forgets it: each starts afresh.
    let mut turned = moved.clone();
    turned.camera.eye = Some(scene.camera.eye + glam::Vec3::new(0.05, 0.0, 0.0));
    assert_eq!(held(&render(&mut renderer, &uploaded, &scene, &turned)), Some(1), "after the camera moved");
    assert_eq!(held(&render(&mut renderer, &uploaded, &scene, &turned)), Some(2));
    let caster = scene.instances.len() - 1;
    scene.instances[caster].world_from_object =
        glam::Mat4::from_translation(glam::Vec3::X * 0.01) * scene.instances[caster].world_from_object;
    renderer.move_instances(&mut uploaded, &scene, &[caster]).unwrap();
    assert_eq!(held(&render(&mut renderer, &uploaded, &scene, &turned)), Some(1), "after a caster moved");
    renderer.forget_penumbra_history();
    assert_eq!(held(&render(&mut renderer, &uploaded, &scene, &turned)), Some(1), "after it was forgotten");

    // A still image gathers as many frames as the settings ask.
    let mut still = turned.clone();
    still.screen.penumbra_frames = 6;
    assert_eq!(held(&render(&mut renderer, &uploaded, &scene, &still)), Some(6));
}

/// A still view stops beaming once its unsure pixels hold the beams
/// `screen.penumbra_frames` gives them: the next frame traces nothing and shows the
/// same image; asking for more frames goes on beaming from what it holds.
#[test]
fn a_settled_still_view_beams_no_more_until_asked_for_more() {
    let gpu = gpu();
    let (scene, mut settings) = spot_on_contact();
    settings.screen.penumbra_frames = 4;
    let mut renderer = Renderer::new(&gpu).unwrap();
    let uploaded = renderer.upload(&scene).unwrap();
    let mut render =
        |s: &Settings| renderer.render_uploaded(&uploaded, &scene, s, &OutputRequest::default()).unwrap();
    let gathered = render(&settings);
    assert_eq!(held(&gathered), Some(4));
    let traced =
        |frame: &crate::Frame| frame.lights[0].traced_pixels.expect("a waited frame counts its beams");
    assert!(traced(&gathered) > 0, "the fourth frame beamed nothing");

    let settled = render(&settings);
    assert_eq!(held(&settled), Some(5), "the history outlived a still view");
    assert_eq!(traced(&settled), 0, "a settled still view went on beaming");
    assert_eq!(
        settled.lights[0].unsure_pixels, gathered.lights[0].unsure_pixels,
        "its history forgot pixels"
    );
    let differ = settled
        .visibility
        .iter()
        .zip(&gathered.visibility)
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(differ, 0, "{differ} pixels of a settled view changed with no beam");

    // Eight frames' worth: the phase the eighth frame beams gets its second beam.
    settings.screen.penumbra_frames = 8;
    let more = render(&settings);
    assert_eq!(held(&more), Some(8), "asking for more frames threw the history away");
    assert!(traced(&more) > 0, "asking for more frames beamed nothing more");
}

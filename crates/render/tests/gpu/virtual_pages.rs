//! Virtual shadow maps' page requests on the GPU (`virtual_map/page_requests.wgsl`)
//! against the clipmap's own arithmetic (`gnomon_math::virtual_map`): the pass must
//! ask for exactly the pages that `Clipmap::request` names for every pixel, under a
//! sun and under a spot.

use std::collections::BTreeSet;

use glam::{Vec2, Vec3, Vec4};
use gnomon_math::{
    Aabb,
    virtual_map::{Clipmap, ClipmapShape, ConeReach, PageKey},
};
use gnomon_render::virtual_map::{AreaSearch, PageRequests, PixelReach};

use crate::support::gpu;

/// A small deterministic generator (an LCG), the same on every platform.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Whether `x`, in units of a grid step, lies within `margin` of a grid line, where
/// the GPU's rounding and the CPU's may fall on different sides.
fn near_grid(x: f32, margin: f32) -> bool {
    let f = x - x.floor();
    f < margin || f > 1.0 - margin
}

#[test]
fn the_gpu_asks_for_exactly_the_pages_the_clipmap_names() {
    // Unreal's levels, and levels of 1024² read at texels 8× finer than the pixels,
    // whose windows leave many of the points to coarser levels
    // (`Clipmap::level_for_point`).
    let asked = asks_for_exactly_the_pages_the_clipmap_names(sun(ClipmapShape::DEFAULT, 1.0), Searches::NONE);
    assert_eq!(asked.fell_back, 0);
    let small = ClipmapShape { virtual_resolution: 1024, ..ClipmapShape::DEFAULT };
    let fell_back = asks_for_exactly_the_pages_the_clipmap_names(sun(small, 0.125), Searches::NONE).fell_back;
    assert!(fell_back > 500, "{fell_back} points read a coarser level than their footprint's");
}

/// Under a spot, whose levels' texels grow with the distance from it, each pixel
/// asks for the level whose texels match its footprint at its own distance, and the
/// points outside its frustum ask for nothing (`Clipmap::sees`); under PCSS for a
/// spot of radius 0.3, for the cone to its disk measured on its near plane.
#[test]
fn the_gpu_asks_for_exactly_the_pages_of_a_spots_clipmap() {
    let asked = asks_for_exactly_the_pages_the_clipmap_names(spot(), Searches::NONE);
    assert!(asked.unseen > 500, "{} points outside the spot's frustum", asked.unseen);
    let cone = ConeReach { light_size: 0.3, level_cap_texels: 32.0, reach_cap_texels: 64.0 };
    let asked =
        asks_for_exactly_the_pages_the_clipmap_names(spot(), Searches { area: None, cone: Some(cone) });
    assert!(asked.search_only >= 10, "{} pages only the cone asks for", asked.search_only);
}

/// Under a sun 10° wide whose penumbrae rays refine, each pixel also asks for the
/// pages its footprint test's search over the sun's cone reads, in the level whose
/// texels the cone spans in at most 32, and in the finer levels it also reads
/// (`Clipmap::search_requests`).
#[test]
fn the_gpu_asks_for_the_pages_of_the_search_over_a_wide_suns_cone() {
    let search = AreaSearch { light_size: 5f32.to_radians().tan(), cap_texels: 32.0 };
    let searches = Searches { area: Some(search), cone: None };
    let asked = asks_for_exactly_the_pages_the_clipmap_names(sun(ClipmapShape::DEFAULT, 1.0), searches);
    // 16 measured: the coarser levels' pages round the points whose cone is widest.
    assert!(asked.search_only >= 10, "{} pages only the search asks for", asked.search_only);
}

/// Under PCSS on a sun 10° wide, each pixel also asks for the pages its blocker
/// search and its filter may read over the sun's cone, in every level from its own
/// to the one whose texels the cone spans in at most the search's cap
/// (`Clipmap::cone_requests`).
#[test]
fn the_gpu_asks_for_the_pages_of_pcss_over_a_wide_suns_cone() {
    let cone =
        ConeReach { light_size: 5f32.to_radians().tan(), level_cap_texels: 32.0, reach_cap_texels: 64.0 };
    let searches = Searches { area: None, cone: Some(cone) };
    let asked = asks_for_exactly_the_pages_the_clipmap_names(sun(ClipmapShape::DEFAULT, 1.0), searches);
    assert!(asked.search_only >= 10, "{} pages only the cone asks for", asked.search_only);
}

/// The searches over a sun's cone whose pages a pixel also asks for.
#[derive(Clone, Copy)]
struct Searches {
    /// The refinement's footprint test's.
    area: Option<AreaSearch>,
    /// PCSS's, in coarser levels.
    cone: Option<ConeReach>,
}

impl Searches {
    const NONE: Searches = Searches { area: None, cone: None };
}

/// What the requests of [`asks_for_exactly_the_pages_the_clipmap_names`] held.
struct Asked {
    /// Points that read a coarser level than their footprint's.
    fell_back: usize,
    /// Pages that only the searches over a sun's cone asked for.
    search_only: usize,
    /// Points the map does not see (outside a spot's frustum).
    unseen: usize,
}

/// The camera every request test looks from.
const CAMERA: Vec3 = Vec3::new(2.0, 6.0, 9.0);

/// A 60° camera 240 pixels high: a pixel's footprint per unit of view depth.
fn footprint_per_depth() -> f32 {
    2.0 * (30f32.to_radians()).tan() / 240.0
}

/// A sun's clipmap of `shape` round [`CAMERA`], for surfaces whose footprint is
/// `footprint_scale` times the camera's, and that scale.
fn sun(shape: ClipmapShape, footprint_scale: f32) -> (Clipmap, f32) {
    let bounds = Aabb::new(Vec3::new(-30.0, 0.0, -30.0), Vec3::new(30.0, 12.0, 30.0));
    let farthest = 40.0 * footprint_scale * footprint_per_depth();
    (Clipmap::new(shape, Vec3::new(-0.4, -1.0, 0.3), CAMERA, &bounds, farthest), footprint_scale)
}

/// A spot 14 units up, 50° from its axis to its frustum's side, looking down and
/// a little toward the camera: most points lie in its frustum, some outside.
fn spot() -> (Clipmap, f32) {
    let position = Vec3::new(0.0, 14.0, 0.0);
    let view = gnomon_math::view_from_world_look_at(position, Vec3::new(1.0, 0.0, 3.0), Vec3::Y);
    (Clipmap::spot(ClipmapShape::DEFAULT, view, 50f32.to_radians().tan(), 0.2, 60.0), 1.0)
}

/// Checks the GPU's requests against `clipmap`'s for surfaces seen from [`CAMERA`]
/// whose footprint is `footprint_scale` times its pixels', and the pages of
/// `searches` over the light's cone.
fn asks_for_exactly_the_pages_the_clipmap_names(
    (clipmap, footprint_scale): (Clipmap, f32),
    searches: Searches,
) -> Asked {
    let gpu = gpu();
    let camera = CAMERA;
    // Surfaces up to 40 units away; the filter reaches 2.5 texels.
    let reach = PixelReach {
        footprint_per_depth: footprint_scale * footprint_per_depth(),
        reach_texels: 2.5,
        area_search: searches.area,
        cone: searches.cone,
    };
    let (width, height) = (96u32, 64u32);
    let mut rng = Lcg(17);
    let mut texels = Vec::with_capacity((width * height) as usize);
    let mut expected = BTreeSet::new();
    let mut searched_pages = BTreeSet::new();
    let (mut fell_back, mut unseen) = (0, 0);
    for _ in 0..width * height {
        // Surfaces from 0.5 to 40 units away, in every direction round the camera.
        let direction =
            Vec3::new(rng.next() - 0.5, rng.next() - 0.8, rng.next() - 0.5).normalize_or(Vec3::NEG_Y);
        let depth = 0.5 + 39.5 * rng.next() * rng.next();
        let point = camera + direction * depth;
        let footprint = depth * reach.footprint_per_depth;
        if !clipmap.sees(point) {
            // Asks for nothing, however near the frustum's side: a pixel there asks
            // for no page round it either.
            let light = clipmap.light_from_world.transform_point3(point);
            let side = clipmap.map_xy(point).abs().max_element();
            if light.z < 0.0 && (side - 1.0).abs() < 1e-3 {
                texels.push(Vec4::ZERO);
                continue;
            }
            unseen += 1;
            texels.push(point.extend(depth));
            continue;
        }
        let xy = clipmap.map_xy(point);
        let map_footprint = clipmap.map_footprint(point, footprint);
        let level = clipmap.level_for_point(xy, map_footprint).unwrap_or(0);
        let page = clipmap.page_size(level);
        let spread = reach.reach_texels * clipmap.texel_size(level);
        // Pixels on a boundary of levels or pages are left out (as background): the
        // two sides' rounding may differ there by an ulp.
        // So are points on the edge of a window the level search passed over.
        let on_window_edge = (clipmap.level_for_footprint(map_footprint)..level).any(|l| {
            let size = clipmap.page_size(l);
            near_grid(xy.x / size, 1e-3) || near_grid(xy.y / size, 1e-3)
        });
        let ambiguous = near_grid((map_footprint / clipmap.finest_texel).log2(), 1e-3)
            || on_window_edge
            || searches.area.is_some_and(|search| {
                search_is_ambiguous(&clipmap, point, level, search, reach.reach_texels)
            })
            || searches
                .cone
                .is_some_and(|cone| cone_is_ambiguous(&clipmap, point, level, cone, reach.reach_texels))
            || [xy - Vec2::splat(spread), xy, xy + Vec2::splat(spread)]
                .iter()
                .any(|p| near_grid(p.x / page, 1e-3) || near_grid(p.y / page, 1e-3));
        if ambiguous || rng.next() < 0.1 {
            texels.push(Vec4::ZERO);
            continue;
        }
        fell_back += usize::from(level > clipmap.level_for_footprint(map_footprint));
        texels.push(point.extend(depth));
        if let Some(rect) = clipmap.request(point, footprint, reach.reach_texels) {
            expected.extend(rect.pages());
        }
        if let Some(search) = searches.area {
            for rect in clipmap.search_requests(point, level, search, reach.reach_texels) {
                searched_pages.extend(rect.pages());
            }
        }
        if let Some(cone) = searches.cone {
            for rect in clipmap.cone_requests(point, level, cone, reach.reach_texels) {
                searched_pages.extend(rect.pages());
            }
        }
    }
    let surface = surface_texture(gpu, &texels, width, height);
    let mut requests = PageRequests::new(gpu).expect("the pass builds");
    let asked: Vec<PageKey> =
        pollster::block_on(requests.request(gpu, &surface, &clipmap, reach)).expect("requested");
    let asked: BTreeSet<PageKey> = asked.into_iter().collect();
    let search_only = searched_pages.difference(&expected).count();
    expected.extend(searched_pages);
    let levels: BTreeSet<u32> = expected.iter().map(|p| p.level).collect();
    assert!(expected.len() > 100 && levels.len() >= 4, "{} pages over levels {levels:?}", expected.len());
    let missing: Vec<_> = expected.difference(&asked).take(5).collect();
    let extra: Vec<_> = asked.difference(&expected).take(5).collect();
    assert!(missing.is_empty() && extra.is_empty(), "missing {missing:?}, extra {extra:?}");
    Asked { fell_back, search_only, unseen }
}

/// The prepass's surface as the request pass reads it: `texels` (world point, view
/// depth) in a `width`×`height` texture.
fn surface_texture(
    gpu: &gnomon_render::Gpu,
    texels: &[Vec4],
    width: u32,
    height: u32,
) -> gnomon_render::wgpu::Texture {
    let surface = gpu.device.create_texture(&gnomon_render::wgpu::TextureDescriptor {
        label: Some("test surface"),
        size: gnomon_render::wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: gnomon_render::wgpu::TextureDimension::D2,
        format: gnomon_render::wgpu::TextureFormat::Rgba32Float,
        usage: gnomon_render::wgpu::TextureUsages::TEXTURE_BINDING
            | gnomon_render::wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    gpu.queue.write_texture(
        surface.as_image_copy(),
        bytemuck::cast_slice(texels),
        gnomon_render::wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(16 * width),
            rows_per_image: Some(height),
        },
        surface.size(),
    );
    surface
}

/// Whether the search's pages for a pixel of `level` at `point` lie where the GPU's
/// rounding and the CPU's may differ: its level's boundary, its squares' page edges
/// (the search level's and the finer levels').
fn search_is_ambiguous(clipmap: &Clipmap, point: Vec3, level: u32, search: AreaSearch, reach: f32) -> bool {
    let square = clipmap.search_square(point, level, search, reach);
    let mut squares = clipmap.finer_search_squares(&square, level, search, reach);
    squares.push(square);
    near_grid((square.cone / (clipmap.texel_size(level) * search.cap_texels)).log2(), 1e-3)
        || near_grid(square.cone / clipmap.texel_size(square.level), 1e-3)
        || squares.iter().any(|s| {
            let page = clipmap.page_size(s.level);
            let (xy, spread) = (s.centre, Vec2::splat(s.reach));
            [xy - spread, xy, xy + spread]
                .iter()
                .any(|p| near_grid(p.x / page, 1e-3) || near_grid(p.y / page, 1e-3))
        })
}

/// Whether the cone's pages for a pixel of `level` at `point` lie where the GPU's
/// rounding and the CPU's may differ: the boundary of its coarsest level, the cone's
/// span in a level's texels where the cap clamps it, its squares' page edges.
fn cone_is_ambiguous(clipmap: &Clipmap, point: Vec3, level: u32, cone: ConeReach, reach: f32) -> bool {
    let radius = clipmap.cone_radius(point, cone.light_size);
    let coarsest = clipmap.search_level(level, radius, cone.level_cap_texels);
    let xy = clipmap.map_xy(point);
    near_grid((radius / (clipmap.texel_size(level) * cone.level_cap_texels)).log2(), 1e-3)
        || (level..=coarsest).any(|l| {
            let texel = clipmap.texel_size(l);
            let spans = (radius / texel).clamp(1.0, cone.reach_cap_texels);
            let (page, spread) = (clipmap.page_size(l), Vec2::splat((spans + 1.0 + reach) * texel));
            // Where the cap clamps the span, both sides clamp it to the same.
            let clamped = radius / texel >= cone.reach_cap_texels * 1.001;
            (near_grid(spans, 1e-3) && !clamped)
                || [xy - spread, xy, xy + spread]
                    .iter()
                    .any(|p| near_grid(p.x / page, 1e-3) || near_grid(p.y / page, 1e-3))
        })
}

/// A frame's virtual pages: a renderer kept across frames draws only pages new or
/// stale, a still sun none, a turned one every page it reads; a pool too small for
/// the view refuses pages, counts them, and their pixels read coarser pages.
mod in_the_frame {
    use glam::{Mat4, Vec3};
    use gnomon_render::{Frame, OutputRequest, PageStats, Renderer};
    use gnomon_scene::{
        Motion, Settings, builtin,
        settings::{Partition, Refine},
    };

    use crate::support;

    fn virtual_sun(pool_side: u32) -> Settings {
        let mut s = support::settings(320, 180, 1024);
        s.shadow.partition = Partition::Virtual;
        s.shadow.virtual_map.pool_side = pool_side;
        s.screen.refine = Refine::Off;
        s
    }

    fn pages(frame: &Frame) -> PageStats {
        frame.lights[0].pages.expect("a virtual light reports its pages")
    }

    /// The share of light-facing pixels in shadow (visibility below a half).
    fn shadowed(frame: &Frame) -> f64 {
        let seen: Vec<f32> = frame.visibility.iter().copied().filter(|v| v.is_finite()).collect();
        seen.iter().filter(|&&v| v < 0.5).count() as f64 / seen.len().max(1) as f64
    }

    #[test]
    fn a_still_sun_draws_no_page_and_a_turned_one_draws_every_page_it_reads() {
        let scene = builtin::spheres();
        let s = virtual_sun(24);
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let uploaded = renderer.upload(&scene).unwrap();
        let request = OutputRequest::default();
        let first = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let p = pages(&first);
        assert!(p.requested > 10 && p.drawn == p.requested && p.refused == 0, "{p:?}");
        // A first frame keeps nothing: its pages take the first slots, and only the
        // layers of the pool they lie in (4 rows of 24 tiles each) are cleared whole,
        // their texels counted.
        let layers = u64::from(p.drawn.div_ceil(24 * gnomon_render::virtual_map::POOL_LAYER_ROWS));
        assert!(layers < 6, "{p:?}");
        assert_eq!(first.lights[0].layer_texels, vec![layers * 24 * 128 * 4 * 128]);
        // It is laid out anew, neighbouring pages in neighbouring tiles, drawn in runs.
        assert!(p.runs > 0 && p.runs * 2 <= p.drawn, "{p:?}");
        let still = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let p = pages(&still);
        assert_eq!((p.drawn, p.kept), (0, p.requested), "{p:?}");
        assert_eq!(still.lights[0].layer_texels.iter().sum::<u64>(), 0);
        // The kept pages shade as the drawn ones did.
        assert_eq!(first.visibility.len(), still.visibility.len());
        let differ = first.visibility.iter().zip(&still.visibility).filter(|(a, b)| (*a - *b).abs() > 1e-6);
        assert_eq!(differ.count(), 0);
        let mut turned = s.clone();
        turned.light.sun_azimuth = Some(turned.light.sun_azimuth.unwrap_or(0.0) + 10.0);
        let p = pages(&renderer.render_uploaded(&uploaded, &scene, &turned, &request).unwrap());
        assert_eq!((p.drawn, p.kept), (p.requested - p.refused, 0), "{p:?}");
    }

    #[test]
    fn an_overfull_pool_refuses_pages_counts_them_and_falls_back_to_coarser_ones() {
        let scene = builtin::spheres();
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let ample = renderer.render(&scene, &virtual_sun(24), &OutputRequest::default()).unwrap();
        let full = renderer.render(&scene, &virtual_sun(2), &OutputRequest::default()).unwrap();
        let (a, f) = (pages(&ample), pages(&full));
        assert_eq!(a.refused, 0, "{a:?}");
        assert_eq!((f.capacity, f.resident), (4, 4), "{f:?}");
        assert_eq!(f.refused, f.requested - 4, "{f:?}");
        // The refused pages' pixels read the coarse resident pages: the spheres'
        // shadows are still there, blurrier, not lost to lit pixels.
        let (sa, sf) = (shadowed(&ample), shadowed(&full));
        assert!(sa > 0.02 && sf > 0.5 * sa, "shadowed: {sa} with room, {sf} with 4 tiles");
    }

    /// Pixels whose visibility differs between two frames of one view.
    fn differing(a: &Frame, b: &Frame) -> usize {
        assert_eq!(a.visibility.len(), b.visibility.len());
        a.visibility
            .iter()
            .zip(&b.visibility)
            .filter(|(x, y)| (x.is_finite() || y.is_finite()) && x != y)
            .count()
    }

    #[test]
    fn a_moving_caster_redraws_only_the_pages_under_it_and_the_frame_matches_one_from_scratch() {
        let mut scene = builtin::spheres();
        let ball = scene.instances.iter().position(|i| i.name == "sphere 1,1").expect("a sphere");
        scene.instances[ball].motion = Motion::Dynamic;
        // A pool of 5² tiles in layers of 4 rows, for the 24 pages the view asks for:
        // the pages lie in both layers.
        let s = virtual_sun(5);
        let request = OutputRequest::default();
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let mut uploaded = renderer.upload(&scene).unwrap();
        let frame = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let first = pages(&frame);
        assert!((21..=25).contains(&first.requested), "{first:?}");
        assert_eq!((first.drawn, first.refused), (first.requested, 0), "{first:?}");
        assert_eq!(frame.lights[0].layer_texels, vec![2 * (5 * 128) * (4 * 128)], "both layers cleared");

        scene.instances[ball].world_from_object *= Mat4::from_translation(Vec3::new(0.7, 0.3, -0.4));
        renderer.move_instances(&mut uploaded, &scene, &[ball]).unwrap();
        let moved = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let p = pages(&moved);
        // The pages under the ball, where it was and where it is, and no others,
        // each cleared and drawn alone: the kept pages must stay.
        assert!(p.drawn > 0 && p.drawn < p.requested / 2, "{p:?}");
        assert_eq!(moved.lights[0].layer_texels, vec![u64::from(p.drawn) * 128 * 128]);
        assert_eq!(p.drawn + p.kept, p.requested, "{p:?}");
        let scratch = Renderer::new(support::gpu()).unwrap().render(&scene, &s, &request).unwrap();
        assert_eq!(differing(&moved, &scratch), 0, "the kept and redrawn pages shade as pages drawn afresh");
        // Without the redraw the ball's old shadow would stay: the frame before the
        // move differs from this one.
        let before = {
            let mut still = builtin::spheres();
            still.instances[ball].motion = Motion::Dynamic;
            Renderer::new(support::gpu()).unwrap().render(&still, &s, &request).unwrap()
        };
        assert!(differing(&before, &moved) > 50, "the move should change the shadows");
    }
}

mod pages_view {
    use gnomon_render::{Frame, OutputRequest, Renderer};
    use gnomon_scene::{
        Settings, builtin,
        settings::{DebugView, Partition, Refine},
    };

    use crate::support;

    fn pages_view(pool_side: u32) -> Settings {
        let mut s = support::settings(320, 180, 1024);
        s.shadow.partition = Partition::Virtual;
        s.shadow.virtual_map.pool_side = pool_side;
        s.screen.refine = Refine::Off;
        s.image.debug_view = DebugView::Pages;
        s
    }

    /// Each pixel's RGB, 0 to 255.
    fn rgb(frame: &Frame) -> Vec<[f32; 3]> {
        frame.color.chunks(4).map(|p| [f32::from(p[0]), f32::from(p[1]), f32::from(p[2])]).collect()
    }

    fn sum(pixel: &[f32; 3]) -> f32 {
        pixel.iter().sum()
    }

    #[test]
    fn the_pages_view_tints_levels_darkens_borders_and_brightens_the_pages_drawn() {
        let scene = builtin::spheres();
        let request = OutputRequest::default();
        let plain_settings = Settings { image: support::settings(320, 180, 1024).image, ..pages_view(24) };
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let uploaded = renderer.upload(&scene).unwrap();
        let plain = renderer.render_uploaded(&uploaded, &scene, &plain_settings, &request).unwrap();
        // The same pages kept, seen through the view: only the colours change.
        let kept = renderer.render_uploaded(&uploaded, &scene, &pages_view(24), &request).unwrap();
        assert_eq!(kept.lights[0].pages.unwrap().drawn, 0);
        let shadows_differ =
            plain.visibility.iter().zip(&kept.visibility).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
        assert_eq!(shadows_differ, 0, "a debug view changes no shadow");
        let (plain_rgb, kept_rgb) = (rgb(&plain), rgb(&kept));
        let tinted = plain_rgb.iter().zip(&kept_rgb).filter(|(a, b)| a != b).count();
        assert!(tinted > plain_rgb.len() / 2, "{tinted} of {} pixels tinted", plain_rgb.len());
        // Page borders: a texel wide, darkened to a quarter (about half in sRGB's
        // steps), where a level's tint keeps 83 % or more.
        let borders =
            plain_rgb.iter().zip(&kept_rgb).filter(|(a, b)| sum(a) > 60.0 && sum(b) < 0.6 * sum(a)).count();
        assert!(borders > 100 && borders < plain_rgb.len() / 10, "{borders} border pixels");
        // A first frame draws every page: brighter than the kept ones.
        let drawn = Renderer::new(support::gpu()).unwrap().render(&scene, &pages_view(24), &request).unwrap();
        // (×1.5 in linear light, about ×1.2 in sRGB's steps): every tinted pixel not
        // already near white.
        let shaded: Vec<(&[f32; 3], [f32; 3])> = plain_rgb
            .iter()
            .zip(&kept_rgb)
            .zip(rgb(&drawn))
            .filter(|((a, b), _)| a != b && sum(b) > 30.0 && sum(b) < 500.0)
            .map(|((_, b), c)| (b, c))
            .collect();
        let brighter = shaded.iter().filter(|(kept, drawn)| sum(drawn) > 1.1 * sum(kept)).count();
        assert!(brighter * 10 > shaded.len() * 9, "{brighter} of {} brighter where drawn", shaded.len());
        // A pool too small: the pixels a coarser page stands in for are reddened.
        let full = Renderer::new(support::gpu()).unwrap().render(&scene, &pages_view(2), &request).unwrap();
        let p = full.lights[0].pages.unwrap();
        assert!(p.refused > 0, "{p:?}");
        // Redder than the same pixel with room for every page (a red share of its
        // colour a tenth higher), and never the other way.
        let red_share = |p: &[f32; 3]| p[0] / sum(p).max(1.0);
        let (full_rgb, roomy_rgb) = (rgb(&full), rgb(&drawn));
        let redder = |a: &[[f32; 3]], b: &[[f32; 3]]| {
            a.iter().zip(b).filter(|(x, y)| red_share(x) > red_share(y) + 0.1).count()
        };
        let (reddened, paler) = (redder(&full_rgb, &roomy_rgb), redder(&roomy_rgb, &full_rgb));
        assert!(reddened > full_rgb.len() / 20 && paler == 0, "{reddened} pixels reddened, {paler} paler");
    }
}

/// The pages along shadow edges (`shadow.virtual_map.edge_levels`): the pixels a
/// frame traces ask for finer pages round them, which narrow the band the next
/// frame traces, without changing its answer; a still view settles and then draws
/// nothing; a light that turns forgets them.
mod along_edges {
    use gnomon_render::{Frame, OutputRequest, PageStats, Renderer};
    use gnomon_scene::{
        Settings, builtin,
        settings::{Partition, Refine},
    };

    use crate::support;

    fn virtual_sun(edge_levels: u32, refine: Refine) -> Settings {
        let mut s = support::settings(320, 180, 1024);
        s.shadow.partition = Partition::Virtual;
        s.shadow.virtual_map.edge_levels = edge_levels;
        s.screen.refine = refine;
        s
    }

    fn pages(frame: &Frame) -> PageStats {
        frame.lights[0].pages.expect("a virtual light reports its pages")
    }

    fn traced(frame: &Frame) -> u32 {
        frame.lights[0].traced_pixels.expect("a refined light counts its traced pixels")
    }

    /// Light-facing pixels whose shadow (lit or not, at a half) differs from `truth`'s.
    fn wrong(frame: &Frame, truth: &Frame) -> usize {
        let side = |v: f32| v.is_finite().then_some(v >= 0.5);
        frame.visibility.iter().zip(&truth.visibility).filter(|(a, b)| side(**a) != side(**b)).count()
    }

    #[test]
    fn finer_pages_along_edges_halve_the_traced_pixels_keep_the_answer_and_settle() {
        let scene = builtin::spheres();
        let request = OutputRequest::default();
        let render =
            |s: &Settings| Renderer::new(support::gpu()).unwrap().render(&scene, s, &request).unwrap();
        // Every pixel traced: the ray-traced answer the others are held to.
        let truth = render(&virtual_sun(0, Refine::EveryPixel));
        let plain = render(&virtual_sun(0, Refine::Auto));
        let p = pages(&plain);
        assert_eq!((p.edges, p.edge_levels), (0, 0), "{p:?}");

        let s = virtual_sun(2, Refine::Auto);
        let mut renderer = Renderer::new(support::gpu()).unwrap();
        let uploaded = renderer.upload(&scene).unwrap();
        let settled = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let p = pages(&settled);
        assert!(p.edges > 0 && p.edge_levels == 2 && p.refused == 0, "{p:?}");
        // Each level halves the band of unsure texels round an edge: two levels
        // should leave well under half the pixels to rays.
        let (before, after) = (traced(&plain), traced(&settled));
        assert!(before > 1000 && 2 * after < before, "traced {before} without the pages, {after} with");
        // The map is sure only where it is right: no pixel more is wrong.
        let (plain_wrong, settled_wrong) = (wrong(&plain, &truth), wrong(&settled, &truth));
        assert!(settled_wrong <= plain_wrong, "wrong: {plain_wrong} without the pages, {settled_wrong} with");

        // Settled: the same view again asks for no new page and draws none.
        let again = renderer.render_uploaded(&uploaded, &scene, &s, &request).unwrap();
        let p = pages(&again);
        assert_eq!((p.drawn, p.edges_new), (0, Some(0)), "{p:?}");
        assert_eq!(traced(&again), after);
        // A turned sun's edges are elsewhere: its first frame forgets them, and it
        // settles as a renderer that never saw the old sun does.
        let mut turned = s.clone();
        turned.light.sun_azimuth = Some(turned.light.sun_azimuth.unwrap_or(0.0) + 10.0);
        let kept = renderer.render_uploaded(&uploaded, &scene, &turned, &request).unwrap();
        let fresh = render(&turned);
        let (k, f) = (pages(&kept), pages(&fresh));
        assert!(f.edges > 0, "{f:?}");
        assert_eq!(
            (k.edges, k.requested, traced(&kept)),
            (f.edges, f.requested, traced(&fresh)),
            "{k:?} {f:?}"
        );
    }
}

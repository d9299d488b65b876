//! Virtual shadow maps' page requests on the GPU (`virtual_map/page_requests.wgsl`)
//! against the clipmap's own arithmetic (`gnomon_math::virtual_map`): the pass must
//! ask for exactly the pages that `Clipmap::request` names for every pixel, under a
//! sun, a spot and a point light.

use std::collections::BTreeSet;

use glam::{Vec2, Vec3, Vec4};
use gnomon_math::{
    Aabb,
    virtual_map::{Clipmap, ClipmapShape, ConeReach, MapProjection, PageKey},
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

/// Under a point light, each pixel asks for the pages of the cube face its direction
/// falls in, at the level whose texels match its footprint at its distance along the
/// face's axis, and none past its face's slot (`Clipmap::pages_around`); under PCSS
/// for a light of radius 0.2, for the cone measured on the face's near plane.
#[test]
fn the_gpu_asks_for_exactly_the_pages_of_a_point_lights_clipmap() {
    let asked = asks_for_exactly_the_pages_the_clipmap_names(point_light(), Searches::NONE);
    assert_eq!(asked.unseen, 0);
    assert!(asked.layers >= 12, "pages in {} layers (faces and levels)", asked.layers);
    let cone = ConeReach { light_size: 0.2, level_cap_texels: 32.0, reach_cap_texels: 64.0 };
    let asked = asks_for_exactly_the_pages_the_clipmap_names(
        point_light(),
        Searches { area: None, cone: Some(cone) },
    );
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
    /// The clipmap's layers (`Clipmap::layers`: levels, a point light's faces) that
    /// the pages asked for lie in.
    layers: usize,
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

/// A point light 3 units up among the surfaces, so that they lie in all its faces.
fn point_light() -> (Clipmap, f32) {
    (Clipmap::point(ClipmapShape::DEFAULT, Vec3::new(1.0, 3.0, 2.0), 0.05, 60.0), 1.0)
}

/// Whether a point light's face for `point` is a tie the GPU's rounding and the
/// CPU's may break differently: its direction's two largest components within a
/// part in 10⁴.
fn face_is_ambiguous(clipmap: &Clipmap, point: Vec3) -> bool {
    let mut a = clipmap.light_from_world.transform_point3(point).abs().to_array();
    a.sort_by(f32::total_cmp);
    clipmap.projection == MapProjection::Cube && a[2] - a[1] < 1e-4 * a[2]
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
            || face_is_ambiguous(&clipmap, point)
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
    let layers = clipmap.layers().iter().filter(|l| expected.iter().any(|&p| l.contains(p))).count();
    Asked { fell_back, search_only, unseen, layers }
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

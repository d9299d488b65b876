//! The clipmap's geometry: levels nest, windows follow the camera by whole pages,
//! requests cover every texel a filter reads, and a caster dirties exactly the pages
//! under its shadow.

use glam::{Vec2, Vec3};

use super::*;
use crate::test_rng::Lcg;

fn scene() -> Aabb {
    Aabb::new(Vec3::new(-40.0, 0.0, -25.0), Vec3::new(40.0, 20.0, 25.0))
}

/// The clipmap of a sun over [`scene`], around `camera`, for a camera whose farthest
/// pixel spans 0.05 world units.
fn clipmap(camera: Vec3) -> Clipmap {
    Clipmap::new(ClipmapShape::DEFAULT, Vec3::new(0.3, -1.0, 0.2), camera, &scene(), 0.05)
}

#[test]
fn the_coarsest_level_serves_the_farthest_pixel_unclamped() {
    for farthest in [1e-4f32, 0.05, 3.0, 700.0] {
        let map = Clipmap::new(ClipmapShape::DEFAULT, Vec3::NEG_Y, Vec3::ZERO, &scene(), farthest);
        let coarsest = map.shape.levels - 1;
        assert!(map.texel_size(coarsest) >= farthest, "{farthest}: {}", map.texel_size(coarsest));
        // The farthest pixel's level matches its footprint: not clamped to a level
        // whose texels are more than twice finer.
        let level = map.level_for_footprint(farthest);
        assert!(map.texel_size(level) <= farthest && 2.0 * map.texel_size(level) > farthest, "{farthest}");
    }
}

#[test]
fn the_coarsest_level_covers_the_scene_and_each_level_halves_the_texel() {
    let map = clipmap(Vec3::new(5.0, 2.0, 3.0));
    let shape = map.shape;
    assert_eq!(map.finest_texel.log2().fract(), 0.0, "a power of two: {}", map.finest_texel);
    for level in 1..shape.levels {
        assert_eq!(map.texel_size(level), 2.0 * map.texel_size(level - 1));
    }
    // Every corner of the scene lies in the coarsest level's window.
    let coarsest = shape.levels - 1;
    for corner in scene().corners() {
        assert!(map.page_at(coarsest, map.map_xy(corner)).is_some(), "{corner}");
    }
    // The depth range holds the whole scene.
    for corner in scene().corners() {
        let depth = -map.light_from_world.transform_point3(corner).z;
        assert!(depth > map.near && depth < map.far, "{depth} outside {}..{}", map.near, map.far);
    }
}

#[test]
fn light_space_is_rigid() {
    let map = clipmap(Vec3::ZERO);
    let (a, b) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(-4.0, 0.5, 7.0));
    let light = |p| map.light_from_world.transform_point3(p);
    assert!((light(a).distance(light(b)) - a.distance(b)).abs() < 1e-4);
}

#[test]
fn pages_nest_across_levels() {
    let map = clipmap(Vec3::ZERO);
    let mut rng = Lcg(3);
    for _ in 0..500 {
        let xy = Vec2::new(rng.range(-30.0, 30.0), rng.range(-30.0, 30.0));
        let level = (rng.next() * 10.0) as u32;
        let (Some(fine), Some(coarse)) = (map.page_at(level, xy), map.page_at(level + 1, xy)) else {
            continue;
        };
        assert_eq!(fine.coarser(), coarse, "{xy} at level {level}");
    }
}

#[test]
fn the_window_follows_the_camera_by_whole_pages_and_stays_centred() {
    let before = clipmap(Vec3::ZERO);
    let after = clipmap(Vec3::new(3.0, 0.0, 1.0));
    let half = (before.shape.pages_per_side() / 2) as i32;
    for level in 0..before.shape.levels {
        let size = after.page_size(level);
        // The camera's page is the window's centre page.
        let centre = (after.map_xy(Vec3::new(3.0, 0.0, 1.0)) / size).floor().as_ivec2();
        assert_eq!(centre - after.origins[level as usize], IVec2::splat(half), "level {level}");
        // A page keeps its world place: its projection depends on its key alone.
        let key = PageKey { level, x: 2, y: -1 };
        assert_eq!(before.page_clip_from_world(key), after.page_clip_from_world(key));
    }
}

#[test]
fn a_pixel_reads_the_coarsest_level_whose_texels_fit_its_footprint() {
    let map = clipmap(Vec3::ZERO);
    let mut rng = Lcg(11);
    for _ in 0..200 {
        let footprint = map.finest_texel * 2f32.powf(rng.range(0.0, 14.0));
        let level = map.level_for_footprint(footprint);
        assert!(map.texel_size(level) <= footprint * (1.0 + 1e-6), "{footprint}: level {level}");
        assert!(map.texel_size(level) * 2.0 > footprint, "{footprint}: level {level} is too fine");
    }
    assert_eq!(map.level_for_footprint(0.0), 0);
    assert_eq!(map.level_for_footprint(f32::NAN), 0);
    assert_eq!(map.level_for_footprint(1e9), map.shape.levels - 1);
}

#[test]
fn a_request_covers_every_texel_the_filter_reaches() {
    let map = clipmap(Vec3::new(1.0, 1.0, 1.0));
    let mut rng = Lcg(5);
    for _ in 0..300 {
        // Near the camera, where every level's window holds the point and its taps.
        let point = Vec3::ONE + rng.vec(-0.5, 0.5);
        let footprint = rng.range(0.001, 0.5);
        let reach = rng.range(0.5, 8.0);
        let rect = map.request(point, footprint, reach).expect("the point lies in its level's window");
        let level = map.level_for_footprint(footprint);
        assert_eq!(rect.level, level);
        let xy = map.map_xy(point);
        let step = map.texel_size(level) * reach;
        for (dx, dy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (0.0, 0.0)] {
            let tap = xy + Vec2::new(dx, dy) * step;
            let page = map.page_at(level, tap).expect("a tap near the camera lies in the window");
            assert!(rect.contains(page), "{page:?} outside {rect:?}");
        }
        // And no more than the square's pages: at most one page beyond each side.
        let pages = (2.0 * step / map.page_size(level)).ceil() as i32 + 1;
        assert!(rect.max.x - rect.min.x < pages && rect.max.y - rect.min.y < pages, "{rect:?}");
    }
}

#[test]
fn a_caster_dirties_exactly_the_pages_under_its_shadow() {
    let map = clipmap(Vec3::ZERO);
    let mut rng = Lcg(9);
    for _ in 0..50 {
        let centre = rng.vec(-5.0, 5.0);
        let caster = Aabb::new(centre - rng.vec(0.05, 1.0), centre + rng.vec(0.05, 1.0));
        // Levels whose windows (32 world units and more) hold every caster whole.
        let level = 12 + (rng.next() * 4.0) as u32;
        let [rect] = map.pages_under(level, &caster)[..] else {
            panic!("one rectangle: the caster is near the camera")
        };
        let in_light = caster.transformed(map.light_from_world);
        let size = map.page_size(level);
        // Every page near the caster: dirtied exactly when its window meets the
        // caster's light-space rectangle.
        for y in rect.min.y - 2..=rect.max.y + 2 {
            for x in rect.min.x - 2..=rect.max.x + 2 {
                let page = PageKey { level, x, y };
                let (low, high) =
                    (Vec2::new(x as f32, y as f32) * size, Vec2::new(x as f32 + 1.0, y as f32 + 1.0) * size);
                let meets = low.x <= in_light.max.x
                    && high.x > in_light.min.x
                    && low.y <= in_light.max.y
                    && high.y > in_light.min.y;
                assert_eq!(rect.contains(page), meets, "{page:?} against {rect:?}");
            }
        }
    }
}

#[test]
fn a_page_projection_maps_its_window_onto_clip_space() {
    let map = clipmap(Vec3::ZERO);
    let key = PageKey { level: 6, x: -3, y: 2 };
    let size = map.page_size(key.level);
    let clip_from_world = map.page_clip_from_world(key);
    let world_from_light = map.light_from_world.inverse();
    let depth = 0.5 * (map.near + map.far);
    let corner = |u: f32, v: f32| {
        let light = Vec3::new((key.x as f32 + u) * size, (key.y as f32 + v) * size, -depth);
        clip_from_world.project_point3(world_from_light.transform_point3(light))
    };
    let low = corner(0.0, 0.0);
    let high = corner(1.0, 1.0);
    assert!((low.x + 1.0).abs() < 1e-3 && (low.y + 1.0).abs() < 1e-3, "{low}");
    assert!((high.x - 1.0).abs() < 1e-3 && (high.y - 1.0).abs() < 1e-3, "{high}");
    assert!((low.z - 0.5).abs() < 1e-3, "{low}");
}

#[test]
fn a_rect_projection_puts_each_page_texel_where_the_page_projection_does() {
    let map = clipmap(Vec3::ZERO);
    let rect = PageRect { level: 4, min: glam::IVec2::new(-2, 5), max: glam::IVec2::new(0, 6) };
    let (columns, rows) = (3.0, 2.0);
    let texels = map.shape.page_size as f32;
    let rect_clip = map.rect_clip_from_world(&rect);
    let world_from_light = map.light_from_world.inverse();
    let size = map.page_size(rect.level);
    let depth = 0.3 * map.near + 0.7 * map.far;
    let mut rng = Lcg(3);
    for page in rect.pages() {
        let page_clip = map.page_clip_from_world(page);
        for _ in 0..20 {
            let (u, v) = (rng.next(), rng.next());
            let light = Vec3::new((page.x as f32 + u) * size, (page.y as f32 + v) * size, -depth);
            let world = world_from_light.transform_point3(light);
            // Viewport texels, v down: the page's own tile, and the rect's.
            let own = page_clip.project_point3(world);
            let own = Vec2::new(own.x + 1.0, 1.0 - own.y) * 0.5 * texels;
            let whole = rect_clip.project_point3(world);
            let whole = Vec2::new((whole.x + 1.0) * columns, (1.0 - whole.y) * rows) * 0.5 * texels;
            let offset = Vec2::new((page.x - rect.min.x) as f32, (rect.max.y - page.y) as f32) * texels;
            assert!((whole - offset - own).length() < 1e-2, "{page:?}: {whole} − {offset} against {own}");
            assert!((rect_clip.project_point3(world).z - page_clip.project_point3(world).z).abs() < 1e-6);
        }
    }
    // A run is a rect of one row.
    let first = PageKey { level: 4, x: -2, y: 5 };
    let run = PageRect { level: 4, min: glam::IVec2::new(-2, 5), max: glam::IVec2::new(0, 5) };
    assert_eq!(map.run_clip_from_world(first, 3), map.rect_clip_from_world(&run));
}

#[test]
fn a_point_outside_its_levels_window_reads_the_finest_coarser_level_that_holds_it() {
    let shape = ClipmapShape { virtual_resolution: 1024, page_size: 128, levels: 6 };
    let bounds = Aabb::new(Vec3::splat(-500.0), Vec3::splat(500.0));
    let map = Clipmap::new(shape, Vec3::NEG_Y, Vec3::ZERO, &bounds, 64.0);
    let footprint = map.texel_size(1);
    let near = map.map_xy(Vec3::new(1.0, 0.0, 1.0));
    assert_eq!(map.level_for_point(near, footprint), Some(1));
    // Level 1's window is 1024 of its texels wide around the camera: a point beyond
    // it reads the first level whose window reaches it, and asks for that level's pages.
    let half_window = |level: u32| 512.0 * map.texel_size(level);
    let far_point = Vec3::new(1.5 * half_window(1), 0.0, 0.0);
    let xy = map.map_xy(far_point);
    let level = map.level_for_point(xy, footprint).expect("a coarser window holds it");
    assert!(level > 1 && map.page_at(level, xy).is_some() && map.page_at(level - 1, xy).is_none(), "{level}");
    let rect = map.request(far_point, footprint, 2.0).expect("pages asked for");
    assert_eq!(rect.level, level);
    assert_eq!(map.level_for_point(Vec2::splat(1e9), footprint), None);
}

/// The search over a sun's cone reads the finest level whose texels span the cone in
/// at most the cap, never finer than the pixel's own, at most the coarsest; and its
/// pages cover the whole cone, or the cap's texels of the coarsest, and the cap's
/// texels round the point in the finer levels it also reads (random points, random
/// cones).
#[test]
fn the_cone_search_reads_the_finest_level_that_spans_it_and_covers_it() {
    let map = clipmap(Vec3::new(5.0, 2.0, 3.0));
    let coarsest = map.shape.levels - 1;
    let mut rng = Lcg(29);
    let mut coarser = 0;
    for _ in 0..2000 {
        let level = (rng.next() * 6.0) as u32;
        let radius = map.texel_size(level) * 2f32.powf(rng.range(-4.0, 12.0));
        let cap = rng.range(1.0, 64.0);
        let read = map.search_level(level, radius, cap);
        assert!(read >= level && read <= coarsest, "{level} {radius} {cap}: {read}");
        if read < coarsest {
            assert!(radius <= cap * map.texel_size(read) * 1.0001, "{level} {radius} {cap}: {read}");
        }
        if read > level {
            coarser += 1;
            assert!(
                radius > cap * map.texel_size(read - 1) * 0.9999,
                "{level} {radius} {cap}: {read} is too coarse"
            );
        }
    }
    assert!(coarser > 500, "{coarser} searches read a coarser level");

    let search = AreaSearch { light_size: 0.1, cap_texels: 16.0 };
    let mut finer = 0;
    for _ in 0..500 {
        let point = Vec3::new(rng.range(-20.0, 20.0), rng.range(0.0, 10.0), rng.range(-15.0, 15.0));
        let level = (rng.next() * 4.0) as u32;
        let rects = map.search_requests(point, level, search, 2.0);
        let light = map.light_from_world.transform_point3(point);
        let cone = search.light_size * (-light.z - map.near).max(0.0);
        let read = map.search_level(level, cone, search.cap_texels);
        // The cone, clamped to the cap at the coarsest level; and the cap's texels
        // round the point in each of the (at most) AREA_SEARCH_FINER_LEVELS finer
        // levels, none finer than the pixel's.
        let first = read.saturating_sub(AREA_SEARCH_FINER_LEVELS).max(level);
        for l in first..=read {
            let texel = map.texel_size(l);
            let reach = if l == read {
                cone.min(search.cap_texels * texel).max(texel)
            } else {
                search.cap_texels * texel
            };
            let Some(page) = map.page_at(l, light.truncate()) else { continue };
            let rect = rects.iter().find(|r| r.level == l).expect("a rectangle for each level read");
            assert!(rect.contains(page));
            finer += usize::from(l < read);
            for corner in
                [Vec2::new(-1.0, -1.0), Vec2::new(1.0, 1.0), Vec2::new(-1.0, 1.0), Vec2::new(1.0, -1.0)]
            {
                let xy = light.truncate() + corner * reach;
                let page = map.page_at(l, xy);
                assert!(page.is_none_or(|p| rect.contains(p)), "{point}: {xy} outside {rect:?}");
            }
        }
        assert!(rects.iter().all(|r| (first..=read).contains(&r.level)), "{point}: {rects:?}");
    }
    assert!(finer > 100, "{finer} finer grids");
}

/// A cone's requests hold every texel that PCSS's two reads over it touch: its blocker
/// search over the whole cone, in the level where the cone spans at most the smaller
/// cap, and its filter over any penumbra narrower than the cone, in the level where
/// that penumbra spans at most the larger cap (`pcss_virtual.wgsl`); and they ask for
/// no level coarser than the search's.
#[test]
fn cone_requests_hold_the_search_and_every_narrower_filter() {
    let map = clipmap(Vec3::new(2.0, 5.0, 3.0));
    let cone = ConeReach { light_size: 0.05, level_cap_texels: 32.0, reach_cap_texels: 64.0 };
    let reach = 2.0;
    let mut rng = Lcg(31);
    let mut coarser = 0;
    for _ in 0..500 {
        let point = Vec3::new(rng.range(-20.0, 20.0), rng.range(0.0, 10.0), rng.range(-15.0, 15.0));
        let level = (rng.next() * 4.0) as u32;
        let rects = map.cone_requests(point, level, cone, reach);
        let radius = map.cone_radius(point, cone.light_size);
        let search = map.search_level(level, radius, cone.level_cap_texels);
        coarser += usize::from(search > level);
        assert!(rects.iter().all(|r| (level..=search).contains(&r.level)), "{point}: {rects:?}");
        let centre = map.map_xy(point);
        let holds = |l: u32, texels: f32| {
            let Some(page) = map.page_at(l, centre) else { return };
            let rect = rects.iter().find(|r| r.level == l).expect("a rectangle for each level read");
            assert!(rect.contains(page));
            let half = (texels + reach) * map.texel_size(l);
            for corner in
                [Vec2::new(-1.0, -1.0), Vec2::new(1.0, 1.0), Vec2::new(-1.0, 1.0), Vec2::new(1.0, -1.0)]
            {
                let xy = centre + corner * half;
                let page = map.page_at(l, xy);
                assert!(page.is_none_or(|p| rect.contains(p)), "{point}: {xy} outside {rect:?}");
            }
        };
        // The search's taps: the cone in its level's texels, clamped as the shader does.
        let texel = map.texel_size(search);
        holds(search, (radius / texel).clamp(1.0, cone.level_cap_texels) + 1.0);
        for _ in 0..8 {
            let penumbra = radius * rng.next();
            let filter = map.search_level(level, penumbra, cone.reach_cap_texels);
            assert!(filter <= search, "{point}: a filter in {filter}, the search in {search}");
            let texel = map.texel_size(filter);
            holds(filter, (penumbra / texel).clamp(0.5, cone.reach_cap_texels) + 1.0);
        }
    }
    assert!(coarser > 100, "{coarser} cones read a coarser level");
}

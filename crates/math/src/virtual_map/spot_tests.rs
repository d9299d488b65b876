//! A spot's clipmap: a mip chain over its frustum whose pages are drawn where its
//! 2D map would put their texels, whose pixels read the level matching their
//! footprint at their distance from the light, and whose casters dirty the pages
//! under their shadow.

use glam::{Vec2, Vec3};

use super::*;
use crate::{spot_light_projection, test_rng::Lcg};

const NEAR: f32 = 0.1;
const FAR: f32 = 30.0;
/// 30°: the tangent of the frustum's half-angle.
const OUTER: f32 = std::f32::consts::FRAC_PI_6;

fn spot() -> (Clipmap, LightProjection) {
    let (position, direction) = (Vec3::new(1.0, 6.0, 2.0), Vec3::new(0.2, -1.0, -0.1).normalize());
    let projection = spot_light_projection(position, direction, OUTER, NEAR, FAR);
    let map = Clipmap::spot(ClipmapShape::DEFAULT, projection.light_from_world, OUTER.tan(), NEAR, FAR);
    (map, projection)
}

/// A random world point inside the spot's frustum, `min_distance` to 20 along its axis.
fn point_in_frustum(map: &Clipmap, rng: &mut Lcg, min_distance: f32) -> Vec3 {
    let distance = rng.range(min_distance, 20.0);
    let half = OUTER.tan() * distance * 0.999;
    let light = Vec3::new(rng.range(-half, half), rng.range(-half, half), -distance);
    map.light_from_world.inverse().transform_point3(light)
}

#[test]
fn a_spot_clipmap_is_a_mip_chain_over_its_frustum() {
    let (map, _) = spot();
    // 128 pages a side: level 6's are 2 × 2 over the frustum.
    assert_eq!(map.shape.levels, 7);
    for level in 0..map.shape.levels {
        let window = map.level_window(level);
        let pages_across = 2.0 / map.page_size(level);
        for corner in [Vec2::splat(-0.999), Vec2::splat(0.999), Vec2::new(-0.999, 0.999)] {
            assert!(map.page_at(level, corner).is_some(), "level {level}: {corner}");
        }
        assert_eq!(
            map.pages_over(level, Vec2::splat(-1.0), Vec2::splat(0.999)).unwrap().pages().count() as f32,
            pages_across * pages_across,
            "{window:?}"
        );
    }
    assert!(map.layers().iter().all(|layer| map.layer_window(layer) == map.level_window(layer.level)));
    // Level 0 is the frustum in virtual_resolution² texels.
    assert_eq!(map.texel_size(0) * map.shape.virtual_resolution as f32, 2.0);
}

#[test]
fn a_spot_page_is_drawn_where_its_2d_map_puts_its_texels() {
    let (map, projection) = spot();
    let full = projection.clip_from_world();
    let texels = map.shape.page_size as f32;
    let mut rng = Lcg(11);
    for _ in 0..200 {
        let world = point_in_frustum(&map, &mut rng, 0.5);
        let level = (rng.next() * map.shape.levels as f32) as u32;
        let xy = map.map_xy(world);
        let page = map.page_at(level, xy).expect("in the frustum");
        // The 2D map's normalized device coordinates and depth are the map space's.
        let ndc = full.project_point3(world);
        assert!(
            (ndc - map.map_point(world)).abs().max_element() < 1e-4,
            "{ndc} against {}",
            map.map_point(world)
        );
        // The page's projection puts the point at its texel within the page, v down.
        let own = map.page_clip_from_world(page).project_point3(world);
        let drawn = Vec2::new(own.x + 1.0, 1.0 - own.y) * 0.5 * texels;
        let within = xy / map.texel_size(level) - Vec2::new(page.x as f32, page.y as f32) * texels;
        let expected = Vec2::new(within.x, texels - within.y);
        assert!((drawn - expected).length() < 2e-2, "{page:?}: {drawn} against {expected}");
        assert!((own.z - ndc.z).abs() < 1e-5, "depth {} against {}", own.z, ndc.z);
    }
}

#[test]
fn a_spot_texel_grows_with_the_distance_and_a_pixel_reads_the_level_of_its_footprint() {
    let (map, projection) = spot();
    let mut rng = Lcg(5);
    for _ in 0..200 {
        let world = point_in_frustum(&map, &mut rng, 0.5);
        let distance = -map.light_from_world.transform_point3(world).z;
        let texel_world = map.texel_size(0) * map.world_per_map(world);
        let resolution = map.shape.virtual_resolution;
        assert!((texel_world - projection.texel_world_size(resolution, distance)).abs() < 1e-4 * texel_world);
        assert_reads_the_level_of_its_footprint(&map, world, rng.range(0.2, 40.0) * texel_world);
    }
}

/// A pixel at `world` whose footprint is `footprint` world units reads texels no
/// larger than it and more than half as large, at its own distance from the light
/// (but at level 0 and at the coarsest level).
pub(super) fn assert_reads_the_level_of_its_footprint(map: &Clipmap, world: Vec3, footprint: f32) {
    let level = map.level_for_footprint(map.map_footprint(world, footprint));
    let read = map.texel_size(level) * map.world_per_map(world);
    let coarsest = level == map.shape.levels - 1;
    assert!(read <= footprint * 1.0001 || level == 0, "{read} > {footprint}");
    assert!(2.0 * read > footprint * 0.9999 || coarsest, "level {level}: {read} ≪ {footprint}");
}

#[test]
fn a_spot_sees_only_its_frustum_and_asks_for_nothing_elsewhere() {
    let (map, _) = spot();
    let from_light = |p: Vec3| map.light_from_world.inverse().transform_point3(p);
    let behind = from_light(Vec3::new(0.1, 0.1, 3.0));
    let aside = from_light(Vec3::new(8.0, 0.0, -5.0));
    let inside = from_light(Vec3::new(0.5, -0.3, -5.0));
    assert!(!map.sees(behind) && !map.sees(aside) && map.sees(inside));
    assert!(map.request(behind, 0.01, 2.0).is_none() && map.request(aside, 0.01, 2.0).is_none());
    let rect = map.request(inside, 0.01, 2.0).expect("inside the frustum");
    let level = map.level_for_footprint(map.map_footprint(inside, 0.01));
    assert_eq!(rect.level, level);
    // Every texel the filter reaches lies in the rectangle.
    let xy = map.map_xy(inside);
    let reach = 2.0 * map.texel_size(level);
    for tap in [xy - Vec2::splat(reach), xy + Vec2::splat(reach), xy] {
        assert!(rect.contains(map.page_at(level, tap).expect("in the window")), "{tap}");
    }
}

#[test]
fn a_caster_dirties_the_spot_pages_under_its_shadow() {
    let (map, _) = spot();
    let mut rng = Lcg(9);
    for _ in 0..100 {
        let centre = point_in_frustum(&map, &mut rng, 1.0);
        let half = rng.vec(0.05, 0.6);
        let caster = Aabb::new(centre - half, centre + half);
        let level = (rng.next() * map.shape.levels as f32) as u32;
        let [rect] = map.pages_under(level, &caster)[..] else { continue };
        for _ in 0..50 {
            let p = caster.min + (caster.max - caster.min) * Vec3::new(rng.next(), rng.next(), rng.next());
            if let Some(page) = map.sees(p).then(|| map.page_at(level, map.map_xy(p))).flatten() {
                assert!(rect.contains(page), "{page:?} outside {rect:?}");
            }
        }
    }
    // A caster across the near plane may shadow anything.
    let at_light = map.light_from_world.inverse().transform_point3(Vec3::new(0.0, 0.0, -0.05));
    let straddling = Aabb::new(at_light - Vec3::splat(0.2), at_light + Vec3::splat(0.2));
    assert_eq!(map.pages_under(3, &straddling), vec![map.level_window(3)]);
}

#[test]
fn a_spot_cone_is_measured_on_its_near_plane_in_map_units() {
    let (map, _) = spot();
    let radius = 0.25;
    let world = map.light_from_world.inverse().transform_point3(Vec3::new(0.0, 0.0, -8.0));
    // Similar triangles: the disk's radius shrinks to r (d − n) / d at the near plane,
    // whose half-width is tan(outer) · n.
    let expected = radius * (8.0 - NEAR) / 8.0 / (OUTER.tan() * NEAR);
    assert!((map.cone_radius(world, radius) - expected).abs() < 1e-4 * expected);
}

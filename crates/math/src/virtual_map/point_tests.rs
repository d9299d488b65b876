//! A point light's clipmap: six spot-like mip chains, one a cube face, side by side
//! in one map space; each point read in the face its direction falls in, at the
//! depth a 2D cube map of the light stores; its pages drawn where the lookup reads
//! them; no request or dirty rectangle crossing a face's slot.

use glam::{Vec2, Vec3};

use super::{cube::CUBE_FACE_TAN_HALF_FOV, *};
use crate::{
    omni::{CubeFace, cube_face_projections},
    test_rng::Lcg,
};

const NEAR: f32 = 0.05;
const FAR: f32 = 40.0;
const POSITION: Vec3 = Vec3::new(1.0, 3.0, -2.0);

fn point_light() -> Clipmap {
    Clipmap::point(ClipmapShape::DEFAULT, POSITION, NEAR, FAR)
}

/// A random world point `min_distance` to 20 from the light, in any direction.
fn point_around(rng: &mut Lcg, min_distance: f32) -> Vec3 {
    let direction = (rng.vec(-1.0, 1.0) + Vec3::splat(1e-3)).normalize();
    POSITION + direction * rng.range(min_distance, 20.0)
}

#[test]
fn a_point_clipmap_holds_six_mip_chains_whose_borders_are_page_borders() {
    let map = point_light();
    // 128 pages a side: a face is 32 pages across at level 0, 2 at level 4.
    assert_eq!(map.shape.levels, 5);
    assert_eq!(map.texel_size(0) * map.shape.virtual_resolution as f32, 8.0);
    let layers = map.layers();
    assert_eq!(layers.len(), 6 * 5);
    for (i, rect) in layers.iter().enumerate() {
        let level = (i / 6) as u32;
        let across = (rect.max - rect.min + IVec2::ONE).as_vec2() * map.page_size(level);
        assert_eq!(across, Vec2::splat(2.0), "layer {i}: {rect:?}");
        assert!(map.level_window(level).contains(PageKey { level, x: rect.min.x, y: rect.min.y }));
        // Its window is a level's size round the slot; a level's window is its own.
        let window = map.layer_window(rect);
        assert_eq!(window.max - window.min, map.level_window(level).max - map.level_window(level).min);
        assert!(rect.pages().all(|p| window.contains(p)));
        // No two faces share a page.
        for other in &layers[i + 1..] {
            assert!(other.level != rect.level || rect.pages().all(|p| !other.contains(p)), "{i}");
        }
    }
}

#[test]
fn a_point_is_read_in_its_face_at_the_depth_of_a_2d_cube_map() {
    let map = point_light();
    let cube = cube_face_projections(POSITION, NEAR, FAR);
    let texels = map.shape.page_size as f32;
    let mut rng = Lcg(3);
    for _ in 0..400 {
        let world = point_around(&mut rng, 0.2);
        let face = CubeFace::of_direction(world - POSITION);
        let at = map.map_point(world);
        // The 2D cube map's face stores the same depth: both are the perspective depth
        // of the distance along the face's axis.
        let stored = cube[face.layer() as usize].clip_from_world().project_point3(world).z;
        assert!((at.z - stored).abs() < 1e-5, "depth {} against {stored}", at.z);
        // The face's own directions keep clear of its slot's guard band.
        let within = at.truncate() - cube::face_slot(face);
        assert!(within.abs().max_element() <= 1.0 / CUBE_FACE_TAN_HALF_FOV + 1e-5, "{within}");
        // The layer's projection draws the point where its lookup reads it, v down.
        let level = (rng.next() * map.shape.levels as f32) as u32;
        let page = map.page_at(level, at.truncate()).expect("in the window");
        let own = map.page_clip_from_world(page).project_point3(world);
        let drawn = Vec2::new(own.x + 1.0, 1.0 - own.y) * 0.5 * texels;
        let within = at.truncate() / map.texel_size(level) - Vec2::new(page.x as f32, page.y as f32) * texels;
        let expected = Vec2::new(within.x, texels - within.y);
        assert!((drawn - expected).length() < 2e-2, "{face:?} {page:?}: {drawn} against {expected}");
        assert!((own.z - stored).abs() < 1e-5);
        let layer = map.layers()[map.layer_of(level, world)];
        assert!(layer.contains(page), "{page:?} outside its face's layer {layer:?}");
    }
}

#[test]
fn a_point_texel_grows_with_the_distance_along_its_faces_axis() {
    let map = point_light();
    let mut rng = Lcg(8);
    for _ in 0..200 {
        let world = point_around(&mut rng, 0.2);
        let axis = (world - POSITION).abs().max_element();
        let texel_world = map.texel_size(0) * map.world_per_map(world);
        let expected = CUBE_FACE_TAN_HALF_FOV * axis * 8.0 / map.shape.virtual_resolution as f32;
        assert!((texel_world - expected).abs() < 1e-4 * expected, "{texel_world} against {expected}");
        super::spot_tests::assert_reads_the_level_of_its_footprint(
            &map,
            world,
            rng.range(0.2, 20.0) * texel_world,
        );
    }
}

#[test]
fn a_point_near_a_faces_border_asks_only_for_pages_of_its_face() {
    let map = point_light();
    let mut rng = Lcg(21);
    for _ in 0..300 {
        // Directions near an edge or a corner of the cube.
        let mut d = Vec3::new(1.0, rng.range(0.97, 1.0), rng.range(-1.0, 1.0));
        d *= Vec3::new(rng.range(-1.0, 1.0).signum(), rng.range(-1.0, 1.0).signum(), 1.0);
        let world = POSITION + d.normalize() * rng.range(0.5, 15.0);
        let footprint = rng.range(1e-4, 0.5);
        let rect = map.request(world, footprint, 12.0).expect("a point light sees every point");
        let layer = map.layers()[map.layer_of(rect.level, world)];
        assert!(rect.pages().all(|p| layer.contains(p)), "{rect:?} leaves {layer:?}");
        // Within the coarsest level's guard band, the reach fits in the slot.
        let xy = map.map_xy(world);
        let face = CubeFace::of_direction(world - POSITION);
        let slack = 1.0 - (xy - cube::face_slot(face)).abs().max_element();
        let guard = 14.0 * map.texel_size(map.shape.levels - 1);
        assert!(slack >= guard, "{slack} < {guard}");
    }
    assert!(!map.sees(POSITION) && map.sees(POSITION + Vec3::new(0.0, -1.0, 0.0)));
}

#[test]
fn a_caster_dirties_the_pages_under_its_shadow_in_every_face() {
    let map = point_light();
    let mut rng = Lcg(13);
    for _ in 0..100 {
        let centre = point_around(&mut rng, 1.5);
        let half = rng.vec(0.05, 1.2);
        let caster = Aabb::new(centre - half, centre + half);
        let level = (rng.next() * map.shape.levels as f32) as u32;
        let rects = map.pages_under(level, &caster);
        assert!(rects.len() <= 6);
        for _ in 0..50 {
            let p = caster.min + (caster.max - caster.min) * Vec3::new(rng.next(), rng.next(), rng.next());
            let page = map.page_at(level, map.map_xy(p)).expect("in the window");
            assert!(rects.iter().any(|r| r.contains(page)), "{page:?} outside {rects:?}");
        }
        let layers = map.layers();
        for rect in &rects {
            assert!(layers.iter().any(|l| rect.pages().all(|p| l.contains(p))), "{rect:?} crosses a slot");
        }
    }
    // A caster round the light may shadow anything, in every face.
    let round = Aabb::new(POSITION - Vec3::splat(0.2), POSITION + Vec3::splat(0.2));
    let expected: Vec<_> = map.layers().into_iter().filter(|l| l.level == 2).collect();
    assert_eq!(map.pages_under(2, &round), expected);
    // A caster within one face's frustum, reaching across others' near planes
    // outside their frusta, shadows only that face.
    let ahead = Aabb::new(POSITION + Vec3::new(2.0, -0.1, -0.1), POSITION + Vec3::new(2.5, 0.1, 0.1));
    assert_eq!(map.pages_under(0, &ahead).len(), 1);
}

#[test]
fn a_point_cone_is_measured_on_its_faces_near_plane() {
    let map = point_light();
    let radius = 0.1;
    let world = POSITION + Vec3::new(0.5, -6.0, 1.0);
    let expected = radius * (6.0 - NEAR) / 6.0 / (CUBE_FACE_TAN_HALF_FOV * NEAR);
    assert!((map.cone_radius(world, radius) - expected).abs() < 1e-4 * expected);
}

#[test]
fn each_face_is_drawn_through_a_rotation_looking_along_its_axis() {
    let map = point_light();
    for face in CubeFace::ALL {
        let frame = map.face_frame(face);
        // A rotation, not a mirror: pages are drawn with any map's winding.
        let rotation = glam::Mat3::from_mat4(frame.view_from_world);
        assert!((rotation.determinant() - 1.0).abs() < 1e-6, "{face:?}");
        // Its view looks down −z at the face's own directions.
        let ahead =
            POSITION + crate::omni::cube_face_view(face, POSITION).inverse().transform_vector3(-Vec3::Z);
        assert!(frame.view_from_world.transform_point3(ahead).abs_diff_eq(-Vec3::Z, 1e-5), "{face:?}");
    }
}

#[test]
fn a_run_of_pages_starts_at_every_faces_left_border() {
    let map = point_light();
    for level in 0..map.shape.levels {
        let window = map.level_window(level);
        for x in window.min.x..=window.max.x {
            let page = PageKey { level, x, y: 0 };
            if !map.layers().iter().any(|l| l.contains(page)) {
                continue;
            }
            let starts = map.layers().iter().any(|l| l.level == level && l.min.x == x);
            assert_eq!(map.starts_layer(page), starts, "{page:?}");
        }
    }
    assert!(!Clipmap::spot(ClipmapShape::DEFAULT, Mat4::IDENTITY, 1.0, NEAR, FAR).starts_layer(PageKey {
        level: 0,
        x: 0,
        y: 0
    }));
}

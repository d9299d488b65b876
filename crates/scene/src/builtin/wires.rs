//! `wires`: casters thinner than a shadow map's texel. Overhead wires, a railing
//! and a row of poles, 4 mm thick, over a ground under a sun 50° up: at the
//! default map's resolution each is a fraction of a texel wide, so the map's
//! rasterization, which stores a caster only where it covers a texel's centre,
//! keeps some of them in broken dashes and loses others whole. The scene the
//! touched layer (`gnomon-render`'s `rays/touched.rs`) is tested on.

use glam::{Mat4, Quat, Vec3};

use super::{GROUND, SceneBuilder, at, point, spot, sun};
use crate::{Camera, Scene, geometry};

/// The casters' thickness, in metres.
pub const WIRE_THICKNESS: f32 = 0.004;

/// Wires in four directions (0°, 3°, 45° and 80° about the vertical, so that some
/// run along the map's texel rows and some across them), 1.2 to 2.6 m up; a railing
/// with balusters every 0.15 m; a row of poles. All 4 mm thick.
pub fn wires() -> Scene {
    let mut b = SceneBuilder::new();
    let ground = b.mesh(geometry::plane(30.0, 30.0));
    let grey = b.material("ground", GROUND);
    let metal = b.material("metal", Vec3::new(0.35, 0.35, 0.4));
    b.place("ground", ground, grey, Mat4::IDENTITY);
    let half = 0.5 * WIRE_THICKNESS;
    let wire = b.mesh(geometry::cuboid(Vec3::new(6.0, half, half)));
    for (set, degrees) in [0.0f32, 3.0, 45.0, 80.0].into_iter().enumerate() {
        let turn = Quat::from_rotation_y(degrees.to_radians());
        for k in 0..3 {
            let lift = 1.2 + 0.35 * set as f32 + 0.1 * k as f32;
            let along = Vec3::new(0.0, lift, -3.0 + 1.7 * set as f32 + 0.45 * k as f32);
            let world_from_object = Mat4::from_rotation_translation(turn, turn * along);
            b.place(&format!("wire {degrees}° {k}"), wire, metal, world_from_object);
        }
    }
    // A railing 1 m high along x at z = 3.5: a top rail and balusters.
    let rail = b.mesh(geometry::cuboid(Vec3::new(3.0, half, half)));
    b.place("rail", rail, metal, at(Vec3::new(-1.0, 1.0, 3.5)));
    let baluster = b.mesh(geometry::cuboid(Vec3::new(half, 0.5, half)));
    for i in 0..40 {
        b.place(&format!("baluster {i}"), baluster, metal, at(Vec3::new(-3.925 + 0.15 * i as f32, 0.5, 3.5)));
    }
    // Poles 2 m high, a metre apart, on a diagonal.
    let pole = b.mesh(geometry::cuboid(Vec3::new(half, 1.0, half)));
    for i in 0..6 {
        let x = 2.5 + 0.7 * i as f32;
        b.place(&format!("pole {i}"), pole, metal, at(Vec3::new(x, 1.0, 1.5 - 0.7 * i as f32)));
    }
    let camera = Camera {
        eye: Vec3::new(0.5, 5.5, 8.5),
        target: Vec3::new(0.0, 0.0, -0.5),
        up: Vec3::Y,
        fov_y_degrees: 50.0,
        near: 0.1,
        far: 60.0,
    };
    b.finish(
        "wires",
        camera,
        super::defaults(
            sun(50.0, 30.0),
            spot(Vec3::new(-3.0, 7.0, 4.0), Vec3::new(0.0, 0.0, 0.0), 45.0, 30.0),
            point(Vec3::new(0.5, 3.2, 0.5), 20.0),
        ),
    )
}

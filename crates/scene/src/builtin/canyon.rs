//! `canyon`: a street canyon under a low sun. Two rows of tall closed boxes
//! (buildings 12 to 80 m high, some with a setback tower) line a street 12 m wide
//! and 300 m long, with alleys between some of them; the sun stands 15° up, across
//! the street, and the camera 2 m above the road looks along it. The buildings'
//! shadows cross the street, and the light through each alley lies on the road and
//! the far walls in sharp wedges beside the buildings' bases: the case issue 76 found
//! a virtual map alone leaking light in (a wedge of light by a tall box's base),
//! and where a map fitted to the whole street spreads its texels thin.

use glam::Vec3;
use gnomon_math::hash::unit_from_hash;

use super::{GROUND, SceneBuilder, at, point, spot, sun};
use crate::{Camera, Scene, geometry};

/// Half the street's width, kerb to kerb, in metres.
const STREET_HALF_WIDTH: f32 = 6.0;
/// How far the street runs from the camera's end, in metres.
const STREET_LENGTH: f32 = 300.0;

/// A deterministic value in [0, 1) from `n`, so that the buildings are the same in
/// every build: the scene is a test fixture.
fn unit(n: u32) -> f32 {
    unit_from_hash(n.wrapping_mul(0x9e37_79b9) ^ 0x85eb_ca6b)
}

/// Buildings along both sides of the street, each a closed box on the ground
/// (about one in three with a narrower tower on it), with an alley 2–5 m wide
/// after about one in three.
pub fn canyon() -> Scene {
    let mut b = SceneBuilder::new();
    let ground = b.mesh(geometry::plane(500.0, 900.0));
    let grey = b.material("ground", GROUND);
    let walls = [
        b.material("brick", Vec3::new(0.62, 0.45, 0.38)),
        b.material("stone", Vec3::new(0.70, 0.68, 0.62)),
        b.material("render", Vec3::new(0.80, 0.76, 0.66)),
    ];
    b.place("ground", ground, grey, at(Vec3::new(0.0, 0.0, -0.5 * STREET_LENGTH)));
    let mut n = 0u32;
    for side in [-1.0f32, 1.0] {
        let mut z = 10.0f32;
        while z > -STREET_LENGTH {
            n += 1;
            let width = 10.0 + 14.0 * unit(4 * n);
            let depth = 14.0 + 10.0 * unit(4 * n + 1);
            let height = 12.0 + 68.0 * unit(4 * n + 2);
            let shape = unit(4 * n + 3);
            let half = Vec3::new(0.5 * depth, 0.5 * height, 0.5 * width);
            let centre = Vec3::new(side * (STREET_HALF_WIDTH + half.x), half.y, z - half.z);
            let block = b.mesh(geometry::cuboid(half));
            let material = walls[(n % 3) as usize];
            b.place(&format!("building {n}"), block, material, at(centre));
            if shape < 0.35 {
                // A tower set back from the street, half as wide, up to as high again.
                let tower_half = Vec3::new(0.3 * depth, 0.5 * height * (0.4 + shape), 0.25 * width);
                let tower_centre = Vec3::new(centre.x + side * 0.15 * depth, height + tower_half.y, centre.z);
                let tower = b.mesh(geometry::cuboid(tower_half));
                b.place(&format!("tower {n}"), tower, material, at(tower_centre));
            }
            let alley = if shape > 0.65 { 2.0 + 3.0 * unit(7 * n) } else { 0.0 };
            z -= width + alley;
        }
    }
    let camera = Camera {
        eye: Vec3::new(1.5, 2.0, 0.0),
        target: Vec3::new(-0.5, 7.0, -60.0),
        up: Vec3::Y,
        fov_y_degrees: 60.0,
        near: 0.1,
        far: 800.0,
    };
    let lights = super::defaults(
        sun(15.0, 20.0),
        spot(Vec3::new(4.0, 9.0, -12.0), Vec3::new(-2.0, 0.0, -22.0), 40.0, 40.0),
        point(Vec3::new(-4.0, 5.0, -30.0), 30.0),
    );
    b.finish("canyon", camera, lights)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_street_stays_clear_and_its_buildings_stand_on_the_ground() {
        let scene = canyon();
        assert!(scene.instances.len() > 30, "{} instances", scene.instances.len());
        for instance in scene.instances.iter().filter(|i| i.name != "ground") {
            let centre = instance.world_from_object.w_axis.truncate();
            let half = scene.meshes[instance.mesh].bounds().max;
            assert!(
                centre.x.abs() - half.x >= STREET_HALF_WIDTH - 1e-3,
                "{} stands in the street",
                instance.name
            );
            assert!(centre.y - half.y >= -1e-3, "{} is under the ground", instance.name);
        }
    }
}

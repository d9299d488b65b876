//! Built-in procedural scenes. Each is selectable by name on the command line and is
//! also a test fixture, so their geometry is exact and documented.

use glam::{Mat4, Vec3};

mod canyon;
mod lamps;
mod wires;

pub use canyon::canyon;
pub use lamps::{MAX_LAMPS, lamp_grid, lamps};
pub use wires::{WIRE_THICKNESS, wires};

use crate::{
    Camera, DirectionalLight, Falloff, Instance, Material, Mesh, PointLight, Scene, SceneLight, SpotLight,
    geometry, sun_direction,
};

/// A built-in scene: its name, what it shows, and how to build it.
pub struct Builtin {
    /// The name that selects it on the command line and in scene files (`builtin = "NAME"`).
    pub name: &'static str,
    /// One line on what the scene shows and what it tests, as the CLI's list of scenes prints it.
    pub description: &'static str,
    /// Builds the scene, deterministically: the built-ins double as test fixtures.
    pub build: fn() -> Scene,
}

/// Every built-in scene. The first is the default.
pub const BUILTINS: &[Builtin] = &[
    Builtin {
        name: "spheres",
        description: "a box and nine spheres on a ground plane: the classic test scene",
        build: spheres,
    },
    Builtin {
        name: "contact",
        description: "objects resting on the ground, thin walls and a narrow gap: peter-panning and leaks",
        build: contact,
    },
    Builtin {
        name: "grazing",
        description: "a large plane lit at a grazing angle with a few casters: shadow acne",
        build: grazing,
    },
    Builtin {
        name: "columns",
        description: "a long ground with rows of columns far from the camera: a large depth range",
        build: columns,
    },
    Builtin {
        name: "wires",
        description: "wires, a railing and poles 4 mm thick over a ground: casters thinner than a map's texel",
        build: wires,
    },
    Builtin {
        name: "canyon",
        description: "a street canyon of tall buildings under a sun 15° up, seen from 2 m above the road: \
                      long shadows across a street and wedges of light through its alleys",
        build: canyon,
    },
    Builtin {
        name: "lamps",
        description: "a courtyard lit by eight shadowed lights at once: a sun, three spots and four point lights; \
                      `lamps:N` for a grid of N shadowed point lights on posts (1 to 64): lighting's cost per light",
        build: lamps,
    },
    Builtin {
        name: "instances",
        description: "10 000 small objects, 90% of them far outside the view and the light's frustum; \
                      `instances:N` for N of them (10 to 4 000 000): submission scaling",
        build: || instances(DEFAULT_INSTANCES),
    },
];

/// The `instances` scene's object count when none is given.
pub const DEFAULT_INSTANCES: usize = 10_000;
/// The most objects `instances:N` builds. The renderer keeps 112 bytes of instance
/// data each in one storage buffer; lavapipe binds 128 MiB of it (1.19 million), and
/// uploading more than a device binds fails with an error that says so.
pub const MAX_INSTANCES: usize = 4_000_000;

/// A built-in scene that cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BuiltinError {
    /// No built-in scene has this name.
    #[error("no built-in scene is called `{0}`")]
    Unknown(String),
    /// `instances:N` with N not a count in range.
    #[error(
        "`instances:{0}`: N must be a whole number from 10 to {MAX_INSTANCES} (a device binds fewer: \
         the renderer says how many when it cannot take them)"
    )]
    InstancesOutOfRange(String),
    /// `lamps:N` with N not a count in range.
    #[error("`lamps:{0}`: N must be a whole number from 1 to {MAX_LAMPS} (the most lights a frame takes)")]
    LampsOutOfRange(String),
}

/// Builds the built-in scene called `name` (`instances:N` for N objects, `lamps:N`
/// for N lamps).
pub fn build(name: &str) -> Result<Scene, BuiltinError> {
    if let Some(text) = name.strip_prefix("instances:") {
        let count = text.replace('_', "").parse::<usize>().ok().filter(|n| (10..=MAX_INSTANCES).contains(n));
        return count.map(instances).ok_or_else(|| BuiltinError::InstancesOutOfRange(text.into()));
    }
    if let Some(text) = name.strip_prefix("lamps:") {
        let count = text.parse::<usize>().ok().filter(|n| (1..=MAX_LAMPS).contains(n));
        return count.map(lamp_grid).ok_or_else(|| BuiltinError::LampsOutOfRange(text.into()));
    }
    BUILTINS
        .iter()
        .find(|b| b.name == name)
        .map(|b| (b.build)())
        .ok_or_else(|| BuiltinError::Unknown(name.into()))
}

/// The names of all built-in scenes, for error messages and help.
pub fn names() -> Vec<&'static str> {
    BUILTINS.iter().map(|b| b.name).collect()
}

/// Incremental construction of a procedural scene.
struct SceneBuilder {
    meshes: Vec<Mesh>,
    materials: Vec<Material>,
    instances: Vec<Instance>,
}

impl SceneBuilder {
    fn new() -> Self {
        Self { meshes: Vec::new(), materials: Vec::new(), instances: Vec::new() }
    }

    fn mesh(&mut self, mesh: Mesh) -> usize {
        self.meshes.push(mesh);
        self.meshes.len() - 1
    }

    fn material(&mut self, name: &str, base_color: Vec3) -> usize {
        self.materials.push(Material::new(name, base_color));
        self.materials.len() - 1
    }

    fn place(&mut self, name: &str, mesh: usize, material: usize, world_from_object: Mat4) {
        self.instances.push(Instance {
            name: name.into(),
            mesh,
            material,
            world_from_object,
            casts_shadow: true,
            motion: crate::Motion::Static,
        });
    }

    fn finish(self, name: &str, camera: Camera, lights: Vec<SceneLight>) -> Scene {
        Scene {
            name: name.into(),
            meshes: self.meshes,
            materials: self.materials,
            instances: self.instances,
            camera,
            lights,
            ambient: Vec3::splat(0.12),
            textures: Vec::new(),
            has_ground: true,
        }
    }
}

/// A teaching scene's lights: a default of each kind, and no list.
fn defaults(sun: DirectionalLight, spot: SpotLight, point: PointLight) -> Vec<SceneLight> {
    vec![
        SceneLight::default_of_kind(sun),
        SceneLight::default_of_kind(spot),
        SceneLight::default_of_kind(point),
    ]
}

fn sun(elevation_degrees: f32, azimuth_degrees: f32) -> DirectionalLight {
    DirectionalLight {
        direction: -sun_direction(elevation_degrees, azimuth_degrees),
        color: Vec3::new(1.0, 0.97, 0.92),
        intensity: 1.0,
        angular_diameter_degrees: 0.0,
    }
}

fn spot(position: Vec3, target: Vec3, outer_degrees: f32, range: f32) -> SpotLight {
    SpotLight {
        position,
        direction: (target - position).normalize(),
        inner_angle_degrees: 0.8 * outer_degrees,
        outer_angle_degrees: outer_degrees,
        range,
        color: Vec3::new(1.0, 0.95, 0.85),
        intensity: 1.0,
        falloff: Falloff::Constant,
        radius: 0.0,
    }
}

fn point(position: Vec3, range: f32) -> PointLight {
    PointLight {
        position,
        range,
        color: Vec3::new(1.0, 0.93, 0.8),
        intensity: 1.0,
        falloff: Falloff::Constant,
        radius: 0.0,
    }
}

fn at(p: Vec3) -> Mat4 {
    Mat4::from_translation(p)
}

const GROUND: Vec3 = Vec3::new(0.72, 0.72, 0.70);

/// A 24 × 24 ground, a 2 × 2 × 2 box and nine spheres of radius 0.55 to 0.95 in a
/// 3 × 3 grid: the left column rests on the ground, the others float 0.5 and 1.5 above it.
pub fn spheres() -> Scene {
    let mut b = SceneBuilder::new();
    let ground = b.mesh(geometry::plane(24.0, 24.0));
    let cube = b.mesh(geometry::cuboid(Vec3::ONE));
    let grey = b.material("ground", GROUND);
    let box_mat = b.material("box", Vec3::new(0.75, 0.45, 0.25));
    b.place("ground", ground, grey, Mat4::IDENTITY);
    b.place("box", cube, box_mat, at(Vec3::new(-6.0, 1.0, -4.0)) * Mat4::from_rotation_y(0.5));
    let palette = [Vec3::new(0.8, 0.2, 0.2), Vec3::new(0.2, 0.65, 0.3), Vec3::new(0.2, 0.4, 0.85)];
    for (row, z) in [-3.0f32, 0.0, 3.0].into_iter().enumerate() {
        for (col, x) in [-3.0f32, 0.0, 3.0].into_iter().enumerate() {
            let radius = 0.55 + 0.2 * row as f32;
            let lift = [0.0, 0.5, 1.5][col];
            let mesh = b.mesh(geometry::uv_sphere(radius, 48, 24));
            let mat = b.material(&format!("sphere {row}{col}"), palette[(row + col) % 3]);
            b.place(&format!("sphere {row},{col}"), mesh, mat, at(Vec3::new(x, radius + lift, z)));
        }
    }
    let camera = Camera {
        eye: Vec3::new(2.0, 9.0, 14.0),
        target: Vec3::new(-0.5, 0.6, 0.0),
        up: Vec3::Y,
        fov_y_degrees: 45.0,
        near: 0.1,
        far: 100.0,
    };
    // The point light hangs among the spheres, between the centre one and its
    // neighbours, so that its shadows fall in every direction.
    b.finish(
        "spheres",
        camera,
        defaults(
            sun(48.0, 35.0),
            spot(Vec3::new(4.0, 9.0, 5.0), Vec3::ZERO, 40.0, 30.0),
            point(Vec3::new(1.5, 2.2, 1.5), 30.0),
        ),
    )
}

/// Objects resting exactly on the ground (y = 0): a 2 × 1 × 2 box, a unit sphere, a
/// cylinder, a 0.04-thick wall, and two 1.5 m cubes with a 0.1 m gap between them.
pub fn contact() -> Scene {
    let mut b = SceneBuilder::new();
    let ground = b.mesh(geometry::plane(16.0, 16.0));
    let grey = b.material("ground", GROUND);
    let warm = b.material("warm", Vec3::new(0.8, 0.5, 0.3));
    let cool = b.material("cool", Vec3::new(0.3, 0.5, 0.8));
    let green = b.material("green", Vec3::new(0.35, 0.7, 0.35));
    b.place("ground", ground, grey, Mat4::IDENTITY);
    let slab = b.mesh(geometry::cuboid(Vec3::new(1.0, 0.5, 1.0)));
    b.place("box", slab, warm, at(Vec3::new(-3.5, 0.5, 0.0)));
    let ball = b.mesh(geometry::uv_sphere(1.0, 48, 24));
    b.place("sphere", ball, cool, at(Vec3::new(0.0, 1.0, -2.5)));
    let post = b.mesh(geometry::cylinder(0.5, 2.0, 32));
    b.place("cylinder", post, green, at(Vec3::new(3.0, 0.0, -3.0)));
    let wall = b.mesh(geometry::cuboid(Vec3::new(1.5, 0.75, 0.02)));
    b.place("thin wall", wall, warm, at(Vec3::new(0.5, 0.75, 2.0)));
    let cube = b.mesh(geometry::cuboid(Vec3::splat(0.75)));
    b.place("gap cube left", cube, cool, at(Vec3::new(3.0, 0.75, 1.5)));
    b.place("gap cube right", cube, cool, at(Vec3::new(3.0 + 1.6, 0.75, 1.5)));
    let camera = Camera {
        eye: Vec3::new(0.0, 6.0, 10.0),
        target: Vec3::new(0.0, 0.3, 0.0),
        up: Vec3::Y,
        fov_y_degrees: 50.0,
        near: 0.1,
        far: 60.0,
    };
    b.finish(
        "contact",
        camera,
        defaults(
            sun(35.0, 200.0),
            spot(Vec3::new(-2.0, 6.0, -5.0), Vec3::new(0.0, 0.0, 0.5), 45.0, 25.0),
            point(Vec3::new(0.5, 2.5, 0.0), 20.0),
        ),
    )
}

/// An 80 × 80 plane under a sun 6° above the horizon, with three 3 m posts and a box.
pub fn grazing() -> Scene {
    let mut b = SceneBuilder::new();
    let ground = b.mesh(geometry::plane(80.0, 80.0));
    let grey = b.material("ground", GROUND);
    let warm = b.material("warm", Vec3::new(0.8, 0.55, 0.3));
    b.place("ground", ground, grey, Mat4::IDENTITY);
    let post = b.mesh(geometry::cuboid(Vec3::new(0.2, 1.5, 0.2)));
    for (i, x) in [-6.0f32, 0.0, 6.0].into_iter().enumerate() {
        b.place(&format!("post {i}"), post, warm, at(Vec3::new(x, 1.5, -2.0 - 2.0 * i as f32)));
    }
    let block = b.mesh(geometry::cuboid(Vec3::new(1.5, 1.0, 1.5)));
    b.place("block", block, warm, at(Vec3::new(-10.0, 1.0, 4.0)));
    let camera = Camera {
        eye: Vec3::new(0.0, 7.0, 22.0),
        target: Vec3::new(0.0, 0.0, -2.0),
        up: Vec3::Y,
        fov_y_degrees: 50.0,
        near: 0.1,
        far: 200.0,
    };
    b.finish(
        "grazing",
        camera,
        defaults(
            sun(6.0, 250.0),
            spot(Vec3::new(-18.0, 2.5, 6.0), Vec3::new(0.0, 0.0, -2.0), 35.0, 60.0),
            point(Vec3::new(-3.0, 1.0, 1.0), 40.0),
        ),
    )
}

/// A 20 × 400 ground running along −z with two rows of 6 m columns every 8 m, seen
/// from one end: a depth range of several hundred metres.
pub fn columns() -> Scene {
    let mut b = SceneBuilder::new();
    let ground = b.mesh(geometry::plane(20.0, 400.0));
    let grey = b.material("ground", GROUND);
    let stone = b.material("stone", Vec3::new(0.78, 0.74, 0.66));
    b.place("ground", ground, grey, at(Vec3::new(0.0, 0.0, -195.0)));
    let column = b.mesh(geometry::cylinder(0.5, 6.0, 24));
    for i in 0..48 {
        let z = -8.0 * i as f32;
        b.place(&format!("column L{i}"), column, stone, at(Vec3::new(-5.0, 0.0, z)));
        b.place(&format!("column R{i}"), column, stone, at(Vec3::new(5.0, 0.0, z)));
    }
    let camera = Camera {
        eye: Vec3::new(0.0, 2.0, 6.0),
        target: Vec3::new(0.0, 1.5, -40.0),
        up: Vec3::Y,
        fov_y_degrees: 60.0,
        near: 0.1,
        far: 500.0,
    };
    b.finish(
        "columns",
        camera,
        defaults(
            sun(40.0, 60.0),
            spot(Vec3::new(0.0, 8.0, -10.0), Vec3::new(0.0, 0.0, -22.0), 50.0, 40.0),
            point(Vec3::new(0.0, 4.0, -20.0), 30.0),
        ),
    )
}

/// `count` small objects (boxes, spheres and cylinders in three colours: nine
/// batches) for scaling tests. A tenth of them stand on a 40 × 48 rectangle the
/// camera sees whole (at any aspect from 1:1), shrunk as they crowd it; the other nine
/// tenths stand on a ring 150 to 400 from its centre, beyond the camera's far plane: outside the view and, since
/// a light's map is fitted to what the camera sees, outside every light frustum. The
/// layout is a fixed pseudo-random sequence, the same on every run.
pub fn instances(count: usize) -> Scene {
    let mut b = SceneBuilder::new();
    let ground = b.mesh(geometry::plane(820.0, 820.0));
    let grey = b.material("ground", GROUND);
    b.place("ground", ground, grey, Mat4::IDENTITY);
    let meshes = [
        b.mesh(geometry::cuboid(Vec3::splat(0.4))),
        b.mesh(geometry::uv_sphere(0.45, 8, 5)),
        b.mesh(geometry::cylinder(0.3, 1.0, 8)),
    ];
    let materials = [
        b.material("warm", Vec3::new(0.8, 0.5, 0.3)),
        b.material("cool", Vec3::new(0.3, 0.5, 0.8)),
        b.material("green", Vec3::new(0.35, 0.7, 0.35)),
    ];
    let near_count = count / 10;
    // Objects of about 0.8 shrink so that 1 000 of them cover the near square as
    // sparsely as any larger number does.
    let scale = (1000.0 / near_count.max(1) as f32).sqrt().min(1.0);
    // A 64-bit LCG (Knuth's MMIX constants): no dependency, the same everywhere.
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    b.instances.reserve(count);
    for i in 0..count {
        let (position, size) = if i < near_count {
            (Vec3::new(40.0 * uniform() - 20.0, 0.0, 48.0 * uniform() - 24.0), scale)
        } else {
            let angle = std::f32::consts::TAU * uniform();
            // Uniform over the ring's area.
            let radius = (150.0f32.powi(2) + uniform() * (400.0f32.powi(2) - 150.0f32.powi(2))).sqrt();
            (Vec3::new(radius * angle.cos(), 0.0, radius * angle.sin()), 1.0)
        };
        let kind = i % 3;
        // Boxes and spheres rest on the ground; cylinders start at it.
        let lift = [0.4, 0.45, 0.0][kind] * size;
        let world_from_object = Mat4::from_scale_rotation_translation(
            Vec3::splat(size),
            glam::Quat::from_rotation_y(std::f32::consts::TAU * uniform()),
            position + Vec3::Y * lift,
        );
        b.instances.push(Instance {
            name: format!("object {i}"),
            mesh: meshes[kind],
            material: materials[(i / 3) % 3],
            world_from_object,
            casts_shadow: true,
            motion: crate::Motion::Static,
        });
    }
    let camera = Camera {
        eye: Vec3::new(0.0, 30.0, 50.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_degrees: 60.0,
        near: 0.1,
        far: 95.0,
    };
    let name =
        if count == DEFAULT_INSTANCES { "instances".to_string() } else { format!("instances:{count}") };
    b.finish(
        &name,
        camera,
        defaults(
            sun(50.0, 30.0),
            spot(Vec3::new(0.0, 18.0, 10.0), Vec3::ZERO, 50.0, 60.0),
            point(Vec3::new(0.0, 4.0, 0.0), 30.0),
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_builds_and_validates() {
        for b in BUILTINS {
            let scene = (b.build)();
            assert_eq!(scene.name, b.name);
            scene.validate().unwrap();
            assert!(scene.triangle_count() > 0);
            assert!((scene.light::<DirectionalLight>().unwrap().direction.length() - 1.0).abs() < 1e-5);
            assert!(
                scene.light::<DirectionalLight>().unwrap().direction.y < 0.0,
                "{}: the sun shines downward",
                b.name
            );
        }
        assert_eq!(build("no-such-scene").unwrap_err(), BuiltinError::Unknown("no-such-scene".into()));
    }

    #[test]
    fn a_non_finite_transform_is_refused_naming_the_instance() {
        let mut scene = spheres();
        scene.instances[1].world_from_object.w_axis.x = f32::NAN;
        let name = scene.instances[1].name.clone();
        let e = scene.validate().unwrap_err().to_string();
        assert!(e.contains(&format!("instance `{name}`")) && e.contains("non-finite transform"), "{e}");
    }

    #[test]
    fn instances_takes_its_count_and_keeps_nine_tenths_far_away() {
        assert_eq!(build("instances").unwrap().instances.len(), 1 + DEFAULT_INSTANCES);
        let scene = build("instances:2_000").unwrap();
        assert_eq!(scene.name, "instances:2000");
        assert_eq!(scene.instances.len(), 1 + 2000, "a ground and the objects");
        let far = scene.instances[1..]
            .iter()
            .filter(|i| i.world_from_object.w_axis.truncate().length() >= 150.0)
            .count();
        assert_eq!(far, 1800);
        for i in &scene.instances[1..] {
            let lowest = scene.meshes[i.mesh].bounds().transformed(i.world_from_object).min.y;
            assert!(lowest.abs() < 1e-4, "{} floats at {lowest}", i.name);
        }
        for bad in ["instances:", "instances:9", "instances:-5", "instances:many", "instances:4000001"] {
            let e = build(bad).unwrap_err();
            assert!(matches!(e, BuiltinError::InstancesOutOfRange(_)), "{bad}: {e}");
            assert!(e.to_string().contains("10 to 4000000"), "{e}");
        }
    }

    #[test]
    fn lamps_n_lights_each_point_of_its_ground_by_the_same_few_lamps() {
        for count in [1, 8, 32, 64] {
            let scene = build(&format!("lamps:{count}")).unwrap();
            scene.validate().unwrap();
            assert_eq!(scene.name, format!("lamps:{count}"));
            assert_eq!(scene.listed_lights().count(), count);
            let lamps: Vec<PointLight> = scene
                .listed_lights()
                .map(|l| match l.light {
                    crate::Light::Point(p) => p,
                    other => panic!("{}: {other:?} is not a lamp", l.name),
                })
                .collect();
            // Every point of the ground among the lamps sees a few of them, the same
            // few whatever their number.
            let (lo, hi) = lamps
                .iter()
                .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), l| (lo.min(l.position), hi.max(l.position)));
            let mut seen = (usize::MAX, 0);
            for i in 0..=40 {
                for j in 0..=40 {
                    let t = Vec3::new(i as f32 / 40.0, 0.0, j as f32 / 40.0);
                    let p = Vec3::new(lo.x, 0.0, lo.z) + t * (hi - lo) * Vec3::new(1.0, 0.0, 1.0);
                    let n = lamps.iter().filter(|l| l.position.distance(p) <= l.range).count();
                    seen = (seen.0.min(n), seen.1.max(n));
                }
            }
            assert!(seen.0 >= 1 && seen.1 <= 6, "lamps:{count}: ground points see {seen:?} lamps");
        }
        for bad in ["lamps:", "lamps:0", "lamps:65", "lamps:x"] {
            let e = build(bad).unwrap_err();
            assert!(matches!(e, BuiltinError::LampsOutOfRange(_)), "{bad}: {e}");
            assert!(e.to_string().contains("1 to 64"), "{e}");
        }
    }

    #[test]
    fn contact_objects_rest_on_the_ground() {
        let scene = contact();
        for i in scene.instances.iter().skip(1) {
            let lowest = scene.meshes[i.mesh].bounds().transformed(i.world_from_object).min.y;
            assert!(lowest.abs() < 1e-5, "{} floats at {lowest}", i.name);
        }
    }

    #[test]
    fn a_ground_is_added_once_and_never_to_a_built_in() {
        let mut scene = spheres();
        let n = scene.instances.len();
        scene.add_ground_plane();
        assert_eq!(scene.instances.len(), n, "the built-ins have a ground");
        scene.has_ground = false;
        scene.add_ground_plane();
        scene.add_ground_plane();
        assert_eq!(scene.instances.len(), n + 1, "added once");
        let ground = scene.instances.last().unwrap();
        assert_eq!(ground.world_from_object.transform_point3(Vec3::ZERO).y, scene.bounds().min.y);
    }

    #[test]
    fn grazing_sun_is_six_degrees_up() {
        let d = grazing().light::<DirectionalLight>().unwrap().direction;
        assert!(((-d.y).asin().to_degrees() - 6.0).abs() < 1e-3);
    }
}

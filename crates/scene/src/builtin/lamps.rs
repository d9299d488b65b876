//! The many-light built-ins: `lamps`, a courtyard under eight lights of every kind,
//! and `lamps:N`, a grid of N shadowed point lights, for how lighting's cost grows
//! with the number of lights.

use glam::{Mat4, Vec3};

use super::{GROUND, SceneBuilder, at, point, spot, sun};
use crate::{
    Camera, Falloff, PointLight, Scene, SceneLight, geometry,
    settings::{FilterSettingsPatch, MAX_LIGHTS, MapSettingsPatch, Partition, ShadowOverrides, Technique},
};

/// The most lamps `lamps:N` places: as many as one frame lights.
pub const MAX_LAMPS: usize = MAX_LIGHTS;

/// Metres between neighbouring lamps of `lamps:N`.
const LAMP_SPACING: f32 = 6.0;
/// A lamp's range, in spacings: it reaches its four nearest neighbours' posts but not
/// the diagonal ones (√2 spacings away), so a point of the ground among the lamps is
/// lit by one to six of them however many there are (tested).
const LAMP_REACH: f32 = 1.25;

/// A grid of `count` point lights (1 to [`MAX_LAMPS`]), ⌈√count⌉ to a row and
/// 6 m apart, each 2.4 m up above a 1.8 m post with a crate beside it, all
/// shadowed (cube maps of 256², the scene's default technique) and of equal
/// range: the ground sees the same few lamps at every point, so the lit work per
/// pixel stays the same as lamps are added while their count grows. The camera
/// frames the whole grid from above one edge. The scene for the cost of lighting per
/// light: `--light all`.
pub fn lamp_grid(count: usize) -> Scene {
    let count = count.clamp(1, MAX_LAMPS);
    let columns = (count as f32).sqrt().ceil() as usize;
    let rows = count.div_ceil(columns);
    let extent = Vec3::new(columns as f32, 0.0, rows as f32) * LAMP_SPACING;
    let mut b = SceneBuilder::new();
    let ground = b.mesh(geometry::plane(extent.x + LAMP_SPACING, extent.z + LAMP_SPACING));
    let grey = b.material("ground", GROUND);
    let stone = b.material("stone", Vec3::new(0.78, 0.74, 0.66));
    let wood = b.material("wood", Vec3::new(0.7, 0.5, 0.3));
    b.place("ground", ground, grey, Mat4::IDENTITY);
    let post = b.mesh(geometry::cuboid(Vec3::new(0.15, 0.9, 0.15)));
    let crate_mesh = b.mesh(geometry::cuboid(Vec3::splat(0.5)));
    // Warm and cool lamps in turn, so that overlapping pools stay distinguishable.
    let palette = [Vec3::new(1.0, 0.8, 0.55), Vec3::new(0.6, 0.8, 1.0), Vec3::new(0.9, 1.0, 0.7)];
    let mut lamps = Vec::with_capacity(count);
    for i in 0..count {
        let cell = Vec3::new((i % columns) as f32 + 0.5, 0.0, (i / columns) as f32 + 0.5);
        let base = cell * LAMP_SPACING - 0.5 * extent;
        b.place(&format!("post {i}"), post, stone, at(base + Vec3::new(0.0, 0.9, 0.0)));
        let beside = base + Vec3::new(0.3 * LAMP_SPACING, 0.5, 0.2 * LAMP_SPACING);
        b.place(&format!("crate {i}"), crate_mesh, wood, at(beside) * Mat4::from_rotation_y(0.37 * i as f32));
        lamps.push(lamp(
            point(base + Vec3::new(0.0, 2.4, 0.0), LAMP_REACH * LAMP_SPACING),
            palette[i % palette.len()],
        ));
    }
    let size = extent.x.max(extent.z);
    let camera = Camera {
        eye: Vec3::new(0.0, 0.7 * size + 4.0, 0.5 * extent.z + 0.45 * size + 5.0),
        target: Vec3::new(0.0, 0.0, 0.05 * extent.z),
        up: Vec3::Y,
        fov_y_degrees: 50.0,
        near: 0.1,
        far: 4.0 * size + 40.0,
    };
    // The lamps are the list, and `--light point` draws the first of them; the sun
    // and the spot are defaults, the spot hung at the first lamp and aimed at the centre.
    let first = lamps[0];
    let mut lights: Vec<SceneLight> = lamps
        .into_iter()
        .enumerate()
        .map(|(i, lamp)| SceneLight {
            shadow: Some(ShadowOverrides {
                map: MapSettingsPatch { resolution: Some(256), ..Default::default() },
                ..Default::default()
            }),
            ..SceneLight::listed(format!("lamp {i}"), lamp)
        })
        .collect();
    lights.push(SceneLight::default_of_kind(sun(50.0, 30.0)));
    lights.push(SceneLight::default_of_kind(spot(first.position, Vec3::ZERO, 40.0, first.range)));
    let mut scene = b.finish(&format!("lamps:{count}"), camera, lights);
    scene.ambient = Vec3::splat(0.05);
    scene
}

/// A lamp: a point light of physical falloff (glTF's `KHR_lights_punctual`,
/// windowed to 0 at its range) of 5 cd: it lights the ground 2.4 m below it at
/// 5 / 2.4² = 0.87 and the foot of a neighbouring post in `lamps:N`, 6 m along, at
/// 0.02, where the old constant lamp lit both alike and stopped at a hard rim.
fn lamp(mut light: PointLight, color: Vec3) -> PointLight {
    light.color = color;
    light.intensity = 5.0;
    light.falloff = Falloff::InverseSquare { window: Some(light.range) };
    light
}

/// A 30 × 30 courtyard with a ring of 3 m pillars, crates and spheres, lit by eight
/// shadowed lights of every type at once, each with its own shadow settings: a low
/// sun with cascades, three spot lights and four coloured point lights (lamps) among
/// the objects. The scene for many lights: `--light all`.
pub fn lamps() -> Scene {
    let mut b = SceneBuilder::new();
    let ground = b.mesh(geometry::plane(30.0, 30.0));
    let grey = b.material("ground", GROUND);
    let stone = b.material("stone", Vec3::new(0.78, 0.74, 0.66));
    let wood = b.material("wood", Vec3::new(0.7, 0.5, 0.3));
    let blue = b.material("blue", Vec3::new(0.3, 0.45, 0.8));
    b.place("ground", ground, grey, Mat4::IDENTITY);
    let pillar = b.mesh(geometry::cuboid(Vec3::new(0.35, 1.5, 0.35)));
    for i in 0..8 {
        let angle = i as f32 * std::f32::consts::FRAC_PI_4;
        let p = Vec3::new(7.0 * angle.cos(), 1.5, 7.0 * angle.sin());
        b.place(&format!("pillar {i}"), pillar, stone, at(p));
    }
    let crate_mesh = b.mesh(geometry::cuboid(Vec3::splat(0.6)));
    for (i, p) in [Vec3::new(-2.5, 0.6, 1.0), Vec3::new(2.0, 0.6, -2.5), Vec3::new(3.0, 0.6, 3.0)]
        .into_iter()
        .enumerate()
    {
        b.place(&format!("crate {i}"), crate_mesh, wood, at(p) * Mat4::from_rotation_y(0.4 * i as f32));
    }
    let ball = b.mesh(geometry::uv_sphere(0.8, 40, 20));
    b.place("sphere 0", ball, blue, at(Vec3::new(0.0, 0.8, 0.0)));
    b.place("sphere 1", ball, blue, at(Vec3::new(-4.0, 0.8, -3.0)));
    let camera = Camera {
        eye: Vec3::new(0.0, 11.0, 16.0),
        target: Vec3::new(0.0, 0.5, 0.0),
        up: Vec3::Y,
        fov_y_degrees: 50.0,
        near: 0.1,
        far: 80.0,
    };
    // Every kind is listed, so `--light sun`, `spot` and `point` draw the first of each.
    let mut scene = b.finish("lamps", camera, courtyard_lights());
    scene.ambient = Vec3::splat(0.06);
    scene
}

/// The courtyard's eight lights, each with its own technique (and map resolution
/// where it sets one): a low sun with cascades, three coloured spots and four lamps,
/// the spots and lamps of physical falloff.
fn courtyard_lights() -> Vec<SceneLight> {
    // Each light's own technique, and map resolution when it has one.
    let own = |technique: Technique, resolution: Option<u32>| ShadowOverrides {
        filter: FilterSettingsPatch { technique: Some(technique), ..Default::default() },
        map: MapSettingsPatch { resolution, ..Default::default() },
        ..Default::default()
    };
    let mut sun_light = sun(25.0, 140.0);
    sun_light.intensity = 0.35;
    let spots = [
        (Vec3::new(-8.0, 6.0, 8.0), Vec3::new(-2.0, 0.0, 1.0), Vec3::new(1.0, 0.6, 0.6)),
        (Vec3::new(8.0, 6.0, 8.0), Vec3::new(2.0, 0.0, -1.0), Vec3::new(0.6, 1.0, 0.6)),
        (Vec3::new(0.0, 7.0, -9.0), Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.6, 0.7, 1.0)),
    ];
    let points = [
        (Vec3::new(-3.0, 2.2, 3.5), Vec3::new(1.0, 0.75, 0.4)),
        (Vec3::new(3.5, 2.0, 0.5), Vec3::new(0.5, 0.8, 1.0)),
        (Vec3::new(0.5, 2.5, -4.0), Vec3::new(1.0, 0.5, 0.8)),
        (Vec3::new(-5.0, 1.8, -0.5), Vec3::new(0.7, 1.0, 0.5)),
    ];
    let mut lights = vec![SceneLight {
        shadow: Some(ShadowOverrides {
            partition: Some(Partition::Cascades),
            ..own(Technique::PCF_POISSON, None)
        }),
        ..SceneLight::listed("sun", sun_light)
    }];
    for (i, (position, target, color)) in spots.into_iter().enumerate() {
        let mut s = spot(position, target, 38.0, 25.0);
        s.color = color;
        // 50 cd: about the old constant 0.5 at the 10 m from lamp to courtyard.
        s.intensity = 50.0;
        s.falloff = Falloff::InverseSquare { window: Some(s.range) };
        let technique = [Technique::PCF, Technique::PCSS, Technique::HARD][i].clone();
        let resolution = if technique == Technique::PCSS {
            s.radius = 0.3;
            None
        } else {
            Some(1024)
        };
        lights.push(SceneLight {
            shadow: Some(own(technique, resolution)),
            ..SceneLight::listed(format!("spot {i}"), s)
        });
    }
    for (i, (position, color)) in points.into_iter().enumerate() {
        let technique =
            [Technique::PCF2X2, Technique::PCF_POISSON, Technique::PCF, Technique::PCSS][i].clone();
        let mut p = lamp(point(position, 22.0), color);
        if technique == Technique::PCSS {
            p.radius = 0.15;
        }
        lights.push(SceneLight {
            shadow: Some(own(technique, Some(512))),
            ..SceneLight::listed(format!("lamp {i}"), p)
        });
    }
    lights
}

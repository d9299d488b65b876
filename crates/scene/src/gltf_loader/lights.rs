//! A glTF file's `KHR_lights_punctual` lights as Gnomon's: the extension's units and
//! distance falloff kept ([`Falloff::InverseSquare`]), its cones fitted to what a
//! spot's map covers, and the lights a file without its own gets.
//!
//! Units: a directional light's intensity is illuminance in lux, a point or spot
//! light's is luminous intensity in candela, and scene units are metres. Gnomon shades
//! one lux of illuminance on a white surface as 1, the brightness of its own sun of
//! intensity 1, so a sun of 3 lux shows as a sun of intensity 3 and a 100 cd lamp lights
//! a surface 10 m away, facing it, as a sun of intensity 1 would (docs/lights.md).

use glam::{Mat4, Vec3};
use gltf::khr_lights_punctual::Kind;

use crate::{DirectionalLight, Falloff, Light, PointLight, SpotLight, lights::Origin, sun_direction};

/// The light a file's `light` becomes where a node of world transform `world` places
/// it; None where the node's transform leaves it no direction. A light without a
/// `range` gets an infinite one, which [`give_range`] replaces once the scene's
/// bounds are known. `warnings` gets a note for a cone wider than a spot's map.
pub(super) fn from_file(
    light: &gltf::khr_lights_punctual::Light,
    world: Mat4,
    warnings: &mut Vec<String>,
) -> Option<Light> {
    let color = Vec3::from_array(light.color());
    let intensity = light.intensity();
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    // The extension's window is at its range; a light without one has none.
    let falloff = Falloff::InverseSquare { window: light.range() };
    let range = light.range().unwrap_or(f32::INFINITY);
    match light.kind() {
        Kind::Directional => (direction != Vec3::ZERO).then_some(Light::Directional(DirectionalLight {
            direction,
            color,
            intensity,
            angular_diameter_degrees: 0.0,
        })),
        Kind::Spot { inner_cone_angle, outer_cone_angle } => {
            if direction == Vec3::ZERO {
                return None;
            }
            // glTF allows cones up to 90°; a spot's perspective map covers 89°.
            let outer = outer_cone_angle.to_degrees().clamp(1.0, 89.0);
            if outer != outer_cone_angle.to_degrees() {
                warnings.push(format!(
                    "light {}: its outer cone of {:.2}° is drawn as {outer}° (a spot's map covers 1° to 89°)",
                    light.index(),
                    outer_cone_angle.to_degrees()
                ));
            }
            Some(Light::Spot(SpotLight {
                position,
                direction,
                inner_angle_degrees: inner_cone_angle.to_degrees().clamp(0.0, outer),
                outer_angle_degrees: outer,
                range,
                color,
                intensity,
                falloff,
                radius: 0.0,
            }))
        }
        Kind::Point => {
            Some(Light::Point(PointLight { position, range, color, intensity, falloff, radius: 0.0 }))
        }
    }
}

/// A spot or point light without a range (an infinite one) gets `reach(position)`,
/// which the loader makes reach past everything the file holds; the range is also the
/// shadow map's far plane, so it must be finite. The falloff keeps no window.
pub(super) fn give_range(light: &mut Light, reach: impl Fn(Vec3) -> f32) {
    let Origin::Local { position, .. } = light.emission().origin else {
        return;
    };
    if let Some(range) = light.range_mut()
        && !range.is_finite()
    {
        *range = reach(position);
    }
}

/// The sun of a file without one: Gnomon's own, of intensity 1 (no falloff).
pub(super) fn default_sun() -> DirectionalLight {
    DirectionalLight {
        direction: -sun_direction(45.0, 30.0),
        color: Vec3::new(1.0, 0.97, 0.92),
        intensity: 1.0,
        angular_diameter_degrees: 0.0,
    }
}

/// The spot of a file without one, before the loader places it over the bounds:
/// Gnomon's teaching light, of constant falloff.
pub(super) fn default_spot() -> SpotLight {
    SpotLight {
        position: Vec3::ONE,
        direction: Vec3::NEG_Y,
        inner_angle_degrees: 28.0,
        outer_angle_degrees: 35.0,
        range: 10.0,
        color: Vec3::new(1.0, 0.95, 0.85),
        intensity: 1.0,
        falloff: Falloff::Constant,
        radius: 0.0,
    }
}

/// The point light of a file without one, before the loader places it.
pub(super) fn default_point() -> PointLight {
    PointLight {
        position: Vec3::ONE,
        range: 10.0,
        color: Vec3::new(1.0, 0.93, 0.8),
        intensity: 1.0,
        falloff: Falloff::Constant,
        radius: 0.0,
    }
}

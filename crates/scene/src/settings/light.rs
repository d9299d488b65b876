//! Which light casts the shadows, its overrides of the scene's light, and how the
//! lights of a render are resolved with their own shadow settings.

use super::*;
use crate::lights::KindType;
use crate::{DirectionalLight, PointLight, SpotLight};

/// Which of the scene's lights is rendered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum LightKind {
    /// The scene's directional light (sun), with an orthographic shadow map fitted to the scene.
    #[default]
    Sun,
    /// The scene's spot light, with a perspective shadow map covering its cone.
    Spot,
    /// The scene's point light, with a cube shadow map (six 90° faces).
    Point,
    /// Every light of the scene's light list at once (scene files' `[[light]]`,
    /// glTF KHR_lights_punctual, the built-in `lamps`), each with its own shadow map
    /// and shadow settings.
    All,
}

/// The light, and overrides of the scene's light parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[serde(default, deny_unknown_fields)]
pub struct LightSettings {
    /// Which light casts the shadows.
    #[cfg_attr(feature = "cli", arg(long = "light", value_enum, default_value_t, help_heading = "Light"))]
    pub kind: LightKind,
    /// Sun elevation above the horizon in degrees, in (0, 90] [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long, value_name = "DEGREES", help_heading = "Light"))]
    pub sun_elevation: Option<f32>,
    /// Sun azimuth in degrees, measured from +z toward +x [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long, value_name = "DEGREES", help_heading = "Light"))]
    pub sun_azimuth: Option<f32>,
    /// Spot light position, as X,Y,Z [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, help_heading = "Light"))]
    pub spot_position: Option<Vec3>,
    /// Point the spot light aims at, as X,Y,Z [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, help_heading = "Light"))]
    pub spot_target: Option<Vec3>,
    /// Spot cone outer half-angle in degrees, in (0, 89]: no light outside it [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long, value_name = "DEGREES", help_heading = "Light"))]
    pub spot_outer_angle: Option<f32>,
    /// Spot cone inner half-angle in degrees, in [0, outer]: full light inside it [default: 80% of outer].
    #[cfg_attr(feature = "cli", arg(long, value_name = "DEGREES", help_heading = "Light"))]
    pub spot_inner_angle: Option<f32>,
    /// Spot light range in world units, > 0; also the shadow map's far plane [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long, value_name = "DISTANCE", help_heading = "Light"))]
    pub spot_range: Option<f32>,
    /// Radius of the spot light's emitting disk in world units, ≥ 0; 0 is a point
    /// light with hard shadows [default: the scene's, 0 for the built-ins].
    #[cfg_attr(feature = "cli", arg(long, value_name = "DISTANCE", help_heading = "Light"))]
    pub spot_radius: Option<f32>,
    /// Angular diameter of the sun's disk in degrees, in [0, 30]; 0 gives hard
    /// shadows, the real sun is about 0.53 [default: the scene's, 0 for the built-ins].
    #[cfg_attr(feature = "cli", arg(long, value_name = "DEGREES", help_heading = "Light"))]
    pub sun_angular_diameter: Option<f32>,
    /// Point light position, as X,Y,Z [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, help_heading = "Light"))]
    pub point_position: Option<Vec3>,
    /// Point light range in world units, > 0; also the cube faces' far plane [default: the scene's].
    #[cfg_attr(feature = "cli", arg(long, value_name = "DISTANCE", help_heading = "Light"))]
    pub point_range: Option<f32>,
    /// Radius of the point light's emitting sphere in world units, ≥ 0; 0 gives hard
    /// shadows [default: the scene's, 0 for the built-ins].
    #[cfg_attr(feature = "cli", arg(long, value_name = "DISTANCE", help_heading = "Light"))]
    pub point_radius: Option<f32>,
    /// With --light all: the light whose visibility the frame outputs and the
    /// reference traces, as an index into the scene's light list.
    #[cfg_attr(feature = "cli", arg(long, value_name = "N", default_value_t = 0, help_heading = "Light"))]
    pub light_index: usize,
}

/// One light of a render, with the shadow settings it is drawn with.
#[derive(Clone, Debug, PartialEq)]
pub struct ResolvedLight {
    /// The light's name in the scene's list, or its type for a single light.
    pub name: String,
    /// The light itself, with the settings' overrides applied to a single light; a list light is
    /// used as the scene defines it.
    pub light: Light,
    /// The render's shadow settings with the light's own laid over them.
    pub shadow: ShadowSettings,
    /// How its technique uses shadow rays: [`RayUse::AsSettingsSay`] as resolved
    /// here; the renderer's technique registry states the technique's own.
    pub rays: RayUse,
}

impl Settings {
    /// The light whose visibility a frame outputs and the reference traces: the
    /// scene's light of the chosen kind with these settings' overrides, or with
    /// --light all the one at --light-index.
    pub fn resolve_light(&self, scene: &Scene) -> Result<Light, SettingsError> {
        let l = &self.light;
        Ok(match l.kind {
            LightKind::All => {
                let lights = self.scene_light_list(scene)?;
                check(
                    l.light_index < lights.len(),
                    "light.light_index",
                    l.light_index,
                    format!("below {}, the number of lights scene `{}` lists", lights.len(), scene.name),
                )?;
                lights[l.light_index].light
            }
            LightKind::Point => {
                let mut point = *scene_light::<PointLight>(scene)?;
                point.position = l.point_position.unwrap_or(point.position);
                point.range = l.point_range.unwrap_or(point.range);
                point.radius = l.point_radius.unwrap_or(point.radius);
                Light::Point(point)
            }
            LightKind::Sun => {
                let mut sun = *scene_light::<DirectionalLight>(scene)?;
                if l.sun_elevation.is_some() || l.sun_azimuth.is_some() {
                    let to_sun = -sun.direction;
                    let elevation = to_sun.y.clamp(-1.0, 1.0).asin().to_degrees();
                    let azimuth = to_sun.x.atan2(to_sun.z).to_degrees();
                    sun.direction = -sun_direction(
                        l.sun_elevation.unwrap_or(elevation),
                        l.sun_azimuth.unwrap_or(azimuth),
                    );
                }
                sun.angular_diameter_degrees = l.sun_angular_diameter.unwrap_or(sun.angular_diameter_degrees);
                Light::Directional(sun)
            }
            LightKind::Spot => {
                let mut spot = *scene_light::<SpotLight>(scene)?;
                let target = spot.position + spot.direction;
                spot.position = l.spot_position.unwrap_or(spot.position);
                if l.spot_position.is_some() || l.spot_target.is_some() {
                    let aim = l.spot_target.unwrap_or(target) - spot.position;
                    check(
                        aim.length() > 1e-6,
                        "light.spot_target",
                        "the spot position",
                        "a point different from the spot light's position",
                    )?;
                    spot.direction = aim.normalize();
                }
                if let Some(outer) = l.spot_outer_angle {
                    spot.outer_angle_degrees = outer;
                    spot.inner_angle_degrees = 0.8 * outer;
                }
                if let Some(inner) = l.spot_inner_angle {
                    spot.inner_angle_degrees = inner;
                }
                check(
                    spot.inner_angle_degrees <= spot.outer_angle_degrees,
                    "light.spot_inner_angle",
                    spot.inner_angle_degrees,
                    format!("at most the outer angle {}", spot.outer_angle_degrees),
                )?;
                spot.range = l.spot_range.unwrap_or(spot.range);
                spot.radius = l.spot_radius.unwrap_or(spot.radius);
                Light::Spot(spot)
            }
        })
    }

    /// Every light of the render, each with its shadow settings: the one light of
    /// --light sun, spot or point with these shadow settings, or with --light all the
    /// scene's list, each light's own settings laid over these. Whether a light's
    /// technique can shadow it (a cube map, a paraboloid, a warped map) is the
    /// renderer's technique registry's to say.
    pub fn resolve_lights(&self, scene: &Scene) -> Result<Vec<ResolvedLight>, SettingsError> {
        if self.light.kind != LightKind::All {
            let light = self.resolve_light(scene)?;
            return Ok(vec![ResolvedLight {
                name: light.type_name().into(),
                light,
                shadow: self.shadow.clone(),
                rays: RayUse::AsSettingsSay,
            }]);
        }
        self.resolve_light(scene)?;
        self.scene_light_list(scene)?
            .iter()
            .map(|entry| {
                let shadow = match &entry.shadow {
                    None => self.shadow.clone(),
                    Some(overrides) => {
                        self.shadow.with_overrides(overrides).map_err(|problem| SettingsError {
                            setting: "[light.shadow]",
                            value: entry.name.clone(),
                            valid: problem.to_string(),
                        })?
                    }
                };
                Ok(ResolvedLight {
                    name: entry.name.clone(),
                    light: entry.light,
                    shadow,
                    rays: RayUse::AsSettingsSay,
                })
            })
            .collect()
    }

    fn scene_light_list<'s>(&self, scene: &'s Scene) -> Result<Vec<&'s crate::SceneLight>, SettingsError> {
        let listed: Vec<&crate::SceneLight> = scene.listed_lights().collect();
        check(
            !listed.is_empty(),
            "light.kind",
            "all",
            format!(
                "a scene with a light list; `{}` has none (scene files list [[light]], glTF files KHR_lights_punctual lights, and the built-in `lamps` has eight)",
                scene.name
            ),
        )?;
        check(
            listed.len() <= MAX_LIGHTS,
            "light.kind",
            "all",
            format!("at most {MAX_LIGHTS} lights; `{}` lists {}", scene.name, listed.len()),
        )?;
        Ok(listed)
    }
}

/// The scene's light of kind `K` ([`Scene::light`]), or an error naming the scene.
fn scene_light<K: KindType>(scene: &Scene) -> Result<&K, SettingsError> {
    scene.light::<K>().ok_or_else(|| SettingsError {
        setting: "light.kind",
        value: K::NAME.into(),
        valid: format!("a kind of light scene `{}` has; it has no {} light", scene.name, K::NAME),
    })
}

/// The most lights one render draws: the lighting pass's tile lists hold a bit per
/// light, in `MAX_LIGHTS / 32` words per tile.
pub const MAX_LIGHTS: usize = 64;

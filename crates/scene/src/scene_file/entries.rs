//! The light tables of a scene file (`[sun]`, `[spot]`, `[point]` and `[[light]]`), and
//! how each becomes a [`Light`]: every number checked against [`crate::limits`], and
//! an error naming the key at fault so that it can be located in the file.

use glam::Vec3;
use serde::Deserialize;

use crate::{
    DirectionalLight, Falloff, Light, PointLight, SpotLight, lights::Tint, limits, settings::ShadowOverrides,
    sun_direction,
};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SunEntry {
    elevation: f32,
    azimuth: f32,
    #[serde(default)]
    angular_diameter: f32,
    #[serde(default, deserialize_with = "super::three::optional")]
    color: Option<[f32; 3]>,
    intensity: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SpotEntry {
    #[serde(deserialize_with = "super::three::exact")]
    position: [f32; 3],
    #[serde(deserialize_with = "super::three::exact")]
    target: [f32; 3],
    outer_angle: f32,
    inner_angle: Option<f32>,
    range: f32,
    #[serde(default)]
    radius: f32,
    #[serde(default, deserialize_with = "super::three::optional")]
    color: Option<[f32; 3]>,
    intensity: Option<f32>,
    falloff: Option<FalloffEntry>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct PointEntry {
    #[serde(deserialize_with = "super::three::exact")]
    position: [f32; 3],
    range: f32,
    #[serde(default)]
    radius: f32,
    #[serde(default, deserialize_with = "super::three::optional")]
    color: Option<[f32; 3]>,
    intensity: Option<f32>,
    falloff: Option<FalloffEntry>,
}

/// One `[[light]]`: a sun, spot or point light with the fields of `[sun]`, `[spot]`
/// or `[point]`, and its own shadow settings.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct LightEntry {
    pub name: Option<String>,
    #[serde(rename = "type")]
    kind: String,
    elevation: Option<f32>,
    azimuth: Option<f32>,
    angular_diameter: Option<f32>,
    #[serde(default, deserialize_with = "super::three::optional")]
    position: Option<[f32; 3]>,
    #[serde(default, deserialize_with = "super::three::optional")]
    target: Option<[f32; 3]>,
    outer_angle: Option<f32>,
    inner_angle: Option<f32>,
    range: Option<f32>,
    radius: Option<f32>,
    #[serde(default, deserialize_with = "super::three::optional")]
    color: Option<[f32; 3]>,
    intensity: Option<f32>,
    falloff: Option<FalloffEntry>,
    pub shadow: Option<ShadowOverrides>,
}

/// A spot or point light's `falloff`: `"constant"` (the default: `intensity` is the
/// irradiance everywhere inside `range`) or `"inverse-square"` (glTF's
/// `KHR_lights_punctual`: `intensity` in candela, windowed to 0 at `range`).
#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum FalloffEntry {
    Constant,
    InverseSquare,
}

impl FalloffEntry {
    fn falloff(entry: Option<Self>, range: f32) -> Falloff {
        match entry {
            None | Some(FalloffEntry::Constant) => Falloff::Constant,
            Some(FalloffEntry::InverseSquare) => Falloff::InverseSquare { window: Some(range) },
        }
    }
}

/// What is wrong with a light table: the key at fault (`None` for the table as a
/// whole) and the problem in words.
#[derive(Debug)]
pub(super) struct EntryError {
    pub key: Option<&'static str>,
    pub problem: String,
}

impl From<limits::LimitError> for EntryError {
    fn from(e: limits::LimitError) -> Self {
        EntryError { key: Some(e.quantity), problem: e.to_string() }
    }
}

impl From<&SunEntry> for LightEntry {
    fn from(sun: &SunEntry) -> Self {
        LightEntry {
            kind: "sun".into(),
            elevation: Some(sun.elevation),
            azimuth: Some(sun.azimuth),
            angular_diameter: Some(sun.angular_diameter),
            color: sun.color,
            intensity: sun.intensity,
            ..Default::default()
        }
    }
}

impl From<&SpotEntry> for LightEntry {
    fn from(spot: &SpotEntry) -> Self {
        LightEntry {
            kind: "spot".into(),
            position: Some(spot.position),
            target: Some(spot.target),
            outer_angle: Some(spot.outer_angle),
            inner_angle: spot.inner_angle,
            range: Some(spot.range),
            radius: Some(spot.radius),
            color: spot.color,
            intensity: spot.intensity,
            falloff: spot.falloff,
            ..Default::default()
        }
    }
}

impl From<&PointEntry> for LightEntry {
    fn from(point: &PointEntry) -> Self {
        LightEntry {
            kind: "point".into(),
            position: Some(point.position),
            range: Some(point.range),
            radius: Some(point.radius),
            color: point.color,
            intensity: point.intensity,
            falloff: point.falloff,
            ..Default::default()
        }
    }
}

fn need<T>(v: Option<T>, key: &'static str, shape: &str) -> Result<T, EntryError> {
    v.ok_or_else(|| EntryError { key: None, problem: format!("needs `{key}`{shape}") })
}

fn checked_position(v: Option<[f32; 3]>, key: &'static str) -> Result<Vec3, EntryError> {
    let v = need(v, key, " = [x, y, z]")?;
    Ok(limits::check_vec3(&limits::COORDINATE, key, Vec3::from_array(v))?)
}

impl LightEntry {
    /// The light's type as the file names it (`sun`, `spot`, `point`, or a mistake).
    pub(super) fn kind(&self) -> &str {
        &self.kind
    }

    /// The light this table describes, every number checked, with `fallback`'s colour
    /// and intensity where it gives none.
    pub(super) fn to_light(&self, fallback: Tint) -> Result<Light, EntryError> {
        let color = match self.color {
            Some(c) => limits::check_vec3(&limits::COLOR_CHANNEL, "color", Vec3::from_array(c))?,
            None => fallback.color,
        };
        let intensity = limits::INTENSITY.check("intensity", self.intensity.unwrap_or(fallback.intensity))?;
        let radius = limits::LIGHT_RADIUS.check("radius", self.radius.unwrap_or(0.0))?;
        match self.kind.as_str() {
            "sun" => {
                let elevation =
                    limits::SUN_ELEVATION.check("elevation", need(self.elevation, "elevation", "")?)?;
                let azimuth = limits::SUN_AZIMUTH.check("azimuth", need(self.azimuth, "azimuth", "")?)?;
                let diameter = limits::SUN_ANGULAR_DIAMETER
                    .check("angular_diameter", self.angular_diameter.unwrap_or(0.0))?;
                Ok(Light::Directional(DirectionalLight {
                    direction: -sun_direction(elevation, azimuth),
                    color,
                    intensity,
                    angular_diameter_degrees: diameter,
                }))
            }
            "spot" => {
                let position = checked_position(self.position, "position")?;
                let target = checked_position(self.target, "target")?;
                let outer = limits::SPOT_OUTER_ANGLE
                    .check("outer_angle", need(self.outer_angle, "outer_angle", "")?)?;
                let inner =
                    limits::SPOT_INNER_ANGLE.check("inner_angle", self.inner_angle.unwrap_or(0.8 * outer))?;
                if inner > outer {
                    return Err(EntryError {
                        key: Some("inner_angle"),
                        problem: format!(
                            "`inner_angle` = {inner} is invalid: at most `outer_angle` = {outer}"
                        ),
                    });
                }
                let aim = target - position;
                if aim.length() < 1e-6 {
                    return Err(EntryError {
                        key: Some("target"),
                        problem: "`target` equals `position`: a spot must aim somewhere".into(),
                    });
                }
                let range = limits::LIGHT_RANGE.check("range", need(self.range, "range", "")?)?;
                Ok(Light::Spot(SpotLight {
                    position,
                    direction: aim.normalize(),
                    inner_angle_degrees: inner,
                    outer_angle_degrees: outer,
                    range,
                    color,
                    intensity,
                    falloff: FalloffEntry::falloff(self.falloff, range),
                    radius,
                }))
            }
            "point" => {
                let range = limits::LIGHT_RANGE.check("range", need(self.range, "range", "")?)?;
                Ok(Light::Point(PointLight {
                    position: checked_position(self.position, "position")?,
                    range,
                    color,
                    intensity,
                    falloff: FalloffEntry::falloff(self.falloff, range),
                    radius,
                }))
            }
            other => Err(EntryError {
                key: Some("type"),
                problem: format!("`type` = \"{other}\" is invalid: sun, spot or point"),
            }),
        }
    }
}

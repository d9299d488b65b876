//! Scene files (TOML): glTF models with transforms, the lights, named camera views,
//! and default render settings, in one human-edited file.
//!
//! ```toml
//! builtin = "columns"                    # optional: start from a built-in scene
//! ground = true                          # add a floor under the models
//!
//! [[model]]
//! file = "tree.glb"                      # relative to this file
//! translation = [0.0, 0.0, 0.0]
//! rotation_degrees = [0.0, 45.0, 0.0]    # about x, then y, then z
//! scale = 1.0
//!
//! [sun]
//! elevation = 55.0                       # degrees above the horizon
//! azimuth = 200.0                        # degrees from +z toward +x
//! angular_diameter = 0.53                # degrees; 0 for hard shadows
//!
//! [spot]
//! position = [2.0, 6.0, 1.0]
//! target = [0.0, 0.0, 0.0]
//! outer_angle = 40.0
//! range = 30.0
//! radius = 0.1
//!
//! [point]                              # the default point light (--light point)
//! position = [0.0, 2.5, 0.0]
//! range = 20.0
//! radius = 0.05                          # 0 for hard shadows
//!
//! [[light]]                              # the light list, rendered with --light all
//! name = "lamp"
//! type = "point"                         # sun, spot or point; the fields as above
//! position = [1.0, 2.0, 0.0]
//! range = 12.0
//! color = [1.0, 0.8, 0.6]
//! [light.shadow]                         # this light's shadow settings, over the render's
//! filter.technique = "pcss"
//! map.resolution = 512
//!
//! [[view]]
//! name = "front"
//! eye = [0.0, 3.0, 9.0]
//! target = [0.0, 1.5, 0.0]
//! fov = 45.0
//!
//! [settings.shadow.filter]               # any of the render settings
//! technique = "pcf"
//! ```

use std::path::{Path, PathBuf};

use glam::{EulerRot, Mat4, Quat, Vec3};
use serde::Deserialize;

use crate::{
    Camera, DirectionalLight, Light, PointLight, Scene, SceneLight, Settings, SpotLight, gltf_loader,
    settings::{ShadowOverrides, ShadowSettings},
    sun_direction,
};

/// A scene file that could not be used.
#[derive(Debug, thiserror::Error)]
#[error("{}: {problem}", path.display())]
pub struct SceneFileError {
    /// The scene file (a model it names that fails to load is reported against it too).
    pub path: PathBuf,
    /// What is wrong with it, in words, for the error message.
    pub problem: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    /// A built-in scene to start from; the models are added to it.
    builtin: Option<String>,
    #[serde(default)]
    ground: bool,
    #[serde(default)]
    model: Vec<ModelEntry>,
    sun: Option<SunEntry>,
    spot: Option<SpotEntry>,
    point: Option<PointEntry>,
    #[serde(default)]
    light: Vec<LightEntry>,
    #[serde(default)]
    view: Vec<ViewEntry>,
    settings: Option<toml::Value>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelEntry {
    file: PathBuf,
    #[serde(default)]
    translation: [f32; 3],
    #[serde(default)]
    rotation_degrees: [f32; 3],
    #[serde(default = "one")]
    scale: f32,
}

fn one() -> f32 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SunEntry {
    elevation: f32,
    azimuth: f32,
    #[serde(default)]
    angular_diameter: f32,
    color: Option<[f32; 3]>,
    intensity: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SpotEntry {
    position: [f32; 3],
    target: [f32; 3],
    outer_angle: f32,
    inner_angle: Option<f32>,
    range: f32,
    #[serde(default)]
    radius: f32,
    color: Option<[f32; 3]>,
    intensity: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PointEntry {
    position: [f32; 3],
    range: f32,
    #[serde(default)]
    radius: f32,
    color: Option<[f32; 3]>,
    intensity: Option<f32>,
}

/// One `[[light]]`: a sun, spot or point light with the fields of `[sun]`, `[spot]`
/// or `[point]`, and its own shadow settings.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightEntry {
    name: Option<String>,
    #[serde(rename = "type")]
    kind: String,
    elevation: Option<f32>,
    azimuth: Option<f32>,
    angular_diameter: Option<f32>,
    position: Option<[f32; 3]>,
    target: Option<[f32; 3]>,
    outer_angle: Option<f32>,
    inner_angle: Option<f32>,
    range: Option<f32>,
    radius: Option<f32>,
    color: Option<[f32; 3]>,
    intensity: Option<f32>,
    shadow: Option<ShadowOverrides>,
}

impl LightEntry {
    /// The light this entry describes, or what is wrong with it.
    fn to_light(&self, defaults: &Scene) -> Result<Light, String> {
        let need = |v: Option<f32>, field: &str| v.ok_or_else(|| format!("needs `{field}`"));
        let need3 = |v: Option<[f32; 3]>, field: &str| {
            v.map(Vec3::from_array).ok_or_else(|| format!("needs `{field}` = [x, y, z]"))
        };
        let color = |fallback: Vec3| self.color.map_or(fallback, Vec3::from_array);
        let positive = |v: f32, field: &str, valid: &str| {
            if v.is_finite() && v > 0.0 { Ok(v) } else { Err(format!("`{field}` = {v} is invalid: {valid}")) }
        };
        let radius = self.radius.unwrap_or(0.0);
        if !(radius.is_finite() && radius >= 0.0) {
            return Err(format!("`radius` = {radius} is invalid: a distance ≥ 0"));
        }
        match self.kind.as_str() {
            "sun" => {
                let elevation = need(self.elevation, "elevation")?;
                if !(elevation > 0.0 && elevation <= 90.0) {
                    return Err(format!("`elevation` = {elevation} is invalid: in (0, 90] degrees"));
                }
                Ok(Light::Directional(DirectionalLight {
                    direction: -sun_direction(elevation, need(self.azimuth, "azimuth")?),
                    color: color(defaults.sun.color),
                    intensity: self.intensity.unwrap_or(1.0),
                    angular_diameter_degrees: self.angular_diameter.unwrap_or(0.0),
                }))
            }
            "spot" => {
                let position = need3(self.position, "position")?;
                let outer = need(self.outer_angle, "outer_angle")?;
                if !(outer > 0.0 && outer <= 89.0) {
                    return Err(format!("`outer_angle` = {outer} is invalid: in (0, 89] degrees"));
                }
                let aim = need3(self.target, "target")? - position;
                if aim.length() < 1e-6 {
                    return Err("`target` equals `position`: a spot must aim somewhere".into());
                }
                Ok(Light::Spot(SpotLight {
                    position,
                    direction: aim.normalize(),
                    inner_angle_degrees: self.inner_angle.unwrap_or(0.8 * outer).min(outer),
                    outer_angle_degrees: outer,
                    range: positive(need(self.range, "range")?, "range", "a distance > 0")?,
                    color: color(defaults.spot.color),
                    intensity: self.intensity.unwrap_or(1.0),
                    radius,
                }))
            }
            "point" => Ok(Light::Point(PointLight {
                position: need3(self.position, "position")?,
                range: positive(need(self.range, "range")?, "range", "a distance > 0")?,
                color: color(defaults.point.color),
                intensity: self.intensity.unwrap_or(1.0),
                radius,
            })),
            other => Err(format!("`type` = \"{other}\" is invalid: sun, spot or point")),
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ViewEntry {
    name: String,
    eye: [f32; 3],
    target: [f32; 3],
    fov: Option<f32>,
    near: Option<f32>,
    far: Option<f32>,
}

/// A loaded scene file: the scene, with the chosen view as its camera, and the
/// file's default settings (a TOML table in the shape of [`Settings`]).
pub struct LoadedSceneFile {
    /// The scene: the built-in start, the models placed, the file's lights, and the chosen view
    /// as its camera. Already validated.
    pub scene: Scene,
    /// The names of the file's `[[view]]`s, in file order (for listing, and for `--view`).
    pub view_names: Vec<String>,
    /// The file's `[settings]` table, already checked against [`Settings`]; the command line's
    /// values are laid over it. `None` when the file has none.
    pub settings: Option<toml::Value>,
}

/// Loads the scene file at `path`, using the view called `view` (or the first).
pub fn load(path: &Path, view: Option<&str>) -> Result<LoadedSceneFile, SceneFileError> {
    let fail = |problem: String| SceneFileError { path: path.to_path_buf(), problem };
    let text = std::fs::read_to_string(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let file: SceneFile = toml::from_str(&text).map_err(|e| fail(e.to_string()))?;
    if file.model.is_empty() && file.builtin.is_none() {
        return Err(fail(
            "lists no models: add at least one [[model]] with a `file`, or start from a built-in \
             scene with `builtin = \"NAME\"`"
                .into(),
        ));
    }
    if let Some(table) = &file.settings {
        // Check the settings now, so that a typo is reported against this file.
        table.clone().try_into::<Settings>().map_err(|e| fail(format!("[settings]: {e}")))?;
    }
    let base = path.parent().unwrap_or(Path::new("."));
    let mut scene: Option<Scene> = match &file.builtin {
        Some(name) => Some(crate::builtin::build(name).ok_or_else(|| {
            fail(format!(
                "builtin = {name:?}: no such built-in scene; choose one of {}",
                crate::builtin::names().join(", ")
            ))
        })?),
        None => None,
    };
    for model in &file.model {
        let model_path = base.join(&model.file);
        let (loaded, _) = gltf_loader::load(&model_path).map_err(|e| fail(format!("model: {e}")))?;
        let [rx, ry, rz] = model.rotation_degrees.map(f32::to_radians);
        let world_from_model = Mat4::from_scale_rotation_translation(
            Vec3::splat(model.scale),
            Quat::from_euler(EulerRot::ZYX, rz, ry, rx),
            Vec3::from_array(model.translation),
        );
        if !world_from_model.is_finite() || model.scale <= 0.0 {
            return Err(fail(format!(
                "model `{}`: the transform must be finite with a scale > 0",
                model.file.display()
            )));
        }
        match &mut scene {
            None => {
                let mut first = loaded;
                for inst in &mut first.instances {
                    inst.world_from_object = world_from_model * inst.world_from_object;
                }
                scene = Some(first);
            }
            Some(s) => s.append(loaded, world_from_model),
        }
    }
    let mut scene = scene.expect("a built-in scene or at least one model");
    scene.name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
    let bounds = scene.bounds();
    if file.builtin.is_none() {
        // glTF models placed by a scene file bring no camera: frame them all.
        scene.camera = crate::framing::default_camera(&scene);
    }
    if file.ground {
        scene.add_ground_plane();
    }
    if let Some(sun) = &file.sun {
        scene.sun.direction = -sun_direction(sun.elevation, sun.azimuth);
        scene.sun.angular_diameter_degrees = sun.angular_diameter;
        scene.sun.color = sun.color.map(Vec3::from_array).unwrap_or(scene.sun.color);
        scene.sun.intensity = sun.intensity.unwrap_or(scene.sun.intensity);
    }
    if let Some(spot) = &file.spot {
        let position = Vec3::from_array(spot.position);
        scene.spot = SpotLight {
            position,
            direction: (Vec3::from_array(spot.target) - position).normalize_or(Vec3::NEG_Y),
            inner_angle_degrees: spot.inner_angle.unwrap_or(0.8 * spot.outer_angle),
            outer_angle_degrees: spot.outer_angle,
            range: spot.range,
            color: spot.color.map(Vec3::from_array).unwrap_or(scene.spot.color),
            intensity: spot.intensity.unwrap_or(scene.spot.intensity),
            radius: spot.radius,
        };
    }
    if let Some(point) = &file.point {
        // Built and checked as a [[light]] of type point is.
        let entry = LightEntry {
            name: None,
            kind: "point".into(),
            position: Some(point.position),
            range: Some(point.range),
            radius: Some(point.radius),
            color: point.color,
            intensity: point.intensity,
            elevation: None,
            azimuth: None,
            angular_diameter: None,
            target: None,
            outer_angle: None,
            inner_angle: None,
            shadow: None,
        };
        let Light::Point(light) = entry.to_light(&scene).map_err(|e| fail(format!("[point]: {e}")))? else {
            unreachable!("a point entry builds a point light")
        };
        scene.point = light;
    }
    if !file.light.is_empty() {
        scene.lights.clear();
    }
    for (i, entry) in file.light.iter().enumerate() {
        let name = entry.name.clone().unwrap_or_else(|| format!("light {i}"));
        let light = entry.to_light(&scene).map_err(|e| fail(format!("[[light]] `{name}`: {e}")))?;
        if let Some(overrides) = &entry.shadow {
            // Checked over the defaults here; over the render's settings when resolved.
            ShadowSettings::default()
                .with_overrides(overrides)
                .map_err(|e| fail(format!("[[light]] `{name}` shadow: {e}")))?;
        }
        scene.lights.push(SceneLight { name, light, shadow: entry.shadow.clone() });
    }
    let view_names: Vec<String> = file.view.iter().map(|v| v.name.clone()).collect();
    let chosen = match view {
        Some(name) => Some(file.view.iter().find(|v| v.name == name).ok_or_else(|| {
            fail(if view_names.is_empty() {
                format!("has no views, so --view {name} cannot be used")
            } else {
                format!("has no view `{name}`; its views are {}", view_names.join(", "))
            })
        })?),
        None => file.view.first(),
    };
    if let Some(v) = chosen {
        let eye = Vec3::from_array(v.eye);
        let far = bounds.corners().iter().map(|p| p.distance(eye)).fold(0.0f32, f32::max) * 1.01;
        scene.camera = Camera {
            eye,
            target: Vec3::from_array(v.target),
            up: Vec3::Y,
            fov_y_degrees: v.fov.unwrap_or(45.0),
            near: v.near.unwrap_or(far.max(1e-3) * 1e-4),
            far: v.far.unwrap_or(far.max(1e-3)),
        };
    }
    scene.validate().map_err(|e| fail(e.to_string()))?;
    Ok(LoadedSceneFile { scene, view_names, settings: file.settings })
}

/// `file`'s settings with every command-line value that differs from its default laid
/// over them: a flag given on the command line wins over the file, a flag left alone
/// does not. (A flag set explicitly to its default value cannot override the file.)
pub fn merge_settings(file: &toml::Value, command_line: &Settings) -> Result<Settings, String> {
    let defaults = toml::Value::try_from(Settings::default()).map_err(|e| e.to_string())?;
    let cli = toml::Value::try_from(command_line).map_err(|e| e.to_string())?;
    let mut merged = toml::Value::try_from(Settings::default()).map_err(|e| e.to_string())?;
    crate::settings::overlay(&mut merged, file);
    overlay_changes(&mut merged, &cli, &defaults);
    merged.try_into().map_err(|e: toml::de::Error| e.to_string())
}

/// Copies the values of `cli` that differ from `defaults` into `into`.
fn overlay_changes(into: &mut toml::Value, cli: &toml::Value, defaults: &toml::Value) {
    match (into, cli) {
        (toml::Value::Table(a), toml::Value::Table(c)) => {
            for (k, v) in c {
                let d = defaults.get(k).cloned().unwrap_or(toml::Value::Table(Default::default()));
                match a.get_mut(k) {
                    Some(slot) => overlay_changes(slot, v, &d),
                    None if *v != d => {
                        a.insert(k.clone(), v.clone());
                    }
                    None => {}
                }
            }
        }
        (slot, v) => {
            if v != defaults {
                *slot = v.clone();
            }
        }
    }
}

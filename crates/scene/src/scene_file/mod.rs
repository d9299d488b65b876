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
    Camera, Scene, SceneLight, Settings, gltf_loader, lights::Tint, limits, settings::ShadowSettings,
};

mod entries;
mod locate;
mod three;

use entries::{EntryError, LightEntry, PointEntry, SpotEntry, SunEntry};
pub use locate::{KeyPath, Step, display, locate};

/// A scene file that could not be used.
#[derive(Debug, thiserror::Error)]
#[error("{}{}: {problem}", path.display(), location.map(|(line, column)| format!(":{line}:{column}")).unwrap_or_default())]
pub struct SceneFileError {
    /// The scene file (a model it names that fails to load is reported against it too).
    pub path: PathBuf,
    /// The 1-based line and column of the value at fault, when it is one value.
    pub location: Option<(usize, usize)>,
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
    #[serde(default, deserialize_with = "three::exact")]
    translation: [f32; 3],
    #[serde(default, deserialize_with = "three::exact")]
    rotation_degrees: [f32; 3],
    #[serde(default = "one")]
    scale: f32,
    /// "dynamic" for a model expected to move: drawn over the shadow maps' cache of
    /// still casters every frame. Overrides what the glTF's nodes say.
    motion: Option<crate::Motion>,
}

fn one() -> f32 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ViewEntry {
    name: String,
    #[serde(deserialize_with = "three::exact")]
    eye: [f32; 3],
    #[serde(deserialize_with = "three::exact")]
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
    /// What its models' loading warned of (skipped points, ignored extensions), each
    /// naming its model.
    pub warnings: Vec<String>,
    /// The file's path and text, to locate a value that later proves invalid.
    source: Source,
}

/// A scene file's path and text: what its errors point into.
struct Source {
    path: PathBuf,
    text: String,
}

impl Source {
    /// An error about the file as a whole.
    fn fail(&self, problem: impl Into<String>) -> SceneFileError {
        SceneFileError { path: self.path.clone(), location: None, problem: clipped(problem.into()) }
    }

    /// An error about the value at `key` (or the nearest table on its way).
    fn fail_at(&self, key: &KeyPath, problem: impl Into<String>) -> SceneFileError {
        SceneFileError {
            path: self.path.clone(),
            location: locate(&self.text, key),
            problem: clipped(problem.into()),
        }
    }
}

/// `problem` with every line longer than a screen's width cut short: toml's errors
/// quote the offending line, which in a malformed file may be megabytes long.
fn clipped(problem: String) -> String {
    const KEEP: usize = 160;
    if problem.lines().all(|l| l.chars().count() <= 2 * KEEP) {
        return problem;
    }
    problem
        .lines()
        .map(|line| {
            let n = line.chars().count();
            if n <= 2 * KEEP {
                line.to_owned()
            } else {
                format!("{}… ({} more characters)", line.chars().take(KEEP).collect::<String>(), n - KEEP)
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Loads the scene file at `path`, using the view called `view` (or the first), its
/// models with the default [`gltf_loader::LoadOptions`].
pub fn load(path: &Path, view: Option<&str>) -> Result<LoadedSceneFile, SceneFileError> {
    load_with(path, view, &gltf_loader::LoadOptions::default())
}

/// Loads the scene file at `path` as [`load`] does, its models with `options`.
pub fn load_with(
    path: &Path,
    view: Option<&str>,
    options: &gltf_loader::LoadOptions,
) -> Result<LoadedSceneFile, SceneFileError> {
    let unreadable = |problem: String| SceneFileError { path: path.to_path_buf(), location: None, problem };
    let limit = crate::limits::MAX_SCENE_FILE_BYTES;
    let bytes = crate::files::read_regular(path, crate::files::Links::Follow, limit, "a scene file")
        .map_err(|e| match e {
            crate::files::ReadError::Missing => unreadable("cannot read: no such file".into()),
            crate::files::ReadError::NotRegular(kind) => {
                unreadable(format!("cannot read: it is {kind}, not a regular file"))
            }
            other => unreadable(other.to_string()),
        })?;
    let text =
        String::from_utf8(bytes).map_err(|_| unreadable("cannot read: it is not UTF-8 text".into()))?;
    let source = Source { path: path.to_path_buf(), text };
    // toml's own errors carry the line, the column and the offending text.
    let file: SceneFile = toml::from_str(&source.text).map_err(|e| source.fail(e.to_string()))?;
    if file.model.is_empty() && file.builtin.is_none() {
        return Err(source.fail(
            "lists no models: add at least one [[model]] with a `file`, or start from a built-in \
             scene with `builtin = \"NAME\"`",
        ));
    }
    if file.settings.is_some() {
        // Check the settings now, read from the text so that toml points at a typo.
        #[derive(Deserialize)]
        struct SettingsOnly {
            #[allow(dead_code, reason = "deserialised only to check it")]
            settings: Settings,
        }
        toml::from_str::<SettingsOnly>(&source.text).map_err(|e| source.fail(format!("[settings]: {e}")))?;
    }
    let (mut scene, warnings) = start_scene(&file, &source, options)?;
    scene.name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
    let bounds = scene.bounds();
    if file.builtin.is_none() {
        // glTF models placed by a scene file bring no camera: frame them all.
        scene.camera = crate::framing::default_camera(&scene);
    }
    if file.ground {
        scene.add_ground_plane();
    }
    apply_lights(&file, &source, &mut scene)?;
    let view_names: Vec<String> = file.view.iter().map(|v| v.name.clone()).collect();
    // `--view NAME` would pick the first of two views of one name, silently.
    for (i, name) in view_names.iter().enumerate() {
        if let Some(first) = view_names[..i].iter().position(|n| n == name) {
            return Err(source.fail_at(
                &[Step::Key("view"), Step::Index(i), Step::Key("name")],
                format!(
                    "[[view]] {} has the name `{name}` of [[view]] {}: each view needs a name of its own",
                    i + 1,
                    first + 1
                ),
            ));
        }
    }
    let chosen = match view {
        Some(name) => Some(file.view.iter().position(|v| v.name == name).ok_or_else(|| {
            source.fail(if view_names.is_empty() {
                format!("has no views, so --view {name} cannot be used")
            } else {
                format!("has no view `{name}`; its views are {}", view_names.join(", "))
            })
        })?),
        None => (!file.view.is_empty()).then_some(0),
    };
    if let Some(i) = chosen {
        let v = &file.view[i];
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
        scene.camera.validate().map_err(|e| {
            let key = [Step::Key("view"), Step::Index(i), Step::Key(e.quantity)];
            source.fail_at(&key, format!("[[view]] `{}`: {e}", v.name))
        })?;
    }
    scene.validate().map_err(|e| source.fail(e.to_string()))?;
    let loaded = LoadedSceneFile { scene, view_names, settings: file.settings, warnings, source };
    loaded.check_settings_alone()?;
    Ok(loaded)
}

/// The built-in scene the file starts from, with its models placed, and what their
/// loading warned of.
fn start_scene(
    file: &SceneFile,
    source: &Source,
    options: &gltf_loader::LoadOptions,
) -> Result<(Scene, Vec<String>), SceneFileError> {
    let mut warnings = Vec::new();
    let mut scene: Option<Scene> = match &file.builtin {
        Some(name) => Some(crate::builtin::build(name).map_err(|e| {
            source.fail_at(
                &[Step::Key("builtin")],
                format!(
                    "builtin = {name:?}: {e}; the built-in scenes are {}",
                    crate::builtin::names().join(", ")
                ),
            )
        })?),
        None => None,
    };
    let base = source.path.parent().unwrap_or(Path::new("."));
    // One budget for every model: a dozen small files must not each take the frame's.
    let mut budget = gltf_loader::sources::Budget::default();
    for (i, model) in file.model.iter().enumerate() {
        let at = |key: &'static str| [Step::Key("model"), Step::Index(i), Step::Key(key)];
        let model_path = base.join(&model.file);
        let (loaded, extras) = gltf_loader::load_charged(&model_path, options, &mut budget)
            .map_err(|e| source.fail_at(&at("file"), format!("model: {e}")))?;
        warnings.extend(extras.warnings.iter().map(|w| format!("model `{}`: {w}", model.file.display())));
        let [rx, ry, rz] = model.rotation_degrees.map(f32::to_radians);
        let world_from_model = Mat4::from_scale_rotation_translation(
            Vec3::splat(model.scale),
            Quat::from_euler(EulerRot::ZYX, rz, ry, rx),
            Vec3::from_array(model.translation),
        );
        limits::check_vec3(&limits::COORDINATE, "translation", Vec3::from_array(model.translation)).map_err(
            |e| source.fail_at(&at("translation"), format!("model `{}`: {e}", model.file.display())),
        )?;
        limits::MODEL_SCALE
            .check("scale", model.scale)
            .and_then(|_| {
                limits::check_vec3(&limits::ANGLE, "rotation_degrees", Vec3::from(model.rotation_degrees))
            })
            .map_err(|e| source.fail_at(&at(e.quantity), format!("model `{}`: {e}", model.file.display())))?;
        let mut loaded = loaded;
        if let Some(motion) = model.motion {
            loaded.instances.iter_mut().for_each(|inst| inst.motion = motion);
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
    Ok((scene.expect("a built-in scene or at least one model"), warnings))
}

/// The file's `[sun]`, `[spot]`, `[point]` and `[[light]]` tables, each checked and
/// placed into `scene`: the first three as their kinds' defaults, the last as the
/// scene's list ([`crate::scene_lights`]).
fn apply_lights(file: &SceneFile, source: &Source, scene: &mut Scene) -> Result<(), SceneFileError> {
    let failed = |table: &str, key: &[Step], e: EntryError| {
        let mut path = key.to_vec();
        path.extend(e.key.map(Step::Key));
        source.fail_at(&path, format!("{table}: {}", e.problem))
    };
    // A light that names no colour takes that of the scene's light of its kind.
    let tint_of = |scene: &Scene, kind: &str| {
        scene.light_of_kind(kind).map_or(Tint { color: Vec3::ONE, intensity: 1.0 }, |l| l.kind().tint())
    };
    // `[sun]`, `[spot]` and `[point]`: their kinds' defaults, falling back on the scene's intensity too.
    let set_default = |scene: &mut Scene, entry: Option<LightEntry>, key: &'static str| {
        let Some(entry) = entry else { return Ok(()) };
        let light = entry
            .to_light(tint_of(scene, key))
            .map_err(|e| failed(&format!("[{key}]"), &[Step::Key(key)], e))?;
        scene.set_default(light);
        Ok::<(), SceneFileError>(())
    };
    set_default(scene, file.sun.as_ref().map(LightEntry::from), "sun")?;
    set_default(scene, file.spot.as_ref().map(LightEntry::from), "spot")?;
    set_default(scene, file.point.as_ref().map(LightEntry::from), "point")?;
    let mut listed = Vec::with_capacity(file.light.len());
    for (i, entry) in file.light.iter().enumerate() {
        let name = entry.name.clone().unwrap_or_else(|| format!("light {i}"));
        let table = format!("[[light]] `{name}`");
        let here = [Step::Key("light"), Step::Index(i)];
        // A listed light takes the colour of the scene's light of its type, at full intensity.
        let fallback = Tint { intensity: 1.0, ..tint_of(scene, entry.kind()) };
        let light = entry.to_light(fallback).map_err(|e| failed(&table, &here, e))?;
        if let Some(overrides) = &entry.shadow {
            // Checked over the defaults here; over the render's settings when resolved.
            ShadowSettings::default().with_overrides(overrides).map_err(|e| {
                let key = [here[0], here[1], Step::Key("shadow")];
                source.fail_at(&key, format!("{table} shadow: {e}"))
            })?;
        }
        listed.push(SceneLight { shadow: entry.shadow.clone(), ..SceneLight::listed(name, light) });
    }
    if !listed.is_empty() {
        scene.replace_listed_lights(listed);
    }
    Ok(())
}

impl LoadedSceneFile {
    /// The file's `[settings]` must be valid on their own, over the defaults: other
    /// commands and the viewer load the file with no flags, and a value a flag happens
    /// to override today is still a mistake in the file.
    fn check_settings_alone(&self) -> Result<(), SceneFileError> {
        let Some(table) = &self.settings else { return Ok(()) };
        let defaults = Settings::default();
        let merged =
            merge_settings(table, &defaults).map_err(|e| self.source.fail(format!("[settings]: {e}")))?;
        merged.validate().map_err(|e| {
            self.blame(&e, &defaults).unwrap_or_else(|| self.source.fail(format!("[settings]: {e}")))
        })
    }

    /// An error that points into this file at the value of `error`'s setting, when
    /// the file's `[settings]` gave it and `command_line` did not change it (a flag
    /// wins over the file, so a bad flag is the flag's fault).
    pub fn blame(
        &self,
        error: &crate::settings::SettingsError,
        command_line: &Settings,
    ) -> Option<SceneFileError> {
        let table = self.settings.as_ref()?;
        let keys: Vec<&str> = error.setting.split('.').collect();
        let given_by_file = keys.iter().try_fold(table, |t, k| t.get(k)).is_some();
        if !given_by_file || changed_on_command_line(command_line, &keys) {
            return None;
        }
        let mut path = vec![Step::Key("settings")];
        path.extend(keys.iter().map(|k| Step::Key(k)));
        let problem = format!("`{}` = {} is invalid: {}", display(&path), error.value, error.valid);
        Some(self.source.fail_at(&path, problem))
    }
}

/// Whether `command_line` sets the setting at `keys` to other than its default.
fn changed_on_command_line(command_line: &Settings, keys: &[&str]) -> bool {
    let value = |s: &Settings| {
        let table = toml::Value::try_from(s).ok()?;
        keys.iter().try_fold(table, |t, k| t.get(k).cloned())
    };
    value(command_line) != value(&Settings::default())
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

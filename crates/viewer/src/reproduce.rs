//! Reproducing a view headlessly: the `gnomon render` command line for it, the scene
//! file that holds it, and screenshots written whole or not at all.

use std::path::{Path, PathBuf};

use anyhow::Context;
use gnomon_scene::Settings;

/// Where the viewer's scene came from, as the command line named it.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneSource {
    /// A built-in scene (`gnomon scenes`).
    Builtin(String),
    /// A glTF file.
    Gltf(PathBuf),
    /// A scene file, with the view chosen from it.
    SceneFile { path: PathBuf, view: Option<String> },
}

impl SceneSource {
    /// Reads a scene argument the way the command line does: `.toml` is a scene
    /// file, `.gltf` or `.glb` a glTF file, anything else a built-in's name.
    pub fn from_argument(name: &str, view: Option<&str>) -> Self {
        let path = Path::new(name);
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("toml") => Self::SceneFile { path: path.to_path_buf(), view: view.map(str::to_string) },
            Some("gltf" | "glb") => Self::Gltf(path.to_path_buf()),
            _ => Self::Builtin(name.to_string()),
        }
    }

    /// The scene's arguments on a `gnomon render` command line.
    fn arguments(&self) -> Vec<String> {
        match self {
            Self::Builtin(name) => vec![name.clone()],
            Self::Gltf(path) => vec![path.display().to_string()],
            Self::SceneFile { path, view } => {
                let mut args = vec![path.display().to_string()];
                if let Some(v) = view {
                    args.extend(["--view".to_string(), v.clone()]);
                }
                args
            }
        }
    }
}

/// The `gnomon render` command that renders this view: the scene, then `flags`.
pub fn render_command(source: &SceneSource, flags: &[String]) -> String {
    let mut words = vec!["gnomon".to_string(), "render".to_string()];
    words.extend(source.arguments());
    words.extend(flags.iter().cloned());
    words.iter().map(|w| shell_quote(w)).collect::<Vec<_>>().join(" ")
}

/// `word` quoted for a POSIX shell where it needs to be.
fn shell_quote(word: &str) -> String {
    let plain =
        !word.is_empty() && word.chars().all(|c| c.is_ascii_alphanumeric() || "-_.,/=:+@%".contains(c));
    if plain { word.to_string() } else { format!("'{}'", word.replace('\'', r"'\''")) }
}

/// A scene file that holds this view: the scene (a built-in, the glTF file, or the
/// original scene file's models and lights, with paths made absolute so that the new
/// file may live anywhere) and every setting, camera included.
pub fn scene_file_text(source: &SceneSource, settings: &Settings) -> anyhow::Result<String> {
    let mut file = toml::Table::new();
    match source {
        SceneSource::Builtin(name) => {
            file.insert("builtin".into(), name.clone().into());
        }
        SceneSource::Gltf(path) => {
            let mut model = toml::Table::new();
            model.insert("file".into(), absolute(path)?.display().to_string().into());
            file.insert("model".into(), toml::Value::Array(vec![model.into()]));
        }
        SceneSource::SceneFile { path, .. } => {
            let text =
                std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display()))?;
            file = toml::from_str(&text).with_context(|| format!("{}: not a scene file", path.display()))?;
            let base = absolute(path)?.parent().map(Path::to_path_buf).unwrap_or_default();
            if let Some(toml::Value::Array(models)) = file.get_mut("model") {
                for model in models {
                    if let Some(toml::Value::String(f)) = model.get_mut("file") {
                        *f = base.join(&*f).display().to_string();
                    }
                }
            }
            // The camera is in the settings now; the file's views would only confuse.
            file.remove("view");
        }
    }
    file.insert("settings".into(), toml::Value::try_from(settings).context("serializing the settings")?);
    let header = "# Saved by `gnomon view`. Render it again with `gnomon render THIS_FILE`.\n";
    Ok(format!("{header}{}", toml::to_string_pretty(&file).context("writing the scene file")?))
}

fn absolute(path: &Path) -> anyhow::Result<PathBuf> {
    std::path::absolute(path).with_context(|| format!("{}: cannot make the path absolute", path.display()))
}

/// Writes `contents` to `path` through a temporary file beside it, so that a failure
/// leaves no half-written file.
#[cfg(not(target_arch = "wasm32"))]
pub fn write_whole(path: &Path, write: impl FnOnce(&Path) -> anyhow::Result<()>) -> anyhow::Result<()> {
    let name = path.file_name().with_context(|| format!("{}: not a file name", path.display()))?;
    let temporary = path.with_file_name(format!(".{}.partial", name.to_string_lossy()));
    let result = write(&temporary).and_then(|()| {
        std::fs::rename(&temporary, path).with_context(|| format!("{}: cannot write", path.display()))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    result
}

/// Saves an RGBA8 image as a PNG, whole or not at all.
#[cfg(not(target_arch = "wasm32"))]
pub fn save_png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> anyhow::Result<()> {
    write_whole(path, |temporary| {
        image::save_buffer_with_format(
            temporary,
            rgba,
            width,
            height,
            image::ExtendedColorType::Rgba8,
            image::ImageFormat::Png,
        )
        .with_context(|| format!("{}: cannot write the PNG", path.display()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings_form::SettingsForm;

    #[test]
    fn commands_quote_what_the_shell_would_split() {
        let source = SceneSource::from_argument("my scenes/tree.toml", Some("close up"));
        let command = render_command(&source, &["--technique".into(), "pcss".into()]);
        assert_eq!(command, "gnomon render 'my scenes/tree.toml' --view 'close up' --technique pcss");
        assert_eq!(SceneSource::from_argument("spheres", None), SceneSource::Builtin("spheres".into()));
        assert!(matches!(SceneSource::from_argument("a/b.GLB", None), SceneSource::Gltf(_)));
    }

    /// A saved scene file loads back to the same scene and the same settings.
    #[test]
    fn a_saved_builtin_view_loads_back_whole() {
        let form = SettingsForm::new();
        let mut settings = Settings::default();
        for (id, value) in [("technique", "pcss"), ("eye", "4,3,6"), ("slope_bias", "1.5")] {
            settings = form.set(&settings, id, Some(value)).unwrap();
        }
        let source = SceneSource::Builtin("columns".into());
        let text = scene_file_text(&source, &settings).unwrap();
        let dir = std::env::temp_dir().join(format!("gnomon-viewer-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("saved.toml");
        std::fs::write(&path, &text).unwrap();
        let loaded = gnomon_scene::scene_file::load(&path, None).unwrap();
        let table = loaded.settings.expect("the settings are saved");
        let reloaded = gnomon_scene::scene_file::merge_settings(&table, &Settings::default()).unwrap();
        assert_eq!(reloaded, settings);
        let builtin = gnomon_scene::builtin::build("columns").unwrap();
        assert_eq!(loaded.scene.triangle_count(), builtin.triangle_count());
        assert_eq!(loaded.scene.camera, builtin.camera);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_failed_write_leaves_nothing_behind() {
        let dir = std::env::temp_dir().join(format!("gnomon-viewer-write-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("shot.png");
        let failed = write_whole(&path, |temporary| {
            std::fs::write(temporary, b"half")?;
            anyhow::bail!("the disk filled up")
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        save_png(&path, 2, 1, &[255, 0, 0, 255, 0, 255, 0, 255]).unwrap();
        assert_eq!(image::open(&path).unwrap().to_rgba8().get_pixel(1, 0).0, [0, 255, 0, 255]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! What the lab commands share: scene lookup, the cached, progress-reporting
//! reference computation, and the truth at the surfaces a frame drew.

use std::time::Instant;

use gnomon_reference::{
    ReferenceImage, ReferenceOptions, TracedScene,
    drawn::{DrawnMetrics, DrawnOptions, DrawnSurfaces, DrawnTruth, drawn_truth, measure_drawn},
    reference_visibility,
};
use gnomon_render::Frame;
use gnomon_scene::{Camera, Light, Scene, Settings, builtin};
use indicatif::{ProgressBar, ProgressStyle};

use crate::cache;

/// Which scene the lab commands work on.
#[derive(clap::Args, Debug)]
pub struct SceneArgs {
    /// Scene: a scene file (.toml), a glTF file (.gltf or .glb) or a built-in scene
    /// (see `gnomon scenes`).
    #[arg(default_value = "spheres")]
    pub scene: String,
    /// Camera view of a scene file (.toml) to use [default: its first view].
    #[arg(long, value_name = "NAME")]
    pub view: Option<String>,
    /// Let a glTF model read buffer and image files outside its own folder (by
    /// default a model may only name files beside or below it).
    #[arg(long)]
    pub allow_outside_uris: bool,
}

impl SceneArgs {
    /// How the models of this scene are loaded.
    pub fn load_options(&self) -> gnomon_scene::gltf_loader::LoadOptions {
        use gnomon_scene::gltf_loader::{LoadOptions, UriScope};
        let uri_scope = if self.allow_outside_uris { UriScope::Anywhere } else { UriScope::ModelFolder };
        LoadOptions { uri_scope }
    }
}

/// The scene `args` names (a scene file, a glTF file or a built-in scene) and the
/// settings to render it with: a scene file's `[settings]` with the command line's
/// changes laid over them, or the command line's alone.
pub fn load(args: &SceneArgs, command_line: &Settings) -> anyhow::Result<(Scene, Settings)> {
    let (name, view) = (args.scene.as_str(), args.view.as_deref());
    let path = std::path::Path::new(name);
    let is_toml = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    let options = args.load_options();
    let (mut scene, settings) = if is_toml {
        let loaded = gnomon_scene::scene_file::load_with(path, view, &options)?;
        for warning in &loaded.warnings {
            eprintln!("gnomon: warning: {name}: {warning}");
        }
        let settings = match &loaded.settings {
            Some(table) => gnomon_scene::scene_file::merge_settings(table, command_line)
                .map_err(|e| anyhow::anyhow!("{name}: [settings]: {e}"))?,
            None => command_line.clone(),
        };
        // A value the file gave is the file's fault: name its line, not a flag.
        if let Err(e) = settings.validate() {
            return Err(match loaded.blame(&e, command_line) {
                Some(located) => located.into(),
                None => e.into(),
            });
        }
        (loaded.scene, settings)
    } else {
        if let Some(v) = view {
            anyhow::bail!("--view {v}: views come from scene files (.toml), and `{name}` is not one");
        }
        command_line.validate()?;
        (load_scene_file(name, &options)?, command_line.clone())
    };
    if settings.scene.ground {
        scene.add_ground_plane();
    }
    // A setting this render ignores is said, not silently dropped (an unresolvable
    // light is reported by the command itself).
    let techniques = gnomon_render::techniques::TechniqueRegistry::builtin();
    if let Ok(lights) = techniques.resolve_lights(&settings, &scene) {
        for unused in settings.unused(&lights) {
            eprintln!("gnomon: warning: {}", gnomon_scene::settings::in_flags(&unused.to_string()));
        }
    }
    Ok((scene, settings))
}

/// The scene `name`: a glTF file (`.gltf` or `.glb`) or a built-in scene, or an error
/// that names the valid choices.
pub fn load_scene_file(
    name: &str,
    options: &gnomon_scene::gltf_loader::LoadOptions,
) -> anyhow::Result<Scene> {
    let path = std::path::Path::new(name);
    let is_gltf = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"));
    if is_gltf {
        let (scene, extras) = gnomon_scene::gltf_loader::load_with(path, options)?;
        for warning in &extras.warnings {
            eprintln!("gnomon: warning: {name}: {warning}");
        }
        if extras.ignored_lights > 0 {
            eprintln!(
                "gnomon: {name}: {} light(s) ignored (a directional or spot light without a direction)",
                extras.ignored_lights
            );
        }
        return Ok(scene);
    }
    builtin::build(name).map_err(|e| match e {
        builtin::BuiltinError::Unknown(_) => anyhow::anyhow!(
            "unknown scene `{name}`: give a scene file (.toml), a glTF file (.gltf or .glb) or one of the built-in scenes {}",
            builtin::names().join(", ")
        ),
        out_of_range @ (builtin::BuiltinError::InstancesOutOfRange(_) | builtin::BuiltinError::LampsOutOfRange(_)) => {
            out_of_range.into()
        }
    })
}

/// A reference and where it came from.
pub struct Reference {
    pub image: ReferenceImage,
    /// Seconds spent building the BVH and tracing, or `None` when it came from the cache.
    pub timing: Option<ReferenceTiming>,
}

/// Where the reference's time went.
pub struct ReferenceTiming {
    pub build_seconds: f64,
    pub trace_seconds: f64,
}

/// Computes (or loads from the cache) the reference for `settings` on `scene`.
pub fn reference(scene: &Scene, settings: &Settings, use_cache: bool) -> anyhow::Result<Reference> {
    let camera: Camera = settings.resolve_camera(scene)?;
    let light: Light = settings.resolve_light(scene)?;
    let options = ReferenceOptions {
        width: settings.image.width,
        height: settings.image.height,
        samples: settings.reference.samples,
    };
    let budget = gnomon_scene::memory::frame_budget().map_err(anyhow::Error::msg)?;
    gnomon_reference::check_memory(scene, &options, &budget)
        .map_err(|e| anyhow::anyhow!("the reference of scene `{}`: {e}", scene.name))?;
    let key = cache::key(scene, &camera, &light, &options);
    let cached = if use_cache { cache::path_for(&key) } else { None };
    if let Some(path) = &cached
        && let Some(image) = cache::load(path, &options)
    {
        eprintln!("gnomon: reference loaded from the cache ({})", path.display());
        return Ok(Reference { image, timing: None });
    }
    let started = Instant::now();
    let traced = TracedScene::build(scene);
    let build_seconds = started.elapsed().as_secs_f64();
    let started = Instant::now();
    let bar = ProgressBar::new(options.height as u64).with_style(
        ProgressStyle::with_template("reference {bar:40} {pos}/{len} rows, {elapsed} elapsed, {eta} left")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let image = reference_visibility(&traced, &camera, &light, &options, &|rows| bar.set_position(rows));
    bar.finish_and_clear();
    let trace_seconds = started.elapsed().as_secs_f64();
    if let Some(path) = &cached
        && let Err(e) = cache::store(path, &image)
    {
        eprintln!("gnomon: warning: could not cache the reference at {}: {e}", path.display());
    }
    Ok(Reference { image, timing: Some(ReferenceTiming { build_seconds, trace_seconds }) })
}

/// The truth at `surfaces` (another frame's, read back by `--surfaces`): traced as
/// [`drawn_metrics`] traces it, with the reference's samples and lift.
pub fn drawn_truth_at(
    scene: &Scene,
    settings: &Settings,
    surfaces: &crate::surfaces_in::ReadSurfaces,
) -> anyhow::Result<DrawnTruth> {
    let drawn = DrawnSurfaces {
        width: surfaces.width,
        position: &surfaces.position,
        geometric_normal: &surfaces.geometric_normal,
    };
    Ok(DrawnTracer::new(scene, settings)?.trace(drawn, surfaces.height, "the given surfaces"))
}

/// The truth at drawn surfaces for one scene and light: the reference's samples,
/// and the lift that tells an ambiguous pixel, 10⁻⁵ of the scene's extent.
struct DrawnTracer {
    light: Light,
    traced: TracedScene,
    options: DrawnOptions,
}

impl DrawnTracer {
    fn new(scene: &Scene, settings: &Settings) -> anyhow::Result<Self> {
        Ok(Self {
            light: settings.resolve_light(scene)?,
            traced: TracedScene::build(scene),
            options: DrawnOptions {
                samples: settings.reference.samples,
                lift: 1e-5 * scene.bounds().extent().length(),
            },
        })
    }

    /// The truth at `surfaces` (`height` rows), with a progress bar naming `what`.
    fn trace(&self, surfaces: DrawnSurfaces, height: u32, what: &str) -> DrawnTruth {
        let bar = ProgressBar::new(u64::from(height)).with_style(
            ProgressStyle::with_template(&format!(
                "truth at {what} {{bar:40}} {{pos}}/{{len}} rows, {{eta}} left"
            ))
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        let truth =
            drawn_truth(&self.traced, &self.light, surfaces, &self.options, &|rows| bar.set_position(rows));
        bar.finish_and_clear();
        truth
    }
}

/// Each frame's metrics against the truth at the surfaces it drew
/// (`gnomon_reference::drawn`): every light-facing pixel counted, traced from the
/// frame's own points and normals. The truth is traced once per distinct set of
/// surfaces: techniques drawn on one path show the same ones.
pub fn drawn_metrics(
    scene: &Scene,
    settings: &Settings,
    frames: &[&Frame],
) -> anyhow::Result<Vec<DrawnMetrics>> {
    let tracer = DrawnTracer::new(scene, settings)?;
    let bits =
        |v: &[glam::Vec3]| -> Vec<u32> { v.iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect() };
    let mut truths: Vec<(Vec<u32>, DrawnTruth)> = Vec::new();
    let mut metrics = Vec::with_capacity(frames.len());
    for frame in frames {
        let key = [bits(&frame.position), bits(&frame.geometric_normal)].concat();
        let known = truths.iter().position(|(k, _)| *k == key);
        let index = match known {
            Some(index) => index,
            None => {
                let surfaces = DrawnSurfaces {
                    width: frame.width,
                    position: &frame.position,
                    geometric_normal: &frame.geometric_normal,
                };
                truths.push((key, tracer.trace(surfaces, frame.height, "the drawn surfaces")));
                truths.len() - 1
            }
        };
        metrics.push(measure_drawn(&frame.visibility, &truths[index].1));
    }
    Ok(metrics)
}

//! The lab's state and what it does, in plain Rust with no JavaScript in sight: a
//! scene on the GPU, settings from flags, and a render that, when asked, also draws
//! the truth (`raytraced`, every pixel traced on the GPU) and measures the frame
//! against it. The JS API (`api.rs`) wraps it; the native tests drive it as it is.

use gnomon_reference::{
    drawn::{DrawnMetrics, DrawnSurfaces, DrawnTruth, measure_drawn},
    heatmap,
};
use gnomon_render::{
    Frame, Gpu, GpuScene, OutputRequest, RenderError, Renderer, techniques::TechniqueRegistry,
};
use gnomon_scene::{Scene, Settings, builtin, gltf_loader, settings::Technique};
use serde::Serialize;

use crate::flags::{Flag, FlagsError, settings_from_flags, technique_name};

/// What the lab could not do, in words a page shows.
#[derive(Debug, thiserror::Error)]
pub enum LabError {
    /// A setting the command line would refuse too.
    #[error("{0}")]
    Settings(#[from] FlagsError),
    /// A scene that could not be built or loaded.
    #[error("{0}")]
    Scene(String),
    /// The renderer's or the device's refusal.
    #[error("{}", gnomon_scene::settings::in_flags(&.0.to_string()))]
    Render(#[from] RenderError),
}

/// The scene the lab shows: as loaded, and on the GPU as drawn (with the ground
/// plane, when the settings ask for one).
struct LoadedScene {
    name: String,
    loaded: Scene,
    drawn: Scene,
    uploaded: GpuScene,
    ground: bool,
}

/// The last frame and its truth.
struct Shown {
    frame: Frame,
    truth: Option<Measured>,
}

/// The frame against `raytraced`.
struct Measured {
    metrics: DrawnMetrics,
    heatmap: Vec<u8>,
}

/// A rendered frame in figures: what the page writes into its status element.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Report {
    /// The scene's name: a built-in scene's, or the file's.
    pub scene: String,
    /// The shadow technique.
    pub technique: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Pixels of the visibility image above 0.5 (background left out).
    pub lit: usize,
    /// Pixels of the visibility image at or below 0.5 (background left out).
    pub shadowed: usize,
    /// Light-facing pixels the frame decides otherwise than `raytraced` does, as a
    /// fraction of those compared; None when the truth was not drawn.
    pub mismatch_vs_raytraced: Option<f64>,
    /// The frame against the truth, in full; None when it was not drawn.
    pub truth: Option<DrawnMetrics>,
    /// The adapter that drew it.
    pub adapter: String,
    /// The frame's GPU time, where the adapter has timestamps.
    pub frame_ms: Option<f64>,
    /// Each kind of pass's GPU time, where the adapter has timestamps.
    pub passes: Vec<PassReport>,
}

/// The GPU time of one kind of pass, every light's together.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PassReport {
    /// `shadow`, `filter`, `prepass`, `mask`, `trace` or `lighting`.
    pub pass: &'static str,
    /// Milliseconds.
    pub ms: f64,
}

/// Whether a render also draws the truth and measures the frame against it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Truth {
    /// Also render `raytraced` and measure every light-facing pixel against it.
    Measure,
    /// The frame alone (for timing, say).
    Skip,
}

/// The lab: a device, a renderer, a scene and settings.
pub struct Lab {
    gpu: Gpu,
    renderer: Renderer,
    scene: LoadedScene,
    settings: Settings,
    shown: Option<Shown>,
}

impl Lab {
    /// A lab on `gpu`, showing the built-in `spheres` with the default settings.
    pub fn new(gpu: Gpu) -> Result<Self, LabError> {
        let renderer = Renderer::new(&gpu)?;
        let settings = Settings::default();
        let scene = upload(&renderer, "spheres".into(), builtin::spheres(), settings.scene.ground)?;
        Ok(Self { gpu, renderer, scene, settings, shown: None })
    }

    /// The adapter's name.
    pub fn adapter(&self) -> &str {
        &self.gpu.info.adapter
    }

    /// Every technique the renderer knows, by name.
    pub fn techniques(&self) -> Vec<String> {
        self.renderer.techniques().iter().map(|t| t.technique().to_string()).collect()
    }

    /// The scene shown, by name.
    pub fn scene_name(&self) -> &str {
        &self.scene.name
    }

    /// Shows the built-in scene `name` (`gnomon scenes` lists them).
    pub fn load_builtin(&mut self, name: &str) -> Result<(), LabError> {
        let scene = builtin_scene(name)?;
        self.show(name.to_string(), scene)
    }

    /// Shows the glTF model `bytes` (a `.glb`, or a `.gltf` with its data embedded),
    /// named `name` in errors. A model that cannot be loaded leaves the lab as it was.
    /// Returns the loader's warnings.
    pub fn load_gltf(&mut self, bytes: &[u8], name: &str) -> Result<Vec<String>, LabError> {
        let (scene, extras) =
            gltf_loader::load_from_bytes(bytes, name).map_err(|e| LabError::Scene(e.to_string()))?;
        self.show(name.to_string(), scene)?;
        Ok(extras.warnings)
    }

    fn show(&mut self, name: String, scene: Scene) -> Result<(), LabError> {
        self.scene = upload(&self.renderer, name, scene, self.settings.scene.ground)?;
        self.shown = None;
        Ok(())
    }

    /// Replaces the settings with the defaults and `flags` over them, checked as the
    /// command line checks them. Wrong flags leave the settings as they were.
    pub fn set_flags(&mut self, flags: &[Flag]) -> Result<(), LabError> {
        let settings = checked_settings(flags, self.renderer.techniques())?;
        if settings.scene.ground != self.scene.ground {
            let LoadedScene { name, loaded, .. } = &self.scene;
            self.scene = upload(&self.renderer, name.clone(), loaded.clone(), settings.scene.ground)?;
        }
        self.settings = settings;
        Ok(())
    }

    /// The settings in use.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Renders the scene with the settings and, with [`Truth::Measure`], the same
    /// view with `raytraced` too, measuring the frame against it.
    pub async fn render(&mut self, truth: Truth) -> Result<Report, LabError> {
        let request = OutputRequest::default();
        let LoadedScene { drawn, uploaded, .. } = &self.scene;
        let frame = self.renderer.render_uploaded_async(uploaded, drawn, &self.settings, &request).await?;
        let truth = if truth == Truth::Measure {
            let mut traced = self.settings.clone();
            traced.shadow.filter.technique = Technique::RAYTRACED;
            let reference = self.renderer.render_uploaded_async(uploaded, drawn, &traced, &request).await?;
            Some(measure(&frame, reference))
        } else {
            None
        };
        let shown = Shown { frame, truth };
        let report = self.report(&shown);
        self.shown = Some(shown);
        Ok(report)
    }

    fn report(&self, shown: &Shown) -> Report {
        let frame = &shown.frame;
        let drawn = frame.visibility.iter().filter(|v| v.is_finite());
        let lit = drawn.clone().filter(|&&v| v > 0.5).count();
        let shadowed = drawn.count() - lit;
        let metrics = shown.truth.as_ref().map(|t| t.metrics.clone());
        Report {
            scene: self.scene.name.clone(),
            technique: technique_name(&self.settings),
            width: frame.width,
            height: frame.height,
            lit,
            shadowed,
            mismatch_vs_raytraced: metrics.as_ref().map(|m| m.mismatch_rate),
            truth: metrics,
            adapter: self.gpu.info.adapter.clone(),
            frame_ms: frame.timings.as_ref().map(|t| t.frame_ms),
            passes: frame.timings.as_ref().map(passes).unwrap_or_default(),
        }
    }

    /// The last frame's lit image: RGBA8, sRGB, top row first.
    pub fn color(&self) -> Option<&[u8]> {
        self.shown.as_ref().map(|s| s.frame.color.as_slice())
    }

    /// The last frame's surfaces: each pixel's world-space point and geometric normal,
    /// row-major, NaN where it shows none.
    pub fn surfaces(&self) -> Option<(&[glam::Vec3], &[glam::Vec3])> {
        self.shown.as_ref().map(|s| (s.frame.position.as_slice(), s.frame.geometric_normal.as_slice()))
    }

    /// The last frame's visibility: 1 lit, 0 shadowed, NaN background; row-major.
    pub fn visibility(&self) -> Option<&[f32]> {
        self.shown.as_ref().map(|s| s.frame.visibility.as_slice())
    }

    /// The last frame's errors against `raytraced` as an RGBA8 picture (the colours
    /// of `gnomon compare`'s heat-maps), when the truth was drawn.
    pub fn heatmap(&self) -> Option<&[u8]> {
        self.shown.as_ref()?.truth.as_ref().map(|t| t.heatmap.as_slice())
    }
}

/// The built-in scene `name`, or an error that lists them.
pub fn builtin_scene(name: &str) -> Result<Scene, LabError> {
    builtin::build(name).map_err(|e| match e {
        builtin::BuiltinError::Unknown(_) => LabError::Scene(format!(
            "unknown scene `{name}`: give one of the built-in scenes {}",
            builtin::names().join(", ")
        )),
        out_of_range @ (builtin::BuiltinError::InstancesOutOfRange(_)
        | builtin::BuiltinError::LampsOutOfRange(_)) => LabError::Scene(out_of_range.to_string()),
    })
}

/// `flags` over the defaults, checked as the command line checks them: each value,
/// and the technique against `techniques`.
pub fn checked_settings(flags: &[Flag], techniques: &TechniqueRegistry) -> Result<Settings, LabError> {
    let settings = settings_from_flags(flags)?;
    techniques
        .check(&settings.shadow)
        .map_err(|e| FlagsError(gnomon_scene::settings::in_flags(&e.to_string())))?;
    Ok(settings)
}

/// `scene` on the GPU, with a ground plane under it when `ground`.
fn upload(renderer: &Renderer, name: String, loaded: Scene, ground: bool) -> Result<LoadedScene, LabError> {
    let mut drawn = loaded.clone();
    if ground {
        drawn.add_ground_plane();
    }
    let uploaded = renderer.upload(&drawn)?;
    Ok(LoadedScene { name, loaded, drawn, uploaded, ground })
}

/// `frame` against `reference`, the same view drawn by `raytraced`: every
/// light-facing pixel compared, the truth's answer being the traced one.
fn measure(frame: &Frame, reference: Frame) -> Measured {
    let surfaces = DrawnSurfaces {
        width: frame.width,
        position: &frame.position,
        geometric_normal: &frame.geometric_normal,
    };
    let truth = DrawnTruth::from_traced(&frame.light, surfaces, reference.visibility);
    Measured {
        metrics: measure_drawn(&frame.visibility, &truth),
        heatmap: heatmap::drawn(&frame.visibility, &truth),
    }
}

/// The timed passes, by kind, those the frame ran.
fn passes(t: &gnomon_render::PassTimings) -> Vec<PassReport> {
    let all = [
        ("shadow", Some(t.shadow_ms)),
        ("filter", t.filter_ms),
        ("prepass", t.prepass_ms),
        ("mask", t.mask_ms),
        ("trace", t.trace_ms),
        ("lighting", Some(t.lighting_ms)),
    ];
    all.into_iter().filter_map(|(pass, ms)| ms.map(|ms| PassReport { pass, ms })).collect()
}

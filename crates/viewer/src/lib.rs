//! `gnomon view`: an interactive window (winit + egui on wgpu) where every technique
//! and setting is live. The settings panel is generated from the same [`Settings`]
//! structure as the CLI's flags ([`settings_form`]); debug views show the shadow maps,
//! cascades, texel density and the error against the ray-traced reference; any view
//! can be copied out as a `gnomon render` command or saved as a scene file.
//!
//! The window runs headless under Xvfb on lavapipe too, which is how it is tested:
//! [`ViewerOptions::script`] drives it through the same [`Action`]s the panel sends.

pub mod camera_rig;
mod debug_views;
mod drag;
mod reproduce;
pub mod settings_form;
mod status_line;
mod ui;
mod window;

use std::path::PathBuf;

use gnomon_scene::{Scene, Settings};

pub use debug_views::measure_aliasing;
pub use drag::Grip;
pub use gnomon_render::LayerCache;
pub use reproduce::{SceneSource, scene_file_text};

/// What the viewer opens and how it runs.
pub struct ViewerOptions {
    pub scene: Scene,
    /// The settings to start from.
    pub settings: Settings,
    /// What the scene alone gives (its scene file's `[settings]`, or the defaults):
    /// "copy as CLI command" writes the flags that differ from these.
    pub baseline: Settings,
    /// Where the scene came from, to name it in commands and scene files.
    pub source: SceneSource,
    /// Close after this many frames.
    pub frames: Option<u32>,
    /// Save the window as a PNG after the last frame (with `frames`) or on close.
    pub screenshot: Option<PathBuf>,
    /// Start with the settings panel hidden (F1 toggles it).
    pub hide_panel: bool,
    /// Start with the shadow-map preview open.
    pub show_maps: bool,
    /// Actions to take at given frames, as if sent by the panel: automation and tests.
    pub script: Vec<(u32, Action)>,
    /// The window's inner size in logical pixels.
    pub window_size: [u32; 2],
}

impl ViewerOptions {
    /// A viewer on `scene` with `settings`, interactive, with every option at rest.
    pub fn new(scene: Scene, settings: Settings, source: SceneSource) -> Self {
        Self {
            scene,
            baseline: Settings::default(),
            settings,
            source,
            frames: None,
            screenshot: None,
            hide_panel: false,
            show_maps: false,
            script: Vec::new(),
            window_size: [1400, 860],
        }
    }
}

/// Something the panel (or a script) asks of the viewer.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Set the setting with clap id `id` to `value`, written as after its flag
    /// (`None` gives an optional setting back to the scene).
    Set { id: String, value: Option<String> },
    /// Save the window as a PNG.
    Screenshot(PathBuf),
    /// Put the `gnomon render` command for this view on the clipboard.
    CopyCommand,
    /// Save the view as a scene file.
    SaveSceneFile(PathBuf),
    /// Trace the reference for this view and show the error heat-map.
    CompareWithReference,
    /// Choose what the central view shows.
    Show(View),
    /// Take hold of an instance to move it (Ctrl + left press on the view): it is a
    /// moving caster until released.
    Grab(Grip),
    /// Carry the held instance to where a point of the view (fractions of its width
    /// and height from its top-left corner) meets the plane it moves across.
    DragTo([f32; 2]),
    /// Move the held instance by a world-space offset (for scripts).
    MoveHeldBy([f32; 3]),
    /// Let go of the held instance.
    Release,
}

/// What the central view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// The lit image (with `--debug-view cascades`, tinted by cascade).
    Lit,
    /// Lloyd's m: screen pixels per shadow texel.
    TexelDensity,
    /// The last comparison with the reference.
    Error,
}

/// What a run did, for scripts and tests.
#[derive(Debug, Default)]
pub struct RunReport {
    pub frames: u32,
    /// Screenshots written, in order.
    pub screenshots: Vec<PathBuf>,
    /// The settings at the end.
    pub settings: Settings,
    /// Messages the viewer showed in its status line (errors included).
    pub messages: Vec<String>,
    /// Where the scene's view sat in the window at the end: x, y, width, height in
    /// physical pixels (screenshots are the whole window).
    pub view_rect: [u32; 4],
    /// The instances that were grabbed, by name, in order.
    pub grabbed: Vec<String>,
    /// For each frame drawn while an instance was held, what the first light's
    /// layers did with their kept maps.
    pub layer_cache_while_held: Vec<Vec<LayerCache>>,
}

/// Opens the window and runs until it is closed (or `frames` have been drawn).
#[cfg(not(target_arch = "wasm32"))]
pub fn run(options: ViewerOptions) -> anyhow::Result<RunReport> {
    window::run(options)
}

/// Starts the viewer on a page's `canvas` and returns at once, with the way to reach
/// it: the browser runs its event loop from then on, and each frame's GPU work as a
/// task of its own. Status lines go to the browser's console, prefixed
/// `gnomon view:`; the error view's truth is the GPU's `raytraced` (a page has no
/// threads for the CPU reference).
#[cfg(target_arch = "wasm32")]
pub fn start_on_canvas(
    options: ViewerOptions,
    canvas: web_sys::HtmlCanvasElement,
) -> anyhow::Result<CanvasViewer> {
    Ok(CanvasViewer { proxy: window::start(options, canvas)? })
}

/// A viewer running on a page's canvas, for the page to talk to.
#[cfg(target_arch = "wasm32")]
pub struct CanvasViewer {
    proxy: winit::event_loop::EventLoopProxy<window::Arrived>,
}

#[cfg(target_arch = "wasm32")]
impl CanvasViewer {
    /// Shows `scene` in place of the one shown, once the frame in flight is done, as
    /// if opened from `source`.
    pub fn show_scene(&self, scene: Scene, source: SceneSource) -> anyhow::Result<()> {
        let new = Box::new(window::NewScene { scene, source });
        self.send(window::Arrived::Scene(new))
    }

    /// Carries out `action`, as if the panels had sent it.
    pub fn act(&self, action: Action) -> anyhow::Result<()> {
        self.send(window::Arrived::Act(action))
    }

    fn send(&self, event: window::Arrived) -> anyhow::Result<()> {
        self.proxy.send_event(event).map_err(|_| anyhow::anyhow!("the viewer has stopped"))
    }
}

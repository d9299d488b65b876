//! The window: winit's event loop, the wgpu surface, egui's renderer, and each
//! frame's work: render the scene live, draw the panels, carry out their actions,
//! present, and save screenshots. The same loop runs on the desktop and on a
//! browser's canvas; [`platform`] holds what differs, and [`job`] the frame's GPU
//! work, which a browser runs while its page goes on.

mod job;
mod live;
mod paint;
mod platform;

use std::sync::Arc;

use anyhow::Context;
use gnomon_render::{RenderError, Renderer, wgpu};
use gnomon_scene::Scene;
use winit::{
    application::ApplicationHandler,
    dpi::LogicalSize,
    event::WindowEvent,
    event_loop::{ActiveEventLoop, ControlFlow, EventLoop},
    window::{Window, WindowId},
};

use self::{
    job::{FrameDone, FrameJob, ReadBack, Workshop},
    live::Live,
    paint::{paint, refresh_picture, show_live_frame},
};
use crate::{
    Action, RunReport, View, ViewerOptions,
    debug_views::{self, ErrorJob},
    drag::{Hand, Reach},
    reproduce,
    ui::{Images, Model},
};

fn event_loop() -> anyhow::Result<EventLoop<Arrived>> {
    let event_loop = EventLoop::with_user_event().build().context(
        "cannot open a window: no display. Set DISPLAY (X11) or WAYLAND_DISPLAY, or run under \
         `xvfb-run -a` (Debian package `xvfb`)",
    )?;
    event_loop.set_control_flow(ControlFlow::Poll);
    Ok(event_loop)
}

#[cfg(not(target_arch = "wasm32"))]
pub(crate) fn run(options: ViewerOptions) -> anyhow::Result<RunReport> {
    let event_loop = event_loop()?;
    let mut app = App::new(options, platform::Host)?;
    platform::run_loop(event_loop, &mut app)?;
    if let Some(e) = app.failure {
        return Err(e);
    }
    app.report.settings = app.model.settings.clone();
    app.report.messages = app.model.messages.clone();
    app.report.view_rect = app.model.view_rect;
    Ok(app.report)
}

/// Starts the viewer on `canvas` and returns the way to reach it; the browser runs
/// it from then on.
#[cfg(target_arch = "wasm32")]
pub(crate) fn start(
    options: ViewerOptions,
    canvas: web_sys::HtmlCanvasElement,
) -> anyhow::Result<winit::event_loop::EventLoopProxy<Arrived>> {
    let event_loop = event_loop()?;
    let app = App::new(options, platform::Host { canvas, proxy: None })?;
    Ok(platform::run_loop(event_loop, app))
}

/// What comes to the event loop from outside it: work that ran on its own, and
/// what the page asks.
pub(crate) enum Arrived {
    /// The GPU device, the surface and the renderer, for the window just made.
    Opened(anyhow::Result<Box<Live>>),
    /// A frame's work, done.
    Frame(Box<FrameDone>),
    /// A scene to show in place of the one shown (from a page: `CanvasViewer`).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    Scene(Box<NewScene>),
    /// An action, as if the panels had sent it (from a page: `CanvasViewer`).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    Act(Action),
}

/// A scene to show, and where it came from (to name it in commands and scene files).
pub(crate) struct NewScene {
    pub scene: Scene,
    pub source: crate::SceneSource,
}

pub(crate) struct App {
    model: Model,
    host: platform::Host,
    /// The window, from its creation until its GPU is ready (then in `live`).
    opening: Option<Arc<Window>>,
    live: Option<Live>,
    /// The instance being moved, if any.
    hand: Hand,
    frames: Option<u32>,
    screenshot: Option<std::path::PathBuf>,
    script: Vec<(u32, Action)>,
    /// Actions that need the renderer, waiting for a frame's work to bring it back.
    waiting: Vec<Action>,
    /// What the next frame reads back for a comparison the panels asked for.
    compare_asked: bool,
    /// A scene to show once the renderer is back from the frame in flight.
    next_scene: Option<NewScene>,
    window_size: [u32; 2],
    report: RunReport,
    failure: Option<anyhow::Error>,
}

impl App {
    fn new(options: ViewerOptions, host: platform::Host) -> anyhow::Result<Self> {
        let ViewerOptions {
            scene,
            settings,
            baseline,
            source,
            frames,
            screenshot,
            hide_panel,
            show_maps,
            mut script,
            window_size,
        } = options;
        settings.validate()?;
        script.sort_by_key(|(frame, _)| *frame);
        let mut model = Model::new(scene, settings, baseline, source, !hide_panel)?;
        model.show_maps = show_maps;
        Ok(Self {
            model,
            host,
            opening: None,
            live: None,
            hand: Hand::default(),
            frames,
            screenshot,
            script,
            waiting: Vec::new(),
            compare_asked: false,
            next_scene: None,
            window_size,
            report: RunReport::default(),
            failure: None,
        })
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        self.model.say(format!("{error:#}"));
        self.failure.get_or_insert(error);
        event_loop.exit();
    }

    fn open_window(&self, event_loop: &ActiveEventLoop) -> anyhow::Result<Arc<Window>> {
        let [w, h] = self.window_size;
        let attributes = Window::default_attributes()
            .with_title(format!("Gnomon · {}", self.model.scene.name))
            .with_inner_size(LogicalSize::new(w, h));
        let attributes = platform::window_attributes(&self.host, attributes);
        Ok(Arc::new(event_loop.create_window(attributes).context("cannot create the window")?))
    }

    /// Takes what `work` made, when it comes back.
    fn arrive(&mut self, event_loop: &ActiveEventLoop, arrived: Arrived) {
        match arrived {
            Arrived::Opened(Ok(live)) => {
                self.opening = None;
                live.window.request_redraw();
                self.live = Some(*live);
            }
            Arrived::Opened(Err(e)) => self.fail(event_loop, e),
            Arrived::Frame(done) => self.finish_frame(*done),
            Arrived::Scene(new) => self.next_scene = Some(*new),
            Arrived::Act(action) => self.model.pending.push(action),
        }
    }

    /// Shows `new` in place of the scene shown, uploaded by `workshop`'s renderer;
    /// a scene that cannot be uploaded is reported, and the old one stays.
    fn switch_scene(&mut self, workshop: &mut Workshop, new: NewScene) {
        let NewScene { mut scene, source } = new;
        if self.model.settings.scene.ground {
            scene.add_ground_plane();
        }
        match workshop.renderer.upload(&scene) {
            Ok(uploaded) => {
                workshop.uploaded = uploaded;
                // What the hand held was an instance of the old scene.
                self.hand = Hand::default();
                self.model.show_scene(scene, source);
            }
            Err(e) => self.model.say(format!("{}: {e}", scene.name)),
        }
    }

    /// One frame: scripted actions, the live render, the panels, their actions, and
    /// the picture on screen.
    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<()> {
        let frame_index = self.report.frames;
        while self.script.first().is_some_and(|(at, _)| *at <= frame_index) {
            let (_, action) = self.script.remove(0);
            self.model.pending.push(action);
        }
        // The scene, live, at the size the central view had last frame.
        self.model.settings.camera.eye = Some(self.model.rig.eye());
        self.model.settings.camera.target = Some(self.model.rig.target);
        let settings = self.model.frame_settings();
        let Some(live) = self.live.as_mut() else { return Ok(()) };
        if let Some(mut workshop) = live.workshop.take() {
            workshop.make_room(settings.image.width, settings.image.height)?;
            if let Some(new) = self.next_scene.take() {
                self.switch_scene(&mut workshop, new);
            }
            let compare = std::mem::take(&mut self.compare_asked);
            let read_back = ReadBack {
                density: self.model.view == View::TexelDensity
                    && self.model.density.as_ref().is_none_or(|d| d.settings != settings),
                compare,
                raytraced: compare && platform::COMPARES_WITH_RAYTRACED,
            };
            let scene = self.model.scene.clone();
            let job = FrameJob { workshop, scene, settings: settings.clone(), read_back };
            platform::spawn(self, event_loop, async move { Arrived::Frame(Box::new(job.run().await)) });
        }
        let Some(live) = self.live.as_mut() else { return Ok(()) };
        let gpu = live.gpu.clone();
        if let Some(result) = self.model.error_job.as_ref().and_then(ErrorJob::poll) {
            self.model.error_job = None;
            match result {
                Ok(picture) => {
                    self.model.say(picture.summary.clone());
                    self.model.error = Some(picture);
                    self.model.view = View::Error;
                }
                Err(e) => self.model.say(e),
            }
        }

        // The panels.
        let ctx = live.egui.egui_ctx().clone();
        refresh_picture(&ctx, self.model.density.as_ref(), &mut live.images.density);
        refresh_picture(&ctx, self.model.error.as_ref(), &mut live.images.error);
        let input = live.egui.take_egui_input(&live.window);
        let model = &mut self.model;
        let images = &live.images;
        let mut output = ctx.run_ui(input, |ui| model.ui(ui, images));
        live.egui.handle_platform_output(&live.window, std::mem::take(&mut output.platform_output));

        // What the panels asked for; what needs the renderer while a frame's work
        // has it waits, in order.
        let mut screenshots = Vec::new();
        let mut panels = Panels {
            model: &mut self.model,
            hand: &mut self.hand,
            report: &mut self.report,
            compare_asked: &mut self.compare_asked,
        };
        let mut actions = std::mem::take(&mut self.waiting);
        actions.append(&mut panels.model.pending);
        for action in actions {
            if !self.waiting.is_empty() {
                self.waiting.push(action);
                continue;
            }
            match panels.carry_out(action, live, &ctx) {
                Carried::Done => {}
                Carried::Screenshot(path) => screenshots.push(path),
                Carried::Wait(action) => self.waiting.push(action),
            }
        }
        let last = self.frames.is_some_and(|n| frame_index + 1 >= n);
        if last && let Some(path) = &self.screenshot {
            screenshots.push(path.clone());
        }

        // Paint.
        let shot_texture = paint(live, &ctx, output, !screenshots.is_empty());
        if let Some(texture) = shot_texture {
            match platform::save_screenshots(&gpu, &texture, &screenshots) {
                Ok(()) => {
                    for path in screenshots {
                        self.model.say(format!("screenshot saved to {}", path.display()));
                        self.report.screenshots.push(path);
                    }
                }
                Err(e) if cfg!(target_arch = "wasm32") => self.model.say(format!("{e:#}")),
                Err(e) => return Err(e),
            }
        }
        self.report.frames += 1;
        if last {
            event_loop.exit();
        }
        Ok(())
    }

    /// Takes a frame's work back: the workshop, the live image, and what it read back.
    fn finish_frame(&mut self, done: FrameDone) {
        let FrameDone { workshop, settings, read_back, live: live_frame, frame, traced } = done;
        let Some(live) = self.live.as_mut() else { return };
        live.workshop = Some(workshop);
        match live_frame {
            Ok(frame) => {
                if self.hand.held.is_some()
                    && let Some(light) = frame.lights.first()
                {
                    self.report.layer_cache_while_held.push(light.layer_cache.clone());
                }
                show_live_frame(live, &frame, self.model.show_maps);
                self.model.record_timings(frame.timings, frame.lights.clone());
            }
            Err(e) => {
                // A refused setting (a map larger than the device allows, say) is
                // reported; the settings that worked stay on screen.
                let message = e.to_string();
                if self.model.messages.last() != Some(&message) {
                    self.model.say(message);
                }
            }
        }
        let frame = match frame.transpose() {
            Ok(frame) => frame,
            Err(e) => return self.model.say(e.to_string()),
        };
        let Some(frame) = frame else { return };
        if read_back.density {
            self.model.density = Some(debug_views::texel_density(&frame, &settings));
        }
        if read_back.compare {
            self.model.say("measuring this view against the reference…");
            let traced = match traced.transpose() {
                Ok(traced) => traced,
                Err(e) => return self.model.say(e.to_string()),
            };
            let job = match platform::error_job(&self.model.scene, frame, traced, settings) {
                Ok(job) => job,
                Err(e) => return self.model.say(e),
            };
            self.model.error_job = Some(job);
        }
    }
}

/// What became of an action.
enum Carried {
    Done,
    /// A screenshot to take, at this path, once the frame is painted.
    Screenshot(std::path::PathBuf),
    /// It needs the renderer, which a frame's work has: it waits for it.
    Wait(Action),
}

/// The largest image `window` can show, in physical pixels: the widest and the
/// tallest of the monitors (winit lists them on Wayland too, where the window's own
/// monitor is unknown until it is shown; none in a browser), and the window itself.
fn largest_monitor(window: &Window) -> gnomon_scene::memory::Window {
    let sizes = window.available_monitors().map(|m| m.size()).chain([window.inner_size()]);
    let (width, height) = sizes.fold((0, 0), |(w, h), s| (w.max(s.width), h.max(s.height)));
    gnomon_scene::memory::Window { width, height }
}

/// Opens the GPU for `window`: the device, the surface, the renderer with `scene`
/// uploaded, and egui's painter.
async fn connect(window: Arc<Window>, scene: Arc<Scene>) -> anyhow::Result<Box<Live>> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
        window.clone(),
    )));
    let surface =
        instance.create_surface(window.clone()).context("cannot create a surface for the window")?;
    let adapter = wgpu::util::initialize_adapter_from_env_or_default(&instance, Some(&surface))
        .await
        .map_err(|_| RenderError::no_adapter())?;
    let gpu = gnomon_render::Gpu::with_adapter_async(&adapter, |_| {}).await?;
    crate::status_line::say(&gpu.info.to_string());
    let size = window.inner_size();
    let mut config = surface
        .get_default_config(&adapter, size.width.max(1), size.height.max(1))
        .context("the adapter cannot present to this window")?;
    let capabilities = surface.get_capabilities(&adapter);
    // egui and the scene image are sRGB-encoded colours: present through an sRGB
    // view (a browser's canvas offers only linear formats, which may be viewed as sRGB).
    if let Some(srgb) = capabilities.formats.iter().find(|f| f.is_srgb()) {
        config.format = *srgb;
    } else if config.format.add_srgb_suffix() != config.format {
        config.view_formats = vec![config.format.add_srgb_suffix()];
    }
    surface.configure(&gpu.device, &config);
    let renderer = Renderer::new(&gpu)?;
    let uploaded = renderer.upload(&scene)?;
    let workshop = Workshop::new(renderer, uploaded, largest_monitor(&window))?;
    let egui_ctx = egui::Context::default();
    let egui = egui_winit::State::new(
        egui_ctx,
        egui::ViewportId::ROOT,
        &window,
        Some(window.scale_factor() as f32),
        None,
        Some(gpu.limits.max_texture_dimension_2d as usize),
    );
    let painter = egui_wgpu::Renderer::new(&gpu.device, paint::target_format(&config), Default::default());
    Ok(Box::new(Live {
        window,
        _instance: instance,
        gpu,
        surface,
        config,
        workshop: Some(workshop),
        egui,
        painter,
        view_texture: None,
        maps_texture: None,
        images: Images::default(),
    }))
}

impl ApplicationHandler<Arrived> for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.live.is_some() || self.opening.is_some() {
            return;
        }
        match self.open_window(event_loop) {
            Ok(window) => {
                self.opening = Some(window.clone());
                let scene = self.model.scene.clone();
                platform::spawn(
                    self,
                    event_loop,
                    async move { Arrived::Opened(connect(window, scene).await) },
                );
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn user_event(&mut self, event_loop: &ActiveEventLoop, arrived: Arrived) {
        self.arrive(event_loop, arrived);
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(live) = self.live.as_mut() else { return };
        let response = live.egui.on_window_event(&live.window, &event);
        match event {
            WindowEvent::CloseRequested => {
                if let Some(path) = self.screenshot.take() {
                    // Asked for a screenshot on close: take it from one more frame.
                    self.frames = Some(self.report.frames + 1);
                    self.screenshot = Some(path);
                    live.window.request_redraw();
                } else {
                    event_loop.exit();
                }
            }
            WindowEvent::Resized(size) => {
                live.config.width = size.width.max(1);
                live.config.height = size.height.max(1);
                live.surface.configure(&live.gpu.device, &live.config);
                live.window.request_redraw();
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw(event_loop) {
                    self.fail(event_loop, e);
                }
            }
            _ => {
                if response.repaint {
                    live.window.request_redraw();
                }
            }
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        // Continuous: the timings and the fly camera want every frame.
        if let Some(live) = &self.live {
            live.window.request_redraw();
        }
    }
}

/// What the panels' actions change: the model, the hand that moves objects, and the
/// run's report.
struct Panels<'a> {
    model: &'a mut Model,
    hand: &'a mut Hand,
    report: &'a mut RunReport,
    /// Set to have the next frame read back what a comparison needs.
    compare_asked: &'a mut bool,
}

impl Panels<'_> {
    /// Carries out one action of the panels (or the script) with the window's
    /// renderer; returns the path of a screenshot it asks for.
    fn carry_out(&mut self, action: Action, live: &mut Live, ctx: &egui::Context) -> Carried {
        match action {
            Action::Set { id, value } => self.model.set(&id, value.as_deref()),
            Action::Show(view) => self.model.view = view,
            Action::Grab(_) | Action::DragTo(_) | Action::MoveHeldBy(_) | Action::Release => {
                let Some(Workshop { renderer, uploaded, .. }) = live.workshop.as_mut() else {
                    return Carried::Wait(action);
                };
                let reach = Reach { model: self.model, renderer, uploaded };
                if let Some(name) = self.hand.act(&action, reach) {
                    self.report.grabbed.push(name);
                }
            }
            Action::Screenshot(path) => return Carried::Screenshot(path),
            Action::CopyCommand => {
                let flags = self.model.form.flags(&self.model.frame_settings(), &self.model.baseline);
                let command = reproduce::render_command(&self.model.source, &flags);
                platform::copy_text(ctx, &command);
                self.model.say(format!("copied: {command}"));
            }
            Action::SaveSceneFile(path) => {
                let saved = reproduce::scene_file_text(&self.model.source, &self.model.frame_settings())
                    .and_then(|text| platform::save_text(&path, text));
                match saved {
                    Ok(said) => self.model.say(said),
                    Err(e) => self.model.say(format!("{e:#}")),
                }
            }
            Action::CompareWithReference => {
                *self.compare_asked = true;
                self.model.say("rendering this view for the reference…");
            }
        }
        Carried::Done
    }
}

//! The window: winit's event loop, the wgpu surface, egui's renderer, and each
//! frame's work: render the scene live, draw the panels, carry out their actions,
//! present, and save screenshots.

use std::sync::Arc;

use anyhow::Context;
use gnomon_render::{GpuScene, LiveFrame, OutputRequest, RenderError, Renderer, wgpu};
use winit::{
    application::ApplicationHandler,
    dpi::LogicalSize,
    event::WindowEvent,
    event_loop::{ActiveEventLoop, ControlFlow, EventLoop},
    window::{Window, WindowId},
};

use crate::{
    Action, RunReport, View, ViewerOptions,
    debug_views::{self, ErrorJob},
    drag::{Hand, Reach},
    reproduce,
    ui::{Images, Model},
};

/// Side of each shadow-map layer in the preview, in pixels.
const MAP_PREVIEW_TILE: u32 = 256;

pub(crate) fn run(options: ViewerOptions) -> anyhow::Result<RunReport> {
    let event_loop = EventLoop::new().context(
        "cannot open a window: no display. Set DISPLAY (X11) or WAYLAND_DISPLAY, or run under \
         `xvfb-run -a` (Debian package `xvfb`)",
    )?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App::new(options)?;
    event_loop.run_app(&mut app).context("the window's event loop failed")?;
    if let Some(e) = app.failure {
        return Err(e);
    }
    app.report.settings = app.model.settings.clone();
    app.report.messages = app.model.messages.clone();
    app.report.view_rect = app.model.view_rect;
    Ok(app.report)
}

/// What exists once the window is open.
struct Live {
    window: Arc<Window>,
    /// The window's device, which the renderer shares.
    gpu: gnomon_render::Gpu,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    renderer: Renderer,
    uploaded: GpuScene,
    egui: egui_winit::State,
    painter: egui_wgpu::Renderer,
    /// The live frame's image as egui knows it.
    view_texture: Option<egui::TextureId>,
    maps_texture: Option<egui::TextureId>,
    images: Images,
}

struct App {
    model: Model,
    live: Option<Live>,
    /// The instance being moved, if any.
    hand: Hand,
    frames: Option<u32>,
    screenshot: Option<std::path::PathBuf>,
    script: Vec<(u32, Action)>,
    window_size: [u32; 2],
    report: RunReport,
    failure: Option<anyhow::Error>,
}

impl App {
    fn new(options: ViewerOptions) -> anyhow::Result<Self> {
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
            live: None,
            hand: Hand::default(),
            frames,
            screenshot,
            script,
            window_size,
            report: RunReport::default(),
            failure: None,
        })
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        self.failure.get_or_insert(error);
        event_loop.exit();
    }

    fn open(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<Live> {
        let [w, h] = self.window_size;
        let window = Arc::new(
            event_loop
                .create_window(
                    Window::default_attributes()
                        .with_title(format!("Gnomon · {}", self.model.scene.name))
                        .with_inner_size(LogicalSize::new(w, h)),
                )
                .context("cannot create the window")?,
        );
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
            Box::new(window.clone()),
        ));
        let surface =
            instance.create_surface(window.clone()).context("cannot create a surface for the window")?;
        let adapter =
            pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(&instance, Some(&surface)))
                .map_err(|_| RenderError::no_adapter())?;
        let gpu = gnomon_render::Gpu::with_adapter(&adapter, |_| {})?;
        eprintln!("gnomon view: {}", gpu.info);
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
            .context("the adapter cannot present to this window")?;
        let capabilities = surface.get_capabilities(&adapter);
        // egui and the scene image are sRGB-encoded colours: present through an sRGB view.
        if let Some(srgb) = capabilities.formats.iter().find(|f| f.is_srgb()) {
            config.format = *srgb;
        }
        surface.configure(&gpu.device, &config);
        let renderer = Renderer::new(&gpu)?;
        let uploaded = renderer.upload(&self.model.scene)?;
        let egui_ctx = egui::Context::default();
        let egui = egui_winit::State::new(
            egui_ctx,
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(gpu.limits.max_texture_dimension_2d as usize),
        );
        let painter = egui_wgpu::Renderer::new(&gpu.device, config.format, Default::default());
        Ok(Live {
            window,
            gpu,
            surface,
            config,
            renderer,
            uploaded,
            egui,
            painter,
            view_texture: None,
            maps_texture: None,
            images: Images::default(),
        })
    }

    /// One frame: scripted actions, the live render, the panels, their actions, and
    /// the picture on screen.
    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<()> {
        let frame_index = self.report.frames;
        while self.script.first().is_some_and(|(at, _)| *at <= frame_index) {
            let (_, action) = self.script.remove(0);
            self.model.pending.push(action);
        }
        let Some(live) = self.live.as_mut() else { return Ok(()) };
        let gpu = live.gpu.clone();

        // The scene, live, at the size the central view had last frame.
        self.model.settings.camera.eye = Some(self.model.rig.eye());
        self.model.settings.camera.target = Some(self.model.rig.target);
        let settings = self.model.frame_settings();
        match live.renderer.render_live(&live.uploaded, &self.model.scene, &settings) {
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
        if self.model.view == View::TexelDensity
            && self.model.density.as_ref().is_none_or(|d| d.settings != settings)
        {
            match live.renderer.render_uploaded(
                &live.uploaded,
                &self.model.scene,
                &settings,
                &OutputRequest::default(),
            ) {
                Ok(frame) => self.model.density = Some(debug_views::texel_density(&frame, &settings)),
                Err(e) => self.model.say(e.to_string()),
            }
        }
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

        // What the panels asked for.
        let mut screenshots = Vec::new();
        let mut panels = Panels { model: &mut self.model, hand: &mut self.hand, report: &mut self.report };
        for action in std::mem::take(&mut panels.model.pending) {
            if let Some(path) = panels.carry_out(action, live, &ctx, &settings) {
                screenshots.push(path);
            }
        }
        let last = self.frames.is_some_and(|n| frame_index + 1 >= n);
        if last && let Some(path) = &self.screenshot {
            screenshots.push(path.clone());
        }

        // Paint.
        let shot_texture = paint(live, &ctx, output, !screenshots.is_empty());
        if let Some(texture) = shot_texture {
            let texels: Vec<u8> = gnomon_render::read_texture(&gpu, &texture)?;
            let rgba = to_rgba(texels, texture.format());
            for path in screenshots {
                reproduce::save_png(&path, texture.width(), texture.height(), &rgba)?;
                self.model.say(format!("screenshot saved to {}", path.display()));
                self.report.screenshots.push(path);
            }
        }
        self.report.frames += 1;
        if last {
            event_loop.exit();
        }
        Ok(())
    }
}

/// Hands a live frame's textures to egui.
fn show_live_frame(live: &mut Live, frame: &LiveFrame, show_maps: bool) {
    let device = &live.gpu.device;
    let view = frame.color.create_view(&Default::default());
    let size = [frame.color.width(), frame.color.height()];
    live.view_texture = Some(match live.view_texture {
        Some(id) => {
            live.painter.update_egui_texture_from_wgpu_texture(device, &view, wgpu::FilterMode::Linear, id);
            id
        }
        None => live.painter.register_native_texture(device, &view, wgpu::FilterMode::Linear),
    });
    live.images.view = live.view_texture.map(|id| (id, size));
    if !show_maps {
        return;
    }
    match live.renderer.preview_shadow_map(frame, MAP_PREVIEW_TILE) {
        Ok(maps) => {
            let view = maps.create_view(&Default::default());
            live.maps_texture = Some(match live.maps_texture {
                Some(id) => {
                    live.painter.update_egui_texture_from_wgpu_texture(
                        device,
                        &view,
                        wgpu::FilterMode::Nearest,
                        id,
                    );
                    id
                }
                None => live.painter.register_native_texture(device, &view, wgpu::FilterMode::Nearest),
            });
            live.images.maps = live.maps_texture.map(|id| (id, [maps.width(), maps.height()]));
        }
        Err(e) => eprintln!("gnomon view: {e}"),
    }
}

/// Uploads a CPU picture to egui when it changed.
fn refresh_picture(
    ctx: &egui::Context,
    picture: Option<&debug_views::Picture>,
    handle: &mut Option<egui::TextureHandle>,
) {
    let Some(picture) = picture else {
        *handle = None;
        return;
    };
    let size = [picture.width as usize, picture.height as usize];
    let name = format!("picture {}", picture.id);
    let stale = handle.as_ref().is_none_or(|h| h.name() != name);
    if stale {
        let image = egui::ColorImage::from_rgba_unmultiplied(size, &picture.rgba);
        // Named by the picture's id: a new picture replaces the texture even when its
        // size and summary are those of the old one.
        let mut options = egui::TextureOptions::LINEAR;
        options.magnification = egui::TextureFilter::Nearest;
        *handle = Some(ctx.load_texture(name, image, options));
    }
}

/// Texels of an 8-bit colour texture as RGBA.
fn to_rgba(mut texels: Vec<u8>, format: wgpu::TextureFormat) -> Vec<u8> {
    if matches!(format, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb) {
        for px in texels.chunks_exact_mut(4) {
            px.swap(0, 2);
        }
    }
    texels
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.live.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(live) => {
                live.window.request_redraw();
                self.live = Some(live);
            }
            Err(e) => self.fail(event_loop, e),
        }
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
}

impl Panels<'_> {
    /// Carries out one action of the panels (or the script) with the window's
    /// renderer; returns the path of a screenshot it asks for.
    fn carry_out(
        &mut self,
        action: Action,
        live: &mut Live,
        ctx: &egui::Context,
        settings: &gnomon_scene::Settings,
    ) -> Option<std::path::PathBuf> {
        match action {
            Action::Set { id, value } => self.model.set(&id, value.as_deref()),
            Action::Show(view) => self.model.view = view,
            Action::Grab(_) | Action::DragTo(_) | Action::MoveHeldBy(_) | Action::Release => {
                let reach =
                    Reach { model: self.model, renderer: &mut live.renderer, uploaded: &mut live.uploaded };
                if let Some(name) = self.hand.act(&action, reach) {
                    self.report.grabbed.push(name);
                }
            }
            Action::Screenshot(path) => return Some(path),
            Action::CopyCommand => {
                let flags = self.model.form.flags(&self.model.frame_settings(), &self.model.baseline);
                let command = reproduce::render_command(&self.model.source, &flags);
                ctx.copy_text(command.clone());
                self.model.say(format!("copied: {command}"));
            }
            Action::SaveSceneFile(path) => {
                let saved = reproduce::scene_file_text(&self.model.source, &self.model.frame_settings())
                    .and_then(|text| {
                        reproduce::write_whole(&path, |temporary| {
                            std::fs::write(temporary, text)
                                .with_context(|| format!("{}: cannot write", path.display()))
                        })
                    });
                match saved {
                    Ok(()) => self.model.say(format!("saved {}", path.display())),
                    Err(e) => self.model.say(format!("{e:#}")),
                }
            }
            Action::CompareWithReference => {
                let request = OutputRequest::default();
                match live.renderer.render_uploaded(&live.uploaded, &self.model.scene, settings, &request) {
                    Ok(frame) => {
                        self.model.say("tracing the reference for this view…");
                        self.model.error_job =
                            Some(ErrorJob::start(&self.model.scene, frame, settings.clone()));
                    }
                    Err(e) => self.model.say(e.to_string()),
                }
            }
        }
        None
    }
}

/// Paints the panels' `output` into the window, and into a texture that can be copied
/// out where `shoot` asks for a screenshot: returns that texture.
fn paint(
    live: &mut Live,
    ctx: &egui::Context,
    mut output: egui::FullOutput,
    shoot: bool,
) -> Option<wgpu::Texture> {
    let gpu = live.gpu.clone();
    let (device, queue) = (&gpu.device, &gpu.queue);
    let jobs = ctx.tessellate(output.shapes, output.pixels_per_point);
    for (id, deltas) in &output.textures_delta.set {
        for delta in deltas {
            live.painter.update_texture(device, queue, *id, delta);
        }
    }
    let screen = egui_wgpu::ScreenDescriptor {
        size_in_pixels: [live.config.width, live.config.height],
        pixels_per_point: output.pixels_per_point,
    };
    let surface_texture = match live.surface.get_current_texture() {
        wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => Some(t),
        wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
            live.surface.configure(device, &live.config);
            None
        }
        _ => None,
    };
    // Screenshots paint the same jobs into a texture that can be copied out.
    let shot_texture = shoot.then(|| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("screenshot"),
            size: wgpu::Extent3d {
                width: screen.size_in_pixels[0],
                height: screen.size_in_pixels[1],
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: live.config.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    let buffers = live.painter.update_buffers(device, queue, &mut encoder, &jobs, &screen);
    let mut targets: Vec<wgpu::TextureView> = Vec::new();
    if let Some(t) = &surface_texture {
        targets.push(t.texture.create_view(&Default::default()));
    }
    if let Some(t) = &shot_texture {
        targets.push(t.create_view(&Default::default()));
    }
    for view in &targets {
        let mut pass = encoder
            .begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r: 0.06, g: 0.06, b: 0.07, a: 1.0 }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            })
            .forget_lifetime();
        live.painter.render(&mut pass, &jobs, &screen);
    }
    queue.submit(buffers.into_iter().chain([encoder.finish()]));
    if let Some(t) = surface_texture {
        live.window.pre_present_notify();
        queue.present(t);
    }
    for id in &output.textures_delta.free {
        live.painter.free_texture(id);
    }
    // Applied above; egui insists that they are drained.
    output.textures_delta.clear();
    shot_texture
}

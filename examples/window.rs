//! Bring your own shading: a winit application with its own device, mesh, camera,
//! pipeline and WGSL shader (`host.rs`, `host.wgsl`), which asks Gnomon only for
//! its sun's shadows and calls `shadow_visibility` from its own fragment shader.
//! The sun circles the scene.
//!
//! `cargo run --release -p gnomon-examples --example window [-- --technique pcss]`
//!
//! With `--frames N --screenshot OUT.png` it draws N frames, saves the last one, prints
//! how many of its pixels are lit and shadowed, and exits: what CI runs under Xvfb.

use std::{path::PathBuf, sync::Arc};

use anyhow::{Context, bail};
use glam::{Mat4, Vec3};
use gnomon_examples::host::{self, HostMesh, HostRenderer, HostTargets, HostVertex};
use gnomon_render::{Gpu, GpuScene, Renderer, read_texture, wgpu};
use gnomon_scene::{
    Camera, DirectionalLight, Material, Mesh, Scene, Settings, settings::Technique, sun_direction,
};
use winit::{
    application::ApplicationHandler,
    dpi::PhysicalSize,
    event::WindowEvent,
    event_loop::{ActiveEventLoop, EventLoop},
    window::{Window, WindowId},
};

/// The command line.
#[derive(Default)]
struct Args {
    technique: Technique,
    frames: Option<u32>,
    screenshot: Option<PathBuf>,
}

fn parse_args() -> anyhow::Result<Args> {
    let mut args = Args::default();
    let mut words = std::env::args().skip(1);
    while let Some(word) = words.next() {
        let mut value = || words.next().with_context(|| format!("{word} needs a value"));
        match word.as_str() {
            // The renderer says whether a technique of this name is registered.
            "--technique" => args.technique = value()?.parse().context("--technique")?,
            "--frames" => args.frames = Some(value()?.parse().context("--frames: expected a count")?),
            "--screenshot" => args.screenshot = Some(value()?.into()),
            other => bail!("unknown argument {other}: expected --technique, --frames or --screenshot"),
        }
    }
    Ok(args)
}

/// The host's own geometry: a ground, a slab on two posts and a box, as world-space
/// triangles in the host's vertex layout.
fn host_geometry() -> Vec<HostVertex> {
    let mut out = Vec::new();
    let mut cuboid = |centre: Vec3, half: Vec3, albedo: Vec3| {
        // Each face: its outward normal and two axes spanning it (counter-clockwise seen from outside).
        for axis in [Vec3::X, Vec3::Y, Vec3::Z, Vec3::NEG_X, Vec3::NEG_Y, Vec3::NEG_Z] {
            let (u, v) = (axis.any_orthonormal_vector(), axis.cross(axis.any_orthonormal_vector()));
            let corner = |a: f32, b: f32| centre + (axis + u * a + v * b) * half;
            let quad = [corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)];
            for i in [0, 1, 2, 0, 2, 3] {
                out.push(HostVertex {
                    position: quad[i].to_array(),
                    normal: axis.to_array(),
                    albedo: albedo.to_array(),
                });
            }
        }
    };
    cuboid(Vec3::new(0.0, -0.05, 0.0), Vec3::new(8.0, 0.05, 8.0), Vec3::splat(0.7));
    cuboid(Vec3::new(-1.5, 1.0, 0.0), Vec3::new(0.2, 1.0, 0.2), Vec3::new(0.8, 0.5, 0.3));
    cuboid(Vec3::new(1.5, 1.0, 0.0), Vec3::new(0.2, 1.0, 0.2), Vec3::new(0.8, 0.5, 0.3));
    cuboid(Vec3::new(0.0, 2.1, 0.0), Vec3::new(2.0, 0.1, 0.8), Vec3::new(0.3, 0.5, 0.8));
    cuboid(Vec3::new(2.5, 0.5, 2.5), Vec3::splat(0.5), Vec3::new(0.3, 0.7, 0.4));
    out
}

/// The same triangles as Gnomon's shadow casters: one mesh, placed as it is.
fn gnomon_scene(vertices: &[HostVertex], camera: Camera) -> Scene {
    let mesh = Mesh {
        name: "host geometry".into(),
        positions: vertices.iter().map(|v| Vec3::from(v.position)).collect(),
        normals: vertices.iter().map(|v| Vec3::from(v.normal)).collect(),
        uvs: vec![glam::Vec2::ZERO; vertices.len()],
        indices: (0..vertices.len() as u32).collect(),
    };
    let mut scene = Scene::new("window example", camera, sun(0));
    scene.place("host geometry", mesh, Material::new("host", Vec3::ONE), Mat4::IDENTITY);
    scene
}

/// The sun of frame `frame`: 50° up, circling by 6° a frame.
fn sun(frame: u32) -> DirectionalLight {
    DirectionalLight {
        direction: -sun_direction(50.0, 30.0 + 6.0 * frame as f32),
        color: Vec3::new(1.0, 0.97, 0.92),
        intensity: 1.0,
        angular_diameter_degrees: 0.5,
    }
}

/// Everything that exists once the window is open.
struct Live {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: Gpu,
    gnomon: Renderer,
    scene: Scene,
    uploaded: GpuScene,
    mesh: HostMesh,
    host: HostRenderer,
    /// The host's visibility and depth targets, made again when the window resizes.
    targets: Targets,
}

/// The targets the host draws beside the window's colour.
struct Targets {
    visibility: wgpu::Texture,
    visibility_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
}

impl Targets {
    fn new(device: &wgpu::Device, size: [u32; 2]) -> Self {
        let visibility = target_texture(device, host::VISIBILITY_FORMAT, wgpu::TextureUsages::COPY_SRC, size);
        let depth = target_texture(device, host::DEPTH_FORMAT, wgpu::TextureUsages::empty(), size);
        let (visibility_view, depth_view) =
            (visibility.create_view(&Default::default()), depth.create_view(&Default::default()));
        Self { visibility, visibility_view, depth_view }
    }
}

/// A render target of the window's size.
fn target_texture(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    [width, height]: [u32; 2],
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("window example target"),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | usage,
        view_formats: &[],
    })
}

struct App {
    args: Args,
    settings: Settings,
    live: Option<Live>,
    frame: u32,
    failure: Option<anyhow::Error>,
}

fn main() -> anyhow::Result<()> {
    let args = parse_args()?;
    let mut settings = Settings::default();
    settings.shadow.filter.technique = args.technique.clone();
    let event_loop =
        EventLoop::new().context("cannot open a display (set DISPLAY, or run under xvfb-run)")?;
    let mut app = App { args, settings, live: None, frame: 0, failure: None };
    event_loop.run_app(&mut app)?;
    app.failure.map_or(Ok(()), Err)
}

impl App {
    fn open(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<Live> {
        let attributes = Window::default_attributes()
            .with_title("Gnomon · bring your own shading")
            .with_inner_size(PhysicalSize::new(800, 450));
        let window = Arc::new(event_loop.create_window(attributes)?);
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
            Box::new(window.clone()),
        ));
        let surface = instance.create_surface(window.clone())?;
        let adapter =
            pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(&instance, Some(&surface)))
                .context("no GPU adapter can present to this window")?;
        // The host's own device; Gnomon shares it.
        let (device, queue) = pollster::block_on(adapter.request_device(&Default::default()))?;
        let gpu = Gpu::from_host(&adapter, &device, &queue);
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
            .context("the adapter cannot present to this window")?;
        if let Some(srgb) = surface.get_capabilities(&adapter).formats.into_iter().find(|f| f.is_srgb()) {
            config.format = srgb;
        }
        surface.configure(&device, &config);
        let vertices = host_geometry();
        let camera = Camera {
            eye: Vec3::new(5.0, 5.0, 8.0),
            target: Vec3::new(0.0, 0.8, 0.0),
            up: Vec3::Y,
            fov_y_degrees: 45.0,
            near: 0.1,
            far: 60.0,
        };
        let scene = gnomon_scene(&vertices, camera);
        let gnomon = Renderer::new(&gpu)?;
        let uploaded = gnomon.upload(&scene)?;
        let host = HostRenderer::new(&device, &gnomon, config.format);
        let mesh = HostMesh::new(&device, &vertices);
        let targets = Targets::new(&device, [config.width, config.height]);
        Ok(Live { window, surface, config, gpu, gnomon, scene, uploaded, mesh, host, targets })
    }

    /// Draws one frame into the window; on the last frame of `--frames`, also into a
    /// texture that is saved as the screenshot.
    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<()> {
        let Some(live) = self.live.as_mut() else { return Ok(()) };
        let last = self.args.frames.is_some_and(|n| self.frame + 1 >= n);
        let (width, height) = (live.config.width, live.config.height);
        live.scene.set_default(sun(self.frame));
        (self.settings.image.width, self.settings.image.height) = (width, height);
        let device = &live.gpu.device;
        let clip_from_world = live.scene.camera.clip_from_world(width as f32 / height as f32);
        live.host.set_camera(&live.gpu.queue, clip_from_world);
        let mut encoder = device.create_command_encoder(&Default::default());
        // Gnomon records its shadow maps into the host's encoder...
        let shadows =
            live.gnomon.record_shadows(&mut encoder, &live.uploaded, &live.scene, &self.settings)?;
        let sun_shadows = &shadows.lights[0];
        let Targets { visibility, visibility_view, depth_view } = &live.targets;
        // ...and the host draws with its own pipeline, reading them.
        let surface_texture = match live.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => Some(t),
            _ => {
                live.surface.configure(device, &live.config);
                None
            }
        };
        if let Some(surface_texture) = &surface_texture {
            let view = surface_texture.texture.create_view(&Default::default());
            let targets = HostTargets { color: &view, visibility: visibility_view, depth: depth_view };
            live.host.draw(device, &mut encoder, &targets, sun_shadows, &live.mesh);
        }
        let shot = last.then(|| {
            target_texture(device, live.config.format, wgpu::TextureUsages::COPY_SRC, [width, height])
        });
        if let Some(shot) = &shot {
            let view = shot.create_view(&Default::default());
            let targets = HostTargets { color: &view, visibility: visibility_view, depth: depth_view };
            live.host.draw(device, &mut encoder, &targets, sun_shadows, &live.mesh);
        }
        live.gpu.queue.submit([encoder.finish()]);
        if let Some(surface_texture) = surface_texture {
            live.window.pre_present_notify();
            live.gpu.queue.present(surface_texture);
        }
        self.frame += 1;
        if let Some(shot) = shot {
            let visibility: Vec<f32> = read_texture(&live.gpu, visibility)?;
            save_screenshot(&live.gpu, &shot, self.args.screenshot.as_ref(), &visibility)?;
            event_loop.exit();
        }
        Ok(())
    }
}

/// Saves `shot` (when asked) and prints how many pixels of the host's surfaces the
/// sun lights and how many lie in its shadow (the sky is neither).
fn save_screenshot(
    gpu: &Gpu,
    shot: &wgpu::Texture,
    path: Option<&PathBuf>,
    visibility: &[f32],
) -> anyhow::Result<()> {
    let lit = visibility.iter().filter(|v| **v > 0.5).count();
    let shadowed = visibility.iter().filter(|v| (0.0..=0.5).contains(*v)).count();
    let label = path.map_or("window".into(), |p| p.display().to_string());
    if let Some(path) = path {
        let mut rgba: Vec<u8> = read_texture(gpu, shot)?;
        if matches!(shot.format(), wgpu::TextureFormat::Bgra8UnormSrgb | wgpu::TextureFormat::Bgra8Unorm) {
            rgba.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
        }
        image::save_buffer(path, &rgba, shot.width(), shot.height(), image::ColorType::Rgba8)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    println!("{label}: {lit} lit and {shadowed} shadowed pixels of {}", visibility.len());
    Ok(())
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
            Err(e) => {
                self.failure = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(live) = self.live.as_mut() else { return };
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                live.config.width = size.width.max(1);
                live.config.height = size.height.max(1);
                live.surface.configure(&live.gpu.device, &live.config);
                live.targets = Targets::new(&live.gpu.device, [live.config.width, live.config.height]);
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw(event_loop) {
                    self.failure = Some(e);
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(live) = &self.live {
            live.window.request_redraw();
        }
    }
}

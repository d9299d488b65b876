//! Bring your own shading: a host's own pipeline and shader (`host.rs`, `host.wgsl`),
//! calling `shadow_visibility` on the groups `Renderer::record_shadows` returns,
//! sees the shadows Gnomon's own lighting pass draws, for every technique and every
//! light kind (a sun, a spot, a point light through a cube or dual paraboloids).

#[path = "../../crates/render/tests/gpu/support/device.rs"]
mod device;
#[path = "../../crates/render/tests/gpu/support/figures.rs"]
#[allow(dead_code)]
mod figures;

use gnomon_examples::host::{self, HostMesh, HostRenderer, HostTargets};
use gnomon_render::{Gpu, OutputRequest, RenderError, Renderer, read_texture, wgpu};
use gnomon_scene::{
    Scene, Settings, builtin,
    settings::{LightKind, OmniMap, RayUse, Refine, ShadowPath, Technique},
};

use device::gpu;

// Wide enough that the sky shows beside the ground: background pixels are compared too.
const WIDTH: u32 = 224;
const HEIGHT: u32 = 112;

fn target(gpu: &Gpu, format: wgpu::TextureFormat) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host target"),
        size: wgpu::Extent3d { width: WIDTH, height: HEIGHT, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// The host's visibility image of `scene` under `settings`.
fn host_visibility(gpu: &Gpu, renderer: &mut Renderer, scene: &Scene, settings: &Settings) -> Vec<f32> {
    let uploaded = renderer.upload(scene).unwrap();
    let mesh = HostMesh::from_scene(&gpu.device, scene);
    let mut host = HostRenderer::new(&gpu.device, renderer, host::COLOR_FORMAT);
    let (color, visibility, depth) = (
        target(gpu, host::COLOR_FORMAT),
        target(gpu, host::VISIBILITY_FORMAT),
        target(gpu, host::DEPTH_FORMAT),
    );
    let views = [&color, &visibility, &depth].map(|t| t.create_view(&Default::default()));
    let targets = HostTargets { color: &views[0], visibility: &views[1], depth: &views[2] };
    let camera = settings.resolve_camera(scene).unwrap();
    let clip_from_world = camera.clip_from_world(WIDTH as f32 / HEIGHT as f32);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let shadows = renderer.record_shadows(&mut encoder, &uploaded, scene, settings).unwrap();
    assert_eq!(shadows.lights.len(), 1, "one light selected");
    host.set_camera(&gpu.queue, clip_from_world);
    host.draw(&gpu.device, &mut encoder, &targets, &shadows.lights[0], &mesh);
    gpu.queue.submit([encoder.finish()]);
    read_texture(gpu, &visibility).unwrap()
}

fn settings(technique: Technique, light: LightKind, omni: OmniMap) -> Settings {
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (WIDTH, HEIGHT);
    // The host's shader reads the maps alone: Gnomon's frame, compared with it, must
    // not refine them by rays either.
    s.screen.refine = Refine::Off;
    s.shadow.map.resolution = 512;
    s.shadow.filter.technique = technique;
    s.light.kind = light;
    s.shadow.map.omni = omni;
    s
}

#[test]
fn a_hosts_shader_sees_gnomons_shadows_for_every_technique_and_light() {
    let gpu = gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::spheres();
    let (mut worst, mut cases) = (0.0f64, 0);
    // A technique that is rays leaves no map for a host to read (refused below).
    let registered: Vec<_> =
        renderer.techniques().iter().filter(|t| t.rays() == RayUse::AsSettingsSay).collect();
    for technique in registered {
        let mut lights = vec![(LightKind::Sun, OmniMap::Cube), (LightKind::Spot, OmniMap::Cube)];
        if technique.cube_wgsl().is_some() {
            lights.push((LightKind::Point, OmniMap::Cube));
        }
        if technique.maps().paraboloid {
            lights.push((LightKind::Point, OmniMap::Paraboloid));
        }
        for (light, omni) in lights {
            let case = format!("{technique:?}, {light:?} light, {omni:?}");
            let settings = settings(technique.technique(), light, omni);
            let frame = renderer.render(&scene, &settings, &OutputRequest::default()).unwrap();
            let hosted = host_visibility(gpu, &mut renderer, &scene, &settings);
            assert_eq!(hosted.len(), frame.visibility.len());
            // Where Gnomon drew nothing (object id 0), the host must not have either (−1).
            let expected =
                frame.visibility.iter().zip(&frame.object_id).map(|(v, id)| if *id == 0 { -1.0 } else { *v });
            let differing = hosted.iter().zip(expected).filter(|(a, b)| (*a - b).abs() > 1e-3).count();
            let rate = differing as f64 / hosted.len() as f64;
            worst = worst.max(rate);
            cases += 1;
            // Not a vacuous match: the host sees lit and shadowed surfaces.
            let shadowed = hosted.iter().filter(|v| (0.0..0.5).contains(*v)).count();
            let lit = hosted.iter().filter(|v| **v > 0.5).count();
            assert!(shadowed > 100 && lit > 100, "{case}: {shadowed} shadowed and {lit} lit pixels");
            // Only silhouette pixels may differ: the host's vertices are baked into
            // world space on the CPU, Gnomon's are transformed on the GPU.
            assert!(rate <= 0.001, "{case}: {} of pixels differ by more than 1e-3", figures::percent(rate));
        }
    }
    figures::figure(
        &format!(
            "receiver: host pixels differing from Gnomon's visibility by > 1e-3, worst of {cases} cases"
        ),
        figures::percent(worst),
        figures::percent(0.001),
    );
}

#[test]
fn the_mask_path_is_refused_with_the_settings_that_chose_it() {
    let gpu = gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::spheres();
    let uploaded = renderer.upload(&scene).unwrap();
    let mut settings = settings(Technique::PCF, LightKind::Sun, OmniMap::Cube);
    settings.screen.shadow_path = ShadowPath::Mask;
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let error = renderer.record_shadows(&mut encoder, &uploaded, &scene, &settings).err().unwrap();
    assert!(matches!(error, RenderError::ReceiverNeedsMapPath));
    assert!(error.to_string().contains("screen.shadow_path"), "{error}");
    // Rays asked for by name are traced in Gnomon's own passes, on either path; the
    // default, auto, yields to the host's shader.
    settings.screen.refine = Refine::Rays;
    for path in [ShadowPath::Auto, ShadowPath::Forward] {
        settings.screen.shadow_path = path;
        let error = renderer.record_shadows(&mut encoder, &uploaded, &scene, &settings).err().unwrap();
        assert!(matches!(error, RenderError::ReceiverNeedsMapPath), "{path:?}");
        assert!(error.to_string().contains("screen.refine"), "{error}");
    }
    settings.screen.shadow_path = ShadowPath::Auto;
    settings.screen.refine = Refine::Auto;
    assert!(renderer.record_shadows(&mut encoder, &uploaded, &scene, &settings).is_ok());
}

#[test]
fn a_technique_that_is_rays_is_refused_by_name() {
    let gpu = gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::spheres();
    let uploaded = renderer.upload(&scene).unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    for path in [ShadowPath::Auto, ShadowPath::Forward] {
        let mut settings = settings(Technique::RAYTRACED, LightKind::Sun, OmniMap::Cube);
        settings.screen.shadow_path = path;
        let error = renderer.record_shadows(&mut encoder, &uploaded, &scene, &settings).err().unwrap();
        assert!(matches!(error, RenderError::ReceiverCannotTrace { .. }), "{path:?}: {error}");
        let message = error.to_string();
        assert!(message.contains("`raytraced`") && message.contains("shadow.filter.technique"), "{message}");
    }
}

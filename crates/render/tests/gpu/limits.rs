//! Bad input at the renderer: settings beyond the device's limits or the documented
//! ranges give errors that name the setting and what is valid, never a panic.

use gnomon_render::{Gpu, OutputRequest, RenderError, Renderer};
use gnomon_scene::{
    Settings, builtin,
    settings::{Refine, Technique},
};

#[test]
fn a_shadow_map_larger_than_the_device_allows_is_refused_by_name() {
    let gpu = Gpu::new_headless_with(|l| l.max_texture_dimension_2d = 1024).expect("adapter");
    let mut renderer = Renderer::new(&gpu).unwrap();
    let mut s = Settings::default();
    s.image.width = 320;
    s.image.height = 240;
    s.shadow.map.resolution = 2048;
    let err = renderer.render(&builtin::spheres(), &s, &OutputRequest::default()).unwrap_err();
    assert!(matches!(err, RenderError::ShadowMapTooLarge { requested: 2048, max: 1024, .. }), "{err:?}");
    let message = err.to_string();
    // The library names the setting, not a command-line flag.
    assert!(message.contains("shadow.map.resolution") && message.contains("1024"), "{message}");
    assert!(!message.contains("--"), "{message}");
    // Within the limit the same renderer works.
    s.shadow.map.resolution = 1024;
    renderer.render(&builtin::spheres(), &s, &OutputRequest::default()).unwrap();
}

#[test]
fn settings_outside_their_ranges_are_refused_before_rendering() {
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let mut s = Settings::default();
    s.shadow.map.resolution = 16384;
    let err = renderer.render(&builtin::spheres(), &s, &OutputRequest::default()).unwrap_err();
    assert!(err.to_string().contains("256 to 8192"), "{err}");
    let mut s = Settings::default();
    s.camera.near = Some(10.0);
    s.camera.far = Some(5.0);
    let err = renderer.render(&builtin::spheres(), &s, &OutputRequest::default()).unwrap_err();
    assert!(err.to_string().contains("`camera.far`") && !err.to_string().contains("--"), "{err}");
}

#[test]
fn an_empty_scene_is_refused() {
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let mut scene = builtin::spheres();
    scene.instances.clear();
    let err = renderer.render(&scene, &Settings::default(), &OutputRequest::default()).unwrap_err();
    assert!(matches!(err, RenderError::EmptyScene(_)), "{err:?}");
}

/// A host's device may have no more than WebGPU's default limits (the window example
/// asks for just those): every pipeline, the ray tracer's included, must fit them.
/// The trace pass once bound nine storage buffers, one more than the default allows.
/// (Only the colour attachments' bytes per sample stay the adapter's: a frame read
/// back whole, as `render` does, needs more than the default; a host drawing into its
/// own target does not.)
#[test]
fn refined_frames_fit_webgpu_default_limits() {
    let gpu = Gpu::new_headless_with(|l| {
        *l = wgpu::Limits {
            max_color_attachment_bytes_per_sample: l.max_color_attachment_bytes_per_sample,
            ..wgpu::Limits::default()
        }
    })
    .expect("adapter");
    let mut renderer = Renderer::new(&gpu).unwrap();
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (160, 90);
    s.shadow.filter.technique = Technique::PCSS;
    s.screen.refine = Refine::Rays;
    // One frame: a still view's last may beam nothing once its penumbrae hold their
    // beams, and the trace pass must run for its limits to be tried.
    s.screen.penumbra_frames = 1;
    for sun_disk in [None, Some(2.0)] {
        s.light.sun_angular_diameter = sun_disk;
        let frame = renderer.render(&builtin::contact(), &s, &OutputRequest::default()).unwrap();
        assert!(frame.lights[0].traced_pixels.is_some_and(|p| p > 0), "{sun_disk:?}");
    }
}

/// Where the device cannot trace (here, too small a storage buffer for the list of
/// pixels to trace), refinement falls back to the map and says why; the `raytraced`
/// technique, which has no map to fall back to, is an error that names the limit.
#[test]
fn refinement_falls_back_and_raytraced_is_refused_where_rays_cannot_run() {
    const LIMIT: u64 = 4096;
    let gpu = Gpu::new_headless_with(|l| l.max_storage_buffer_binding_size = LIMIT).expect("adapter");
    let mut renderer = Renderer::new(&gpu).unwrap();
    let scene = builtin::spheres();
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (160, 90);
    s.screen.refine = Refine::Rays;
    let frame = renderer.render(&scene, &s, &OutputRequest::default()).unwrap();
    let light = &frame.lights[0];
    let why = light.refine_fallback.as_ref().expect("the fallback says why").to_string();
    assert!(why.contains(&LIMIT.to_string()), "{why}");
    assert_eq!(light.refine, Refine::Off, "drawn unrefined");
    assert_eq!(light.traced_pixels, None);
    s.shadow.filter.technique = Technique::RAYTRACED;
    let err = renderer.render(&scene, &s, &OutputRequest::default()).unwrap_err();
    assert!(matches!(err, RenderError::TechniqueNeedsRays { .. }), "{err:?}");
    let message = err.to_string();
    assert!(message.contains("`raytraced`") && message.contains(&LIMIT.to_string()), "{message}");
    assert!(!message.contains("--"), "{message}");
}

/// A host's device opened with wgpu's default limits takes a renderer: what needs
/// more (the colour attachments of the lighting passes, the prepass and the light
/// list) is built only when first drawn. The window example opens its device so.
#[test]
fn a_renderer_opens_on_a_device_with_default_limits() {
    let gpu = Gpu::new_headless_with(|l| *l = wgpu::Limits::default()).expect("adapter");
    Renderer::new(&gpu).expect("a renderer on default limits");
}

/// Issue 49: an image whose side the device takes but whose targets it cannot hold
/// (16384² × 16 bytes is 4 GiB a target; lavapipe's largest buffer is 2 GiB) is
/// refused before anything is created, naming the limit, not with a validation error
/// about an invalid texture.
#[test]
fn an_image_larger_than_the_devices_largest_buffer_is_refused_by_name() {
    let gpu = Gpu::new_headless_with(|l| l.max_buffer_size = 1 << 20).expect("adapter");
    let mut renderer = Renderer::new(&gpu).unwrap();
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (512, 512);
    let err = renderer.render(&builtin::spheres(), &s, &OutputRequest::default()).unwrap_err();
    let RenderError::ImageTooManyBytes { bytes, max_buffer, max_pixels, .. } = err else { panic!("{err:?}") };
    assert_eq!((bytes, max_buffer, max_pixels), (512 * 512 * 16, 1 << 20, (1 << 20) / 16));
    (s.image.width, s.image.height) = (256, 256);
    renderer.render(&builtin::spheres(), &s, &OutputRequest::default()).expect("2¹⁶ pixels of 16 bytes fit");
}

/// The frame's memory is charged before any of it is allocated: past the budget the
/// renderer refuses, naming the largest item, and the same renderer then renders a
/// frame within it.
#[test]
fn a_frame_over_the_memory_budget_is_refused_before_anything_is_allocated() {
    let gpu = crate::support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let mut s = Settings::default();
    (s.image.width, s.image.height) = (640, 360);
    // 640×360 takes 56 MiB of targets at 256 B a pixel: over a 32 MiB budget.
    renderer.set_memory_budget(32 << 20);
    assert_eq!(renderer.memory_budget().bytes, 32 << 20);
    let err = renderer.render(&builtin::spheres(), &s, &OutputRequest::default()).unwrap_err();
    let RenderError::OverBudget { over, .. } = &err else { panic!("{err:?}") };
    let message = err.to_string();
    assert!(
        message.contains("the image's targets, 640×360") && message.contains("at most 32.0 MiB"),
        "{message}"
    );
    assert!(message.contains("set by the host"), "{message}");
    // A budget of exactly what it asked for renders it.
    renderer.set_memory_budget(over.total);
    renderer.render(&builtin::spheres(), &s, &OutputRequest::default()).unwrap();
}

//! Bad input at the renderer: settings beyond the device's limits or the documented
//! ranges give errors that name the setting and what is valid, never a panic.

use gnomon_render::{Gpu, OutputRequest, RenderError, Renderer};
use gnomon_scene::{Settings, builtin};

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
    let gpu = Gpu::new_headless().expect("adapter");
    let mut renderer = Renderer::new(&gpu).unwrap();
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
    let gpu = Gpu::new_headless().expect("adapter");
    let mut renderer = Renderer::new(&gpu).unwrap();
    let mut scene = builtin::spheres();
    scene.instances.clear();
    let err = renderer.render(&scene, &Settings::default(), &OutputRequest::default()).unwrap_err();
    assert!(matches!(err, RenderError::EmptyScene(_)), "{err:?}");
}

//! Gnomon draws into the host's frame (`Renderer::render_into`): the image recorded
//! into the host's encoder and copied into the host's texture is the image Gnomon
//! renders on its own, in the target's size, in any colour format.

use crate::support;

use gnomon_render::{HostTarget, OutputRequest, Renderer, read_texture, wgpu};
use gnomon_scene::{Settings, builtin};

fn host_texture(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    width: u32,
    height: u32,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host target"),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// The sRGB transfer function's inverse, for one 8-bit channel.
fn linear(srgb: u8) -> f32 {
    let c = srgb as f32 / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

#[test]
fn the_image_drawn_into_a_hosts_texture_is_gnomons_own_in_any_format() {
    let gpu = support::gpu();
    let mut renderer = Renderer::new(gpu).unwrap();
    let scene = builtin::spheres();
    let uploaded = renderer.upload(&scene).unwrap();
    let (width, height) = (200, 120);
    let mut own = Settings::default();
    (own.image.width, own.image.height) = (width, height);
    // Every frame draws its map, so that all draw the same things (a kept map would
    // draw none after the first; `map_cache.rs` tests that).
    own.shadow.map.cache = gnomon_scene::settings::MapCache::Off;
    let frame = renderer.render_uploaded(&uploaded, &scene, &own, &OutputRequest::default()).unwrap();
    // The host's settings say another size: the target's wins.
    let mut hosted = own.clone();
    (hosted.image.width, hosted.image.height) = (64, 64);

    // The same format as Gnomon's image: the same bytes.
    let srgb = host_texture(&gpu.device, wgpu::TextureFormat::Rgba8UnormSrgb, width, height);
    // A linear float format: the same colours, decoded.
    let float = host_texture(&gpu.device, wgpu::TextureFormat::Rgba16Float, width, height);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    for texture in [&srgb, &float] {
        let view = texture.create_view(&Default::default());
        let stats = renderer
            .render_into(&mut encoder, &HostTarget::new(texture, &view), &uploaded, &scene, &hosted)
            .unwrap();
        assert_eq!(stats, frame.stats, "the same passes drew the same things");
    }
    gpu.queue.submit([encoder.finish()]);

    let bytes: Vec<u8> = read_texture(gpu, &srgb).unwrap();
    assert_eq!(bytes.len(), frame.color.len());
    let differing = bytes.iter().zip(&frame.color).filter(|(a, b)| a.abs_diff(**b) > 1).count();
    assert_eq!(differing, 0, "{differing} channels of the sRGB target differ from Gnomon's image");

    let halves: Vec<u16> = read_texture(gpu, &float).unwrap();
    let worst = halves
        .iter()
        .zip(&frame.color)
        .enumerate()
        .filter(|(i, _)| i % 4 != 3)
        .map(|(_, (h, c))| (half_to_f32(*h) - linear(*c)).abs())
        .fold(0.0f32, f32::max);
    // One 8-bit step of sRGB at its brightest is 0.0088 in linear terms; 16-bit floats
    // keep 11 bits of mantissa.
    assert!(worst < 0.01, "the float target is {worst} away from Gnomon's colours, decoded");
}

/// An IEEE 754 half-precision float's value.
fn half_to_f32(bits: u16) -> f32 {
    let sign = if bits & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = ((bits >> 10) & 0x1f) as i32;
    let mantissa = (bits & 0x3ff) as f32;
    match exponent {
        0 => sign * mantissa * 2f32.powi(-24),
        31 => sign * f32::INFINITY,
        e => sign * (1.0 + mantissa / 1024.0) * 2f32.powi(e - 15),
    }
}

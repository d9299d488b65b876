//! The materials' textures on the GPU: one bind group per texture, each with the
//! sampler its glTF sampler asks for.

use gnomon_scene::{Scene, Texture, Wrap};
use wgpu::util::DeviceExt;

use crate::{Gpu, passes::Layouts};

/// A bind group per texture (after a white 1×1 default at index 0), each texture
/// with the sampler its glTF sampler asks for.
pub(super) fn material_groups(gpu: &Gpu, scene: &Scene, layouts: &Layouts) -> Vec<wgpu::BindGroup> {
    let device = &gpu.device;
    let white = Texture {
        name: "white".into(),
        width: 1,
        height: 1,
        rgba8: vec![255; 4],
        wrap_u: Wrap::Repeat,
        wrap_v: Wrap::Repeat,
        nearest: true,
    };
    std::iter::once(&white)
        .chain(&scene.textures)
        .map(|t| {
            let texture = device.create_texture_with_data(
                &gpu.queue,
                &wgpu::TextureDescriptor {
                    label: Some(&t.name),
                    size: wgpu::Extent3d { width: t.width, height: t.height, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: wgpu::TextureFormat::Rgba8UnormSrgb,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                },
                wgpu::util::TextureDataOrder::LayerMajor,
                &t.rgba8,
            );
            let address = |w: Wrap| match w {
                Wrap::Repeat => wgpu::AddressMode::Repeat,
                Wrap::MirroredRepeat => wgpu::AddressMode::MirrorRepeat,
                Wrap::ClampToEdge => wgpu::AddressMode::ClampToEdge,
            };
            let filter = if t.nearest { wgpu::FilterMode::Nearest } else { wgpu::FilterMode::Linear };
            let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(&t.name),
                address_mode_u: address(t.wrap_u),
                address_mode_v: address(t.wrap_v),
                mag_filter: filter,
                min_filter: filter,
                ..Default::default()
            });
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&t.name),
                layout: &layouts.material,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(
                            &texture.create_view(&Default::default()),
                        ),
                    },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&sampler) },
                ],
            })
        })
        .collect()
}

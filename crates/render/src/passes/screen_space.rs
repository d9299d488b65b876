//! The mask path's screen-space passes (as in Unity URP's screen-space shadows): the
//! depth-and-normal prepass, and one full-screen shadow-mask pass per light that
//! resolves the light's shadow once per pixel (with contact shadows when the light
//! has them) into that light's layer of the mask.

use std::collections::HashMap;

use super::{
    Layouts, compose_wgsl,
    lighting::{self, Lookup, MapLookup},
};
use crate::techniques::TechniqueRef;
use gnomon_scene::settings::Refine;

/// The prepass's encoded normals: shading normal in xy, geometric normal in zw.
pub(crate) const NORMALS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// The prepass's surface: the world point each pixel sees in xyz (interpolated from
/// the vertices, so on its triangle; prepass.wgsl says why) and its linear view depth
/// in w (0 where no surface is seen).
pub(crate) const SURFACE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// The prepass's object: the instance it kept at each pixel, + 1 (0 where no surface
/// is seen), which the lighting passes shade alone (seen_prepass.wgsl).
pub(crate) const OBJECT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// The mask, one array layer per light: visibility + 2 × the shadow-map layer that
/// shaded it, per pixel (that layer + `uniforms::TRACED_LAYER_FLAG` where rays decided
/// the pixel, under the traced debug view). A 32-bit float keeps the visibility exact, where half floats
/// would round it by up to 2.4e-4; packing the layer in keeps it 4 bytes a pixel.
pub(crate) const MASK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// A mask pipeline per technique and lookup kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct MaskKey {
    pub technique: TechniqueRef,
    /// How the light's map is looked up.
    pub lookup: MapLookup,
    /// Which of its pixels trace a shadow ray.
    pub refine: Refine,
    /// Whether its refined pixels look for penumbrae too.
    pub size: crate::rays::LightSize,
}

/// The prepass's WGSL, composed: the lighting pass's vertex stage (`vs_surface`) and
/// its own fragment stage.
pub(crate) fn prepass_wgsl() -> String {
    let mut parts = lighting::camera_shading_wgsl();
    parts.push(lighting::SURFACE_WGSL.to_owned());
    parts.push(super::OCTAHEDRON_WGSL.to_owned());
    parts.push(include_str!("prepass.wgsl").to_owned());
    let refs: Vec<&str> = parts.iter().map(String::as_str).collect();
    compose_wgsl(&refs)
}

/// The shadow-mask pass's WGSL for `key`, composed.
pub(crate) fn mask_wgsl(key: MaskKey) -> String {
    let mut parts = lighting::camera_shading_wgsl();
    if crate::rays::classifies_penumbrae(key.refine, key.lookup, key.size) {
        parts.extend(lighting::penumbra_lookup_wgsl(key.technique, key.lookup));
    } else {
        parts.extend(lighting::visibility_wgsl(key.technique, Lookup::Own(key.lookup)));
    }
    parts.push(super::OCTAHEDRON_WGSL.to_owned());
    parts.push(include_str!("contact.wgsl").to_owned());
    parts.push(super::SCREEN_COMMON_WGSL.to_owned());
    parts.extend(crate::rays::mask_refine_wgsl(key.refine, key.lookup, key.size));
    parts.push(super::FULLSCREEN_WGSL.to_owned());
    parts.push(mask_module(key).to_owned());
    let refs: Vec<&str> = parts.iter().map(String::as_str).collect();
    compose_wgsl(&refs)
}

/// The module of `key`'s mask pass: the penumbra classification's
/// (rays/penumbra_mask.wgsl, `fs_penumbra_mask`) for a light whose penumbrae it
/// classifies, shadow_mask.wgsl's (`fs_mask`) for every other.
fn mask_module(key: MaskKey) -> &'static str {
    if crate::rays::classifies_penumbrae(key.refine, key.lookup, key.size) {
        include_str!("../rays/penumbra_mask.wgsl")
    } else {
        include_str!("shadow_mask.wgsl")
    }
}

/// The fragment entry point of [`mask_module`].
fn mask_entry(key: MaskKey) -> &'static str {
    if crate::rays::classifies_penumbrae(key.refine, key.lookup, key.size) {
        "fs_penumbra_mask"
    } else {
        "fs_mask"
    }
}

pub(crate) struct ScreenSpacePass {
    prepass_layout: wgpu::PipelineLayout,
    /// Built on first use: its targets take more colour-attachment bytes than a
    /// device opened with wgpu's default limits allows (36 of 32), and a host on such
    /// a device never draws the mask path.
    prepass: Option<wgpu::RenderPipeline>,
    mask_layout: wgpu::PipelineLayout,
    /// The mask pipelines that list pixels for rays bind the list in group 1.
    refine_layout: wgpu::PipelineLayout,
    /// Those that classify penumbrae bind the light's penumbra history in group 3.
    penumbra_layout: wgpu::PipelineLayout,
    masks: HashMap<MaskKey, wgpu::RenderPipeline>,
}

impl ScreenSpacePass {
    pub fn new(device: &wgpu::Device, layouts: &Layouts) -> Self {
        let prepass_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("prepass"),
            bind_group_layouts: &[Some(&layouts.scene), Some(&layouts.camera), None, Some(&layouts.material)],
            immediate_size: 0,
        });
        let mask_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow mask"),
            bind_group_layouts: &[Some(&layouts.scene), Some(&layouts.screen), Some(&layouts.shadow)],
            immediate_size: 0,
        });
        let refine_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow mask, refined by rays"),
            bind_group_layouts: &[Some(&layouts.scene), Some(&layouts.refine_screen), Some(&layouts.shadow)],
            immediate_size: 0,
        });
        let penumbra_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow mask, penumbrae classified"),
            bind_group_layouts: &[
                Some(&layouts.scene),
                Some(&layouts.refine_screen),
                Some(&layouts.shadow),
                Some(&layouts.penumbra_history),
            ],
            immediate_size: 0,
        });
        Self {
            prepass_layout,
            prepass: None,
            mask_layout,
            refine_layout,
            penumbra_layout,
            masks: HashMap::new(),
        }
    }

    /// The prepass pipeline: groups 0 (scene), 1 (camera) and 3 (material).
    pub fn prepass(&mut self, device: &wgpu::Device) -> &wgpu::RenderPipeline {
        let layout = &self.prepass_layout;
        self.prepass.get_or_insert_with(|| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("prepass"),
                source: wgpu::ShaderSource::Wgsl(prepass_wgsl().into()),
            });
            lighting::SurfacePipeline {
                label: "prepass",
                layout,
                module: &module,
                fragment_entry: "fs_prepass",
                targets: &[
                    Some(NORMALS_FORMAT.into()),
                    Some(SURFACE_FORMAT.into()),
                    Some(OBJECT_FORMAT.into()),
                ],
                depth: lighting::SurfaceDepth::Nearest,
            }
            .create(device)
        })
    }

    /// The mask pipeline of a technique, lookup and refinement: groups 0 (scene and
    /// light), 1 (camera and prepass, and when it refines the list of unsure pixels
    /// and the light's counters) and 2 (the light's shadow resources), drawn as one
    /// full-screen triangle.
    pub fn mask(&mut self, device: &wgpu::Device, key: MaskKey) -> &wgpu::RenderPipeline {
        let layout = if crate::rays::classifies_penumbrae(key.refine, key.lookup, key.size) {
            &self.penumbra_layout
        } else {
            match key.refine {
                Refine::Off => &self.mask_layout,
                Refine::Auto | Refine::Rays | Refine::EveryPixel => &self.refine_layout,
            }
        };
        self.masks.entry(key).or_insert_with(|| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("shadow mask"),
                source: wgpu::ShaderSource::Wgsl(mask_wgsl(key).into()),
            });
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("shadow mask"),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_fullscreen"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(mask_entry(key)),
                    compilation_options: Default::default(),
                    targets: &[Some(MASK_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        })
    }
}

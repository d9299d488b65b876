//! The lighting pass: every instance shaded from the camera with the selected
//! technique's shadow lookup, writing the colour image and the per-pixel outputs.
//! With many lights, one pass per light: the first writes every target, the others
//! add their light to the colour on the same depths, each with its own technique.
//! On the mask path every pass tests the prepass's depths and reads its light's
//! visibility from the shadow mask instead of looking it up.

use std::collections::HashMap;

use super::wgsl_interfaces::{
    IS_SEEN_SURFACE, LOOKUP_VISIBILITY, PENUMBRA_LAYER, PIXEL_VISIBILITY, SEEN_SURFACE,
};
use super::{
    CAMERA_MATERIAL_BINDINGS, CAMERA_STRUCT_WGSL, LIGHT_WGSL, Layouts, OWN_CAMERA_BINDING, OWN_LIGHT_BINDING,
    SCENE_COMMON_WGSL, SHADING_WGSL, camera_binding_wgsl, compose_wgsl, light_binding_wgsl,
    material_bindings_wgsl,
};
use gnomon_scene::settings::Refine;

use crate::{
    gpu_types::VertexStream,
    rays::{self, LightSize, Traversal},
    techniques::{self, TechniqueRef},
};

pub(crate) const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub(crate) const VISIBILITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
pub(crate) const POSITION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub(crate) const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub(crate) const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The colour attachments, in location order.
pub(crate) const TARGETS: [wgpu::TextureFormat; 5] =
    [COLOR_FORMAT, VISIBILITY_FORMAT, POSITION_FORMAT, NORMAL_FORMAT, ID_FORMAT];

/// Bytes a pixel of the largest camera-sized target: the position and normal outputs'
/// 32-bit RGBA, as the prepass's surface and normals.
pub(crate) const LARGEST_TARGET_BYTES: u64 = 16;

/// Bytes per pixel of all colour attachments together (checked against the device).
pub(crate) fn target_bytes_per_pixel() -> u32 {
    TARGETS.iter().map(|f| f.block_copy_size(None).unwrap_or(16)).sum()
}

/// What a light's lighting pass writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum LightingRole {
    /// The first light: clears and writes every target and the depth.
    First,
    /// A later light: adds its light to the colour where the depth is equal, and
    /// replaces the visibility target when `visibility` (the light the frame reports).
    Added { visibility: bool },
}

/// What makes two lighting pipelines differ.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct LightingKey {
    pub technique: TechniqueRef,
    pub lookup: Lookup,
    pub role: LightingRole,
    /// Which fragments trace shadow rays in the pass: on the forward path, as the
    /// light's refinement says; always off on the mask path, whose mask holds the
    /// rays' answers.
    pub refine: Refine,
    /// Whether its traced fragments look for penumbrae (`Hard` where it traces none).
    pub size: LightSize,
    /// How its rays traverse the casters (`Shader` where it traces none).
    pub traversal: Traversal,
}

/// How the lighting pass finds a receiver's visibility.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Lookup {
    /// In the light's own map.
    Own(MapLookup),
    /// Not at all: the screen-space shadow mask holds it (the mask pass made the
    /// lookup, in the light's own map).
    Mask,
}

/// The WGSL that defines `pixel_visibility` for a technique and lookup: the
/// technique's shadow lookup and the rules of resolve_visibility.wgsl, or on the
/// mask path the read of the mask. Shared by the lighting and shadow-mask passes.
pub(crate) fn visibility_wgsl(technique: TechniqueRef, lookup: Lookup) -> Vec<String> {
    let map = match lookup {
        Lookup::Own(map) => map,
        Lookup::Mask => {
            return vec![
                include_str!("mask_lookup.wgsl").to_owned(),
                PIXEL_VISIBILITY.bind("mask_pixel_visibility"),
            ];
        }
    };
    let mut parts = vec![techniques::shadow_bindings_wgsl(techniques::OWN_SHADOW_BINDINGS)];
    parts.extend(resolved_lookup_wgsl(technique, map));
    parts
}

pub(crate) use crate::light_map::MapLookup;

/// `pixel_visibility` of a technique and map lookup, without the declarations of the
/// shadow resources it reads (`techniques::shadow_bindings_wgsl`, in whichever group
/// the pass binds them): the technique's lookup, the light kind's visibility
/// function and the rules of resolve_visibility.wgsl.
pub(crate) fn resolved_lookup_wgsl(technique: TechniqueRef, lookup: MapLookup) -> Vec<String> {
    let mut parts = techniques::helper_wgsl();
    let (visibility, implementation) = match lookup {
        MapLookup::Cube => {
            parts.push(techniques::CUBE_WGSL.to_owned());
            let cube = technique.cube_wgsl().unwrap_or_else(|| {
                unreachable!("{technique:?} has no cube lookup; the registry refuses it for point lights")
            });
            parts.extend(techniques::technique_wgsl(technique.get(), cube));
            (include_str!("cube_visibility.wgsl"), "cube_lookup_visibility")
        }
        MapLookup::Map => {
            parts.extend(techniques::technique_wgsl(technique.get(), technique.wgsl()));
            (include_str!("map_visibility.wgsl"), "map_lookup_visibility")
        }
        MapLookup::Paraboloid => {
            parts.extend(techniques::technique_wgsl(technique.get(), technique.wgsl()));
            (include_str!("paraboloid_visibility.wgsl"), "paraboloid_lookup_visibility")
        }
        MapLookup::Virtual => {
            parts.push(techniques::VIRTUAL_QUERY_WGSL.to_owned());
            let own = technique.virtual_wgsl().unwrap_or_else(|| {
                unreachable!("{technique:?} has no virtual lookup; the registry refuses it for virtual maps")
            });
            // With its 2D lookup, which the shared shading helpers import.
            let sources: Vec<&str> = technique.wgsl().iter().chain(own).copied().collect();
            parts.extend(techniques::technique_wgsl(technique.get(), &sources));
            (include_str!("../virtual_map/virtual_visibility.wgsl"), "virtual_lookup_visibility")
        }
    };
    parts.push(visibility.to_owned());
    parts.push(LOOKUP_VISIBILITY.bind(implementation));
    parts.push(include_str!("resolve_visibility.wgsl").to_owned());
    parts.push(PIXEL_VISIBILITY.bind("resolved_pixel_visibility"));
    parts
}

/// `pixel_visibility` of the mask pass of a light whose penumbrae it classifies
/// (`rays::classifies_penumbrae`) on its 2D map or cube: the classification
/// (rays/penumbra_classify.wgsl: lit, umbra or unsure, no technique's estimate) and
/// the rules of resolve_visibility.wgsl, with `penumbra_layer`. The technique is
/// linked for the lookup's choice of layer, which the classification shares.
pub(crate) fn penumbra_lookup_wgsl(technique: TechniqueRef, lookup: MapLookup) -> Vec<String> {
    let mut parts = vec![techniques::shadow_bindings_wgsl(techniques::OWN_SHADOW_BINDINGS)];
    parts.extend(techniques::helper_wgsl());
    let (layout, names) = match lookup {
        MapLookup::Map => {
            parts.extend(techniques::technique_wgsl(technique.get(), technique.wgsl()));
            parts.push(include_str!("map_visibility.wgsl").to_owned());
            (include_str!("../rays/penumbra_map.wgsl"), ["penumbra_map_lookup", "map_penumbra_layer"])
        }
        MapLookup::Cube => {
            parts.push(techniques::CUBE_WGSL.to_owned());
            let cube = technique.cube_wgsl().unwrap_or_else(|| {
                unreachable!("{technique:?} has no cube lookup; the registry refuses it for point lights")
            });
            parts.extend(techniques::technique_wgsl(technique.get(), cube));
            parts.push(include_str!("cube_visibility.wgsl").to_owned());
            (include_str!("../rays/penumbra_cube.wgsl"), ["penumbra_cube_lookup", "cube_penumbra_layer"])
        }
        MapLookup::Paraboloid | MapLookup::Virtual => {
            unreachable!("{lookup:?}: `rays::classifies_penumbrae` classifies 2D maps and cubes alone")
        }
    };
    parts.push(include_str!("../rays/penumbra_classify.wgsl").to_owned());
    parts.push(layout.to_owned());
    parts.push(LOOKUP_VISIBILITY.bind(names[0]));
    parts.push(PENUMBRA_LAYER.bind(names[1]));
    parts.push(include_str!("resolve_visibility.wgsl").to_owned());
    parts.push(PIXEL_VISIBILITY.bind("resolved_pixel_visibility"));
    parts
}

/// The start of every module that shades from the camera: the light, the scene's
/// declarations, the camera and the shared shading helpers.
pub(crate) fn camera_shading_wgsl() -> Vec<String> {
    vec![
        LIGHT_WGSL.to_owned(),
        SCENE_COMMON_WGSL.to_owned(),
        light_binding_wgsl(OWN_LIGHT_BINDING),
        material_bindings_wgsl(CAMERA_MATERIAL_BINDINGS),
        CAMERA_STRUCT_WGSL.to_owned(),
        camera_binding_wgsl(OWN_CAMERA_BINDING),
        SHADING_WGSL.to_owned(),
    ]
}

/// The vertex stage (`vs_surface`) and normals of the passes that draw the scene
/// from the camera: the lighting pass and the prepass.
pub(crate) const SURFACE_WGSL: &str = include_str!("surface.wgsl");

/// What the lighting passes share: their outputs and the cascade view's tints.
pub(crate) const LIGHTING_COMMON_WGSL: &str = include_str!("lighting_common.wgsl");

/// How a pass that draws the scene from the camera tests and writes depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SurfaceDepth {
    /// Draws the nearest surfaces and writes their depths: the prepass, and the first
    /// lighting pass on the forward path.
    Nearest,
    /// Shades exactly the surfaces an earlier pass drew, on its depths: the same
    /// vertex transform, its position invariant, gives the same depths.
    Equal,
}

/// A pipeline that draws the scene from the camera with `vs_surface`, both sides of
/// every triangle (as a ray tracer sees them; the shaders flip back faces' normals).
pub(crate) struct SurfacePipeline<'a> {
    pub label: &'a str,
    pub layout: &'a wgpu::PipelineLayout,
    pub module: &'a wgpu::ShaderModule,
    pub fragment_entry: &'a str,
    pub targets: &'a [Option<wgpu::ColorTargetState>],
    pub depth: SurfaceDepth,
}

impl SurfacePipeline<'_> {
    pub fn create(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        let nearest = self.depth == SurfaceDepth::Nearest;
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(self.label),
            layout: Some(self.layout),
            vertex: wgpu::VertexState {
                module: self.module,
                entry_point: Some("vs_surface"),
                compilation_options: Default::default(),
                buffers: &VertexStream::Full.buffers(),
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(nearest),
                depth_compare: Some(if nearest {
                    wgpu::CompareFunction::Less
                } else {
                    wgpu::CompareFunction::Equal
                }),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: self.module,
                entry_point: Some(self.fragment_entry),
                compilation_options: Default::default(),
                targets: self.targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}

/// The WGSL that defines `seen_surface`, the surface a lighting pass shades at a
/// pixel: the fragment's own on the forward path, the prepass's on the mask path.
pub(crate) fn seen_surface_wgsl(lookup: Lookup) -> Vec<String> {
    let (seen, own) = match lookup {
        Lookup::Own(_) => (vec![include_str!("seen_own.wgsl")], "own"),
        Lookup::Mask => (vec![super::SCREEN_COMMON_WGSL, include_str!("seen_prepass.wgsl")], "prepass"),
    };
    let mut parts: Vec<String> =
        [super::OCTAHEDRON_WGSL].into_iter().chain(seen).map(str::to_owned).collect();
    parts.push(SEEN_SURFACE.bind(&format!("{own}_seen_surface")));
    parts.push(IS_SEEN_SURFACE.bind(&format!("{own}_is_seen_surface")));
    parts
}

/// The lighting pass's WGSL for `key`, composed.
pub(crate) fn lighting_wgsl(key: LightingKey) -> String {
    let mut parts = camera_shading_wgsl();
    parts.extend(visibility_wgsl(key.technique, key.lookup));
    parts.extend(match key.lookup {
        Lookup::Own(map) => rays::forward_refine_wgsl(key.refine, map, key.size, key.traversal),
        Lookup::Mask => rays::forward_refine_wgsl(Refine::Off, MapLookup::Map, key.size, key.traversal),
    });
    parts.push(SURFACE_WGSL.to_owned());
    parts.push(LIGHTING_COMMON_WGSL.to_owned());
    parts.extend(seen_surface_wgsl(key.lookup));
    parts.push(include_str!("lighting.wgsl").to_owned());
    let refs: Vec<&str> = parts.iter().map(String::as_str).collect();
    compose_wgsl(&refs)
}

/// Lighting pipelines, one per technique, lookup, role and refinement, built on
/// first use.
pub(crate) struct LightingPass {
    layout: wgpu::PipelineLayout,
    /// On the mask path group 1 holds the prepass's outputs beside the camera.
    mask_layout: wgpu::PipelineLayout,
    /// The layouts of the pipelines that trace rays, by traversal (ray queries' where
    /// the device has them): the camera's group holds the tracer's resources too.
    tracing_layouts: HashMap<Traversal, wgpu::PipelineLayout>,
    pipelines: HashMap<LightingKey, wgpu::RenderPipeline>,
}

impl LightingPass {
    pub fn new(device: &wgpu::Device, layouts: &Layouts) -> Self {
        let layout = |label, camera| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[
                    Some(&layouts.scene),
                    Some(camera),
                    Some(&layouts.shadow),
                    Some(&layouts.material),
                ],
                immediate_size: 0,
            })
        };
        let ray_queries = device.features().contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY);
        let traversals = [Some(Traversal::Shader), ray_queries.then_some(Traversal::RayQuery)];
        Self {
            layout: layout("lighting", &layouts.camera),
            mask_layout: layout("lighting on the mask path", &layouts.screen),
            tracing_layouts: traversals
                .into_iter()
                .flatten()
                .map(|t| (t, layout("lighting, tracing shadow rays", layouts.forward_rays.get(t))))
                .collect(),
            pipelines: HashMap::new(),
        }
    }

    /// The pipeline of `key`: groups 0 (scene and light), 1 (the camera; with the
    /// casters' BVH and the light's counters where the key refines; with the
    /// prepass's outputs on the mask path), 2 (the light's shadow resources) and 3
    /// (each draw's material).
    pub fn pipeline(&mut self, device: &wgpu::Device, key: LightingKey) -> &wgpu::RenderPipeline {
        // Reading the mask is the same shader whatever technique filled it: one
        // pipeline serves them all, and it traces nothing.
        let key = match key.lookup {
            Lookup::Mask => LightingKey {
                technique: TechniqueRef::any_builtin(),
                refine: Refine::Off,
                size: LightSize::Hard,
                traversal: Traversal::Shader,
                ..key
            },
            Lookup::Own(_) if key.refine == Refine::Off => {
                LightingKey { size: LightSize::Hard, traversal: Traversal::Shader, ..key }
            }
            Lookup::Own(_) => key,
        };
        let layout = match (key.lookup, key.refine) {
            (Lookup::Mask, _) => &self.mask_layout,
            (Lookup::Own(_), Refine::Off) => &self.layout,
            (Lookup::Own(_), Refine::Auto | Refine::Rays | Refine::EveryPixel) => {
                &self.tracing_layouts[&key.traversal]
            }
        };
        self.pipelines.entry(key).or_insert_with(|| {
            let source = lighting_wgsl(key);
            let label = key.technique.technique().to_string();
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(&label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
            let targets: Vec<Option<wgpu::ColorTargetState>> = TARGETS
                .iter()
                .enumerate()
                .map(|(i, &format)| {
                    let mut target = wgpu::ColorTargetState::from(format);
                    if let LightingRole::Added { visibility } = key.role {
                        match i {
                            // Light adds up in linear space (the sRGB target blends linearly).
                            0 => {
                                target.blend = Some(wgpu::BlendState {
                                    color: wgpu::BlendComponent {
                                        src_factor: wgpu::BlendFactor::One,
                                        dst_factor: wgpu::BlendFactor::One,
                                        operation: wgpu::BlendOperation::Add,
                                    },
                                    alpha: wgpu::BlendComponent::REPLACE,
                                })
                            }
                            1 if visibility => {}
                            _ => target.write_mask = wgpu::ColorWrites::empty(),
                        }
                    }
                    Some(target)
                })
                .collect();
            // The first light's pass draws the depths, unless the prepass has; later
            // lights shade exactly the surfaces it (or the prepass) found.
            let first = key.role == LightingRole::First && key.lookup != Lookup::Mask;
            SurfacePipeline {
                label: "lighting",
                layout,
                module: &module,
                fragment_entry: "fs_lighting",
                targets: &targets,
                depth: if first { SurfaceDepth::Nearest } else { SurfaceDepth::Equal },
            }
            .create(device)
        })
    }
}

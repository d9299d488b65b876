//! The typed CPU↔GPU interface: the uniform structs every pass binds, each field
//! named as in its WGSL mirror, integers and flags as `u32`; the limits and light
//! kinds shared with WGSL, generated into every shader ([`wgsl_constants`]); and the
//! builders that fill the uniforms from a light, its layout and its settings.
//!
//! Layout rules. Every struct is `repr(C)` in WGSL's uniform layout: matrices and
//! `vec4`s at 16-byte offsets, a `vec3` followed by one 4-byte scalar, scalars in
//! groups of four. `naga_layout_tests` (no device needed) parses every composed shader
//! and checks each struct's size and each field's offset against the Rust type.

mod light;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use gnomon_scene::{
    Camera, Falloff,
    settings::{DebugView, MAX_CASCADES as SETTINGS_MAX_CASCADES},
};

pub use light::{
    BiasGpu, CascadeChoiceGpu, ContactGpu, EmitterGpu, LightGpu, LightInputs, MapGpu, PcfGpu, PcssGpu,
    RaysGpu,
};

use crate::techniques;

/// The most cascades (array layers) a light's uniform holds: the settings' limit.
pub const MAX_CASCADES: usize = SETTINGS_MAX_CASCADES as usize;

/// What kind of light a [`LightGpu`] describes (`LIGHT_SUN`, … in WGSL).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightKindGpu {
    /// A directional light (`LIGHT_SUN`).
    Sun = 0,
    /// A spot light (`LIGHT_SPOT`).
    Spot = 1,
    /// A point light (`LIGHT_POINT`).
    Point = 2,
}

impl LightKindGpu {
    /// Every kind, for generating the WGSL constants.
    pub const ALL: [LightKindGpu; 3] = [LightKindGpu::Sun, LightKindGpu::Spot, LightKindGpu::Point];

    /// Its name in WGSL.
    pub const fn wgsl_name(self) -> &'static str {
        match self {
            LightKindGpu::Sun => "LIGHT_SUN",
            LightKindGpu::Spot => "LIGHT_SPOT",
            LightKindGpu::Point => "LIGHT_POINT",
        }
    }
}

/// How a [`LightGpu`]'s light weakens with distance (`FALLOFF_CONSTANT`, … in WGSL):
/// [`gnomon_scene::Falloff`] on the GPU.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FalloffGpu {
    /// No falloff inside the range (`FALLOFF_CONSTANT`); also every sun.
    Constant = 0,
    /// `KHR_lights_punctual`'s windowed inverse square (`FALLOFF_INVERSE_SQUARE`).
    InverseSquare = 1,
}

impl FalloffGpu {
    /// Every falloff, for generating the WGSL constants.
    pub const ALL: [FalloffGpu; 2] = [FalloffGpu::Constant, FalloffGpu::InverseSquare];

    /// Its name in WGSL.
    pub const fn wgsl_name(self) -> &'static str {
        match self {
            FalloffGpu::Constant => "FALLOFF_CONSTANT",
            FalloffGpu::InverseSquare => "FALLOFF_INVERSE_SQUARE",
        }
    }

    /// The falloff's code and its window (0 for none), as the uniforms hold them.
    pub fn of(falloff: Falloff) -> (u32, f32) {
        match falloff {
            Falloff::Constant => (FalloffGpu::Constant as u32, 0.0),
            Falloff::InverseSquare { window } => (FalloffGpu::InverseSquare as u32, window.unwrap_or(0.0)),
        }
    }
}

/// One layer (cascade) of a light's map (`Cascade` in `light.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CascadeGpu {
    /// World size of one texel of an orthographic layer (the largest, for a warped
    /// one); 0 for a perspective layer, whose texels grow with distance instead.
    pub texel_world: f32,
    /// The world step over which a warped layer's texel size is measured by finite
    /// differences (about a texel at its far edge).
    pub warp_step: f32,
    /// View depth where the cascade starts, in world units.
    pub split_start: f32,
    /// View depth where the cascade ends, in world units; `f32::MAX` for a map that covers every depth.
    pub split_end: f32,
    /// 1 for a warped layer (PSM, LiSPSM, TSM), whose texel size varies across it.
    pub warped: u32,
    /// Padding to WGSL's 16-byte layout.
    pub _pad0: u32,
    /// Padding to WGSL's 16-byte layout.
    pub _pad1: u32,
    /// Padding to WGSL's 16-byte layout.
    pub _pad2: u32,
}

/// The camera uniform (`Camera` in `camera.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CameraGpu {
    /// World space to the camera's clip space (WebGPU depth in [0, 1]).
    pub clip_from_world: Mat4,
    /// World space to the camera's view space (right-handed, looking down −z).
    pub view_from_world: Mat4,
    /// The camera's view space to world space: reconstructs positions from depth.
    pub world_from_view: Mat4,
    /// Camera position in world space, for view vectors (specular highlights).
    pub eye: Vec3,
    /// The debug view ([`debug_view_code`]): `DEBUG_VIEW_*` in WGSL.
    pub debug_view: u32,
    /// clip_from_view's x and y scales (a symmetric perspective).
    pub scale_x: f32,
    /// clip_from_view's y scale, 1 / tan(fov_y / 2).
    pub scale_y: f32,
    /// Near plane distance in world units (view depth at clip depth 0).
    pub near: f32,
    /// Far plane distance in world units (view depth at clip depth 1).
    pub far: f32,
    /// The image's width and height in pixels, and their inverses.
    pub width: f32,
    /// Image height in pixels.
    pub height: f32,
    /// 1 / width, to turn pixel coordinates into NDC.
    pub inv_width: f32,
    /// 1 / height, to turn pixel coordinates into NDC.
    pub inv_height: f32,
}

impl CameraGpu {
    /// The uniform for `camera` drawing a `width` × `height` image, with `debug_view`
    /// over it.
    pub fn new(camera: &Camera, width: u32, height: u32, debug_view: DebugView) -> Self {
        let aspect = width as f32 / height as f32;
        let clip_from_view = camera.clip_from_view(aspect);
        Self {
            clip_from_world: camera.clip_from_world(aspect),
            view_from_world: camera.view_from_world(),
            world_from_view: camera.view_from_world().inverse(),
            eye: camera.eye,
            debug_view: debug_view_code(debug_view),
            scale_x: clip_from_view.x_axis.x,
            scale_y: clip_from_view.y_axis.y,
            near: camera.near,
            far: camera.far,
            width: width as f32,
            height: height as f32,
            inv_width: 1.0 / width as f32,
            inv_height: 1.0 / height as f32,
        }
    }
}

/// How the camera uniform names a debug view to the shaders.
pub fn debug_view_code(view: DebugView) -> u32 {
    match view {
        DebugView::None => 0,
        DebugView::Cascades => 1,
        DebugView::Traced => 2,
    }
}

/// Added to the map layer a pixel's mask stores (visibility + 2 × layer) when rays
/// decided it and the traced view is on, for the lighting pass to tint it: above
/// every layer index (cascades, cube faces).
pub const TRACED_LAYER_FLAG: u32 = 16;
const _: () = assert!(TRACED_LAYER_FLAG as usize >= MAX_CASCADES && TRACED_LAYER_FLAG >= 6);

/// The WGSL declarations generated from Rust, composed before every shader: the
/// shared limits and the light kinds, so that no number is written twice.
pub fn wgsl_constants() -> String {
    let mut s = String::from("// Generated by gnomon_render::uniforms::wgsl_constants.\n");
    s += &format!("const MAX_CASCADES: u32 = {MAX_CASCADES}u;\n");
    s += &format!("const POISSON_DISK_SIZE: u32 = {}u;\n", techniques::POISSON_DISK_SIZE);
    s += &format!("const MAX_BLUR_TAPS: u32 = {}u;\n", 2 * gnomon_scene::settings::MAX_BLUR_RADIUS + 1);
    s += &format!("const MAX_KERNEL_TEXELS: f32 = {:?};\n", gnomon_scene::settings::MAX_KERNEL_TEXELS);
    s += &format!("const TRACED_LAYER_FLAG: u32 = {TRACED_LAYER_FLAG}u;\n");
    s += &format!("const LIGHT_TILE: u32 = {}u;\n", crate::passes::light_list::LIGHT_TILE);
    s += &format!("const LIGHT_WORDS: u32 = {}u;\n", crate::passes::light_list::LIGHT_WORDS);
    for (name, view) in
        [("NONE", DebugView::None), ("CASCADES", DebugView::Cascades), ("TRACED", DebugView::Traced)]
    {
        s += &format!("const DEBUG_VIEW_{name}: u32 = {}u;\n", debug_view_code(view));
    }
    for kind in LightKindGpu::ALL {
        s += &format!("const {}: u32 = {}u;\n", kind.wgsl_name(), kind as u32);
    }
    for falloff in FalloffGpu::ALL {
        s += &format!("const {}: u32 = {}u;\n", falloff.wgsl_name(), falloff as u32);
    }
    s += &format!("const CULL_WORKGROUP: u32 = {}u;\n", crate::passes::gpu_cull::CULL_WORKGROUP);
    for code in crate::passes::gpu_cull::WindingCode::ALL {
        s += &format!("const {}: u32 = {}u;\n", code.wgsl_name(), code as u32);
    }
    s
}

/// A GPU struct's fields as Rust lays them out, for the layout test to compare with
/// the WGSL struct of the same name.
#[cfg(test)]
pub(crate) struct StructLayout {
    pub wgsl_name: &'static str,
    pub size: usize,
    pub fields: Vec<(&'static str, usize)>,
}

/// `StructLayout` of a `repr(C)` struct, listing its fields by name.
#[cfg(test)]
macro_rules! struct_layout {
    ($ty:ty as $wgsl:literal { $($field:ident),* $(,)? }) => {
        $crate::uniforms::StructLayout {
            wgsl_name: $wgsl,
            size: std::mem::size_of::<$ty>(),
            fields: vec![$((stringify!($field), std::mem::offset_of!($ty, $field))),*],
        }
    };
}

/// Every uniform struct shared with WGSL.
#[cfg(test)]
pub(crate) fn struct_layouts() -> Vec<StructLayout> {
    use crate::passes::{depth_reduce, gpu_cull, light_list, map_preview, moments};
    vec![
        struct_layout!(LightGpu as "Light" {
            clip_from_world, light_from_world, emitter, ambient, _pad0, map, cascade_choice, bias, pcf, pcss,
            contact, rays, technique, cascade_clip_from_world, cascades,
        }),
        struct_layout!(EmitterGpu as "Emitter" {
            radiance, kind, direction, range, position, cos_inner, cos_outer, falloff, falloff_window, size,
        }),
        struct_layout!(MapGpu as "ShadowMap" {
            layer_count, moment_layers, resolution, near, far, texel_ortho, texel_per_distance, _pad0,
        }),
        struct_layout!(CascadeChoiceGpu as "CascadeChoice" { by_projection, blend, _pad0, _pad1 }),
        struct_layout!(BiasGpu as "Bias" { normal_offset, depth, slope, receiver_plane }),
        struct_layout!(PcfGpu as "Pcf" { kernel_width, kernel_in_world, poisson_taps, _pad0 }),
        struct_layout!(PcssGpu as "Pcss" { blocker_taps, max_penumbra_texels, _pad0, _pad1 }),
        struct_layout!(ContactGpu as "Contact" { steps, length, thickness, bias, distance, _pad0, _pad1, _pad2 }),
        struct_layout!(RaysGpu as "Rays" { penumbra_rays, _pad0, _pad1, _pad2 }),
        struct_layout!(techniques::NoParams as "NoParams" { _pad0, _pad1 }),
        struct_layout!(techniques::variance::VarianceParams as "VarianceParams" {
            positive_exponent, negative_exponent, min_variance, bleeding_reduction, variant, _pad0, _pad1, _pad2,
        }),
        struct_layout!(techniques::esm::EsmParams as "EsmParams" { exponent, _pad0, _pad1, _pad2, _pad3 }),
        struct_layout!(techniques::msm::MsmParams as "MsmParams" { moment_bias, hausdorff, quantised, _pad0, _pad1 }),
        struct_layout!(techniques::convolution::ConvolutionParams as "ConvolutionParams" {
            terms, attenuation, scale, offset, _pad0,
        }),
        struct_layout!(light_list::LightListGpu as "LightList" {
            ambient, shown, tiles_x, _pad0, _pad1, _pad2,
        }),
        struct_layout!(crate::gpu_types::InstanceGpu as "Instance" {
            world_from_object, base_color, specular, shininess, object_id, alpha_cutoff, textured, _pad0, _pad1,
            _pad2,
        }),
        struct_layout!(CascadeGpu as "Cascade" {
            texel_world, warp_step, split_start, split_end, warped, _pad0, _pad1, _pad2,
        }),
        struct_layout!(CameraGpu as "Camera" {
            clip_from_world, view_from_world, world_from_view, eye, debug_view, scale_x, scale_y, near,
            far, width, height, inv_width, inv_height,
        }),
        struct_layout!(depth_reduce::BoundsParams as "BoundsParams" {
            world_from_clip, light_from_world, splits, near, far, cascade_count, blend,
        }),
        struct_layout!(depth_reduce::Planes as "Planes" { near, far, _pad0, _pad1 }),
        struct_layout!(map_preview::PreviewParams as "Preview" { tile, layer_count, resolution, _pad, layers }),
        struct_layout!(map_preview::PreviewLayer as "PreviewLayer" { perspective, near, far, _pad }),
        struct_layout!(crate::gpu_scene::shadow_items::ItemGpu as "ShadowItem" {
            min, bucket, max, has_cone, axis, sin_half_angle, index_count, first_index, base_vertex,
            first_instance,
        }),
        struct_layout!(gpu_cull::CullViewGpu as "CullView" { planes, centre, item_count, near, _pad0, _pad1 }),
        struct_layout!(gpu_cull::BucketGpu as "CullBucket" { first_slot, culled }),
        struct_layout!(crate::gpu_scene::DrawArgs as "DrawArgs" {
            index_count, instance_count, first_index, base_vertex, first_instance,
        }),
        struct_layout!(moments::FilterParamsGpu as "FilterParams" {
            direction, radius, log_c, sigma, _pad0, _pad1, _pad2,
        }),
    ]
}

//! The typed CPU↔GPU interface: the uniform structs every pass binds, each field
//! named as in its WGSL mirror, integers and flags as `u32`; the light kinds and
//! limits that `passes::generated` writes into every shader; and the builders that
//! fill the uniforms from a light (`uniforms/light.rs`), its layout and its settings. It
//! depends on no pass.
//!
//! Layout rules. Every struct is `repr(C)` in WGSL's uniform layout: matrices and
//! `vec4`s at 16-byte offsets, a `vec3` followed by one 4-byte scalar, scalars in
//! groups of four. `passes::interface_tests` (no device needed) parses every composed
//! shader and checks each struct's size and each field's offset against the Rust type.

mod light;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use gnomon_scene::{
    Camera, Falloff, Light,
    settings::{DebugView, MAX_CASCADES as SETTINGS_MAX_CASCADES},
};

pub use light::{
    BiasGpu, CascadeChoiceGpu, ContactGpu, EmitterGpu, LightGpu, LightInputs, MapGpu, PcfGpu, PcssGpu,
    RaysGpu,
};

/// The most cascades (array layers) a light's uniform holds: the settings' limit.
pub const MAX_CASCADES: usize = SETTINGS_MAX_CASCADES as usize;

/// A light kind as the shaders know it: its id ([`Light::kind_id`], the index of its
/// name in [`Light::KIND_NAMES`]) and its WGSL constant (`LIGHT_SUN`, …), generated
/// from the scene's kinds so that a new kind needs nothing here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightKindGpu {
    /// The kind's id, as `EmitterGpu::kind` holds it.
    pub id: u32,
    /// The kind's name in the scene (`sun`).
    pub name: &'static str,
}

impl LightKindGpu {
    /// Every kind, for generating the WGSL constants.
    pub fn all() -> impl Iterator<Item = LightKindGpu> {
        Light::KIND_NAMES.iter().enumerate().map(|(id, &name)| LightKindGpu { id: id as u32, name })
    }

    /// Its name in WGSL: `LIGHT_` and the kind's name in capitals.
    pub fn wgsl_name(self) -> String {
        format!("LIGHT_{}", self.name.to_uppercase())
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
        DebugView::Pages => 3,
    }
}

/// Added to the map layer a pixel's mask stores (visibility + 2 × layer) when rays
/// decided it and the traced view is on, for the lighting pass to tint it: above
/// every layer index (cascades, cube faces, a virtual map's levels). Under the pages
/// view, the multiples of it above the level carry the page's flags instead
/// (`virtual_page_flags` in page_lookup.wgsl).
pub const TRACED_LAYER_FLAG: u32 = 16;
const _: () = assert!(TRACED_LAYER_FLAG as usize >= MAX_CASCADES && TRACED_LAYER_FLAG >= 6);

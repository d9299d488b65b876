//! The typed CPU↔GPU interface: the uniform structs every pass binds, each field
//! named as in its WGSL mirror, integers and flags as `u32`; the limits and light
//! kinds shared with WGSL, generated into every shader ([`wgsl_constants`]); and the
//! builders that fill the uniforms from a light, its layout and its settings.
//!
//! Layout rules. Every struct is `repr(C)` in WGSL's uniform layout: matrices and
//! `vec4`s at 16-byte offsets, a `vec3` followed by one 4-byte scalar, scalars in
//! groups of four. `naga_layout_tests` (no device needed) parses every composed shader
//! and checks each struct's size and each field's offset against the Rust type.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, UVec4, Vec3, Vec4};
use gnomon_math::ProjectionKind;
use gnomon_scene::{
    Camera, Falloff, Light, Scene, Settings,
    settings::{CascadeSelection, DebugView, KernelUnit, MAX_CASCADES as SETTINGS_MAX_CASCADES, OmniMap},
};

use crate::{layout::ShadowLayout, techniques};

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

/// A technique's own parameters ([`techniques::ShadowTechnique::params`]): reals and
/// integers, each technique documenting what it puts where (`TechniqueParams` in WGSL).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct TechniqueParams {
    /// Real-valued parameters (an exponent, a bias, …), laid out by each technique.
    pub reals: Vec4,
    /// Counts, variants and switches (0 or 1).
    pub integers: UVec4,
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

/// The light uniform (`Light` in `light.wgsl`): the light, its map's layers and the
/// shadow settings its passes read.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightGpu {
    /// The layer being drawn (shadow passes) or layer 0 (everything else).
    pub clip_from_world: Mat4,
    /// World space to layer 0's light view space: the light's axes, and distances along its view axis.
    pub light_from_world: Mat4,
    /// Colour × intensity.
    pub radiance: Vec3,
    /// A [`LightKindGpu`].
    pub kind: u32,
    /// The sun's travel direction or the spot's axis (unit).
    pub direction: Vec3,
    /// A spot or point light's range in world units.
    pub range: f32,
    /// A spot or point light's position.
    pub position: Vec3,
    /// Layers of the map: cascades, cube faces or paraboloids.
    pub layer_count: u32,
    /// Ambient light, added once by the first light's pass.
    pub ambient: Vec3,
    /// Moment-map layers per cascade, for the filterable techniques.
    pub moment_layers: u32,
    /// cos of the spot's inner and outer angles.
    pub cos_inner: f32,
    /// cos of the spot's outer half-angle: no light outside it (−1, every direction, for other lights).
    pub cos_outer: f32,
    /// The map's near and far planes along the light's axis.
    pub map_near: f32,
    /// The map's far plane along the light's axis, in world units.
    pub map_far: f32,
    /// Texel world size of an orthographic map, and per unit of distance for a
    /// perspective one.
    pub texel_ortho: f32,
    /// Texel world size per unit of distance from the light, for a perspective map (0 for an
    /// orthographic one; for a paraboloid map, radians per texel on its axis).
    pub texel_per_distance: f32,
    /// The normal offset, in texels.
    pub normal_offset: f32,
    /// Texels per side of each layer.
    pub resolution: f32,
    /// The PCF kernel's width, in texels or world units (`kernel_in_world`).
    pub kernel_width: f32,
    /// 1 when `kernel_width` is in world units, 0 when in texels.
    pub kernel_in_world: u32,
    /// Taps of the Poisson-disk PCF and of PCSS's filtering step, at most the disk's size.
    pub poisson_taps: u32,
    /// 1 to tilt the compared depth along the receiver's plane across the kernel, 0 not.
    pub receiver_plane_bias: u32,
    /// PCSS: the light's size (spot or point radius in world units, tan of the sun's
    /// angular radius), blocker-search taps, the largest radius in texels.
    pub light_size: f32,
    /// PCSS: taps of the blocker search, at most the Poisson disk's size.
    pub blocker_taps: u32,
    /// PCSS: the largest blocker-search and penumbra radius, in texels.
    pub max_penumbra_texels: f32,
    /// 1 to pick cascades by projection, 0 by view depth.
    pub select_by_projection: u32,
    /// The blend band as a fraction of a cascade's depth range.
    pub cascade_blend: f32,
    /// The rasterizer's depth bias, for the passes that write their own depth (a
    /// point light's distance cube): constant, in units of the last mantissa bit, and
    /// slope-scaled.
    pub depth_bias: f32,
    /// Slope-scaled depth bias: multiplies the depth a surface spans across one texel.
    pub slope_bias: f32,
    /// Contact shadows: ray steps (0 when off), ray length in world units, thickness
    /// as a fraction of view depth, the ray's start offset along the normal, and the
    /// view depth where they end.
    pub contact_steps: u32,
    /// Contact shadows: length of the ray toward the light, in world units.
    pub contact_length: f32,
    /// Contact shadows: assumed thickness of the depth buffer's surfaces, as a fraction of view depth.
    pub contact_thickness: f32,
    /// Contact shadows: the ray's start offset along the surface normal, in world units.
    pub contact_bias: f32,
    /// Contact shadows: the view depth beyond which they are off (faded over its last quarter).
    pub contact_distance: f32,
    /// Refinement by rays: the rays a refined pixel casts over the light's area
    /// (`ScreenSpaceSettings::penumbra_rays`), 0 for a hard light, whose pixel casts
    /// one ray to its centre.
    pub penumbra_rays: u32,
    /// A spot or point light's [`FalloffGpu`] with distance.
    pub falloff: u32,
    /// Where an inverse-square falloff's window reaches 0, in world units; 0 for no
    /// window.
    pub falloff_window: f32,
    /// Padding to the 16-byte alignment of `params`.
    pub _pad0: u32,
    /// The technique's own parameters ([`TechniqueParams`]).
    pub params: TechniqueParams,
    /// Each layer's clip_from_world (a paraboloid's: its hemisphere's frame);
    /// layer 0 equals `clip_from_world` outside the shadow passes.
    pub cascade_clip_from_world: [Mat4; MAX_CASCADES],
    /// Each layer's texel size, view-depth span and warp flag; unused layers are zero.
    pub cascades: [CascadeGpu; MAX_CASCADES],
}

impl Default for LightGpu {
    fn default() -> Self {
        Self {
            clip_from_world: Mat4::IDENTITY,
            light_from_world: Mat4::IDENTITY,
            cascade_clip_from_world: [Mat4::IDENTITY; MAX_CASCADES],
            ..Zeroable::zeroed()
        }
    }
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

/// What a light's uniform is made from.
pub struct LightInputs<'a> {
    /// The scene, for its ambient light.
    pub scene: &'a Scene,
    /// The light the uniform describes.
    pub light: &'a Light,
    /// The light's map layers: projections and cascade splits.
    pub layout: &'a ShadowLayout,
    /// The render's settings with this light's shadow settings.
    pub settings: &'a Settings,
    /// The technique's own parameters ([`techniques::ShadowTechnique::params`]).
    pub params: TechniqueParams,
    /// The filterable map the technique samples, if it has one (for its moment layer count).
    pub filterable_map: Option<techniques::FilterableMap>,
}

impl LightGpu {
    /// The uniform of one light of a frame.
    pub fn new(inputs: &LightInputs) -> Self {
        let LightInputs { scene, light, layout, settings, params, filterable_map } = *inputs;
        let projection = &layout.projections[0];
        let shadow = &settings.shadow;
        let resolution = shadow.map.resolution;
        let (texel_ortho, texel_per_distance) = projection.texel_size_coefficients(resolution);
        let f = &shadow.filter;
        let contact = &shadow.contact;
        let mut uniform = LightGpu {
            clip_from_world: projection.clip_from_world(),
            light_from_world: projection.light_from_world,
            ambient: scene.ambient,
            layer_count: layout.projections.len() as u32,
            moment_layers: filterable_map.map_or(1, |m| m.layers),
            cos_inner: 1.0,
            cos_outer: -1.0,
            map_near: projection.near,
            map_far: projection.far,
            texel_ortho,
            texel_per_distance,
            normal_offset: shadow.bias.normal_offset,
            resolution: resolution as f32,
            kernel_width: f.pcf_kernel,
            kernel_in_world: (f.kernel_unit == KernelUnit::World).into(),
            poisson_taps: f.poisson_samples,
            receiver_plane_bias: f.receiver_plane_bias.into(),
            light_size: light_size(light),
            blocker_taps: f.pcss.blocker_samples,
            max_penumbra_texels: f.pcss.max_radius,
            select_by_projection: (shadow.cascades.cascade_selection == CascadeSelection::Projection).into(),
            cascade_blend: shadow.cascades.cascade_blend,
            depth_bias: shadow.bias.depth_bias as f32,
            slope_bias: shadow.bias.slope_bias,
            contact_distance: contact.contact_distance,
            penumbra_rays: if light.is_hard() { 0 } else { settings.screen.penumbra_rays },
            params,
            ..Default::default()
        };
        if contact.contact_shadows {
            uniform.contact_steps = contact.contact_steps;
            uniform.contact_length = contact.contact_length;
            uniform.contact_thickness = contact.contact_thickness;
            uniform.contact_bias = contact.contact_bias;
        }
        uniform.set_layers(layout, resolution);
        uniform.set_light(light);
        if let (Light::Point(_), OmniMap::Paraboloid) = (light, shadow.map.omni) {
            uniform.set_paraboloids(layout, resolution);
        }
        uniform
    }

    /// Each layer's projection, texel size and view-depth span.
    fn set_layers(&mut self, layout: &ShadowLayout, resolution: u32) {
        self.cascade_clip_from_world = [self.clip_from_world; MAX_CASCADES];
        for (i, p) in layout.projections.iter().enumerate() {
            self.cascade_clip_from_world[i] = p.clip_from_world();
            let texel = p.texel_size_coefficients(resolution).0;
            let warped = matches!(p.kind, ProjectionKind::Warped { .. });
            self.cascades[i] = CascadeGpu {
                texel_world: texel,
                warp_step: texel,
                split_start: layout.splits.get(i).map_or(0.0, |z| z.min(f32::MAX)),
                split_end: layout.splits.get(i + 1).map_or(0.0, |z| z.min(f32::MAX)),
                warped: warped.into(),
                ..Default::default()
            };
        }
    }

    /// The light's kind, colour, position and cone.
    fn set_light(&mut self, light: &Light) {
        match light {
            Light::Directional(sun) => {
                self.kind = LightKindGpu::Sun as u32;
                self.radiance = sun.color * sun.intensity;
                self.direction = sun.direction.normalize();
            }
            Light::Spot(spot) => {
                self.kind = LightKindGpu::Spot as u32;
                self.radiance = spot.color * spot.intensity;
                self.direction = spot.direction.normalize();
                self.position = spot.position;
                self.range = spot.range;
                (self.falloff, self.falloff_window) = FalloffGpu::of(spot.falloff);
                self.cos_inner = spot.inner_angle_degrees.to_radians().cos();
                self.cos_outer = spot.outer_angle_degrees.to_radians().cos();
            }
            Light::Point(point) => {
                self.kind = LightKindGpu::Point as u32;
                self.radiance = point.color * point.intensity;
                self.position = point.position;
                self.range = point.range;
                (self.falloff, self.falloff_window) = FalloffGpu::of(point.falloff);
            }
        }
    }

    /// The paraboloid passes read each hemisphere's frame, not a projection; its
    /// texels are 4 / resolution radians wide on the axis, the largest.
    fn set_paraboloids(&mut self, layout: &ShadowLayout, resolution: u32) {
        for (frame, p) in self.cascade_clip_from_world.iter_mut().zip(&layout.projections) {
            *frame = p.light_from_world;
        }
        self.cascades = [CascadeGpu::default(); MAX_CASCADES];
        self.texel_ortho = 0.0;
        self.texel_per_distance = 4.0 / resolution as f32;
    }

    /// This uniform drawing layer `layer` of the map.
    pub fn for_layer(&self, layer: usize) -> Self {
        LightGpu { clip_from_world: self.cascade_clip_from_world[layer], ..*self }
    }
}

/// PCSS's light size, the same quantity the reference's area light uses.
fn light_size(light: &Light) -> f32 {
    match light {
        Light::Directional(sun) => (0.5 * sun.angular_diameter_degrees.to_radians()).tan(),
        Light::Spot(spot) => spot.radius,
        Light::Point(point) => point.radius,
    }
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
            clip_from_world, light_from_world, radiance, kind, direction, range, position, layer_count,
            ambient, moment_layers, cos_inner, cos_outer, map_near, map_far, texel_ortho,
            texel_per_distance, normal_offset, resolution, kernel_width, kernel_in_world, poisson_taps,
            receiver_plane_bias, light_size, blocker_taps, max_penumbra_texels, select_by_projection,
            cascade_blend, depth_bias, slope_bias, contact_steps, contact_length, contact_thickness,
            contact_bias, contact_distance, penumbra_rays, falloff, falloff_window, _pad0, params, cascade_clip_from_world,
            cascades,
        }),
        struct_layout!(TechniqueParams as "TechniqueParams" { reals, integers }),
        struct_layout!(light_list::EmitterGpu as "Emitter" {
            radiance, kind, direction, range, position, cos_inner, cos_outer, falloff, falloff_window, _pad0,
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

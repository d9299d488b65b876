//! The light uniform (`Light` in `passes/light.wgsl`) and the blocks it is made of:
//! the light as it emits ([`EmitterGpu`], the same struct the light-list pass keeps
//! an array of), then one block per group of shadow settings, in the order of the
//! settings' tables (`shadow.map`, `shadow.cascades`, `shadow.bias`,
//! `shadow.filter` and its `pcss`, `shadow.contact`, `screen`), then the
//! technique's own typed parameters ([`TechniqueParams`]) and the map's layers.
//! Every field means one thing for every light and every technique: a pass reads
//! `light.pcf.kernel_width`, never a slot whose meaning depends on who wrote it.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use gnomon_math::ProjectionKind;
use gnomon_scene::{
    Light, Scene, Settings,
    lights::{Cone, Origin},
    settings::{CascadeSelection, KernelUnit},
};

#[cfg(doc)]
use super::LightKindGpu;
use super::{CascadeGpu, FalloffGpu, MAX_CASCADES};
use crate::{
    layout::ShadowLayout,
    light_map::MapLookup,
    techniques::{self, ParamsBlockGpu, TechniqueParams},
};

/// A light as it emits (`Emitter` in `light.wgsl`): the light uniform's first block,
/// and one element of the light-list pass's array.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct EmitterGpu {
    /// Colour × intensity.
    pub radiance: Vec3,
    /// The light's kind ([`LightKindGpu`]), which only `light_kinds.wgsl` reads.
    pub kind: u32,
    /// The sun's travel direction or the spot's axis (unit).
    pub direction: Vec3,
    /// A spot or point light's range in world units.
    pub range: f32,
    /// A spot or point light's position.
    pub position: Vec3,
    /// cos of the spot's inner half-angle (1 for other lights).
    pub cos_inner: f32,
    /// cos of the spot's outer half-angle: no light outside it (−1, every direction,
    /// for other lights).
    pub cos_outer: f32,
    /// A spot or point light's [`FalloffGpu`] with distance.
    pub falloff: u32,
    /// Where an inverse-square falloff's window reaches 0, in world units; 0 for no
    /// window.
    pub falloff_window: f32,
    /// The light's size, the same quantity the reference's area light uses: a spot's
    /// or point light's radius in world units, the tan of the sun's angular radius.
    /// PCSS scales its penumbrae by it and refinement samples the area it spans.
    pub size: f32,
}

impl EmitterGpu {
    /// How `light` emits: its kind's [`Emission`](gnomon_scene::lights::Emission), packed.
    pub fn of(light: &Light) -> Self {
        let emission = light.emission();
        let (falloff, falloff_window) = FalloffGpu::of(emission.falloff);
        let cone = emission.cone.unwrap_or(Cone { cos_inner: 1.0, cos_outer: -1.0 });
        let mut e = EmitterGpu {
            radiance: emission.radiance,
            kind: light.kind_id(),
            falloff,
            falloff_window,
            cos_inner: cone.cos_inner,
            cos_outer: cone.cos_outer,
            size: emission.area.size(),
            ..Default::default()
        };
        match emission.origin {
            Origin::Infinite { travel } => e.direction = travel,
            Origin::Local { position, range, axis } => {
                (e.position, e.range, e.direction) = (position, range, axis)
            }
        }
        e
    }
}

/// The light's map (`ShadowMap` in `light.wgsl`): its layers and the texel sizes
/// and depth range the lookups convert by.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MapGpu {
    /// Layers of the map: cascades, cube faces or paraboloids.
    pub layer_count: u32,
    /// Moment-map layers per cascade, for the filterable techniques.
    pub moment_layers: u32,
    /// Texels per side of each layer.
    pub resolution: f32,
    /// The map's near plane along the light's axis, in world units.
    pub near: f32,
    /// The map's far plane along the light's axis, in world units.
    pub far: f32,
    /// Texel world size of an orthographic map.
    pub texel_ortho: f32,
    /// Texel world size per unit of distance from the light, for a perspective map (0
    /// for an orthographic one; for a paraboloid map, radians per texel on its axis).
    pub texel_per_distance: f32,
    /// Padding to WGSL's 16-byte struct alignment.
    pub _pad0: u32,
}

/// How a pixel picks its cascade (`CascadeChoice`; `shadow.cascades`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CascadeChoiceGpu {
    /// 1 to pick cascades by projection, 0 by view depth.
    pub by_projection: u32,
    /// The blend band as a fraction of a cascade's depth range.
    pub blend: f32,
    /// Padding.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
}

/// The biases against acne (`Bias`; `shadow.bias`, and the filter's receiver-plane
/// switch).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BiasGpu {
    /// The receiver's normal offset, in texels.
    pub normal_offset: f32,
    /// The rasterizer's constant depth bias, in units of the last mantissa bit, for
    /// the passes that write their own depth (a point light's distance cube).
    pub depth: f32,
    /// Slope-scaled depth bias: multiplies the depth a surface spans across one texel.
    pub slope: f32,
    /// 1 to tilt the compared depth along the receiver's plane across the kernel
    /// (Isidoro 2006), 0 not.
    pub receiver_plane: u32,
}

/// The PCF kernel (`Pcf`; `shadow.filter`), which PCSS's filtering step uses too.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PcfGpu {
    /// The kernel's width, in texels or world units (`kernel_in_world`).
    pub kernel_width: f32,
    /// 1 when `kernel_width` is in world units, 0 when in texels.
    pub kernel_in_world: u32,
    /// Taps of the Poisson-disk PCF and of PCSS's filtering step, at most the disk's
    /// size.
    pub poisson_taps: u32,
    /// Padding.
    pub _pad0: u32,
}

/// PCSS's blocker search (`Pcss`; `shadow.filter.pcss`). The light's size is the
/// emitter's.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct PcssGpu {
    /// Taps of the blocker search, at most the Poisson disk's size.
    pub blocker_taps: u32,
    /// The largest penumbra radius, in texels.
    pub max_penumbra_texels: f32,
    /// The largest blocker-search radius, in texels.
    pub max_search_texels: f32,
    /// Padding.
    pub _pad1: u32,
}

/// Contact shadows (`Contact`; `shadow.contact`): all zero when they are off.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ContactGpu {
    /// Ray steps (0 when off).
    pub steps: u32,
    /// Length of the ray toward the light, in world units.
    pub length: f32,
    /// Assumed thickness of the depth buffer's surfaces, as a fraction of view depth.
    pub thickness: f32,
    /// The ray's start offset along the surface normal, in world units.
    pub bias: f32,
    /// The view depth beyond which they are off (faded over its last quarter).
    pub distance: f32,
    /// Padding.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

/// Refinement by rays (`Rays`; `screen`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct RaysGpu {
    /// The rays a refined pixel casts over the light's area
    /// (`ScreenSpaceSettings::penumbra_rays`), 0 for a hard light, whose pixel casts
    /// one ray to its centre.
    pub penumbra_rays: u32,
    /// 1 where the light's penumbra history holds the last frame's answers, which this
    /// frame then starts from; 0 where anything they depend on changed
    /// (`frame/penumbra_history.rs`).
    pub history: u32,
    /// The frames the history holds, counting this one: which quarter of the unsure
    /// pixels this frame beams, and how their samples turn.
    pub frame: u32,
    /// The frames a still view's penumbrae gather (`screen.penumbra_frames`): once an
    /// unsure pixel holds the beams that many frames give it (one every
    /// `PENUMBRA_PHASES`th frame, rays/penumbra_mask.wgsl), it is beamed no more
    /// until something it depends on moves, so that a settled view costs its mask
    /// pass alone.
    pub penumbra_frames: u32,
}

/// The light uniform (`Light` in `light.wgsl`): the light, its map's layers and the
/// shadow settings its passes read, a block per group.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightGpu {
    /// The layer being drawn (shadow passes) or layer 0 (everything else).
    pub clip_from_world: Mat4,
    /// World space to layer 0's light view space: the light's axes, and distances
    /// along its view axis.
    pub light_from_world: Mat4,
    /// How the light emits.
    pub emitter: EmitterGpu,
    /// Ambient light, added once by the first light's pass (zero for the others).
    pub ambient: Vec3,
    /// Padding to WGSL's 16-byte struct alignment.
    pub _pad0: u32,
    /// The map's layers, texel sizes and depth range.
    pub map: MapGpu,
    /// How a pixel picks its cascade.
    pub cascade_choice: CascadeChoiceGpu,
    /// The biases.
    pub bias: BiasGpu,
    /// The PCF kernel.
    pub pcf: PcfGpu,
    /// PCSS's blocker search.
    pub pcss: PcssGpu,
    /// Contact shadows.
    pub contact: ContactGpu,
    /// Refinement by rays.
    pub rays: RaysGpu,
    /// The technique's own parameters, as its WGSL struct lays them out
    /// ([`techniques::ShadowTechnique::params`]).
    pub technique: ParamsBlockGpu,
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
            emitter: EmitterGpu::of(light),
            ambient: scene.ambient,
            map: MapGpu {
                layer_count: layout.projections.len() as u32,
                moment_layers: filterable_map.map_or(1, |m| m.layers),
                resolution: resolution as f32,
                near: projection.near,
                far: projection.far,
                texel_ortho,
                texel_per_distance,
                _pad0: 0,
            },
            cascade_choice: CascadeChoiceGpu {
                by_projection: (shadow.cascades.cascade_selection == CascadeSelection::Projection).into(),
                blend: shadow.cascades.cascade_blend,
                ..Default::default()
            },
            bias: BiasGpu {
                normal_offset: shadow.bias.normal_offset,
                depth: shadow.bias.depth_bias as f32,
                slope: shadow.bias.slope_bias,
                receiver_plane: f.receiver_plane_bias.into(),
            },
            pcf: PcfGpu {
                kernel_width: f.pcf_kernel,
                kernel_in_world: (f.kernel_unit == KernelUnit::World).into(),
                poisson_taps: f.poisson_samples,
                _pad0: 0,
            },
            pcss: PcssGpu {
                blocker_taps: f.pcss.blocker_samples,
                max_penumbra_texels: f.pcss.max_penumbra,
                max_search_texels: f.pcss.max_radius,
                ..Default::default()
            },
            rays: RaysGpu {
                penumbra_rays: if light.is_hard() { 0 } else { settings.screen.penumbra_rays },
                penumbra_frames: settings.screen.penumbra_frames,
                ..Default::default()
            },
            technique: params.block(),
            ..Default::default()
        };
        if contact.contact_shadows {
            uniform.contact = ContactGpu {
                steps: contact.contact_steps,
                length: contact.contact_length,
                thickness: contact.contact_thickness,
                bias: contact.contact_bias,
                distance: contact.contact_distance,
                ..Default::default()
            };
        }
        uniform.set_layers(layout, resolution);
        if MapLookup::of(light, shadow) == MapLookup::Paraboloid {
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

    /// The paraboloid passes read each hemisphere's frame, not a projection; its
    /// texels are 4 / resolution radians wide on the axis, the largest.
    fn set_paraboloids(&mut self, layout: &ShadowLayout, resolution: u32) {
        for (frame, p) in self.cascade_clip_from_world.iter_mut().zip(&layout.projections) {
            *frame = p.light_from_world;
        }
        self.cascades = [CascadeGpu::default(); MAX_CASCADES];
        self.map.texel_ortho = 0.0;
        self.map.texel_per_distance = 4.0 / resolution as f32;
    }

    /// This uniform drawing layer `layer` of the map.
    pub fn for_layer(&self, layer: usize) -> Self {
        LightGpu { clip_from_world: self.cascade_clip_from_world[layer], ..*self }
    }
}

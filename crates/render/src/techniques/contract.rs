//! The technique contract: [`ShadowTechnique`], every fact a technique states about
//! itself, and the types of those facts (the maps it reads, how far its filter
//! reaches, the settings that move its edges, its filterable map). Each technique's
//! module implements it; the registry (`registry.rs`) and the passes ask it.

use gnomon_scene::settings::{FilterSettings, RayUse, SettingsError, Technique};

use super::params::TechniqueParams;

/// A map of functions of depth that a filterable technique samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterableMap {
    /// RGBA layers per texel.
    pub layers: u32,
    /// When set, every filter averages in log space with this exponent (ESM).
    pub log_space_exponent: Option<f32>,
    /// Whether the technique's lookup uses mipmaps when they are asked for.
    pub mipmapped: bool,
}

/// The precision of the filterable map's channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapPrecision {
    /// 32-bit float.
    Single,
    /// 16-bit float: techniques may store their values in a better-conditioned basis.
    Half,
}

/// Which maps a technique can read besides a plain 2D map of a sun or a spot, which
/// every technique reads. (A point light's cube map takes the techniques that have a
/// cube lookup, [`ShadowTechnique::cube_wgsl`].)
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MapSupport {
    /// A point light's dual paraboloids, read through the 2D lookup in each
    /// hemisphere's projection (`shadow.map.omni` paraboloid).
    pub paraboloid: bool,
    /// A perspective-warped map (`shadow.map.warp`: PSM, LiSPSM, TSM), whose depth is
    /// not linear in distance and whose texels change size across the map.
    pub warped: bool,
    /// A sun's map drawn with depth clamping ("pancaking", `shadow.map.depth_clamp`),
    /// where casters before the near plane are flattened onto it.
    pub clamped_depth: bool,
}

impl MapSupport {
    /// A technique that only compares the receiver's depth with the stored depths
    /// around its own texel reads any map: the comparison holds in any monotonic
    /// depth, and a flattened caster still lies in front.
    pub const ANY: MapSupport = MapSupport { paraboloid: true, warped: true, clamped_depth: true };
    /// A technique that filters functions of depth needs depth linear in distance
    /// (no warp), and has no paraboloid lookup; clamping keeps depth linear.
    pub const LINEAR_DEPTH: MapSupport = MapSupport { paraboloid: false, warped: false, clamped_depth: true };
}

/// How far a technique's lookup on a virtual map reads
/// ([`ShadowTechnique::virtual_reach`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VirtualReach {
    /// Texels of the pixel's own level round its texel (beyond the bilinear
    /// footprint).
    Texels(f32),
    /// The light's cone from the receiver, read in the levels from the pixel's own up
    /// to the one whose texels the cone spans in at most `level_cap` texels, and in
    /// each as many texels as it spans there, at most `reach_cap`
    /// ([`gnomon_math::virtual_map::ConeReach`]).
    Cone {
        /// The most texels of its level the coarsest read spans.
        level_cap: f32,
        /// The most texels of any level a read reaches.
        reach_cap: f32,
    },
}

/// The settings that move where a technique puts its shadow edges: what
/// `gnomon calibrate` may sweep for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tunables {
    /// The shadow pass's rasterizer bias (`shadow.bias.depth_bias` and `slope_bias`):
    /// every technique that reads the depths the shadow pass stored, directly or
    /// through moments made from them.
    pub raster_bias: bool,
    /// The receiver's normal offset (`shadow.bias.normal_offset`): every technique
    /// whose lookup position the offset moves.
    pub normal_offset: bool,
    /// The PCF kernel's width (`shadow.filter.pcf_kernel`).
    pub kernel: bool,
}

impl Tunables {
    /// Depths from the shadow pass, looked up at the offset position.
    pub const BIAS: Tunables = Tunables { raster_bias: true, normal_offset: true, kernel: false };
    /// The bias, and a kernel of `shadow.filter.pcf_kernel`.
    pub const BIAS_AND_KERNEL: Tunables = Tunables { raster_bias: true, normal_offset: true, kernel: true };
    /// Nothing: the technique's answer depends on none of these settings.
    pub const NONE: Tunables = Tunables { raster_bias: false, normal_offset: false, kernel: false };
}

/// A shadow technique as the renderer sees it: every fact about it, in one place.
pub trait ShadowTechnique: Sync {
    /// The name that selects this technique (`shadow.filter.technique`).
    fn technique(&self) -> Technique;
    /// What it does, in a line, with its reference: `gnomon techniques`, `--help` and
    /// the viewer show it.
    fn summary(&self) -> &'static str;
    /// WGSL sources implementing `sample_shadow` (as `<module>_sample_shadow`, or
    /// under the contract's own name): the renderer's own modules (`include_str!` of
    /// a `.wgsl` under `src/`), or a host's WGSL, whose names from the renderer's
    /// modules are imported for it (`passes::link`).
    fn wgsl(&self) -> &'static [&'static str];
    /// The technique's parameters, typed ([`GpuParams`](super::GpuParams)), passed to the shader as
    /// `light.technique`. Their WGSL struct is a property of the type, not of the
    /// values: [`ShadowTechnique::params_struct`] asks it of the defaults.
    fn params(&self, _settings: &FilterSettings, _precision: MapPrecision) -> TechniqueParams {
        TechniqueParams::default()
    }
    /// The WGSL struct its parameters take, for the generated
    /// `alias TechniqueParams = …;` of every shader it is composed into.
    fn params_struct(&self) -> TechniqueParams {
        self.params(&FilterSettings::default(), MapPrecision::Single)
    }
    /// WGSL sources implementing `fn sample_shadow_cube(q: CubeQuery) -> f32` (as
    /// `<module>_sample_shadow_cube`, or under the contract's own name), the lookup
    /// in a point light's cube map (see `cube.wgsl`), for the techniques that can
    /// shadow a point light; `None` for the others, which the settings' checks then
    /// refuse for point lights.
    fn cube_wgsl(&self) -> Option<&'static [&'static str]> {
        None
    }
    /// WGSL sources implementing `fn sample_shadow_virtual(q: VirtualQuery) -> f32`
    /// (as `<module>_sample_shadow_virtual`, or under the contract's own name), the
    /// lookup in a virtual map (a sun's, a spot's or a point light's) through its
    /// page table (see
    /// `virtual_query.wgsl`), for the techniques that can read one; `None` for the
    /// others, which the settings' checks then refuse with `shadow.partition`
    /// virtual.
    fn virtual_wgsl(&self) -> Option<&'static [&'static str]> {
        None
    }
    /// The maps it can read besides a plain 2D map.
    fn maps(&self) -> MapSupport;
    /// How far, in texels, the technique's lookup reaches from the receiver's texel
    /// (beyond the bilinear footprint): a sample-fitted cascade keeps this margin
    /// around its samples. `kernel_texels` is the PCF kernel's width in texels.
    fn filter_reach_texels(&self, settings: &FilterSettings, kernel_texels: f32) -> f32;
    /// How far its lookup on a virtual map reads (which pages each pixel asks for):
    /// the filter's reach in the pixel's own level
    /// ([`ShadowTechnique::filter_reach_texels`]), unless it reads the light's cone in
    /// coarser levels, as PCSS does.
    fn virtual_reach(&self, settings: &FilterSettings, kernel_texels: f32) -> VirtualReach {
        VirtualReach::Texels(self.filter_reach_texels(settings, kernel_texels))
    }
    /// The settings that move its shadow edges.
    fn tunables(&self) -> Tunables;
    /// The filterable map the technique samples, if any.
    fn filterable_map(&self, _settings: &FilterSettings) -> Option<FilterableMap> {
        None
    }
    /// How it uses shadow rays. A technique that answers from its map leaves them to
    /// `screen.refine` (the default). One that is rays, [`RayUse::EveryPixel`], has
    /// every pixel of its light traced: the frame takes the mask path under
    /// `--shadow-path auto`, a host's shader cannot read it
    /// ([`crate::RenderError::ReceiverCannotTrace`]), and a device that cannot trace
    /// the scene is an error ([`crate::RenderError::TechniqueNeedsRays`]), not a
    /// fallback to its map.
    fn rays(&self) -> RayUse {
        RayUse::AsSettingsSay
    }
    /// Checks the filter settings against what this technique needs beyond their
    /// own ranges (which [`gnomon_scene::Settings::validate`] checks).
    fn validate(&self, _settings: &FilterSettings) -> Result<(), SettingsError> {
        Ok(())
    }
}

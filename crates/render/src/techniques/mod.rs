//! The shadow techniques. Each family is a module with its WGSL beside it, and each
//! technique is one line of [`BUILTIN`]. A technique states every fact about itself
//! through [`ShadowTechnique`]: its name and summary, its WGSL and parameters, the
//! maps it can read and how far its filter reaches. The passes, the layout and the
//! settings' checks ask a [`TechniqueRegistry`] and know nothing else about it: a host
//! registers a technique of its own with [`TechniqueRegistry::with`].
//!
//! A technique's WGSL implements the technique contract
//! (`passes::wgsl_interfaces::TECHNIQUE_CONTRACT`) under its module's name:
//! `fn pcf_box_sample_shadow(q: ShadowQuery) -> f32` (the lookup, see `common.wgsl`),
//! returning the lit fraction in [0, 1], and the shader's generated module binds
//! `sample_shadow` to it (a host's technique may define `sample_shadow` itself). It
//! may read the shadow bindings of `bindings.wgsl`, the `light` uniform
//! (`passes/light_binding.wgsl`), whose `technique` block carries the typed values of
//! [`ShadowTechnique::params`] ([`TechniqueParams`]), and the helpers of
//! `common.wgsl`. A built-in technique's `.wgsl` is a WESL module that imports each
//! of these (`import package::techniques::bindings::shadow_map;`); a host's WGSL is
//! linked into the shader's `package::variant`, which imports them for it
//! (`passes::link`). A filterable technique also defines
//! `fn <module>_encode_moments(d: f32, layer: u32) -> vec4<f32>`, which the moment pass
//! applies to every texel's linear depth d ∈ [0, 1].

pub(crate) mod convolution;
pub(crate) mod esm;
pub(crate) mod msm;
mod params;
mod pcf;
mod pcss;
mod raytraced;
mod registry;
pub(crate) mod variance;

use gnomon_scene::settings::{FilterSettings, RayUse, SettingsError, Technique};

pub use params::{GpuParams, NoParams, PARAMS_BYTES, ParamsBlockGpu, TechniqueParams};
pub use registry::{RegistryError, TechniqueRef, TechniqueRegistry};

use crate::passes::binding_place::BindingPlace;
use crate::passes::wgsl_interfaces::TECHNIQUE_CONTRACT;

/// Every built-in technique, in the order the command line lists them. Adding one
/// is its module, its WGSL and one line here.
pub static BUILTIN: &[&dyn ShadowTechnique] = &[
    &pcf::HARD,
    &pcf::PCF2X2,
    &pcf::PCF_BOX,
    &pcf::PCF_TENT,
    &pcf::PCF_POISSON,
    &pcss::Pcss,
    &variance::VSM,
    &esm::Esm,
    &variance::EVSM2,
    &variance::EVSM4,
    &msm::HAMBURGER,
    &msm::HAUSDORFF,
    &convolution::Convolution,
    &raytraced::Raytraced,
];

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
    /// The technique's parameters, typed ([`GpuParams`]), passed to the shader as
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

/// A technique's WGSL `sources` (its lookup's, or its cube lookup's), after the
/// generated line that types `light.technique` as its parameter struct.
pub(crate) fn technique_wgsl(technique: &dyn ShadowTechnique, sources: &[&str]) -> Vec<String> {
    let mut parts = vec![technique.params_struct().wgsl_alias()];
    parts.extend(sources.iter().map(|s| (*s).to_owned()));
    for interface in TECHNIQUE_CONTRACT {
        // Two implementations of one contract function leave the binding out, and
        // naga then refuses the shader by the interface's name: the registry's test
        // `every_technique_defines_its_entry_points` names the culprits first.
        if let Ok(Some(implementation)) = interface.implementation_in(sources)
            && implementation != interface.name
        {
            parts.push(interface.bind(&implementation));
        }
    }
    parts
}

/// The helpers every cube lookup shares, which a technique's cube WGSL imports.
pub(crate) const CUBE_WGSL: &str = include_str!("cube.wgsl");

/// The query and helpers every virtual-map lookup shares, which a technique's
/// virtual WGSL imports.
pub(crate) const VIRTUAL_QUERY_WGSL: &str = include_str!("virtual_query.wgsl");

/// Taps in the shared Poisson disk: the most any technique may ask for, the end of
/// the settings' `POISSON_TAPS` (which `Settings::validate` holds every render to).
pub const POISSON_DISK_SIZE: usize = *gnomon_scene::settings::POISSON_TAPS.end() as usize;

/// Where Gnomon's lighting, mask and moment passes bind the shadow resources a
/// technique may read: group 2, from binding 0 (`Layouts::shadow`).
pub(crate) const OWN_SHADOW_BINDINGS: BindingPlace = BindingPlace { group: 2, binding: 0 };

/// The shadow resources a technique may read (`bindings.wgsl`, declared once), the
/// first (`shadow_map`) at `place` and the other six after it.
pub(crate) fn shadow_bindings_wgsl(place: BindingPlace) -> String {
    place.declare("SHADOW")
}

/// The WGSL every technique is composed with, before its own: the shadow bindings,
/// the generated kernels, the lookup contract and its helpers.
pub(crate) fn shared_wgsl() -> Vec<String> {
    let mut parts = vec![shadow_bindings_wgsl(OWN_SHADOW_BINDINGS)];
    parts.extend(helper_wgsl());
    parts
}

/// [`shared_wgsl`] without the bindings: the generated kernels, the lookup contract
/// and its helpers.
pub(crate) fn helper_wgsl() -> Vec<String> {
    vec![
        poisson_disk_wgsl().to_owned(),
        include_str!("common.wgsl").to_owned(),
        include_str!("filterable.wgsl").to_owned(),
    ]
}

/// The shared Poisson disk as generated WGSL, made once: building it is quadratic
/// in its taps, and every shader with a technique is composed with it.
fn poisson_disk_wgsl() -> &'static str {
    static DISK: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    DISK.get_or_init(|| {
        let disk: Vec<String> = gnomon_math::kernels::poisson_disk(POISSON_DISK_SIZE)
            .iter()
            .map(|p| format!("vec2<f32>({:.6}, {:.6})", p.x, p.y))
            .collect();
        format!(
            "// Generated by gnomon_math::kernels::poisson_disk: a progressive Poisson disk in\n\
             // the unit disk; any prefix is well spread.\n\
             var<private> POISSON_DISK: array<vec2<f32>, {POISSON_DISK_SIZE}> = array<vec2<f32>, {POISSON_DISK_SIZE}>(\n    {}\n);\n",
            disk.join(",\n    ")
        )
    })
}

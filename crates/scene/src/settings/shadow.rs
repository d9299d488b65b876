//! The shadow map and its partition: bias and culling, the map's resolution,
//! format, fit and warp, the point lights' map, cascades, and the checks that tie
//! them together.

use super::ranges::SettingRange;
use super::*;

/// Which faces the shadow pass culls.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum CullMode {
    /// Cull the back faces of closed meshes, and draw both faces of open ones (and of
    /// glTF double-sided materials). Culling is safe only on a closed mesh: through a
    /// single-sided wall or roof whose back faces the light, a culled pass lets the
    /// light in. Closedness is found when the scene is uploaded
    /// (`gnomon_math::topology`).
    #[default]
    Auto,
    /// Cull faces turned away from the light on every single-sided mesh, closed or
    /// not: leaks through open meshes whose back faces the light.
    Back,
    /// Cull faces turned toward the light, so closed meshes store their back faces:
    /// the classic anti-acne trick, which can leak where meshes are open or thin.
    Front,
    /// Draw both sides.
    None,
}

/// The bias axis: offsets that keep a surface from shadowing itself (acne) without
/// detaching shadows from their casters (peter-panning).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[derive(struct_patch::Patch)]
#[patch(attribute(derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)))]
#[patch(attribute(serde(default, deny_unknown_fields)))]
#[patch(attribute(allow(missing_docs)))]
#[patch(attribute(
    doc = "Overrides of [`BiasSettings`], as a light's own shadow settings write them: each field as documented there, `None` to keep the value it is laid over."
))]
#[serde(default, deny_unknown_fields)]
pub struct BiasSettings {
    /// Rasterizer constant depth bias, in the depth format's units (D3D `DepthBias`).
    /// For Depth32Float one unit is 2^(e−23) for a primitive whose largest depth has
    /// exponent e: about 6e-8 at depth 0.5. Its bound, 2^24 units either way, is the
    /// whole [0, 1] depth range at depths in [0.5, 1).
    #[cfg_attr(feature = "cli", arg(long, value_name = "UNITS", default_value_t = BiasSettings::default().depth_bias, help_heading = "Shadow bias"))]
    pub depth_bias: i32,
    /// Rasterizer slope-scaled depth bias (D3D `SlopeScaledDepthBias`): multiplies the
    /// caster's depth slope per shadow texel, so 1 pushes a surface back by the depth
    /// it spans across one texel.
    #[cfg_attr(feature = "cli", arg(long, value_name = "FACTOR", default_value_t = BiasSettings::default().slope_bias, help_heading = "Shadow bias"))]
    pub slope_bias: f32,
    /// Normal-offset bias: the receiver is pushed along its surface normal by this many
    /// shadow texels (world size of a texel at the receiver) times 1 − N·L before the
    /// lookup, so surfaces facing the light are hardly moved and grazing ones fully
    /// (Holbert, "Normal offset shadows", 2011).
    #[cfg_attr(feature = "cli", arg(long, value_name = "TEXELS", default_value_t = BiasSettings::default().normal_offset, help_heading = "Shadow bias"))]
    pub normal_offset: f32,
    /// Faces culled when drawing casters into the shadow map.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Shadow bias"))]
    pub cull: CullMode,
}

/// The largest constant depth bias either way, in depth units: 2^24 units span the
/// whole [0, 1] range of a Depth32Float map at depths in [0.5, 1), so any more pushes
/// every caster past the far plane.
pub const MAX_DEPTH_BIAS: i32 = 1 << 24;
/// The largest slope-scaled bias: 100 texels' worth of a caster's depth slope, far
/// past the few that any surface needs (a larger one only detaches every shadow).
pub const MAX_SLOPE_BIAS: f32 = 100.0;
/// The largest normal offset, in shadow texels: twice the widest PCF kernel.
pub const MAX_NORMAL_OFFSET: f32 = 2.0 * MAX_KERNEL_TEXELS;
/// `shadow.bias.depth_bias`'s range.
pub const DEPTH_BIAS_RANGE: SettingRange = SettingRange::closed(
    "shadow.bias.depth_bias",
    -(MAX_DEPTH_BIAS as f64),
    MAX_DEPTH_BIAS as f64,
    "depth units",
);
/// `shadow.bias.slope_bias`'s range: a factor.
pub const SLOPE_BIAS_RANGE: SettingRange =
    SettingRange::closed("shadow.bias.slope_bias", 0.0, MAX_SLOPE_BIAS as f64, "");
/// `shadow.bias.normal_offset`'s range.
pub const NORMAL_OFFSET_RANGE: SettingRange =
    SettingRange::closed("shadow.bias.normal_offset", 0.0, MAX_NORMAL_OFFSET as f64, "texels");
/// `shadow.map.resolution`'s range.
pub const RESOLUTION_RANGE: SettingRange = SettingRange::closed(
    "shadow.map.resolution",
    MIN_SHADOW_RESOLUTION as f64,
    MAX_SHADOW_RESOLUTION as f64,
    "texels",
);
/// `shadow.cascades.count`'s range.
pub const CASCADE_COUNT_RANGE: SettingRange =
    SettingRange::closed("shadow.cascades.count", 1.0, MAX_CASCADES as f64, "");
/// `shadow.cascades.split_lambda`'s range.
pub const SPLIT_LAMBDA_RANGE: SettingRange =
    SettingRange::closed("shadow.cascades.split_lambda", 0.0, 1.0, "");
/// `shadow.cascades.cascade_blend`'s range: a fraction of a cascade's depth range.
pub const CASCADE_BLEND_RANGE: SettingRange =
    SettingRange::closed("shadow.cascades.cascade_blend", 0.0, 0.5, "");

impl BiasSettings {
    /// No bias at all, for demonstrating acne.
    pub fn none() -> Self {
        Self { depth_bias: 0, slope_bias: 0.0, normal_offset: 0.0, cull: CullMode::Back }
    }

    /// These settings with no depth offset in the map (constant or slope-scaled): for a
    /// map read for where its casters are, not compared with a receiver's depth.
    pub fn without_depth_offsets(&self) -> Self {
        Self { depth_bias: 0, slope_bias: 0.0, ..self.clone() }
    }
}

impl Default for BiasSettings {
    fn default() -> Self {
        Self { depth_bias: 0, slope_bias: 1.5, normal_offset: 0.3, cull: CullMode::Auto }
    }
}

/// The storage format of the shadow map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum MapFormat {
    /// 32-bit float depth: exact enough for every technique here, and filterable by comparison.
    #[default]
    Depth32float,
}

/// What a directional light's map is fitted to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Fit {
    /// The whole scene's bounds, whatever the camera sees: stable, but texels are
    /// spent on ground the camera never shows.
    Scene,
    /// The potential receivers: the intersection of the camera's view frustum with the
    /// scene's bounds in x and y, extended toward the light to every caster in z.
    #[default]
    Receivers,
}

/// The map axis: the shadow map's size and format.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[derive(struct_patch::Patch)]
#[patch(attribute(derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)))]
#[patch(attribute(serde(default, deny_unknown_fields)))]
#[patch(attribute(allow(missing_docs)))]
#[patch(attribute(
    doc = "Overrides of [`MapSettings`], as a light's own shadow settings write them: each field as documented there, `None` to keep the value it is laid over."
))]
#[serde(default, deny_unknown_fields)]
pub struct MapSettings {
    /// Shadow map width and height in texels, at most the device's largest 2D texture
    /// too.
    #[cfg_attr(feature = "cli", arg(long = "shadow-res", value_name = "TEXELS", default_value_t = MapSettings::default().resolution, help_heading = "Shadow map"))]
    pub resolution: u32,
    /// Shadow map texel format.
    #[cfg_attr(
        feature = "cli",
        arg(long = "shadow-format", value_enum, default_value_t, help_heading = "Shadow map")
    )]
    pub format: MapFormat,
    /// What a sun's map covers (a spot's map always covers its cone).
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Shadow map"))]
    pub fit: Fit,
    /// Perspective warp of a sun's single map, fitted to the receivers. Warped maps store
    /// depth that is monotonic along each light ray but not linear in distance, so they
    /// take the depth-comparison techniques (hard and the PCF family) with kernels in
    /// texels; a spot's map is perspective already and ignores this.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Shadow map"))]
    pub warp: WarpKind,
    /// Depth clamping ("pancaking") where the device supports it (unclipped depth): a
    /// sun's map fitted to the receivers (--fit receivers, tight cascades) starts its
    /// depth range at the nearest receiver, and casters nearer the sun are clamped onto
    /// that plane, so the range, and the depth error, shrink. Never for PCSS, stable
    /// cascades or warps.
    #[cfg_attr(feature = "cli", arg(long, value_name = "BOOL", default_value_t = true, action = clap::ArgAction::Set, help_heading = "Shadow map"))]
    pub depth_clamp: bool,
    /// How a point light's map covers every direction.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Shadow map"))]
    pub omni: OmniMap,
    /// How finely the casters are culled against each layer of the map. The map is the
    /// same either way: this only changes what it costs.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Shadow map"))]
    pub caster_culling: CasterCulling,
    /// How each layer's draws are submitted. The map is the same either way: this only
    /// changes what it costs.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Shadow map"))]
    pub draw_submission: DrawSubmission,
    /// What the map keeps across frames. The map is the same either way: this only
    /// changes what it costs.
    #[cfg_attr(
        feature = "cli",
        arg(long = "map-cache", value_enum, default_value_t, help_heading = "Shadow map")
    )]
    pub cache: MapCache,
}

impl Default for MapSettings {
    fn default() -> Self {
        Self {
            resolution: 2048,
            format: MapFormat::default(),
            fit: Fit::default(),
            warp: WarpKind::default(),
            depth_clamp: true,
            omni: OmniMap::default(),
            caster_culling: CasterCulling::default(),
            draw_submission: DrawSubmission::default(),
            cache: MapCache::default(),
        }
    }
}

/// What a shadow map keeps across frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum MapCache {
    /// Each layer keeps what its still casters (`Motion::Static`) drew, and draws
    /// them again only when its projection, the light, the bias or a still caster
    /// changes; the casters that move (`Motion::Dynamic`) are drawn over a copy of it
    /// every frame. A still scene under a still light then draws no shadow pass.
    #[default]
    StillCasters,
    /// Every layer draws every caster every frame.
    Off,
}

/// How finely a shadow layer's casters are culled against its frustum.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum CasterCulling {
    /// Each instance, and each cluster of about a hundred triangles of a large mesh
    /// drawn once: a layer skips the clusters outside its frustum and those whose every
    /// face the pass would cull (by their cone of normals). A cascade a few metres
    /// wide then draws a few metres of a large mesh, not all of it.
    #[default]
    Clusters,
    /// Each instance as a whole, by its bounds: a large mesh is drawn whole into every
    /// layer that it reaches. The baseline that clusters are measured against.
    Instances,
}

/// How a shadow layer's draws are submitted. Unless `direct`, the camera's passes
/// (the prepass and lighting) draw each texture's run of meshes as one multi-draw too.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum DrawSubmission {
    /// A compute pass culls the layer's casters (each instance, and each cluster of
    /// a large mesh, against the layer's frustum and by its cone of normals) and
    /// writes the draws it keeps and their count into buffers; the layer then draws
    /// them with one multi-draw per pipeline whose count the GPU read. The CPU uploads
    /// no draw arguments (it still culls, for the frame's counts and to know which
    /// layers hold moving casters). Where the device cannot take a count
    /// from a buffer, the CPU culls and the layer's draws are `indirect`.
    #[default]
    GpuCulled,
    /// The CPU culls, and each run of draws that share their state (pipeline,
    /// material, scissor) is one multi-draw from a buffer of draw arguments: a layer
    /// costs one command per pipeline however many meshes it draws. Where the device
    /// cannot (no first instance in indirect draws), the draws are issued one by one.
    Indirect,
    /// One command per draw, in the shadow passes and the camera's alike: the
    /// fallback, and the baseline indirect draws are measured and tested against.
    Direct,
}

/// The parametrization of a point light's map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum OmniMap {
    /// A cube: six 90° faces, sampled by direction; uniform texels within a factor
    /// of 3 in solid angle, six passes.
    #[default]
    Cube,
    /// Dual paraboloids (Brabec, Annen & Seidel 2002): two hemispheres, the lower
    /// one around the light's −y axis, in two passes. Cheaper to draw, but the
    /// parabolic mapping bends straight edges that the rasterizer draws straight,
    /// and texels grow 4× from the axis to the rim. Hard and PCF lookups only.
    Paraboloid,
}

/// Perspective warps of a sun's map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum WarpKind {
    /// No warp: an orthographic map.
    #[default]
    None,
    /// Perspective shadow maps (Stamminger & Drettakis 2002): the map drawn in the
    /// camera's post-perspective space, the camera slid back to take in every caster.
    Psm,
    /// Light-space perspective shadow maps (Wimmer, Scherzer & Purgathofer 2004), with
    /// n_opt = (z_n + √(z_n·z_f)) / sin γ.
    Lispsm,
    /// Trapezoidal shadow maps (Martin & Tan 2004), with the 80 % rule.
    Tsm,
}

/// How the light's view is split into shadow maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Partition {
    /// One map covering what the light must see (see --fit).
    #[default]
    Single,
    /// Cascaded shadow maps for a sun: the view frustum split along its depth, one
    /// --shadow-res map per slice, in a depth texture array (a spot keeps one map).
    Cascades,
    /// A virtual shadow map (issue 53): for a sun, a clipmap of 16384² levels in 128²
    /// pages around the camera, each level twice the area of the one before; for a
    /// spot, a mip chain of such levels over its frustum; for a point light, one over
    /// each of its cube's faces (whatever --omni says). Only the
    /// pages that visible pixels read, at their own footprint, are drawn, into a pool
    /// of tiles (--page-pool), and kept until the light or a caster over them moves.
    /// Filtered by pcf2x2, a PCF kernel (pcf, pcf-tent, pcf-poisson) or pcss, each
    /// tap through the page table; not the filterable maps yet.
    Virtual,
}

/// How the view depth range is divided among cascades.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum SplitScheme {
    /// Equal depth ranges.
    Uniform,
    /// Equal depth ratios, matching perspective texel density.
    Log,
    /// Parallel-split shadow maps: λ·log + (1 − λ)·uniform (λ = 1 is fully log).
    #[default]
    Practical,
}

/// How each cascade's map is placed over its slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum CascadeFit {
    /// The slice's potential receivers exactly: the most texels on screen, but the
    /// map's size and position change as the camera moves, so edges shimmer.
    Tight,
    /// The slice's bounding sphere, snapped to whole texels: a fixed size whatever the
    /// camera's orientation, moving in texel steps, so edges hold still.
    #[default]
    Stable,
}

/// How a pixel picks its cascade.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum CascadeSelection {
    /// By the pixel's view depth against the split distances.
    #[default]
    Depth,
    /// The first cascade whose map contains the pixel's projection: uses the finer
    /// maps wherever their (stable, larger) windows reach.
    Projection,
}

/// Cascaded shadow maps (--partition cascades).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[derive(struct_patch::Patch)]
#[patch(attribute(derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)))]
#[patch(attribute(serde(default, deny_unknown_fields)))]
#[patch(attribute(allow(missing_docs)))]
#[patch(attribute(
    doc = "Overrides of [`CascadeSettings`], as a light's own shadow settings write them: each field as documented there, `None` to keep the value it is laid over."
))]
#[serde(default, deny_unknown_fields)]
pub struct CascadeSettings {
    /// Number of cascades.
    #[cfg_attr(feature = "cli", arg(long = "cascades", value_name = "N", default_value_t = CascadeSettings::default().count, help_heading = "Cascades"))]
    pub count: u32,
    /// Split scheme of the view depth range.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Cascades"))]
    pub split: SplitScheme,
    /// λ of the practical split scheme: 1 is fully logarithmic, 0 uniform.
    #[cfg_attr(feature = "cli", arg(long, value_name = "LAMBDA", default_value_t = CascadeSettings::default().split_lambda, help_heading = "Cascades"))]
    pub split_lambda: f32,
    /// Farthest view depth the cascades cover, in world units, > 0 [default: the
    /// camera's far plane]. Beyond it a sun casts no shadow.
    #[cfg_attr(feature = "cli", arg(long, value_name = "DISTANCE", help_heading = "Cascades"))]
    pub shadow_distance: Option<f32>,
    /// How each cascade's map is fitted to its slice.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Cascades"))]
    pub cascade_fit: CascadeFit,
    /// How a pixel chooses its cascade.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Cascades"))]
    pub cascade_selection: CascadeSelection,
    /// Width of the band at the far end of each cascade over which it blends into the
    /// next, as a fraction of the cascade's depth range.
    #[cfg_attr(feature = "cli", arg(long, value_name = "FRACTION", default_value_t = CascadeSettings::default().cascade_blend, help_heading = "Cascades"))]
    pub cascade_blend: f32,
    /// Keep the cascades fitted to the first frame while the camera moves (along
    /// `compare --camera-path`, or in the viewer), to see what refitting buys.
    #[cfg_attr(feature = "cli", arg(long = "freeze-cascades", help_heading = "Cascades"))]
    pub freeze: bool,
    /// Sample-distribution shadow maps (Lauritzen, Salvi & Lefohn 2011): split the view
    /// depths the camera actually sees, reduced on the GPU from a depth prepass of the
    /// shadow casters, instead of the depths where the view frustum meets the scene's
    /// bounds. Costs a prepass and a read back of two numbers before the shadow pass.
    #[cfg_attr(feature = "cli", arg(long, help_heading = "Cascades"))]
    pub sdsm: bool,
    /// With --sdsm, also fit each tight cascade in x and y to the light-space bounds of
    /// the samples it serves (a second reduction of the same depth buffer), instead of
    /// to its whole slice of the view frustum.
    #[cfg_attr(feature = "cli", arg(long, help_heading = "Cascades"))]
    pub sdsm_bounds: bool,
}

impl Default for CascadeSettings {
    fn default() -> Self {
        Self {
            count: 4,
            split: SplitScheme::default(),
            split_lambda: 0.8,
            shadow_distance: None,
            cascade_fit: CascadeFit::default(),
            cascade_selection: CascadeSelection::default(),
            cascade_blend: 0.1,
            freeze: false,
            sdsm: false,
            sdsm_bounds: false,
        }
    }
}

/// A light's own shadow settings: any of [`ShadowSettings`]' fields, each laid over
/// the render's ([`ShadowSettings::with_overrides`]). A scene file's `[light.shadow]`
/// table is one, and so is a built-in scene's light list entry.
pub type ShadowOverrides = ShadowSettingsPatch;

/// Shadow settings, one field per orthogonal axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[derive(struct_patch::Patch)]
#[patch(attribute(derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)))]
#[patch(attribute(serde(default, deny_unknown_fields)))]
#[patch(attribute(allow(missing_docs)))]
#[patch(attribute(
    doc = "Overrides of [`ShadowSettings`], as a light's own shadow settings write them: each field as documented there, `None` to keep the value it is laid over."
))]
#[serde(default, deny_unknown_fields)]
pub struct ShadowSettings {
    /// The filter: which technique samples the map, and its parameters.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[patch(nesting)]
    pub filter: FilterSettings,
    /// Biases against shadow acne (constant, slope-scaled, normal offset) and face culling.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[patch(nesting)]
    pub bias: BiasSettings,
    /// The map: resolution, storage format, fit, warp, depth clamping, point-light layout.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[patch(nesting)]
    pub map: MapSettings,
    /// Partition of the light's view into maps.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Shadow map"))]
    pub partition: Partition,
    /// The cascades, used with `--partition cascades`.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[patch(nesting)]
    pub cascades: CascadeSettings,
    /// Contact shadows for this light.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[patch(nesting)]
    pub contact: ContactSettings,
    /// The virtual map, used with `--partition virtual`.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[patch(nesting)]
    pub virtual_map: VirtualMapSettings,
}

impl ShadowSettings {
    /// These settings with `overrides` laid over them, checked.
    pub fn with_overrides(&self, overrides: &ShadowOverrides) -> Result<ShadowSettings, SettingsError> {
        use struct_patch::Patch as _;
        let mut shadow = self.clone();
        shadow.apply(overrides.clone());
        shadow.validate()?;
        Ok(shadow)
    }

    /// Checks every shadow value against its documented range, group by group, and
    /// the combinations that cannot work together.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let s = self;
        s.filter.validate()?;
        if s.map.warp != WarpKind::None {
            let warp = value_name(&s.map.warp);
            check(
                s.partition == Partition::Single,
                "shadow.map.warp",
                &warp,
                "a warp of a single map: with `shadow.partition` cascades or virtual use `shadow.map.warp` none",
            )?;
            check(
                s.filter.kernel_unit == KernelUnit::Texels,
                "shadow.map.warp",
                &warp,
                "with `shadow.filter.kernel_unit` world: a warped map's kernels are in texels",
            )?;
        }
        s.cascades.validate()?;
        s.bias.validate()?;
        RESOLUTION_RANGE.check(s.map.resolution)?;
        s.contact.validate()?;
        s.virtual_map.validate()?;
        Ok(())
    }
}

impl FilterSettings {
    fn validate(&self) -> Result<(), SettingsError> {
        let f = self;
        match f.kernel_unit {
            KernelUnit::Texels => check(
                PCF_KERNEL_TEXELS_RANGE.allows(f.pcf_kernel),
                "shadow.filter.pcf_kernel",
                f.pcf_kernel,
                format!(
                    "{} (or a world width with `shadow.filter.kernel_unit` world)",
                    PCF_KERNEL_TEXELS_RANGE.describe()
                ),
            )?,
            KernelUnit::World => check(
                crate::limits::LIGHT_RANGE.allows(f.pcf_kernel),
                "shadow.filter.pcf_kernel",
                f.pcf_kernel,
                "a world width in (0, 1e7]",
            )?,
        }
        POISSON_SAMPLES_RANGE.check(f.poisson_samples)?;
        BLOCKER_SAMPLES_RANGE.check(f.pcss.blocker_samples)?;
        PCSS_MAX_RADIUS_RANGE.check(f.pcss.max_radius)?;
        PCSS_MAX_PENUMBRA_RANGE.check(f.pcss.max_penumbra)?;
        f.moments.validate()?;
        Ok(())
    }
}

impl CascadeSettings {
    fn validate(&self) -> Result<(), SettingsError> {
        let c = self;
        CASCADE_COUNT_RANGE.check(c.count)?;
        SPLIT_LAMBDA_RANGE.check(c.split_lambda)?;
        CASCADE_BLEND_RANGE.check(c.cascade_blend)?;
        check_limit(c.shadow_distance, "shadow.cascades.shadow_distance", &crate::limits::CLIP_DISTANCE)?;
        if c.sdsm_bounds {
            check(
                c.sdsm,
                "shadow.cascades.sdsm_bounds",
                "set",
                "only with `shadow.cascades.sdsm`, whose depth prepass it reduces",
            )?;
            check(
                c.cascade_fit == CascadeFit::Tight,
                "shadow.cascades.sdsm_bounds",
                "set",
                "only with `shadow.cascades.cascade_fit` tight: bounds that follow every pixel cannot keep a stable cascade still",
            )?;
        }
        Ok(())
    }
}

impl BiasSettings {
    fn validate(&self) -> Result<(), SettingsError> {
        let b = self;
        DEPTH_BIAS_RANGE.check(b.depth_bias)?;
        SLOPE_BIAS_RANGE.check(b.slope_bias)?;
        NORMAL_OFFSET_RANGE.check(b.normal_offset)?;
        Ok(())
    }
}

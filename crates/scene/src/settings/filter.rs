//! The shadow filter: the technique and its parameters (PCF kernel, PCSS, the
//! moment maps of the filterable techniques), with their checks.

use super::ranges::SettingRange;
use std::borrow::Cow;

use super::*;

/// A shadow technique, by the name the command line and files use (`pcf2x2`, `vsm`).
///
/// What a name means (its WGSL, its parameters, which lights and maps it can take) is
/// the renderer's technique registry's business (`gnomon_render::techniques`); this
/// crate only checks that a name is well formed, and names the built-in techniques so
/// settings can be written in code. A host registers its own technique under a name
/// of its own and selects it with [`Technique::named`].
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct Technique(Cow<'static, str>);

impl Technique {
    /// One point-sampled depth comparison: Williams (1978).
    pub const HARD: Technique = Technique::named("hard");
    /// The hardware comparison sampler with linear filtering: 2×2 bilinear PCF.
    pub const PCF2X2: Technique = Technique::named("pcf2x2");
    /// Box PCF from bilinear comparison taps (Castaño 2013).
    pub const PCF: Technique = Technique::named("pcf");
    /// Tent PCF from bilinear comparison taps (Castaño 2013).
    pub const PCF_TENT: Technique = Technique::named("pcf-tent");
    /// PCF over a rotated Poisson disk.
    pub const PCF_POISSON: Technique = Technique::named("pcf-poisson");
    /// Percentage-closer soft shadows (Fernando 2005).
    pub const PCSS: Technique = Technique::named("pcss");
    /// Variance shadow maps (Donnelly & Lauritzen 2006).
    pub const VSM: Technique = Technique::named("vsm");
    /// Exponential shadow maps (Annen et al. 2008).
    pub const ESM: Technique = Technique::named("esm");
    /// Exponential variance shadow maps, positive exponent (Lauritzen & McCool 2008).
    pub const EVSM2: Technique = Technique::named("evsm2");
    /// Exponential variance shadow maps, both exponents.
    pub const EVSM4: Technique = Technique::named("evsm4");
    /// Moment shadow maps, Hamburger bound (Peters & Klein 2015).
    pub const MSM_HAMBURGER: Technique = Technique::named("msm-hamburger");
    /// Moment shadow maps, Hausdorff bound.
    pub const MSM_HAUSDORFF: Technique = Technique::named("msm-hausdorff");
    /// Convolution shadow maps (Annen et al. 2007).
    pub const CONVOLUTION: Technique = Technique::named("convolution");

    /// A shadow ray at every pixel over the scene's BVH: the exact upper baseline.
    pub const RAYTRACED: Technique = Technique::named("raytraced");

    /// The most characters a technique's name has.
    pub const MAX_NAME_LENGTH: usize = 32;

    /// The technique registered under `name`. A name is checked when it is parsed
    /// ([`str::parse`], a flag or a file); one written in code is trusted, and the
    /// renderer refuses it if nothing is registered under it.
    pub const fn named(name: &'static str) -> Technique {
        Technique(Cow::Borrowed(name))
    }

    /// The name used on the command line and in files.
    pub fn name(&self) -> &str {
        &self.0
    }
}

impl Default for Technique {
    fn default() -> Self {
        Technique::PCF2X2
    }
}

impl std::fmt::Display for Technique {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl TryFrom<String> for Technique {
    type Error = SettingsError;
    /// A well-formed name: 1 to [`Technique::MAX_NAME_LENGTH`] lowercase ASCII
    /// letters, digits and `-`, starting with a letter. Whether a technique is
    /// registered under it is for the renderer to say.
    fn try_from(name: String) -> Result<Self, SettingsError> {
        let well_formed = name.len() <= Technique::MAX_NAME_LENGTH
            && name.starts_with(|c: char| c.is_ascii_lowercase())
            && name.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-');
        check(
            well_formed,
            "shadow.filter.technique",
            &name,
            format!(
                "a technique's name: 1 to {} lowercase letters, digits and `-`, starting with a letter",
                Technique::MAX_NAME_LENGTH
            ),
        )?;
        Ok(Technique(Cow::Owned(name)))
    }
}

impl std::str::FromStr for Technique {
    type Err = SettingsError;
    fn from_str(name: &str) -> Result<Self, SettingsError> {
        Technique::try_from(name.to_owned())
    }
}

impl From<Technique> for String {
    fn from(t: Technique) -> String {
        t.0.into_owned()
    }
}

#[cfg(feature = "cli")]
/// Lists `choices`, each a technique's name and one line of help, as the possible
/// values of every `technique` and `techniques` argument of `command` and of its
/// subcommands, so that `--help`, the parser's errors and the viewer's panel offer the
/// renderer's registered techniques (this crate does not know them).
pub fn offer_techniques(command: clap::Command, choices: &[(String, String)]) -> clap::Command {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    let values: Vec<PossibleValue> =
        choices.iter().map(|(name, help)| PossibleValue::new(name.clone()).help(help.clone())).collect();
    let command = command.mut_args(|arg| match arg.get_id().as_str() {
        "technique" | "techniques" => {
            arg.value_parser(PossibleValuesParser::new(values.clone()).try_map(Technique::try_from))
        }
        _ => arg,
    });
    command.mut_subcommands(|sub| offer_techniques(sub, choices))
}

/// The settings' command as the front ends show it: the registry's techniques
/// offered ([`offer_techniques`]) and every ranged flag's range in its help
/// ([`super::ranges::annotate_ranges`]).
#[cfg(feature = "cli")]
pub fn settings_command(command: clap::Command, choices: &[(String, String)]) -> clap::Command {
    super::ranges::annotate_ranges(offer_techniques(command, choices))
}

/// The unit of a PCF kernel's width.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum KernelUnit {
    /// Shadow-map texels: the same blur everywhere in the map.
    #[default]
    Texels,
    /// World units at the receiver: the same softness in the world whatever the
    /// map's resolution or, for a spot light, the distance (capped at 32 texels).
    World,
}

/// The filter axis: which technique, and its parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[derive(struct_patch::Patch)]
#[patch(attribute(derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)))]
#[patch(attribute(serde(default, deny_unknown_fields)))]
#[patch(attribute(allow(missing_docs)))]
#[patch(attribute(
    doc = "Overrides of [`FilterSettings`], as a light's own shadow settings write them: each field as documented there, `None` to keep the value it is laid over."
))]
#[serde(default, deny_unknown_fields)]
pub struct FilterSettings {
    /// Shadow filtering technique.
    #[cfg_attr(
        feature = "cli",
        arg(long, value_name = "NAME", default_value_t, help_heading = "Shadow filter")
    )]
    pub technique: Technique,
    /// Kernel width of `pcf`, `pcf-tent` and `pcf-poisson`, in --kernel-unit units (a
    /// world width in (0, 1e7] when those are world units).
    #[cfg_attr(feature = "cli", arg(long, value_name = "WIDTH", default_value_t = FilterSettings::default().pcf_kernel, help_heading = "Shadow filter"))]
    pub pcf_kernel: f32,
    /// Unit of --pcf-kernel.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Shadow filter"))]
    pub kernel_unit: KernelUnit,
    /// Taps of `pcf-poisson` and of PCSS's filtering step.
    #[cfg_attr(feature = "cli", arg(long, value_name = "N", default_value_t = FilterSettings::default().poisson_samples, help_heading = "Shadow filter"))]
    pub poisson_samples: u32,
    /// Receiver-plane depth bias for the PCF family and PCSS: tilt the compared depth
    /// across the kernel along the receiver's plane, from the screen-space derivatives
    /// of its shadow coordinates, so wide kernels don't shadow their own receiver.
    #[cfg_attr(feature = "cli", arg(long, value_name = "BOOL", default_value_t = FilterSettings::default().receiver_plane_bias, action = clap::ArgAction::Set, help_heading = "Shadow filter"))]
    pub receiver_plane_bias: bool,
    /// PCSS: blocker-search taps, and the largest search and penumbra radii.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[patch(nesting)]
    pub pcss: PcssSettings,
    /// Parameters of the filterable (moment and exponential) maps.
    #[cfg_attr(feature = "cli", command(flatten))]
    #[patch(nesting)]
    pub moments: MomentSettings,
}

/// The taps a Poisson-disk kernel may take (`poisson_samples`,
/// `pcss.blocker_samples`): at least enough to cover the disk, at most the disk the
/// GPU holds (`POISSON_DISK_SIZE` in WGSL is the end of this range).
pub const POISSON_TAPS: std::ops::RangeInclusive<u32> = 8..=64;

/// The widest blur of a moment map, in texels on each side (`moments.blur_radius`):
/// each texel of each of the blur's two passes reads `2 × MAX_BLUR_RADIUS + 1` taps.
pub const MAX_BLUR_RADIUS: u32 = 16;

/// `shadow.filter.pcf_kernel`'s range when in texels (in world units it is any
/// distance, [`crate::limits::LIGHT_RANGE`]).
pub const PCF_KERNEL_TEXELS_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.pcf_kernel", 1.0, MAX_KERNEL_TEXELS as f64, "texels");
/// `shadow.filter.poisson_samples`' range: [`POISSON_TAPS`].
pub const POISSON_SAMPLES_RANGE: SettingRange = SettingRange::closed(
    "shadow.filter.poisson_samples",
    *POISSON_TAPS.start() as f64,
    *POISSON_TAPS.end() as f64,
    "taps",
);
/// `shadow.filter.pcss.blocker_samples`' range: [`POISSON_TAPS`].
pub const BLOCKER_SAMPLES_RANGE: SettingRange = SettingRange::closed(
    "shadow.filter.pcss.blocker_samples",
    *POISSON_TAPS.start() as f64,
    *POISSON_TAPS.end() as f64,
    "taps",
);
/// `shadow.filter.pcss.max_radius`' range.
pub const PCSS_MAX_RADIUS_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.pcss.max_radius", 1.0, 64.0, "texels");
/// `shadow.filter.pcss.max_penumbra`'s range.
pub const PCSS_MAX_PENUMBRA_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.pcss.max_penumbra", 1.0, 256.0, "texels");
/// `shadow.filter.moments.blur_radius`' range: [`MAX_BLUR_RADIUS`].
pub const BLUR_RADIUS_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.moments.blur_radius", 0.0, MAX_BLUR_RADIUS as f64, "texels");
/// `shadow.filter.moments.min_variance`' range.
pub const MIN_VARIANCE_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.moments.min_variance", 0.0, 1.0, "");
/// `shadow.filter.moments.bleeding_reduction`'s range.
pub const BLEEDING_REDUCTION_RANGE: SettingRange =
    SettingRange::below("shadow.filter.moments.bleeding_reduction", 0.0, 1.0, "");
/// `shadow.filter.moments.esm_exponent`'s range. ESM stores d itself and
/// exponentiates in the shader: exp(88) is near `f32::MAX`.
pub const ESM_EXPONENT_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.moments.esm_exponent", 1.0, 88.0, "");
/// `shadow.filter.moments.evsm_positive`'s range. EVSM stores exp(c·d) and its
/// square, so at 32 bits its exponents stay below ln(f32::MAX) / 2; a 16-bit format
/// bounds them further (EVSM's own check, `techniques::variance`).
pub const EVSM_POSITIVE_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.moments.evsm_positive", 0.0, 42.0, "");
/// `shadow.filter.moments.evsm_negative`'s range, as [`EVSM_POSITIVE_RANGE`].
pub const EVSM_NEGATIVE_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.moments.evsm_negative", 0.0, 42.0, "");
/// `shadow.filter.moments.moment_bias`' range.
pub const MOMENT_BIAS_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.moments.moment_bias", 0.0, 0.1, "");
/// `shadow.filter.moments.csm_terms`' range.
pub const CSM_TERMS_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.moments.csm_terms", 1.0, 16.0, "terms");
/// `shadow.filter.moments.csm_attenuation`'s range.
pub const CSM_ATTENUATION_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.moments.csm_attenuation", 0.0, 1000.0, "");
/// `shadow.filter.moments.csm_scale`'s range.
pub const CSM_SCALE_RANGE: SettingRange =
    SettingRange::above("shadow.filter.moments.csm_scale", 0.0, 100.0, "");
/// `shadow.filter.moments.csm_offset`'s range.
pub const CSM_OFFSET_RANGE: SettingRange =
    SettingRange::closed("shadow.filter.moments.csm_offset", -0.5, 0.5, "");

impl Default for FilterSettings {
    fn default() -> Self {
        Self {
            technique: Technique::default(),
            pcf_kernel: 3.0,
            kernel_unit: KernelUnit::default(),
            poisson_samples: 32,
            receiver_plane_bias: true,
            pcss: PcssSettings::default(),
            moments: MomentSettings::default(),
        }
    }
}

/// PCSS: the light's size comes from the light (--spot-radius or
/// --sun-angular-diameter), the same parameter the reference's area light uses.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[derive(struct_patch::Patch)]
#[patch(attribute(derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)))]
#[patch(attribute(serde(default, deny_unknown_fields)))]
#[patch(attribute(allow(missing_docs)))]
#[patch(attribute(
    doc = "Overrides of [`PcssSettings`], as a light's own shadow settings write them: each field as documented there, `None` to keep the value it is laid over."
))]
#[serde(default, deny_unknown_fields)]
pub struct PcssSettings {
    /// Depth taps of PCSS's blocker search.
    #[cfg_attr(feature = "cli", arg(long, value_name = "N", default_value_t = PcssSettings::default().blocker_samples, help_heading = "PCSS"))]
    pub blocker_samples: u32,
    /// Largest blocker-search radius, in texels. The search spans the light's cone
    /// at the map's near plane, which under a spot's perspective can be hundreds of
    /// texels: spread that wide, its taps average unrelated casters.
    #[cfg_attr(feature = "cli", arg(long, value_name = "TEXELS", default_value_t = PcssSettings::default().max_radius, help_heading = "PCSS"))]
    pub max_radius: f32,
    /// Largest penumbra radius, in texels: wider penumbrae are clipped to it. A
    /// separate cap from the search's: a fine map under a low, wide sun (a single
    /// map fitted to the receivers) has penumbrae wider than 32 texels, and clipping
    /// them there doubled PCSS's penumbra error on `grazing` under a 2° sun
    /// (docs/measured-soft.md, "Soft shadows"). A point light's 2048² cube faces under
    /// a wide sphere want more (up to 256); a virtual map asks for the pages as far
    /// as it reaches, so on one it costs pages.
    #[cfg_attr(feature = "cli", arg(long, value_name = "TEXELS", default_value_t = PcssSettings::default().max_penumbra, help_heading = "PCSS"))]
    pub max_penumbra: f32,
}

impl Default for PcssSettings {
    fn default() -> Self {
        Self { blocker_samples: 32, max_radius: 32.0, max_penumbra: 64.0 }
    }
}

/// Storage format of a filterable moment map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum MomentFormat {
    /// 32-bit float where the adapter can filter it, else 16-bit (the GL backend).
    #[default]
    Auto,
    /// 32-bit float per channel (needs FLOAT32_FILTERABLE).
    Rgba32float,
    /// 16-bit float per channel: half the memory and bandwidth. MSM then stores its
    /// moments in Peters & Klein's optimised basis (use --moment-bias 6e-5), and EVSM
    /// exponents must be at most 5.54.
    Rgba16float,
}

/// Parameters of the filterable techniques: VSM, ESM, EVSM, MSM and convolution.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
#[derive(struct_patch::Patch)]
#[patch(attribute(derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)))]
#[patch(attribute(serde(default, deny_unknown_fields)))]
#[patch(attribute(allow(missing_docs)))]
#[patch(attribute(
    doc = "Overrides of [`MomentSettings`], as a light's own shadow settings write them: each field as documented there, `None` to keep the value it is laid over."
))]
#[serde(default, deny_unknown_fields)]
pub struct MomentSettings {
    /// Radius of the separable Gaussian blur of the moment map, in texels (σ = radius / 2;
    /// 0 is no blur).
    #[cfg_attr(feature = "cli", arg(long, value_name = "TEXELS", default_value_t = MomentSettings::default().blur_radius, help_heading = "Filterable maps"))]
    pub blur_radius: u32,
    /// Build mipmaps of the moment map and sample them trilinearly (VSM, EVSM, MSM,
    /// convolution), against aliasing when the map is minified on screen.
    #[cfg_attr(feature = "cli", arg(long, help_heading = "Filterable maps"))]
    pub mipmaps: bool,
    /// Texel format of the moment map.
    #[cfg_attr(feature = "cli", arg(long, value_enum, default_value_t, help_heading = "Filterable maps"))]
    pub moment_format: MomentFormat,
    /// Smallest variance Chebyshev's bound may use (VSM, EVSM), in units of the
    /// normalised light depth squared: ≥ 0. Hides acne from quantisation.
    #[cfg_attr(feature = "cli", arg(long, value_name = "VARIANCE", default_value_t = MomentSettings::default().min_variance, help_heading = "Filterable maps"))]
    pub min_variance: f32,
    /// Light-bleeding reduction (VSM, EVSM, MSM): the bound below this is cut to 0
    /// and the rest rescaled to [0, 1] (Lauritzen's linstep).
    #[cfg_attr(feature = "cli", arg(long, value_name = "AMOUNT", default_value_t = MomentSettings::default().bleeding_reduction, help_heading = "Filterable maps"))]
    pub bleeding_reduction: f32,
    /// ESM exponent c: visibility = exp(c·(d_occluder − d_receiver)) (the map stores d
    /// and filters in log space, so c is not limited by the format).
    #[cfg_attr(feature = "cli", arg(long, value_name = "C", default_value_t = MomentSettings::default().esm_exponent, help_heading = "Filterable maps"))]
    pub esm_exponent: f32,
    /// EVSM positive exponent (at most 5.54 for a 16-bit map).
    #[cfg_attr(feature = "cli", arg(long, value_name = "C", default_value_t = MomentSettings::default().evsm_positive, help_heading = "Filterable maps"))]
    pub evsm_positive: f32,
    /// EVSM negative exponent (evsm4; at most 5.54 for a 16-bit map).
    #[cfg_attr(feature = "cli", arg(long, value_name = "C", default_value_t = MomentSettings::default().evsm_negative, help_heading = "Filterable maps"))]
    pub evsm_negative: f32,
    /// MSM moment bias α: the moments are blended toward those of a two-point
    /// distribution by this fraction (Peters & Klein use 3e-5 at 32 bits, 6e-5 at 16).
    #[cfg_attr(feature = "cli", arg(long, value_name = "ALPHA", default_value_t = MomentSettings::default().moment_bias, help_heading = "Filterable maps"))]
    pub moment_bias: f32,
    /// Fourier terms M of convolution shadow maps (2M channels).
    #[cfg_attr(feature = "cli", arg(long, value_name = "M", default_value_t = MomentSettings::default().csm_terms, help_heading = "Filterable maps"))]
    pub csm_terms: u32,
    /// Ringing attenuation α of convolution shadow maps: term k is weighted by
    /// exp(−α (k/M)²); 0 is the raw truncated series. ≥ 0.
    #[cfg_attr(feature = "cli", arg(long, value_name = "ALPHA", default_value_t = MomentSettings::default().csm_attenuation, help_heading = "Filterable maps"))]
    pub csm_attenuation: f32,
    /// Scale s of the convolution reconstruction: visibility = s·(f − ½ + o) + ½.
    #[cfg_attr(feature = "cli", arg(long, value_name = "S", default_value_t = MomentSettings::default().csm_scale, help_heading = "Filterable maps"))]
    pub csm_scale: f32,
    /// Offset o of the convolution reconstruction (see --csm-scale).
    #[cfg_attr(feature = "cli", arg(long, value_name = "O", default_value_t = MomentSettings::default().csm_offset, help_heading = "Filterable maps"))]
    pub csm_offset: f32,
}

impl Default for MomentSettings {
    fn default() -> Self {
        Self {
            blur_radius: 2,
            mipmaps: false,
            moment_format: MomentFormat::default(),
            min_variance: 1e-6,
            bleeding_reduction: 0.2,
            esm_exponent: 80.0,
            evsm_positive: 40.0,
            evsm_negative: 5.0,
            moment_bias: 3e-5,
            csm_terms: 8,
            csm_attenuation: 2.0,
            csm_scale: 2.0,
            csm_offset: 0.25,
        }
    }
}

impl MomentSettings {
    pub(super) fn validate(&self) -> Result<(), SettingsError> {
        BLUR_RADIUS_RANGE.check(self.blur_radius)?;
        MIN_VARIANCE_RANGE.check(self.min_variance)?;
        BLEEDING_REDUCTION_RANGE.check(self.bleeding_reduction)?;
        ESM_EXPONENT_RANGE.check(self.esm_exponent)?;
        EVSM_POSITIVE_RANGE.check(self.evsm_positive)?;
        EVSM_NEGATIVE_RANGE.check(self.evsm_negative)?;
        MOMENT_BIAS_RANGE.check(self.moment_bias)?;
        CSM_TERMS_RANGE.check(self.csm_terms)?;
        CSM_ATTENUATION_RANGE.check(self.csm_attenuation)?;
        CSM_SCALE_RANGE.check(self.csm_scale)?;
        CSM_OFFSET_RANGE.check(self.csm_offset)?;
        Ok(())
    }
}

//! The Chebyshev family: variance shadow maps (Donnelly & Lauritzen 2006) and
//! exponential variance shadow maps in two- and four-component forms (Lauritzen &
//! McCool 2008).

use bytemuck::{Pod, Zeroable};
use gnomon_scene::settings::{FilterSettings, MomentFormat, SettingsError, Technique};

use super::{
    contract::{FilterableMap, MapPrecision, MapSupport, ShadowTechnique, Tunables},
    params::{GpuParams, TechniqueParams},
};

/// The Chebyshev family's parameters (`VarianceParams` in variance.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct VarianceParams {
    /// c⁺, the positive warp's exponent (EVSM).
    pub positive_exponent: f32,
    /// c⁻, the negative warp's exponent (EVSM4).
    pub negative_exponent: f32,
    /// The least variance the bound assumes, in depth units.
    pub min_variance: f32,
    /// The fraction of the bound cut away as light bleeding.
    pub bleeding_reduction: f32,
    /// 0 VSM, 2 EVSM2, 4 EVSM4: the moments of the warps kept.
    pub variant: u32,
    /// Padding to `PARAMS_BYTES`.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
}

impl GpuParams for VarianceParams {
    const WGSL_NAME: &'static str = "VarianceParams";
}

/// The largest EVSM exponent whose warped depth squared, exp(2c), stays finite in a
/// 16-bit float (max 65504): ln(65504) / 2.
pub const HALF_MAX_EXPONENT: f32 = 5.54;

/// One technique of the family; they differ only in the warp `variant` selects in
/// `variance.wgsl`: 0 none (VSM), 2 positive (EVSM2), 4 positive and negative (EVSM4).
pub struct Chebyshev {
    technique: Technique,
    summary: &'static str,
    variant: u32,
}

pub static VSM: Chebyshev = Chebyshev {
    technique: Technique::VSM,
    summary: "Variance shadow maps (Donnelly & Lauritzen 2006): blurred (d, d²) and Chebyshev's bound.",
    variant: 0,
};
pub static EVSM2: Chebyshev = Chebyshev {
    technique: Technique::EVSM2,
    summary: "Exponential variance shadow maps, positive exponent only (Lauritzen & McCool 2008).",
    variant: 2,
};
pub static EVSM4: Chebyshev = Chebyshev {
    technique: Technique::EVSM4,
    summary: "Exponential variance shadow maps with positive and negative exponents.",
    variant: 4,
};

impl ShadowTechnique for Chebyshev {
    fn technique(&self) -> Technique {
        self.technique.clone()
    }

    fn summary(&self) -> &'static str {
        self.summary
    }

    fn maps(&self) -> MapSupport {
        MapSupport::LINEAR_DEPTH
    }

    /// EVSM stores exp(c·d) and its square: in a 16-bit map the exponents must keep
    /// exp(2c) below 65504 ([`HALF_MAX_EXPONENT`]). (With `auto` on a 16-bit adapter
    /// the renderer clamps them instead, in [`Chebyshev::params`].)
    fn validate(&self, s: &FilterSettings) -> Result<(), SettingsError> {
        if self.variant == 0 || s.moments.moment_format != MomentFormat::Rgba16float {
            return Ok(());
        }
        let bounded = |setting: &'static str, value: f32| {
            if value <= HALF_MAX_EXPONENT {
                Ok(())
            } else {
                Err(SettingsError {
                    setting,
                    value: value.to_string(),
                    valid: format!(
                        "0 to {HALF_MAX_EXPONENT} with `shadow.filter.technique` {} and `shadow.filter.moments.moment_format` rgba16float",
                        self.technique
                    ),
                })
            }
        };
        bounded("shadow.filter.moments.evsm_positive", s.moments.evsm_positive)?;
        bounded("shadow.filter.moments.evsm_negative", s.moments.evsm_negative)
    }

    /// The bias moves its edges; it has no kernel of `pcf_kernel`.
    fn tunables(&self) -> Tunables {
        Tunables::BIAS
    }

    /// The moment map's blur radius.
    fn filter_reach_texels(&self, s: &FilterSettings, _: f32) -> f32 {
        s.moments.blur_radius as f32
    }
    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("variance.wgsl")]
    }
    /// At 16 bits the exponents are clamped to [`HALF_MAX_EXPONENT`].
    fn params(&self, s: &FilterSettings, precision: MapPrecision) -> TechniqueParams {
        let m = &s.moments;
        let limit = if precision == MapPrecision::Half { HALF_MAX_EXPONENT } else { f32::MAX };
        TechniqueParams::new(VarianceParams {
            positive_exponent: m.evsm_positive.min(limit),
            negative_exponent: m.evsm_negative.min(limit),
            min_variance: m.min_variance,
            bleeding_reduction: m.bleeding_reduction,
            variant: self.variant,
            ..Default::default()
        })
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(FilterableMap { layers: 1, log_space_exponent: None, mipmapped: true })
    }
}

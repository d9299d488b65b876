//! The Chebyshev family: variance shadow maps (Donnelly & Lauritzen 2006) and
//! exponential variance shadow maps in two- and four-component forms (Lauritzen &
//! McCool 2008).

use glam::{UVec4, Vec4};
use gnomon_scene::settings::{FilterSettings, MomentFormat, SettingsError, Technique};

use super::{FilterableMap, MapPrecision, MapSupport, ShadowTechnique, Tunables};
use crate::uniforms::TechniqueParams;

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
    /// integers.x = variant; reals = (c⁺, c⁻, minimum variance, bleeding reduction).
    /// At 16 bits the exponents are clamped to [`HALF_MAX_EXPONENT`].
    fn params(&self, s: &FilterSettings, precision: MapPrecision) -> TechniqueParams {
        let m = &s.moments;
        let limit = if precision == MapPrecision::Half { HALF_MAX_EXPONENT } else { f32::MAX };
        TechniqueParams {
            reals: Vec4::new(
                m.evsm_positive.min(limit),
                m.evsm_negative.min(limit),
                m.min_variance,
                m.bleeding_reduction,
            ),
            integers: UVec4::new(self.variant, 0, 0, 0),
        }
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(FilterableMap { layers: 1, log_space_exponent: None, mipmapped: true })
    }
}

//! The Chebyshev family: variance shadow maps (Donnelly & Lauritzen 2006) and
//! exponential variance shadow maps in two- and four-component forms (Lauritzen &
//! McCool 2008).

use glam::Vec4;
use gnomon_scene::settings::{FilterSettings, Technique};

use super::{FilterableMap, MapPrecision, ShadowTechnique};

pub struct Vsm;
pub struct Evsm2;
pub struct Evsm4;

const WGSL: &[&str] = &[include_str!("variance.wgsl")];

/// The largest EVSM exponent whose warped depth squared, exp(2c), stays finite in a
/// 16-bit float (max 65504): ln(65504) / 2.
pub const HALF_MAX_EXPONENT: f32 = 5.54;

/// params[0] = (variant, c⁺, c⁻, minimum variance), params[1].x = bleeding reduction.
/// At 16 bits the exponents are clamped to [`HALF_MAX_EXPONENT`].
fn params(variant: f32, s: &FilterSettings, precision: MapPrecision) -> [Vec4; 2] {
    let m = &s.moments;
    let limit = if precision == MapPrecision::Half { HALF_MAX_EXPONENT } else { f32::MAX };
    [
        Vec4::new(variant, m.evsm_positive.min(limit), m.evsm_negative.min(limit), m.min_variance),
        Vec4::new(m.bleeding_reduction, 0.0, 0.0, 0.0),
    ]
}

const MAP: FilterableMap = FilterableMap { layers: 1, log_space_exponent: None, mipmapped: true };

impl ShadowTechnique for Vsm {
    fn technique(&self) -> Technique {
        Technique::Vsm
    }
    fn wgsl(&self) -> &'static [&'static str] {
        WGSL
    }
    fn params(&self, s: &FilterSettings, p: MapPrecision) -> [Vec4; 2] {
        params(0.0, s, p)
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(MAP)
    }
}

impl ShadowTechnique for Evsm2 {
    fn technique(&self) -> Technique {
        Technique::Evsm2
    }
    fn wgsl(&self) -> &'static [&'static str] {
        WGSL
    }
    fn params(&self, s: &FilterSettings, p: MapPrecision) -> [Vec4; 2] {
        params(2.0, s, p)
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(MAP)
    }
}

impl ShadowTechnique for Evsm4 {
    fn technique(&self) -> Technique {
        Technique::Evsm4
    }
    fn wgsl(&self) -> &'static [&'static str] {
        WGSL
    }
    fn params(&self, s: &FilterSettings, p: MapPrecision) -> [Vec4; 2] {
        params(4.0, s, p)
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(MAP)
    }
}

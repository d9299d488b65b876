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

/// params[0] = (variant, c⁺, c⁻, minimum variance), params[1].x = bleeding reduction.
fn params(variant: f32, s: &FilterSettings) -> [Vec4; 2] {
    let m = &s.moments;
    [
        Vec4::new(variant, m.evsm_positive, m.evsm_negative, m.min_variance),
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
    fn params(&self, s: &FilterSettings, _: MapPrecision) -> [Vec4; 2] {
        params(0.0, s)
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
    fn params(&self, s: &FilterSettings, _: MapPrecision) -> [Vec4; 2] {
        params(2.0, s)
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
    fn params(&self, s: &FilterSettings, _: MapPrecision) -> [Vec4; 2] {
        params(4.0, s)
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(MAP)
    }
}

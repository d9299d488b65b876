//! Moment shadow maps (Peters & Klein 2015): four moments, with the Hamburger and
//! the Hausdorff bounds, and their optimised quantisation for 16-bit maps.

use glam::Vec4;
use gnomon_scene::settings::{FilterSettings, Technique};

use super::{FilterableMap, MapPrecision, ShadowTechnique};

pub struct MsmHamburger;
pub struct MsmHausdorff;

/// 16-bit maps store the moments in Peters & Klein's optimised basis (params[0].z = 1).
fn quantised(precision: MapPrecision) -> f32 {
    (precision == MapPrecision::Half) as u8 as f32
}

const MAP: FilterableMap = FilterableMap { layers: 1, log_space_exponent: None, mipmapped: true };

impl ShadowTechnique for MsmHamburger {
    fn technique(&self) -> Technique {
        Technique::MsmHamburger
    }
    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("msm.wgsl")]
    }
    fn params(&self, s: &FilterSettings, precision: MapPrecision) -> [Vec4; 2] {
        [Vec4::new(s.moments.moment_bias, 0.0, quantised(precision), 0.0), Vec4::ZERO]
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(MAP)
    }
}

impl ShadowTechnique for MsmHausdorff {
    fn technique(&self) -> Technique {
        Technique::MsmHausdorff
    }
    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("msm.wgsl")]
    }
    fn params(&self, s: &FilterSettings, precision: MapPrecision) -> [Vec4; 2] {
        [Vec4::new(s.moments.moment_bias, 1.0, quantised(precision), 0.0), Vec4::ZERO]
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(MAP)
    }
}

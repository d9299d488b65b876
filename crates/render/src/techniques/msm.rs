//! Moment shadow maps (Peters & Klein 2015): four moments, with the Hamburger and
//! the Hausdorff bounds.

use glam::Vec4;
use gnomon_scene::settings::{FilterSettings, Technique};

use super::{FilterableMap, ShadowTechnique};

pub struct MsmHamburger;
pub struct MsmHausdorff;

const MAP: FilterableMap = FilterableMap { layers: 1, log_space_exponent: None, mipmapped: true };

impl ShadowTechnique for MsmHamburger {
    fn technique(&self) -> Technique {
        Technique::MsmHamburger
    }
    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("msm.wgsl")]
    }
    fn params(&self, s: &FilterSettings) -> [Vec4; 2] {
        [Vec4::new(s.moments.moment_bias, 0.0, 0.0, 0.0), Vec4::ZERO]
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
    fn params(&self, s: &FilterSettings) -> [Vec4; 2] {
        [Vec4::new(s.moments.moment_bias, 1.0, 0.0, 0.0), Vec4::ZERO]
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(MAP)
    }
}

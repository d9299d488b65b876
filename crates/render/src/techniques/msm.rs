//! Moment shadow maps (Peters & Klein 2015): four moments, with the Hamburger and
//! the Hausdorff bounds, and their optimised quantisation for 16-bit maps.

use glam::Vec4;
use gnomon_scene::settings::{FilterSettings, Technique};

use super::{FilterableMap, MapPrecision, ShadowTechnique};

/// One moment-map technique: the two differ only in the bound they reconstruct.
pub struct Msm {
    technique: Technique,
    hausdorff: bool,
}

pub static HAMBURGER: Msm = Msm { technique: Technique::MsmHamburger, hausdorff: false };
pub static HAUSDORFF: Msm = Msm { technique: Technique::MsmHausdorff, hausdorff: true };

impl ShadowTechnique for Msm {
    fn technique(&self) -> Technique {
        self.technique
    }
    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("msm.wgsl")]
    }
    /// params[0] = (moment bias, 1 for Hausdorff, 1 for the optimised 16-bit basis, 0).
    fn params(&self, s: &FilterSettings, precision: MapPrecision) -> [Vec4; 2] {
        let quantised = precision == MapPrecision::Half;
        [
            Vec4::new(s.moments.moment_bias, self.hausdorff as u8 as f32, quantised as u8 as f32, 0.0),
            Vec4::ZERO,
        ]
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(FilterableMap { layers: 1, log_space_exponent: None, mipmapped: true })
    }
}

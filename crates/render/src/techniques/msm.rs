//! Moment shadow maps (Peters & Klein 2015): four moments, with the Hamburger and
//! the Hausdorff bounds, and their optimised quantisation for 16-bit maps.

use glam::{UVec4, Vec4};
use gnomon_scene::settings::{FilterSettings, Technique};

use super::{FilterableMap, MapPrecision, MapSupport, ShadowTechnique, Tunables};
use crate::uniforms::TechniqueParams;

/// One moment-map technique: the two differ only in the bound they reconstruct.
pub struct Msm {
    technique: Technique,
    summary: &'static str,
    hausdorff: bool,
}

pub static HAMBURGER: Msm = Msm {
    technique: Technique::MSM_HAMBURGER,
    summary: "Moment shadow maps (Peters & Klein 2015), four moments, Hamburger bound.",
    hausdorff: false,
};
pub static HAUSDORFF: Msm = Msm {
    technique: Technique::MSM_HAUSDORFF,
    summary: "Moment shadow maps, four moments, Hausdorff bound (depths in [0, 1]).",
    hausdorff: true,
};

impl ShadowTechnique for Msm {
    fn technique(&self) -> Technique {
        self.technique.clone()
    }

    fn summary(&self) -> &'static str {
        self.summary
    }

    fn maps(&self) -> MapSupport {
        MapSupport::LINEAR_DEPTH
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
        &[include_str!("msm.wgsl")]
    }
    /// reals.x = moment bias; integers = (1 for Hausdorff, 1 for the optimised 16-bit
    /// basis, 0, 0).
    fn params(&self, s: &FilterSettings, precision: MapPrecision) -> TechniqueParams {
        let quantised = precision == MapPrecision::Half;
        TechniqueParams {
            reals: Vec4::new(s.moments.moment_bias, 0.0, 0.0, 0.0),
            integers: UVec4::new(self.hausdorff.into(), quantised.into(), 0, 0),
        }
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(FilterableMap { layers: 1, log_space_exponent: None, mipmapped: true })
    }
}

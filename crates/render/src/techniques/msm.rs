//! Moment shadow maps (Peters & Klein 2015): four moments, with the Hamburger and
//! the Hausdorff bounds, and their optimised quantisation for 16-bit maps.

use bytemuck::{Pod, Zeroable};
use glam::UVec4;
use gnomon_scene::settings::{FilterSettings, Technique};

use super::{
    contract::{FilterableMap, MapPrecision, MapSupport, ShadowTechnique, Tunables},
    params::{GpuParams, TechniqueParams},
};

/// The moment maps' parameters (`MsmParams` in msm.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MsmParams {
    /// α, the moment bias toward ½δ₀ + ½δ₁.
    pub moment_bias: f32,
    /// 1 for the Hausdorff bound, 0 for Hamburger.
    pub hausdorff: u32,
    /// 1 when the map stores the optimised 16-bit basis.
    pub quantised: u32,
    /// Padding to `PARAMS_BYTES`.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: UVec4,
}

impl GpuParams for MsmParams {
    const WGSL_NAME: &'static str = "MsmParams";
}

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
    /// The moment bias, the bound, and whether a 16-bit map stores the optimised basis.
    fn params(&self, s: &FilterSettings, precision: MapPrecision) -> TechniqueParams {
        let quantised = precision == MapPrecision::Half;
        TechniqueParams::new(MsmParams {
            moment_bias: s.moments.moment_bias,
            hausdorff: self.hausdorff.into(),
            quantised: quantised.into(),
            ..Default::default()
        })
    }
    fn filterable_map(&self, _: &FilterSettings) -> Option<FilterableMap> {
        Some(FilterableMap { layers: 1, log_space_exponent: None, mipmapped: true })
    }
}

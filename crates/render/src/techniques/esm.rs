//! `esm`: exponential shadow maps (Annen et al. 2008), filtered in log space.

use bytemuck::{Pod, Zeroable};
use glam::UVec4;
use gnomon_scene::settings::{FilterSettings, Technique};

use super::{
    contract::{FilterableMap, MapPrecision, MapSupport, ShadowTechnique, Tunables},
    params::{GpuParams, TechniqueParams},
};

/// ESM's parameters (`EsmParams` in esm.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct EsmParams {
    /// The exponent c of exp(c·d).
    pub exponent: f32,
    /// Padding to `PARAMS_BYTES`.
    pub _pad0: u32,
    /// Padding.
    pub _pad1: u32,
    /// Padding.
    pub _pad2: u32,
    /// Padding.
    pub _pad3: UVec4,
}

impl GpuParams for EsmParams {
    const WGSL_NAME: &'static str = "EsmParams";
}

pub struct Esm;

impl ShadowTechnique for Esm {
    fn technique(&self) -> Technique {
        Technique::ESM
    }

    fn summary(&self) -> &'static str {
        "Exponential shadow maps (Annen et al. 2008): exp(c·d), filtered in log space."
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
        &[include_str!("esm.wgsl")]
    }
    /// reals.x = the exponent c.
    fn params(&self, s: &FilterSettings, _: MapPrecision) -> TechniqueParams {
        TechniqueParams::new(EsmParams { exponent: s.moments.esm_exponent, ..Default::default() })
    }
    fn filterable_map(&self, s: &FilterSettings) -> Option<FilterableMap> {
        // The lookup filters bilinearly in log space by hand, at the top level only.
        Some(FilterableMap { layers: 1, log_space_exponent: Some(s.moments.esm_exponent), mipmapped: false })
    }
}

//! `esm`: exponential shadow maps (Annen et al. 2008), filtered in log space.

use glam::Vec4;
use gnomon_scene::settings::{FilterSettings, Technique};

use super::{FilterableMap, MapPrecision, MapSupport, ShadowTechnique, Tunables};
use crate::uniforms::TechniqueParams;

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
        TechniqueParams { reals: Vec4::new(s.moments.esm_exponent, 0.0, 0.0, 0.0), ..Default::default() }
    }
    fn filterable_map(&self, s: &FilterSettings) -> Option<FilterableMap> {
        // The lookup filters bilinearly in log space by hand, at the top level only.
        Some(FilterableMap { layers: 1, log_space_exponent: Some(s.moments.esm_exponent), mipmapped: false })
    }
}

//! `convolution`: convolution shadow maps (Annen et al. 2007), a truncated Fourier
//! series of the depth test with ringing attenuation.

use glam::{UVec4, Vec4};
use gnomon_scene::settings::{FilterSettings, Technique};

use super::{FilterableMap, MapPrecision, MapSupport, ShadowTechnique, Tunables};
use crate::uniforms::TechniqueParams;

pub struct Convolution;

impl ShadowTechnique for Convolution {
    fn technique(&self) -> Technique {
        Technique::CONVOLUTION
    }

    fn summary(&self) -> &'static str {
        "Convolution shadow maps (Annen et al. 2007): a Fourier series of the depth test."
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
        &[include_str!("convolution.wgsl")]
    }
    /// integers.x = terms M; reals = (attenuation α, scale s, offset o, 0).
    fn params(&self, s: &FilterSettings, _: MapPrecision) -> TechniqueParams {
        let m = &s.moments;
        TechniqueParams {
            reals: Vec4::new(m.csm_attenuation, m.csm_scale, m.csm_offset, 0.0),
            integers: UVec4::new(m.csm_terms, 0, 0, 0),
        }
    }
    fn filterable_map(&self, s: &FilterSettings) -> Option<FilterableMap> {
        // A sin and a cos per term, four channels per layer.
        Some(FilterableMap {
            layers: s.moments.csm_terms.div_ceil(2),
            log_space_exponent: None,
            mipmapped: true,
        })
    }
}

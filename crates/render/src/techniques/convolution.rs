//! `convolution`: convolution shadow maps (Annen et al. 2007), a truncated Fourier
//! series of the depth test with ringing attenuation.

use glam::Vec4;
use gnomon_scene::settings::{FilterSettings, Technique};

use super::{FilterableMap, MapPrecision, ShadowTechnique};

pub struct Convolution;

impl ShadowTechnique for Convolution {
    fn technique(&self) -> Technique {
        Technique::Convolution
    }
    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("convolution.wgsl")]
    }
    fn params(&self, s: &FilterSettings, _: MapPrecision) -> [Vec4; 2] {
        let m = &s.moments;
        [Vec4::new(m.csm_terms as f32, m.csm_attenuation, m.csm_scale, m.csm_offset), Vec4::ZERO]
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

//! `convolution`: convolution shadow maps (Annen et al. 2007), a truncated Fourier
//! series of the depth test with ringing attenuation.

use bytemuck::{Pod, Zeroable};
use glam::UVec4;
use gnomon_scene::settings::{FilterSettings, Technique};

use super::{
    contract::{FilterableMap, MapPrecision, MapSupport, ShadowTechnique, Tunables},
    params::{GpuParams, TechniqueParams},
};

/// Convolution shadow maps' parameters (`ConvolutionParams` in convolution.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ConvolutionParams {
    /// M, the Fourier terms kept.
    pub terms: u32,
    /// α, the attenuation of the higher terms against ringing.
    pub attenuation: f32,
    /// s, the reconstruction's sharpening scale.
    pub scale: f32,
    /// o, its offset.
    pub offset: f32,
    /// Padding to `PARAMS_BYTES`.
    pub _pad0: UVec4,
}

impl GpuParams for ConvolutionParams {
    const WGSL_NAME: &'static str = "ConvolutionParams";
}

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
    /// The terms M, the attenuation α, the scale s and the offset o.
    fn params(&self, s: &FilterSettings, _: MapPrecision) -> TechniqueParams {
        let m = &s.moments;
        TechniqueParams::new(ConvolutionParams {
            terms: m.csm_terms,
            attenuation: m.csm_attenuation,
            scale: m.csm_scale,
            offset: m.csm_offset,
            ..Default::default()
        })
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

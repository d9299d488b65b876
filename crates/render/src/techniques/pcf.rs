//! The percentage-closer filtering family: compare first, then filter the binary
//! results. W. Reeves, D. Salesin, R. Cook, "Rendering antialiased shadows with depth
//! maps", SIGGRAPH 1987. Both variants use the comparison sampler, whose linear
//! filter is the hardware's 2×2 bilinear PCF.

use gnomon_scene::settings::{FilterSettings, Technique};

use super::ShadowTechnique;

/// `pcf2x2`: one hardware bilinear comparison tap.
pub struct Pcf2x2;

/// `pcf`: an N×N box of bilinear comparison taps spaced one texel apart.
pub struct PcfBox;

impl ShadowTechnique for Pcf2x2 {
    fn technique(&self) -> Technique {
        Technique::Pcf2x2
    }

    fn wgsl(&self) -> &'static str {
        include_str!("pcf.wgsl")
    }

    fn filter_params(&self, _: &FilterSettings) -> [f32; 4] {
        [0.0; 4]
    }
}

impl ShadowTechnique for PcfBox {
    fn technique(&self) -> Technique {
        Technique::Pcf
    }

    fn wgsl(&self) -> &'static str {
        include_str!("pcf.wgsl")
    }

    fn filter_params(&self, settings: &FilterSettings) -> [f32; 4] {
        [settings.pcf_kernel as f32, 0.0, 0.0, 0.0]
    }
}

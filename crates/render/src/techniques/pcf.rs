//! The percentage-closer filtering family: compare first, then filter the binary
//! results. W. Reeves, D. Salesin, R. Cook, "Rendering antialiased shadows with depth
//! maps", SIGGRAPH 1987. Every variant reads the comparison sampler, whose linear
//! filter is the hardware's 2×2 bilinear PCF; the kernel width and receiver-plane
//! bias are common settings, carried in `light.kernel_width`, `kernel_in_world`, `poisson_taps` and `receiver_plane_bias`.

use gnomon_scene::settings::{FilterSettings, Technique};

use super::{MapSupport, ShadowTechnique, Tunables};

/// `pcf2x2`: one hardware bilinear comparison tap.
pub struct Pcf2x2;
/// `pcf`: a box kernel from bilinear taps with exact weights (Castaño 2013).
pub struct PcfBox;
/// `pcf-tent`: a tent kernel from bilinear taps with exact weights.
pub struct PcfTent;
/// `pcf-poisson`: a rotated Poisson disk of bilinear taps.
pub struct PcfPoisson;

const PCF_WGSL: &str = include_str!("pcf.wgsl");

impl ShadowTechnique for Pcf2x2 {
    fn technique(&self) -> Technique {
        Technique::PCF2X2
    }

    fn summary(&self) -> &'static str {
        "The hardware comparison sampler with linear filtering: 2×2 bilinear PCF."
    }

    fn maps(&self) -> MapSupport {
        MapSupport::ANY
    }

    /// The bias moves its edges; it has no kernel of `pcf_kernel`.
    fn tunables(&self) -> Tunables {
        Tunables::BIAS
    }

    /// One bilinear tap: no reach beyond its footprint.
    fn filter_reach_texels(&self, _: &FilterSettings, _: f32) -> f32 {
        0.0
    }

    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("pcf2x2.wgsl")]
    }

    fn cube_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(&[include_str!("pcf2x2_cube.wgsl")])
    }

    fn virtual_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(&[include_str!("pcf2x2_virtual.wgsl")])
    }
}

impl ShadowTechnique for PcfBox {
    fn technique(&self) -> Technique {
        Technique::PCF
    }

    fn summary(&self) -> &'static str {
        "Box PCF of the kernel's width, from bilinear comparison taps with exact area weights (Castaño 2013): a W×W box in ⌈(W+1)/2⌉² taps."
    }

    fn maps(&self) -> MapSupport {
        MapSupport::ANY
    }

    /// The bias moves its edges, and its kernel is `pcf_kernel` wide.
    fn tunables(&self) -> Tunables {
        Tunables::BIAS_AND_KERNEL
    }

    /// Half the kernel's width each side.
    fn filter_reach_texels(&self, _: &FilterSettings, kernel_texels: f32) -> f32 {
        0.5 * kernel_texels
    }

    fn wgsl(&self) -> &'static [&'static str] {
        &[PCF_WGSL, include_str!("pcf_box.wgsl")]
    }

    fn cube_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(&[include_str!("pcf_box_cube.wgsl")])
    }

    fn virtual_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(&[include_str!("pcf_box_virtual.wgsl")])
    }
}

impl ShadowTechnique for PcfTent {
    fn technique(&self) -> Technique {
        Technique::PCF_TENT
    }

    fn summary(&self) -> &'static str {
        "Tent PCF of the kernel's width from bilinear comparison taps (Castaño 2013): smoother edges than the box at the same cost."
    }

    fn maps(&self) -> MapSupport {
        MapSupport::ANY
    }

    /// The bias moves its edges, and its kernel is `pcf_kernel` wide.
    fn tunables(&self) -> Tunables {
        Tunables::BIAS_AND_KERNEL
    }

    /// Half the kernel's width each side.
    fn filter_reach_texels(&self, _: &FilterSettings, kernel_texels: f32) -> f32 {
        0.5 * kernel_texels
    }

    fn wgsl(&self) -> &'static [&'static str] {
        &[PCF_WGSL, include_str!("pcf_tent.wgsl")]
    }

    fn cube_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(&[include_str!("pcf_tent_cube.wgsl")])
    }

    fn virtual_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(&[include_str!("pcf_tent_virtual.wgsl")])
    }
}

impl ShadowTechnique for PcfPoisson {
    fn technique(&self) -> Technique {
        Technique::PCF_POISSON
    }

    fn summary(&self) -> &'static str {
        "PCF over a Poisson disk of the kernel's diameter, rotated per pixel by interleaved gradient noise (Jimenez 2014): noise instead of banding."
    }

    fn maps(&self) -> MapSupport {
        MapSupport::ANY
    }

    /// The bias moves its edges, and its kernel is `pcf_kernel` wide.
    fn tunables(&self) -> Tunables {
        Tunables::BIAS_AND_KERNEL
    }

    /// The disk's radius, half the kernel's width.
    fn filter_reach_texels(&self, _: &FilterSettings, kernel_texels: f32) -> f32 {
        0.5 * kernel_texels
    }

    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("pcf_poisson.wgsl")]
    }

    fn cube_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(&[include_str!("pcf_poisson_cube.wgsl")])
    }

    fn virtual_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(&[include_str!("pcf_poisson_virtual.wgsl")])
    }
}

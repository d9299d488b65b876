//! Williams' test and the percentage-closer filtering family, as the rows of one
//! table: compare first, then filter the binary results. L. Williams, "Casting curved
//! shadows on curved surfaces", SIGGRAPH 1978; W. Reeves, D. Salesin, R. Cook,
//! "Rendering antialiased shadows with depth maps", SIGGRAPH 1987. Every filtered
//! variant reads the comparison sampler, whose linear filter is the hardware's 2×2
//! bilinear PCF; the kernel width and receiver-plane bias are common settings,
//! carried in `light.kernel_width`, `kernel_in_world`, `poisson_taps` and
//! `receiver_plane_bias`. A row differs from the others only in its name, its
//! kernel and its WGSL: a new PCF-like technique is a row here, its WGSL, and its
//! line in `BUILTIN`.

use gnomon_scene::settings::{FilterSettings, Technique};

use super::contract::{MapSupport, ShadowTechnique, Tunables};

/// What a row's lookup filters over.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kernel {
    /// One tap (a point sample, or one bilinear comparison): no `pcf_kernel`, no
    /// reach beyond its footprint.
    OneTap,
    /// A kernel `pcf_kernel` texels wide, reaching half its width each side.
    Wide,
}

/// One member of the family.
pub struct PcfVariant {
    technique: Technique,
    summary: &'static str,
    kernel: Kernel,
    wgsl: &'static [&'static str],
    cube_wgsl: &'static [&'static str],
    /// `None` where it has no lookup through a virtual map's page table.
    virtual_wgsl: Option<&'static [&'static str]>,
}

const PCF_WGSL: &str = include_str!("pcf.wgsl");

/// `hard`: Williams' depth comparison, one point sample, no filtering; on a cube,
/// the nearest texel along the direction, compared once.
pub static HARD: PcfVariant = PcfVariant {
    technique: Technique::HARD,
    summary: "One point-sampled depth comparison: Williams (1978), the textbook algorithm.",
    kernel: Kernel::OneTap,
    wgsl: &[include_str!("hard.wgsl")],
    cube_wgsl: &[include_str!("hard_cube.wgsl")],
    virtual_wgsl: None,
};

/// `pcf2x2`: one hardware bilinear comparison tap.
pub static PCF2X2: PcfVariant = PcfVariant {
    technique: Technique::PCF2X2,
    summary: "The hardware comparison sampler with linear filtering: 2×2 bilinear PCF.",
    kernel: Kernel::OneTap,
    wgsl: &[include_str!("pcf2x2.wgsl")],
    cube_wgsl: &[include_str!("pcf2x2_cube.wgsl")],
    virtual_wgsl: Some(&[include_str!("pcf2x2_virtual.wgsl")]),
};

/// `pcf`: a box kernel from bilinear taps with exact weights (Castaño 2013).
pub static PCF_BOX: PcfVariant = PcfVariant {
    technique: Technique::PCF,
    summary: "Box PCF of the kernel's width, from bilinear comparison taps with exact area weights (Castaño 2013): a W×W box in ⌈(W+1)/2⌉² taps.",
    kernel: Kernel::Wide,
    wgsl: &[PCF_WGSL, include_str!("pcf_box.wgsl")],
    cube_wgsl: &[include_str!("pcf_box_cube.wgsl")],
    virtual_wgsl: Some(&[include_str!("pcf_box_virtual.wgsl")]),
};

/// `pcf-tent`: a tent kernel from bilinear taps with exact weights.
pub static PCF_TENT: PcfVariant = PcfVariant {
    technique: Technique::PCF_TENT,
    summary: "Tent PCF of the kernel's width from bilinear comparison taps (Castaño 2013): smoother edges than the box at the same cost.",
    kernel: Kernel::Wide,
    wgsl: &[PCF_WGSL, include_str!("pcf_tent.wgsl")],
    cube_wgsl: &[include_str!("pcf_tent_cube.wgsl")],
    virtual_wgsl: Some(&[include_str!("pcf_tent_virtual.wgsl")]),
};

/// `pcf-poisson`: a rotated Poisson disk of bilinear taps, its radius half the
/// kernel's width.
pub static PCF_POISSON: PcfVariant = PcfVariant {
    technique: Technique::PCF_POISSON,
    summary: "PCF over a Poisson disk of the kernel's diameter, rotated per pixel by interleaved gradient noise (Jimenez 2014): noise instead of banding.",
    kernel: Kernel::Wide,
    wgsl: &[include_str!("pcf_poisson.wgsl")],
    cube_wgsl: &[include_str!("pcf_poisson_cube.wgsl")],
    virtual_wgsl: Some(&[include_str!("pcf_poisson_virtual.wgsl")]),
};

impl ShadowTechnique for PcfVariant {
    fn technique(&self) -> Technique {
        self.technique.clone()
    }

    fn summary(&self) -> &'static str {
        self.summary
    }

    /// Each compares the receiver's depth with the stored depths around its own
    /// texel, which holds in any monotonic depth.
    fn maps(&self) -> MapSupport {
        MapSupport::ANY
    }

    /// The bias moves every row's edges; a wide kernel is `pcf_kernel` wide.
    fn tunables(&self) -> Tunables {
        match self.kernel {
            Kernel::OneTap => Tunables::BIAS,
            Kernel::Wide => Tunables::BIAS_AND_KERNEL,
        }
    }

    fn filter_reach_texels(&self, _: &FilterSettings, kernel_texels: f32) -> f32 {
        match self.kernel {
            Kernel::OneTap => 0.0,
            Kernel::Wide => 0.5 * kernel_texels,
        }
    }

    fn wgsl(&self) -> &'static [&'static str] {
        self.wgsl
    }

    fn cube_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(self.cube_wgsl)
    }

    fn virtual_wgsl(&self) -> Option<&'static [&'static str]> {
        self.virtual_wgsl
    }
}

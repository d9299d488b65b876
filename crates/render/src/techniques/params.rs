//! A technique's own parameters, typed on both sides. Each technique that has any
//! declares a `repr(C)` struct ([`GpuParams`]) and a WGSL struct of the same name
//! beside its lookup (`struct VarianceParams { … }` in `variance.wgsl`); the naga
//! interface test checks the two field by field. The light uniform holds the values
//! in a block of [`PARAMS_BYTES`] ([`ParamsBlockGpu`]), and every shader the
//! technique is composed into reads it through the generated line
//! `alias TechniqueParams = VarianceParams;` ([`TechniqueParams::wgsl_alias`]), so
//! `light.technique.min_variance` means one thing in every shader that can name it.
//! A shader composed without a technique sees [`NoParams`].

use bytemuck::{Pod, Zeroable};
use glam::UVec4;

/// The bytes of the light uniform's technique block: every technique's struct is
/// padded to exactly this, so that the `Light` struct's layout is one for all.
pub const PARAMS_BYTES: usize = 32;

/// A technique's parameter struct: `repr(C)`, [`PARAMS_BYTES`] long, with a WGSL
/// struct named [`GpuParams::WGSL_NAME`] of the same fields in the technique's WGSL.
pub trait GpuParams: Pod {
    /// The WGSL struct's name; unique among every WGSL source of the crate.
    const WGSL_NAME: &'static str;
}

/// The light uniform's technique block, as bytes (`TechniqueParams` in WGSL, an alias
/// of the composed technique's struct).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ParamsBlockGpu {
    /// The technique's struct's words.
    pub words: [UVec4; 2],
}

const _: () = assert!(std::mem::size_of::<ParamsBlockGpu>() == PARAMS_BYTES);

/// A technique's parameter values and the WGSL struct that reads them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TechniqueParams {
    wgsl_name: &'static str,
    block: ParamsBlockGpu,
}

impl TechniqueParams {
    /// `params` as the light uniform holds them.
    ///
    /// # Panics
    /// Never for a struct of [`PARAMS_BYTES`]: the size is checked when this is
    /// compiled for `P` (a post-monomorphisation error for any other size).
    pub fn new<P: GpuParams>(params: P) -> Self {
        const { assert!(std::mem::size_of::<P>() == PARAMS_BYTES, "a technique's params must be PARAMS_BYTES") };
        Self { wgsl_name: P::WGSL_NAME, block: bytemuck::cast(params) }
    }

    /// The WGSL struct's name.
    pub fn wgsl_name(&self) -> &'static str {
        self.wgsl_name
    }

    /// The values, as the light uniform's block.
    pub fn block(&self) -> ParamsBlockGpu {
        self.block
    }

    /// How the generated line that types `light.technique` begins.
    pub(crate) const ALIAS_PREFIX: &str = "alias TechniqueParams = ";

    /// The generated WGSL line that makes `light.technique` this struct.
    pub fn wgsl_alias(&self) -> String {
        format!("{}{};\n", Self::ALIAS_PREFIX, self.wgsl_name)
    }
}

impl Default for TechniqueParams {
    fn default() -> Self {
        Self::new(NoParams::default())
    }
}

/// The parameters of a technique that has none, and of a shader composed without a
/// technique (`NoParams` in `light.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct NoParams {
    /// Padding to [`PARAMS_BYTES`].
    pub _pad0: UVec4,
    /// Padding to [`PARAMS_BYTES`].
    pub _pad1: UVec4,
}

impl GpuParams for NoParams {
    const WGSL_NAME: &'static str = "NoParams";
}

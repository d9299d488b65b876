//! `hard`: Williams' original depth comparison, one point sample, no filtering.
//! L. Williams, "Casting curved shadows on curved surfaces", SIGGRAPH 1978.

use gnomon_scene::settings::{FilterSettings, Technique};

use super::{MapSupport, ShadowTechnique, Tunables};

pub struct Hard;

impl ShadowTechnique for Hard {
    fn technique(&self) -> Technique {
        Technique::HARD
    }

    fn summary(&self) -> &'static str {
        "One point-sampled depth comparison: Williams (1978), the textbook algorithm."
    }

    fn maps(&self) -> MapSupport {
        MapSupport::ANY
    }

    /// The bias moves its edges; it has no kernel of `pcf_kernel`.
    fn tunables(&self) -> Tunables {
        Tunables::BIAS
    }

    /// One point sample: no reach.
    fn filter_reach_texels(&self, _: &FilterSettings, _: f32) -> f32 {
        0.0
    }

    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("hard.wgsl")]
    }

    fn cube_wgsl(&self) -> Option<&'static [&'static str]> {
        // The nearest texel along the direction, compared once.
        Some(&[include_str!("hard_cube.wgsl")])
    }
}

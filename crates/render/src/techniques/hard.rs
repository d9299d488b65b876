//! `hard`: Williams' original depth comparison, one point sample, no filtering.
//! L. Williams, "Casting curved shadows on curved surfaces", SIGGRAPH 1978.

use gnomon_scene::settings::Technique;

use super::ShadowTechnique;

pub struct Hard;

impl ShadowTechnique for Hard {
    fn technique(&self) -> Technique {
        Technique::Hard
    }

    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("hard.wgsl")]
    }
}

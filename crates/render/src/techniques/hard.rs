//! `hard`: Williams' original depth comparison, one point sample, no filtering.
//! L. Williams, "Casting curved shadows on curved surfaces", SIGGRAPH 1978.

use gnomon_scene::settings::{FilterSettings, Technique};

use super::ShadowTechnique;

pub struct Hard;

impl ShadowTechnique for Hard {
    fn technique(&self) -> Technique {
        Technique::Hard
    }

    fn wgsl(&self) -> &'static str {
        include_str!("hard.wgsl")
    }

    fn filter_params(&self, _: &FilterSettings) -> [f32; 4] {
        [0.0; 4]
    }
}

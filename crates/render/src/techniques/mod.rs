//! The shadow techniques. Each family is a module with its WGSL beside it, and is
//! registered once in [`REGISTRY`]; the lighting pass asks the registry for the WGSL
//! and the parameters of the selected [`Technique`] and knows nothing else about it.
//!
//! A technique's WGSL defines `fn sample_shadow(coords: vec3<f32>) -> f32`, given
//! (u, v, depth) in shadow-map texture space, returning the lit fraction in [0, 1].
//! It may use the bindings `shadow_map` (`texture_depth_2d`), `shadow_compare` (a
//! linear comparison sampler, `LessEqual`) and the `light` uniform, whose `filter`
//! vector carries the parameters from [`ShadowTechnique::filter_params`].

mod hard;
mod pcf;

use gnomon_scene::settings::{FilterSettings, Technique};

/// A shadow technique as the renderer sees it.
pub trait ShadowTechnique: Sync {
    /// The settings value that selects this technique.
    fn technique(&self) -> Technique;
    /// WGSL source defining `sample_shadow`.
    fn wgsl(&self) -> &'static str;
    /// The four floats passed to the shader as `light.params`.
    fn filter_params(&self, settings: &FilterSettings) -> [f32; 4];
}

/// Every technique, in the order the command line lists them.
pub static REGISTRY: &[&dyn ShadowTechnique] = &[&hard::Hard, &pcf::Pcf2x2, &pcf::PcfBox];

/// The registered implementation of `technique`.
pub fn lookup(technique: Technique) -> &'static dyn ShadowTechnique {
    REGISTRY.iter().copied().find(|t| t.technique() == technique).unwrap_or_else(|| {
        unreachable!("technique {technique:?} is not registered; see `every_technique_is_registered_once`")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_technique_is_registered_once() {
        for t in Technique::all() {
            let n = REGISTRY.iter().filter(|r| r.technique() == *t).count();
            assert_eq!(n, 1, "{t:?} is registered {n} times");
        }
        assert_eq!(REGISTRY.len(), Technique::all().len());
    }

    #[test]
    fn every_technique_defines_sample_shadow() {
        for t in REGISTRY {
            assert!(t.wgsl().contains("fn sample_shadow(coords: vec3<f32>) -> f32"), "{:?}", t.technique());
        }
    }
}

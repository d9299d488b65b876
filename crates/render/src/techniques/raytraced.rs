//! `raytraced`: no shadow map at all, a shadow ray at every pixel. Each pixel that
//! faces the light traces one ray to a hard light, or `screen.penumbra_rays`
//! stratified rays over a light's area, through the GPU BVH of the casters
//! (`rays/`): the exact answer up to the penumbra's sampling noise, and the upper
//! baseline of cost for the hybrid refinement (`screen.refine`) to beat.
//! T. Whitted, "An improved illumination model for shaded display", CACM 1980; R.
//! Cook, T. Porter, L. Carpenter, "Distributed ray tracing", SIGGRAPH 1984.

use gnomon_scene::settings::{FilterSettings, RayUse, Technique};

use super::contract::{MapSupport, ShadowTechnique, Tunables};

pub struct Raytraced;

impl ShadowTechnique for Raytraced {
    fn technique(&self) -> Technique {
        Technique::RAYTRACED
    }

    fn summary(&self) -> &'static str {
        "A shadow ray at every pixel through the casters' BVH, stratified over an area light \
         (Whitted 1980; Cook et al. 1984): exact, the upper baseline of cost."
    }

    fn wgsl(&self) -> &'static [&'static str] {
        &[include_str!("raytraced.wgsl")]
    }

    fn cube_wgsl(&self) -> Option<&'static [&'static str]> {
        Some(&[include_str!("raytraced_cube.wgsl")])
    }

    /// Rays do not care what the map is.
    fn maps(&self) -> MapSupport {
        MapSupport::ANY
    }

    /// It reads no map, so a fitted cascade needs no margin for it.
    fn filter_reach_texels(&self, _: &FilterSettings, _: f32) -> f32 {
        0.0
    }

    /// Neither bias nor kernel reaches a ray.
    fn tunables(&self) -> Tunables {
        Tunables::NONE
    }

    fn rays(&self) -> RayUse {
        RayUse::EveryPixel
    }
}

//! What a frame does about refinement by rays around its passes: before recording,
//! building the casters' BVH, or drawing every light unrefined where the device
//! cannot trace the scene or the image; after, reporting per light the pixels traced
//! or why it fell back.

use gnomon_scene::{
    Scene, Settings,
    settings::{RayUse, Refine},
};

use super::{Renderer, outputs::TimedLights, plan::FramePlan};
use crate::{
    Gpu, GpuScene, RenderError,
    rays::{self, RaysUnavailable, RefineLists},
    readback,
};

/// Lights drawn unrefined though they asked for rays, and why.
pub(super) struct Fallback {
    why: RaysUnavailable,
    lights: Vec<usize>,
}

impl Renderer {
    /// Builds the casters' BVH where a light of `plan` refines by rays. Where the device
    /// cannot trace the scene or an image of this size, every such light is drawn
    /// unrefined instead (its refinement turned off in `plan`), and the fallback says
    /// why. Errs on a failure of the device, and where a light's technique is rays
    /// ([`RenderError::TechniqueNeedsRays`]).
    pub(super) fn prepare_rays(
        &self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        plan: &mut FramePlan,
    ) -> Result<Option<Fallback>, RenderError> {
        let asked: Vec<usize> =
            (0..plan.lights.len()).filter(|&i| plan.lights[i].refine != Refine::Off).collect();
        if asked.is_empty() {
            return Ok(None);
        }
        let limit = rays::storage_limit(&self.gpu);
        let available = match rays::check_image(settings.image.width, settings.image.height, limit) {
            Ok(()) => uploaded.build_rays(&self.gpu, scene, &self.layouts.rays)?.map(|_| ()),
            Err(why) => Err(why),
        };
        let Err(why) = available else { return Ok(None) };
        // A technique that is rays has no map to fall back to.
        if let Some(light) =
            asked.iter().map(|&i| &plan.lights[i]).find(|l| l.technique.rays() == RayUse::EveryPixel)
        {
            return Err(RenderError::TechniqueNeedsRays {
                light: light.name.clone(),
                technique: light.technique.technique().to_string(),
                why,
            });
        }
        for &index in &asked {
            plan.lights[index].refine = Refine::Off;
        }
        Ok(Some(Fallback { why, lights: asked }))
    }
}

/// Writes into each light's stats why it fell back, and, given the copy of the
/// counters (`traced`, submitted), the pixels it traced.
pub(super) fn report(
    gpu: &Gpu,
    plan: &FramePlan,
    timed: &mut TimedLights,
    fallback: Option<Fallback>,
    traced: Option<wgpu::Buffer>,
) -> Result<(), RenderError> {
    if let Some(Fallback { why, lights }) = fallback {
        for index in lights {
            timed.lights[index].refine_fallback = Some(why.clone());
        }
    }
    if let Some(counters) = traced {
        let words: Vec<u32> = readback::read_buffer(gpu, &counters)?;
        let listed = RefineLists::listed(&words, plan.lights.len());
        for ((stats, light), listed) in timed.lights.iter_mut().zip(&plan.lights).zip(listed) {
            if light.refine != Refine::Off {
                stats.traced_pixels = Some(listed);
                stats.rays_per_pixel = light.light_gpu.penumbra_rays.max(1);
            }
        }
    }
    Ok(())
}

//! What a frame does about refinement by rays around its passes: before recording,
//! building the casters' BVH (and, for ray queries, the adapter's acceleration
//! structures), or drawing every light unrefined where the device cannot trace the
//! scene or the image; after, reporting per light the pixels traced, how, or why it
//! fell back.

use gnomon_scene::{
    Scene, Settings,
    settings::{RayUse, Refine},
};

use super::{Renderer, outputs::TimedLights, plan::FramePlan};
use crate::{
    Gpu, GpuScene, RenderError,
    rays::{self, RayQueriesUnavailable, RaysUnavailable, RefineLists, Traversal},
    readback,
};

/// What a frame's rays fell back to, where they could not run as asked.
#[derive(Default)]
pub(super) struct Fallbacks {
    /// Lights drawn unrefined though they asked for rays, and why.
    unrefined: Option<(RaysUnavailable, Vec<usize>)>,
    /// Why the shader traced where ray queries were asked for.
    tracer: Option<RayQueriesUnavailable>,
}

impl Renderer {
    /// Builds the casters' BVH where a light of `plan` refines by rays, and the
    /// acceleration structures where the frame's rays traverse them
    /// (`plan.traversal`, resolved here from `screen.tracer`). Where the device cannot
    /// trace the scene or an image of this size, every such light is drawn unrefined
    /// instead (its refinement turned off in `plan`); where it cannot run ray queries
    /// on it, the shader traces. The fallbacks say why. Errs on a failure of the
    /// device, and where a light's technique is rays
    /// ([`RenderError::TechniqueNeedsRays`]).
    pub(super) fn prepare_rays(
        &self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        plan: &mut FramePlan,
    ) -> Result<Fallbacks, RenderError> {
        let asked: Vec<usize> =
            (0..plan.lights.len()).filter(|&i| plan.lights[i].refine != Refine::Off).collect();
        if asked.is_empty() {
            return Ok(Fallbacks::default());
        }
        let limit = rays::storage_limit(&self.gpu);
        let built = match rays::check_image(settings.image.width, settings.image.height, limit) {
            Ok(()) => uploaded.build_rays(&self.gpu, scene, self.layouts.rays.get(Traversal::Shader))?,
            Err(why) => Err(why),
        };
        let bvh = match built {
            Ok(bvh) => bvh,
            Err(why) => return self.unrefined(plan, asked, why),
        };
        let (traversal, mut tracer) = Traversal::resolve(settings.screen.tracer, &self.gpu);
        plan.traversal = match traversal {
            Traversal::Shader => Traversal::Shader,
            Traversal::RayQuery => {
                match bvh.build_accel(&self.gpu, self.layouts.rays.get(Traversal::RayQuery))? {
                    Ok(()) => Traversal::RayQuery,
                    Err(why) => {
                        tracer = Some(why);
                        Traversal::Shader
                    }
                }
            }
        };
        Ok(Fallbacks { unrefined: None, tracer })
    }

    /// Turns off the refinement of the `asked` lights of `plan`, which the device
    /// cannot trace for `why`; a light whose technique is rays has no map to fall
    /// back to.
    fn unrefined(
        &self,
        plan: &mut FramePlan,
        asked: Vec<usize>,
        why: RaysUnavailable,
    ) -> Result<Fallbacks, RenderError> {
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
        Ok(Fallbacks { unrefined: Some((why, asked)), tracer: None })
    }
}

/// The rays a pixel of `light` the mask path traced casts: one under a hard light; a
/// penumbra beam's samples under a light with an area, which it beams through the
/// shader's BVH whatever traverses the hard rays.
fn rays_per_pixel(light: &super::plan::LightPlan) -> u32 {
    match rays::LightSize::of(&light.light) {
        rays::LightSize::Hard => 1,
        rays::LightSize::Area => gnomon_math::light_masks::SAMPLES as u32,
    }
}

/// Writes into each light's stats how its rays traversed the casters, why it fell
/// back, and, given the copy of the counters (`traced`, submitted), the pixels it
/// traced.
pub(super) async fn report(
    gpu: &Gpu,
    plan: &FramePlan,
    timed: &mut TimedLights,
    fallbacks: Fallbacks,
    traced: Option<wgpu::Buffer>,
) -> Result<(), RenderError> {
    if let Some((why, lights)) = fallbacks.unrefined {
        for index in lights {
            timed.lights[index].refine_fallback = Some(why.clone());
        }
    }
    for (stats, light) in timed.lights.iter_mut().zip(&plan.lights) {
        if light.refine != Refine::Off {
            // The mask path beams a light with an area through the shader's BVH.
            let beamed = plan.mask_path && rays::LightSize::of(&light.light) == rays::LightSize::Area;
            stats.traversal = Some(if beamed { Traversal::Shader } else { plan.traversal });
            stats.tracer_fallback = fallbacks.tracer.clone();
        }
    }
    if let Some(counters) = traced {
        let words: Vec<u32> = readback::read_buffer(gpu, &counters).await?;
        let listed = RefineLists::listed(&words, plan.lights.len());
        for ((stats, light), listed) in timed.lights.iter_mut().zip(&plan.lights).zip(listed) {
            if light.refine != Refine::Off {
                stats.traced_pixels = Some(listed.traced);
                stats.unsure_pixels = Some(listed.unsure);
                stats.rays_per_pixel = rays_per_pixel(light);
            }
        }
    }
    Ok(())
}

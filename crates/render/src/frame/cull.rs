//! Culling for a frame: which casters each layer of each light draws, and which
//! instances the camera sees, every view culled in one parallel sweep.

use gnomon_math::culling::Frustum;
use gnomon_scene::settings::{CasterCulling, DrawSubmission, RayUse};

use super::{
    Renderer,
    plan::{FramePlan, LightPlan},
};
use crate::{
    GpuCullUnavailable, GpuScene, RenderError,
    gpu_scene::{CullView, Granularity, LayerFaces, Visible},
};

/// Which casters each layer of each light draws, and what the camera sees.
pub(super) struct Culled {
    pub camera: Visible,
    /// Per light, per layer.
    pub layers: Vec<Vec<Visible>>,
    /// Why the lights that were to cull on the GPU culled on the CPU, if they did.
    pub gpu_cull_fallback: Option<GpuCullUnavailable>,
}

/// Culls for every layer of every light, and for the camera, in parallel.
fn cull(uploaded: &GpuScene, plan: &FramePlan) -> Culled {
    let camera_view = CullView {
        frustum: Frustum::from_clip_from_world(plan.camera.clip_from_world(plan.aspect)),
        near: true,
        casters_only: false,
        // The passes from the camera draw meshes whole, in their own triangle order.
        granularity: Granularity::Instances,
    };
    // A light whose technique is rays reads no map (`techniques/raytraced.rs`):
    // nothing is culled for its layers, nor drawn into them.
    let reads_map = plan.lights.iter().filter(|light| light.technique.rays() == RayUse::AsSettingsSay);
    let layer_views = reads_map.flat_map(|light| {
        light.layout.projections.iter().map(move |projection| layer_view(light, projection.clip_from_world()))
    });
    let views: Vec<CullView> = std::iter::once(camera_view).chain(layer_views).collect();
    let mut culled = uploaded.cull(&views).into_iter();
    let camera = culled.next().expect("the camera's view was culled");
    let layers = plan
        .lights
        .iter()
        .map(|light| {
            let layers = light.layout.projections.len();
            match light.technique.rays() {
                RayUse::AsSettingsSay => culled.by_ref().take(layers).collect(),
                RayUse::EveryPixel => vec![Visible::default(); layers],
            }
        })
        .collect();
    Culled { camera, layers, gpu_cull_fallback: None }
}

/// What a shadow pass of `light` through `clip_from_world` (a layer, or a part of
/// one) culls its casters against.
pub(super) fn layer_view(light: &LightPlan, clip_from_world: glam::Mat4) -> CullView {
    let shadow = &light.settings.shadow;
    CullView {
        frustum: Frustum::from_clip_from_world(clip_from_world),
        // A pass that clamps depth draws the casters before its near plane too.
        near: !light.layout.depth_clamp,
        casters_only: true,
        granularity: match shadow.map.caster_culling {
            CasterCulling::Clusters => Granularity::Clusters {
                faces: LayerFaces::of(clip_from_world, light.depth_target(), shadow.bias.cull),
            },
            CasterCulling::Instances => Granularity::Instances,
        },
    }
}

impl Renderer {
    /// Culls for every layer of every light of `plan` and for the camera ([`cull`]),
    /// first uploading the shadow items the GPU culler reads, once per scene, where a
    /// light culls its layers on the GPU and the device can draw what it kept
    /// (`DrawSubmission::GpuCulled`). A scene the device cannot take this way is culled
    /// on the CPU, the same map.
    pub(super) fn cull_frame(&self, uploaded: &GpuScene, plan: &FramePlan) -> Result<Culled, RenderError> {
        let wanted =
            plan.lights.iter().any(|l| l.settings.shadow.map.draw_submission == DrawSubmission::GpuCulled);
        let gpu_cull_fallback = match (wanted, self.gpu.indirect_count) {
            (false, _) => None,
            (true, false) => Some(GpuCullUnavailable::NoIndirectCount),
            // Ok(Err(why)): this device cannot; the passes then cull on the CPU.
            (true, true) => match uploaded.shadow_items(&self.gpu)? {
                Ok(_) | Err(GpuCullUnavailable::NoCasters) => None,
                Err(why) => Some(why),
            },
        };
        Ok(Culled { gpu_cull_fallback, ..cull(uploaded, plan) })
    }
}

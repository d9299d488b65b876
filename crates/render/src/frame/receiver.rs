//! Bring your own shading: the shadow maps of a scene's lights, drawn for the host's
//! camera into the host's command encoder, and handed over as one bind group per
//! light with the WGSL that reads it (`shadow_visibility`, documented in
//! `passes/receiver.wgsl`). The host shades with its own pipeline and shader.

use gnomon_scene::{
    Light, Scene, Settings,
    settings::{Lighting, RayUse, Refine, ScreenSpaceSettings, Technique},
};

use super::{Renderer, bindings::ReceiverUniforms, recording::Recording};
use crate::{
    GpuScene, RenderError,
    frame::DrawStats,
    passes::{lighting::MapLookup, receiver},
    techniques::TechniqueRef,
    timing::PassClock,
    uniforms::CameraGpu,
};

/// The shadows of a frame's lights, ready for a host's shader: one entry per light
/// the settings select, in their order. The bind groups stay valid until the
/// renderer's next frame.
pub struct Shadows {
    /// Each light's receiver.
    pub lights: Vec<LightShadows>,
    /// What the shadow passes drew.
    pub stats: DrawStats,
}

/// One light's shadows: the group to bind where the host's shader declared it, and
/// which receiver WGSL reads it.
pub struct LightShadows {
    /// The light, as the scene (or the settings' override) has it.
    pub light: Light,
    /// Its uniform, the camera's, its maps and their samplers, in the layout of
    /// [`Renderer::receiver_layout`].
    pub bind_group: wgpu::BindGroup,
    /// The WGSL that reads it: [`ReceiverVariant::wgsl`].
    pub variant: ReceiverVariant,
}

/// What a receiver's WGSL depends on: the light's technique and how its map is
/// looked up (2D layers, a cube, dual paraboloids). Lights of equal variants share
/// a host pipeline; cache the host's pipelines by it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ReceiverVariant {
    technique: TechniqueRef,
    lookup: MapLookup,
}

impl ReceiverVariant {
    /// The technique whose lookup it composes.
    pub fn technique(&self) -> Technique {
        self.technique.technique()
    }

    /// The receiver module, with its bind group at index `group` of the host's
    /// pipeline layout. It declares `shadow_visibility(world, normal, frag_coord) ->
    /// f32`, `shadow_light_direction(world) -> vec4<f32>` and `shadow_light_radiance()
    /// -> vec3<f32>`; append the host's shader to it to make one module. Its
    /// module-scope names (`light`, `camera`, `shadow_map`, `sample_shadow`, …) are
    /// taken: the host's shader must not reuse them.
    pub fn wgsl(&self, group: u32) -> String {
        receiver::receiver_wgsl(self.technique, self.lookup, group)
    }
}

impl Renderer {
    /// The layout of every light's receiver group ([`LightShadows::bind_group`]), for
    /// the host's pipeline layout: fixed for the renderer's life.
    pub fn receiver_layout(&self) -> &wgpu::BindGroupLayout {
        &self.layouts.receiver
    }

    /// Draws the shadow maps (and moment maps) of the lights `settings` select, fitted
    /// to the scene's camera (set `scene.camera` to the host's, and
    /// `settings.image` to its target's size), into `encoder`, which the host submits
    /// before drawing with them, or in the same submission before its own passes.
    /// Nothing is submitted here, except SDSM's depth prepass, which needs the camera's
    /// depths before the maps are fitted.
    ///
    /// The mask path (`screen.shadow_path = "mask"`, contact shadows) needs Gnomon's
    /// own depth prepass, and rays asked for by name (on either path) are traced in
    /// Gnomon's own passes: for those this returns
    /// [`RenderError::ReceiverNeedsMapPath`]; a technique that is rays (`raytraced`)
    /// has no map for the host to read ([`RenderError::ReceiverCannotTrace`]). The
    /// default refinement, `auto`, and the light list run only where Gnomon draws the
    /// image: here the maps' answer is the host's, and so is the lighting.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn record_shadows(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
    ) -> Result<Shadows, RenderError> {
        pollster::block_on(self.record_shadows_async(encoder, uploaded, scene, settings))
    }

    /// [`Renderer::record_shadows`], for a host that cannot block (a browser): SDSM's
    /// cascades wait for the camera's depths to be read back.
    pub async fn record_shadows_async(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
    ) -> Result<Shadows, RenderError> {
        self.pool.end_frame();
        settings.validate()?;
        self.check_map_limits(settings)?;
        // What only Gnomon's own frames do: the default refinement, and lighting from
        // the light list (which would take the mask path); the host lights its pixels.
        let refine = match settings.screen.refine {
            Refine::Auto => Refine::Off,
            named @ (Refine::Off | Refine::Rays | Refine::EveryPixel) => named,
        };
        let screen = ScreenSpaceSettings { refine, lighting: Lighting::PerLight, ..settings.screen.clone() };
        let settings = &Settings { screen, ..settings.clone() };
        let plan = self.plan_frame(uploaded, scene, settings, None).await?;
        if let Some(light) = plan.lights.iter().find(|l| l.technique.rays() == RayUse::EveryPixel) {
            return Err(RenderError::ReceiverCannotTrace {
                light: light.name.clone(),
                technique: light.technique.technique().to_string(),
            });
        }
        if plan.mask_path || plan.lights.iter().any(|l| l.refine != Refine::Off) {
            return Err(RenderError::ReceiverNeedsMapPath);
        }
        let culled = self.cull_frame(uploaded, &plan)?;
        let gpu = self.gpu.clone();
        gpu.checked("recording the shadows for the host's shader", || {
            let mut rec = Recording {
                encoder,
                clock: PassClock::off(),
                stats: DrawStats::default(),
                layer_commands: Default::default(),
            };
            let (width, height) = (settings.image.width, settings.image.height);
            let camera_gpu = CameraGpu::new(&plan.camera, width, height, settings.image.debug_view);
            let camera = self.pool.uniform(&gpu.queue, "camera", &camera_gpu);
            let mut lights = Vec::with_capacity(plan.lights.len());
            self.map_cache.begin_frame(plan.lights.len());
            for (index, light) in plan.lights.iter().enumerate() {
                let map =
                    self.record_shadow_maps(&mut rec, uploaded, light, &culled.layers[index], index as u32);
                let derived = super::record::DerivedInputs { history: None, bvh: None };
                let maps = self.light_maps(&mut rec, light, index as u32, &map, derived);
                let uniforms = ReceiverUniforms { light: &maps.light_buffer, camera: &camera };
                let bind_group =
                    self.fixed.receiver_group(&mut self.pool, &self.layouts, uniforms, maps.views(None));
                let variant = ReceiverVariant { technique: light.technique, lookup: maps.lookup };
                lights.push(LightShadows { light: light.light, bind_group, variant });
            }
            Shadows { lights, stats: rec.stats }
        })
    }
}

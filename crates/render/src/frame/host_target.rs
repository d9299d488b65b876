//! Gnomon draws, into the host's frame: the lit scene, from the host's camera, with
//! every pass recorded into the host's command encoder and the image copied into the
//! host's texture. Nothing is submitted or read back; nothing is timed.

use gnomon_scene::{Scene, Settings};

use super::{DrawStats, Renderer, record::Readback, recording::Recording};
use crate::{GpuScene, RenderError, passes::blit::HostTarget, timing::PassClock};

impl Renderer {
    /// Renders the lit scene into the host's `target`, recording every pass into the
    /// host's `encoder`, which the host submits. The camera is the scene's (set
    /// `scene.camera` to the host's, or override it in `settings.camera`); the image
    /// takes the target's size, whatever `settings.image` says. Linear colour is
    /// written: an sRGB target encodes it. Returns what the passes drew.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn render_into(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &HostTarget,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
    ) -> Result<DrawStats, RenderError> {
        pollster::block_on(self.render_into_async(encoder, target, uploaded, scene, settings))
    }

    /// [`Renderer::render_into`], for a host that cannot block (a browser): SDSM's
    /// cascades wait for the camera's depths to be read back.
    pub async fn render_into_async(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        target: &HostTarget<'_>,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
    ) -> Result<DrawStats, RenderError> {
        let mut settings = settings.clone();
        (settings.image.width, settings.image.height) = (target.width, target.height);
        self.pool.end_frame();
        settings.validate()?;
        self.check_limits(&settings)?;
        let plan = self.plan_frame(uploaded, scene, &settings, None).await?;
        let culled = self.cull_frame(uploaded, &plan)?;
        let gpu = self.gpu.clone();
        gpu.checked("rendering into the host's target", || {
            let mut rec = Recording {
                encoder,
                clock: PassClock::off(),
                stats: DrawStats::default(),
                layer_commands: Default::default(),
            };
            let drawn = self.record_passes(&mut rec, uploaded, &settings, &plan, &culled, Readback::NONE);
            self.passes.blit.record(&gpu.device, &mut self.pool, rec.encoder, &drawn.color, target);
            rec.stats
        })
    }
}

//! The depth-only baseline of `gnomon bench --depth-only`: the shadow maps a frame
//! would draw (same layers, resolution, cull mode, bias and depth clamp), drawn from
//! world-space positions with no instance data, to time against the shadow pass.
// `gnomon bench` runs the baseline, and a browser runs no bench: there its entry
// points are left out, and what only they use is unused.
#![cfg_attr(target_arch = "wasm32", allow(dead_code))]

use gnomon_scene::{Scene, Settings};

use super::Renderer;
use crate::{
    GpuScene, RenderError,
    passes::{
        SHADOW_FORMAT,
        depth_baseline::{BaselineLayer, BaselineRaster, DepthBaselineScene},
        shadow::{DepthRange, DepthTarget},
    },
    pool::ViewKey,
    readback,
    timing::{ClockChoice, FrameTimes, PassClock, PassKind},
};

/// What a depth-only baseline run measured and read.
struct BaselineRun {
    times: Option<FrameTimes>,
    /// The reported light's map, every layer, when asked for.
    shown_map: Option<Vec<f32>>,
    lights: usize,
}

/// What a baseline run is for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum BaselinePurpose {
    /// Timing every light's layers with this clock.
    Time(ClockChoice),
    /// Reading the reported light's map back.
    ReadShownMap,
}

impl Renderer {
    /// Uploads the depth-only baseline's geometry for `scene`: every caster flattened
    /// into world space ([`Renderer::time_depth_baseline`]).
    pub fn upload_depth_baseline(&self, scene: &Scene) -> Result<DepthBaselineScene, RenderError> {
        DepthBaselineScene::upload(&self.gpu, scene)
    }

    /// Times the depth-only baseline drawing the shadow maps this frame would draw
    /// (the same layers, resolution, cull mode and depth clamp): per light, the time
    /// of all its layers; None for a dual-paraboloid map, which no matrix can draw.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn time_depth_baseline(
        &mut self,
        baseline: &DepthBaselineScene,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        clock: ClockChoice,
    ) -> Result<Vec<Option<f64>>, RenderError> {
        let purpose = BaselinePurpose::Time(clock);
        let run =
            pollster::block_on(self.record_depth_baseline(baseline, uploaded, scene, settings, purpose))?;
        let times = run.times.map(|t| t.passes).unwrap_or_default();
        Ok((0..run.lights as u32)
            .map(|light| {
                let mut layers = times.iter().filter(|p| p.light == Some(light)).peekable();
                layers.peek()?;
                Some(layers.map(|p| p.ms).sum())
            })
            .collect())
    }

    /// The depth-only baseline's map of the reported light, every layer, read back
    /// (as [`crate::ShadowMapImage::depth`] lays them out): to check that it draws
    /// what the shadow pass draws.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn depth_baseline_map(
        &mut self,
        baseline: &DepthBaselineScene,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
    ) -> Result<Vec<f32>, RenderError> {
        let purpose = BaselinePurpose::ReadShownMap;
        let run =
            pollster::block_on(self.record_depth_baseline(baseline, uploaded, scene, settings, purpose))?;
        run.shown_map.ok_or_else(|| RenderError::Gpu {
            during: "drawing the depth-only baseline",
            message: "a dual-paraboloid map has no baseline".into(),
        })
    }

    /// Records and submits the baseline's maps for the frame `settings` plans
    /// (for `gnomon bench`, which a browser does not run).
    async fn record_depth_baseline(
        &mut self,
        baseline: &DepthBaselineScene,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        purpose: BaselinePurpose,
    ) -> Result<BaselineRun, RenderError> {
        self.pool.end_frame();
        settings.validate()?;
        self.check_limits(settings)?;
        let plan = self.plan_frame(uploaded, scene, settings, None).await?;
        let gpu = self.gpu.clone();
        let layers: u32 = plan.lights.iter().map(|p| p.layers()).sum();
        let clock = match purpose {
            BaselinePurpose::Time(clock) => Some(clock),
            BaselinePurpose::ReadShownMap => None,
        };
        let (pending_times, pending_map) = gpu.checked("drawing the depth-only baseline", || {
            let mut clock = PassClock::new(&gpu, &mut self.pool, layers, clock);
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let mut pending_map = None;
            for (index, light) in plan.lights.iter().enumerate() {
                let target = match light.depth_target() {
                    // No matrix draws a paraboloid: the baseline has none.
                    DepthTarget::Paraboloid => continue,
                    target @ (DepthTarget::Projected | DepthTarget::CubeFace) => target,
                };
                let map = self.pool.texture(
                    "baseline depth",
                    light.map_size(),
                    SHADOW_FORMAT,
                    wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                );
                for layer in 0..light.layers() {
                    let view = self.pool.view(&map, ViewKey::layer(layer));
                    let slot =
                        clock.begin(&gpu, &mut encoder, PassKind::Shadow, Some(index as u32), Some(layer));
                    let drawn = BaselineLayer {
                        clip_from_world: light.light_gpu.cascade_clip_from_world[layer as usize],
                        raster: BaselineRaster {
                            bias: &light.settings.shadow.bias,
                            depth_range: DepthRange::clamped_if(light.layout.depth_clamp),
                            target,
                        },
                        target: &view,
                    };
                    let writes = clock.render_writes(slot);
                    self.passes.depth_baseline.record(
                        &gpu,
                        &mut self.pool,
                        &mut encoder,
                        baseline,
                        drawn,
                        writes,
                    );
                    clock.end(&gpu, &mut encoder, slot);
                }
                if purpose == BaselinePurpose::ReadShownMap && index == plan.shown {
                    let aspect = wgpu::TextureAspect::DepthOnly;
                    pending_map = Some(readback::record(&mut self.pool, &mut encoder, &map, aspect));
                }
            }
            let pending_times = clock.resolve(&mut self.pool, &mut encoder);
            gpu.queue.submit([encoder.finish()]);
            (pending_times, pending_map)
        })?;
        let times = pending_times.read(&gpu).await?;
        let map = match pending_map {
            Some(p) => Some(p.read::<f32>(&gpu).await?),
            None => None,
        };
        Ok(BaselineRun { times, shown_map: map, lights: plan.lights.len() })
    }
}

//! The renderer: what it keeps across frames (pipelines, layouts, samplers and the
//! pool of transient resources) and its entry points. A frame is planned
//! ([`plan`]: camera, lights, layouts, uniforms), culled and recorded ([`record`]:
//! shadow maps, moment maps, screen-space passes, lighting), submitted, and read
//! back ([`outputs`]). The depth-only baseline lives in [`baseline`].

mod baseline;
mod bindings;
mod cull;
mod depth_pass;
mod derived_cache;
mod host_target;
mod late;
mod light_passes;
mod map_cache;
mod memory;
mod moment_cache;
mod outputs;
mod penumbra_history;
#[cfg(test)]
mod penumbra_tests;
mod plan;
mod receiver;
mod record;
mod recording;
mod refine;
mod screen;
mod shadow_maps;
mod tile_pass;
#[cfg(test)]
mod touched_tests;
#[cfg(test)]
mod virtual_depth_tests;
mod virtual_pages;
mod virtual_record;

use gnomon_scene::{Scene, Settings, settings::MomentFormat};

pub use crate::pool::Creations;
pub use map_cache::LayerCache;
pub use outputs::{
    CpuTimings, Frame, FrameCost, LightStats, LiveFrame, OutputRequest, PassTimings, ShadowMapImage,
};
pub use receiver::{LightShadows, ReceiverVariant, Shadows};
pub use recording::DrawStats;
pub use virtual_pages::{PageStats, VirtualLevels};

use crate::{
    Gpu, GpuScene, RenderError,
    passes::{
        Layouts, blit::BlitPass, depth_baseline::DepthBaselinePass, depth_reduce::DepthReducePass,
        gpu_cull::GpuCullPass, light_list::LightListPass, lighting, lighting::LightingPass,
        map_preview::MapPreviewPass, map_scroll::MapScrollPass, moments::MomentPass,
        screen_space::ScreenSpacePass, shadow::ShadowPass,
    },
    pool::Pool,
    rays::{PyramidPass, TouchedPass, TracePasses},
    techniques::TechniqueRegistry,
    timing::ClockChoice,
};
use bindings::FixedBindings;
use late::LateTimes;
use record::{Readback, SubmitRequest, TimesWanted};

/// The pass pipelines, built once (and per variant on first use).
struct Passes {
    shadow: ShadowPass,
    lighting: LightingPass,
    light_list: LightListPass,
    screen_space: ScreenSpacePass,
    trace: TracePasses,
    moments: MomentPass,
    pyramid: PyramidPass,
    touched: TouchedPass,
    depth_reduce: DepthReducePass,
    map_preview: MapPreviewPass,
    map_scroll: MapScrollPass,
    gpu_cull: GpuCullPass,
    depth_baseline: DepthBaselinePass,
    blit: BlitPass,
}

/// The renderer: everything a frame reuses. Create one per device and keep it; a
/// steady sequence of frames creates no texture, buffer or bind group after the
/// first ([`Renderer::creations`]).
pub struct Renderer {
    gpu: Gpu,
    layouts: Layouts,
    passes: Passes,
    fixed: FixedBindings,
    pool: Pool,
    /// Live frames' pass times, read when they arrive.
    late_times: LateTimes,
    /// The techniques its settings may name.
    techniques: TechniqueRegistry,
    /// Each light's map as its still casters drew it, kept across frames.
    map_cache: map_cache::MapCache,
    /// Each light's penumbra history, kept across frames where nothing moved.
    penumbra_histories: penumbra_history::PenumbraHistories,
    /// Each virtual light's pool of pages, kept across frames.
    virtual_lights: virtual_pages::VirtualLights,
    /// The bytes a frame may hold, and where that limit came from
    /// ([`gnomon_scene::memory::frame_budget`]).
    memory_budget: gnomon_scene::memory::FrameBudget,
}

impl Renderer {
    /// A renderer on `gpu`'s device (which it shares, not copies), with the built-in
    /// techniques.
    pub fn new(gpu: &Gpu) -> Result<Self, RenderError> {
        Self::with_techniques(gpu, TechniqueRegistry::builtin())
    }

    /// A renderer that knows `techniques`: the built-in ones and any the host
    /// registered ([`TechniqueRegistry::with`]).
    pub fn with_techniques(gpu: &Gpu, techniques: TechniqueRegistry) -> Result<Self, RenderError> {
        let memory_budget = gnomon_scene::memory::frame_budget().map_err(RenderError::MemoryBudget)?;
        gpu.checked("creating the renderer", || {
            let device = &gpu.device;
            let layouts = Layouts::new(device);
            let passes = Passes {
                shadow: ShadowPass::new(device, &layouts),
                lighting: LightingPass::new(device, &layouts),
                light_list: LightListPass::new(device, &layouts),
                screen_space: ScreenSpacePass::new(device, &layouts),
                trace: TracePasses::default(),
                moments: MomentPass::new(device, &gpu.queue),
                pyramid: PyramidPass::new(device),
                touched: TouchedPass::new(device),
                depth_reduce: DepthReducePass::new(device),
                map_preview: MapPreviewPass::new(device),
                map_scroll: MapScrollPass::new(device),
                gpu_cull: GpuCullPass::new(device),
                depth_baseline: DepthBaselinePass::new(device),
                blit: BlitPass::new(device),
            };
            Self {
                gpu: Gpu::clone(gpu),
                fixed: FixedBindings::new(device),
                pool: Pool::new(device),
                late_times: LateTimes::default(),
                map_cache: map_cache::MapCache::default(),
                penumbra_histories: penumbra_history::PenumbraHistories::default(),
                virtual_lights: virtual_pages::VirtualLights::default(),
                techniques,
                layouts,
                passes,
                memory_budget,
            }
        })
    }

    /// The techniques its settings may name.
    pub fn techniques(&self) -> &TechniqueRegistry {
        &self.techniques
    }

    /// The device the renderer draws with.
    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// How many GPU resources the renderer's frames have created so far: after the
    /// first frame of given settings, the same frame again adds none.
    pub fn creations(&self) -> Creations {
        let mut creations = self.pool.creations();
        // The kept maps' textures (depths and moments) live outside the pool, made
        // again only when a map's size changes (`map_cache.rs`, `moment_cache.rs`).
        creations.textures += self.map_cache.created() + self.penumbra_histories.created();
        creations
    }

    /// Uploads `scene` and renders it. To render one scene many times, upload it once
    /// with [`Renderer::upload`] and call [`Renderer::render_uploaded`].
    #[cfg(not(target_arch = "wasm32"))]
    pub fn render(
        &mut self,
        scene: &Scene,
        settings: &Settings,
        request: &OutputRequest,
    ) -> Result<Frame, RenderError> {
        pollster::block_on(self.render_async(scene, settings, request))
    }

    /// [`Renderer::render`], for a caller that cannot block (a browser): the frame's
    /// readbacks are awaited.
    pub async fn render_async(
        &mut self,
        scene: &Scene,
        settings: &Settings,
        request: &OutputRequest,
    ) -> Result<Frame, RenderError> {
        settings.validate()?;
        self.check_frame_memory(scene, settings)?;
        let uploaded = self.upload(scene)?;
        self.render_uploaded_async(&uploaded, scene, settings, request).await
    }

    /// Throws every light's penumbra history away: the next frame starts afresh, as
    /// after a cut, though nothing it would notice moved (a host that cuts to another
    /// shot of the same scene, or a measure of a first frame).
    pub fn forget_penumbra_history(&mut self) {
        self.penumbra_histories.forget_all();
    }

    /// Uploads a scene's geometry, instances and textures.
    pub fn upload(&self, scene: &Scene) -> Result<GpuScene, RenderError> {
        self.check_scene_memory(scene)?;
        GpuScene::upload(&self.gpu, scene, &self.layouts)
    }

    /// Follows instances that moved since `uploaded` was made from `scene`: set their
    /// new `world_from_object` in `scene`, then name them here (by their index in
    /// `scene.instances`). Their transforms are rewritten on the GPU, and the culling
    /// trees, the bounds the lights are fitted to and (once built for rays) the casters'
    /// BVH are refitted, not rebuilt: the next frame draws and traces the scene as it
    /// now stands, at a cost that follows what moved, not the scene's size. Anything
    /// else changed in `scene` (meshes, materials, which instances cast) needs a new
    /// [`Renderer::upload`]. An index out of range, a non-finite transform or an
    /// instance list that grew or shrank is refused, naming it, before anything
    /// changes.
    pub fn move_instances(
        &self,
        uploaded: &mut GpuScene,
        scene: &Scene,
        moved: &[usize],
    ) -> Result<(), RenderError> {
        uploaded.move_instances(&self.gpu, scene, moved)
    }

    /// Checks `settings` against the device's limits and the registered techniques,
    /// for a frame Gnomon draws.
    pub fn check_limits(&self, settings: &Settings) -> Result<(), RenderError> {
        self.check_map_limits(settings)?;
        let limits = &self.gpu.limits;
        let needed = lighting::target_bytes_per_pixel();
        if limits.max_color_attachment_bytes_per_sample < needed {
            return Err(RenderError::AttachmentsTooLarge {
                available: limits.max_color_attachment_bytes_per_sample,
                needed,
                adapter: self.gpu.info.adapter.clone(),
            });
        }
        Ok(())
    }

    /// Checks what the shadow maps of `settings` need of the device, and that a
    /// registered technique can draw them ([`TechniqueRegistry::check`]): all that a
    /// host drawing its own image needs, [`Renderer::record_shadows`]. Each light's
    /// kind is checked against its technique when a frame is planned.
    pub fn check_map_limits(&self, settings: &Settings) -> Result<(), RenderError> {
        self.techniques.check(&settings.shadow)?;
        let limits = &self.gpu.limits;
        let adapter = self.gpu.info.adapter.clone();
        let max = limits.max_texture_dimension_2d;
        let requested = settings.shadow.map.resolution;
        if requested > max {
            return Err(RenderError::ShadowMapTooLarge { requested, max, adapter });
        }
        let (width, height) = (settings.image.width, settings.image.height);
        if width > max || height > max {
            return Err(RenderError::ImageTooLarge { width, height, max, adapter });
        }
        // Every camera-sized target is read back through one buffer: the largest (16
        // bytes a pixel) must fit the device's largest buffer.
        let bytes = u64::from(width) * u64::from(height) * lighting::LARGEST_TARGET_BYTES;
        if bytes > limits.max_buffer_size {
            let max_buffer = limits.max_buffer_size;
            let max_pixels = max_buffer / lighting::LARGEST_TARGET_BYTES;
            return Err(RenderError::ImageTooManyBytes {
                width,
                height,
                bytes,
                max_buffer,
                max_pixels,
                adapter,
            });
        }
        self.moment_format(settings)?;
        Ok(())
    }

    /// The moment map's format for these settings on this device.
    pub fn moment_format(&self, settings: &Settings) -> Result<wgpu::TextureFormat, RenderError> {
        let filterable = self.gpu.device.features().contains(wgpu::Features::FLOAT32_FILTERABLE);
        match settings.shadow.filter.moments.moment_format {
            MomentFormat::Rgba16float => Ok(wgpu::TextureFormat::Rgba16Float),
            MomentFormat::Auto if !filterable => Ok(wgpu::TextureFormat::Rgba16Float),
            MomentFormat::Auto => Ok(wgpu::TextureFormat::Rgba32Float),
            MomentFormat::Rgba32float if filterable => Ok(wgpu::TextureFormat::Rgba32Float),
            MomentFormat::Rgba32float => {
                Err(RenderError::MomentFormatUnsupported { adapter: self.gpu.info.adapter.clone() })
            }
        }
    }

    /// Renders an uploaded scene. `scene` must be the one `uploaded` was made from.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn render_uploaded(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        request: &OutputRequest,
    ) -> Result<Frame, RenderError> {
        pollster::block_on(self.render_uploaded_async(uploaded, scene, settings, request))
    }

    /// [`Renderer::render_uploaded`], for a caller that cannot block (a browser):
    /// the frame's readbacks are awaited.
    pub async fn render_uploaded_async(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        request: &OutputRequest,
    ) -> Result<Frame, RenderError> {
        // A still view of a virtual map settles over frames: each frame's traced
        // pixels ask for the pages along shadow edges one level finer, which the
        // next frame draws (`shadow.virtual_map.edge_levels`, `virtual_map/edges.rs`).
        // The first frame whose pages were settled already, or the frame after the
        // last level's, is the one returned. A still view's penumbrae gather their
        // beams over frames too (`screen.penumbra_frames`, rays/penumbra_mask.wgsl):
        // the frame returned is the first whose history holds that many.
        let levels = self.settling_frames(scene, settings)?;
        let mut frames = 0;
        let submitted = loop {
            let submit = SubmitRequest {
                readback: Readback { images: true, shadow_map: request.shadow_map },
                fixed_layout: request.fixed_layout.as_ref(),
                clock: None,
                times: TimesWanted::Now,
            };
            let submitted = self.submit(uploaded, scene, settings, submit).await?;
            let penumbrae = settings.screen.penumbra_frames;
            let gathered = submitted.penumbrae_gathered(penumbrae) || frames >= levels + penumbrae;
            if (frames >= levels || submitted.edges_settled()) && gathered {
                break submitted;
            }
            frames += 1;
        };
        let frame = submitted.read(&self.gpu, settings).await?;
        self.gpu.deferred_error()?;
        Ok(frame)
    }

    /// Renders an uploaded scene and leaves the image and the shadow map on the GPU,
    /// for a window to draw ([`LiveFrame`]). Its textures stay valid until the next
    /// frame. It does not wait for the GPU to finish it: its pass times are the
    /// previous frame's, read once this one is submitted ([`LiveFrame::timings_age`]).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn render_live(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
    ) -> Result<LiveFrame, RenderError> {
        pollster::block_on(self.render_live_async(uploaded, scene, settings))
    }

    /// [`Renderer::render_live`], for a caller that cannot block (a browser).
    pub async fn render_live_async(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
    ) -> Result<LiveFrame, RenderError> {
        let submit = SubmitRequest {
            readback: Readback::NONE,
            fixed_layout: None,
            clock: None,
            times: TimesWanted::Late,
        };
        let submitted = self.submit(uploaded, scene, settings, submit).await?;
        self.gpu.deferred_error()?;
        Ok(submitted.live(self.late_times.latest_age()))
    }

    /// The shadow map of `frame`, every layer side by side in grayscale (near black,
    /// far white; perspective layers linearized), each `tile` pixels square: an
    /// `Rgba8Unorm` texture for a UI to show.
    pub fn preview_shadow_map(&mut self, frame: &LiveFrame, tile: u32) -> Result<wgpu::Texture, RenderError> {
        let Self { gpu, passes, pool, .. } = self;
        gpu.checked("drawing the shadow map preview", || {
            passes.map_preview.draw(gpu, pool, &frame.shadow_map, &frame.layout.projections, tile.max(8))
        })
    }

    /// Renders an uploaded scene for its pass times and draw counts alone: nothing is
    /// read back but the timestamps, so timing loops don't pay for image copies.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn time_passes(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        clock: ClockChoice,
    ) -> Result<FrameCost, RenderError> {
        pollster::block_on(self.time_passes_async(uploaded, scene, settings, clock))
    }

    /// [`Renderer::time_passes`], for a caller that cannot block (a browser).
    pub async fn time_passes_async(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        clock: ClockChoice,
    ) -> Result<FrameCost, RenderError> {
        let submit = SubmitRequest {
            readback: Readback::NONE,
            fixed_layout: None,
            clock: Some(clock),
            times: TimesWanted::Now,
        };
        let cost = self.submit(uploaded, scene, settings, submit).await?.cost();
        self.gpu.deferred_error()?;
        Ok(cost)
    }
}

//! One frame: resolve the camera and light, draw the shadow map, shade the image,
//! and read every output back.

use std::time::Instant;

use glam::{Vec3, Vec4};
use gnomon_math::{
    LightProjection, ProjectionKind,
    culling::Frustum,
    fitting::directional_light_view,
    omni::{cube_texel_world_size, paraboloid_texel_world_size},
};
use gnomon_scene::{
    Camera, Light, Scene, Settings,
    settings::{
        BiasSettings, CascadeSelection, DebugView, KernelUnit, LightKind, MomentFormat, OmniMap, Partition,
        Technique,
    },
};
use wgpu::util::DeviceExt;

use crate::{
    Gpu, GpuScene, RenderError,
    gpu_scene::{CullView, Visible},
    gpu_types::{CameraGpu, LightGpu, MAX_CASCADES, VertexStream},
    layout::{SampleDistribution, ShadowLayout, cascade_splits, shadow_layout},
    passes::{
        Layouts, SHADOW_FORMAT, begin_depth_pass,
        depth_baseline::{BaselineRaster, DepthBaselinePass, DepthBaselineScene},
        depth_reduce::{BoundsRequest, DepthReducePass},
        lighting::{self, LightingKey, LightingPass, LightingRole, Lookup},
        map_preview::MapPreviewPass,
        moments::MomentPass,
        screen_space::{self, MaskKey, ScreenSpacePass},
        shadow::{
            Coverage, DepthRange, DepthTarget, ShadowPass, ShadowPipelineKey, ShadowPipelineShape, Sides,
        },
    },
    readback, techniques,
    timing::{ClockChoice, PassClock, PassKind, PassTime, TimingSource},
};

/// Optional outputs of a frame.
#[derive(Clone, Debug, Default)]
pub struct OutputRequest {
    /// Read the shadow map back (resolution² floats).
    pub shadow_map: bool,
    /// Draw the shadow maps with this layout instead of fitting one to the camera:
    /// frozen cascades, to watch how a layout fitted to one view serves another.
    pub fixed_layout: Option<ShadowLayout>,
}

/// The light's depth map as rendered, with what is needed to interpret it.
#[derive(Clone, Debug)]
pub struct ShadowMapImage {
    pub resolution: u32,
    /// Array layers: cascades, cube faces (WebGPU's order) or paraboloids; 1 for a
    /// single map.
    pub layers: u32,
    /// Raw depth in [0, 1], row-major, top row first (texture space, v down), layer
    /// after layer.
    pub depth: Vec<f32>,
}

impl ShadowMapImage {
    /// One layer's texels.
    pub fn layer(&self, layer: u32) -> &[f32] {
        let texels = (self.resolution * self.resolution) as usize;
        &self.depth[layer as usize * texels..(layer as usize + 1) * texels]
    }
}

/// Everything a frame produced. Images are row-major, top row first.
#[derive(Clone, Debug)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// RGBA8, sRGB-encoded.
    pub color: Vec<u8>,
    /// Shadow factor in [0, 1] (1 lit); 0 outside a spot light's cone or range;
    /// NaN where no surface is seen (background).
    pub visibility: Vec<f32>,
    /// World-space position of the visible surface; NaN for background.
    pub position: Vec<Vec3>,
    /// World-space unit normal of the visible surface, facing the camera; NaN for background.
    pub normal: Vec<Vec3>,
    /// View-space depth (distance along the camera's axis); NaN for background.
    pub depth: Vec<f32>,
    /// Instance index + 1 of the visible surface; 0 for background.
    pub object_id: Vec<u32>,
    pub camera: Camera,
    /// The light whose visibility the frame reports: the one light, or with
    /// `--light all` the one at `--light-index`. The shadow-map fields below are its.
    pub light: Light,
    /// The shadow map's projection (the first cascade's, with cascades).
    pub light_projection: LightProjection,
    /// Every layer's projection: one per cascade, or just `light_projection`.
    pub cascades: Vec<LightProjection>,
    /// The view depths bounding the cascades (one more than there are cascades).
    pub cascade_splits: Vec<f32>,
    /// The shadow map was drawn with depth clamping: its near plane sits at the nearest
    /// receiver, and casters before it are clamped onto it.
    pub shadow_depth_clamp: bool,
    pub shadow_resolution: u32,
    pub shadow_map: Option<ShadowMapImage>,
    /// GPU time of each pass, where the device has timestamp queries.
    pub timings: Option<PassTimings>,
    /// Draw calls and state changes, every light together.
    pub stats: DrawStats,
    /// What each light drew and cost, in the order they were drawn.
    pub lights: Vec<LightStats>,
    /// The moment map's texel format, for the filterable techniques.
    pub moment_format: Option<wgpu::TextureFormat>,
    /// Shadows were resolved in a screen-space mask (a prepass, then one mask pass
    /// per light), not per fragment in the lighting passes.
    pub shadow_mask: bool,
}

/// A frame left on the GPU for a window to show: nothing is read back but the pass
/// timestamps, so it costs what the passes cost.
#[derive(Clone, Debug)]
pub struct LiveFrame {
    /// The lit image, RGBA8 sRGB, bindable as a texture.
    pub color: wgpu::Texture,
    /// The reported light's shadow map: a Depth32Float 2D array, one layer per cascade
    /// (six for a cube), bindable as a texture.
    pub shadow_map: wgpu::Texture,
    pub camera: Camera,
    pub light: Light,
    /// The reported light's layers and cascade splits.
    pub layout: ShadowLayout,
    pub timings: Option<PassTimings>,
    pub stats: DrawStats,
    pub lights: Vec<LightStats>,
    pub shadow_mask: bool,
}

/// What one light of a frame drew and cost.
#[derive(Clone, Debug, PartialEq)]
pub struct LightStats {
    /// The light's name in the scene's list, or its type for a single light.
    pub name: String,
    /// "sun", "spot" or "point".
    pub kind: &'static str,
    pub technique: Technique,
    /// Texels per side of each of its layers.
    pub resolution: u32,
    /// Draw calls into each layer of its map (one per cascade, six for a cube): the
    /// casters that survived culling against that layer's frustum.
    pub layer_draws: Vec<u32>,
    /// Instances drawn into each layer: those whose bounds reach into its frustum.
    pub layer_instances: Vec<u32>,
    /// The time of each layer's shadow pass, where the frame was timed.
    pub layer_ms: Vec<f64>,
    /// Time of its shadow passes (every layer), moment pass and lighting pass, where
    /// the frame was timed.
    pub shadow_ms: Option<f64>,
    pub filter_ms: Option<f64>,
    pub lighting_ms: Option<f64>,
    /// GPU time of its shadow-mask pass, on the mask path.
    pub mask_ms: Option<f64>,
}

impl LightStats {
    /// Draw calls into its map, every layer together.
    pub fn shadow_draws(&self) -> u32 {
        self.layer_draws.iter().sum()
    }
}

/// What a depth-only baseline run measured and read.
struct BaselineRun {
    times: Option<crate::timing::FrameTimes>,
    /// The reported light's map, every layer, when asked for.
    shown_map: Option<Vec<f32>>,
    lights: usize,
}

/// A frame, as decided before recording.
struct FramePlan {
    camera: Camera,
    aspect: f32,
    /// Whether the lights' shadows go through the screen-space mask path.
    mask_path: bool,
    /// The reported light's index.
    shown: usize,
    plans: Vec<LightPlan>,
}

/// One light of a frame, as decided before recording.
struct LightPlan {
    name: String,
    light: Light,
    /// The render's settings with this light's shadow settings.
    settings: Settings,
    layout: ShadowLayout,
    filterable_map: Option<techniques::FilterableMap>,
    moment_format: wgpu::TextureFormat,
    light_gpu: LightGpu,
}

/// What a frame submitted: the CPU-side cost of drawing the scene.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawStats {
    /// Draw calls in the shadow pass.
    pub shadow_draws: u32,
    /// Draw calls in the lighting pass.
    pub lighting_draws: u32,
    /// Draw calls in the mask path's prepass.
    pub prepass_draws: u32,
    /// Pipeline changes, every pass together.
    pub pipeline_changes: u32,
    /// Bind group changes, every pass together.
    pub bind_group_changes: u32,
    /// Instances drawn into shadow maps, every layer of every light together.
    pub shadow_instances: u32,
    /// Instances the camera sees, drawn by the lighting pass.
    pub lighting_instances: u32,
}

impl DrawStats {
    fn add(&mut self, other: &DrawStats) {
        self.shadow_draws += other.shadow_draws;
        self.lighting_draws += other.lighting_draws;
        self.prepass_draws += other.prepass_draws;
        self.pipeline_changes += other.pipeline_changes;
        self.bind_group_changes += other.bind_group_changes;
        self.shadow_instances += other.shadow_instances;
        self.lighting_instances += other.lighting_instances;
    }
}

/// What a frame cost the CPU, in milliseconds: fitting the lights' projections,
/// culling (every layer and the camera, in parallel), and recording and submitting
/// the commands. `submit_ms` is the whole, from the call to the queue's submit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CpuTimings {
    pub plan_ms: f64,
    pub cull_ms: f64,
    pub record_ms: f64,
    pub submit_ms: f64,
}

/// What timing one frame measured: the summary, each pass, the draws and the CPU
/// cost ([`Renderer::time_passes`]).
#[derive(Clone, Debug)]
pub struct FrameCost {
    /// None only when the frame was not timed.
    pub timings: Option<PassTimings>,
    /// Each pass's time: every layer of every light's map, filters, screen-space
    /// passes and lighting.
    pub passes: Vec<PassTime>,
    pub stats: DrawStats,
    pub lights: Vec<LightStats>,
    pub cpu: CpuTimings,
}

/// GPU time per pass, in milliseconds, from timestamp queries; with many lights,
/// each kind of pass summed over the lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassTimings {
    pub shadow_ms: f64,
    /// The moment pass (encoding, blur, mipmaps) of the filterable techniques.
    pub filter_ms: Option<f64>,
    pub lighting_ms: f64,
    /// On the mask path: the depth-and-normal prepass, and the mask passes.
    pub prepass_ms: Option<f64>,
    pub mask_ms: Option<f64>,
    /// The whole frame on the GPU, from the first shadow pass's start to the last
    /// lighting pass's end (SDSM's prepass not included).
    pub frame_ms: f64,
    /// GPU timestamps, or the CPU wall clock where the adapter has none.
    pub source: TimingSource,
}

impl Frame {
    pub fn pixel_count(&self) -> usize {
        (self.width * self.height) as usize
    }

    /// The shadow layout this frame was drawn with, to draw others with it
    /// ([`OutputRequest::fixed_layout`]).
    pub fn shadow_layout(&self) -> ShadowLayout {
        ShadowLayout {
            projections: self.cascades.clone(),
            splits: self.cascade_splits.clone(),
            depth_clamp: self.shadow_depth_clamp,
        }
    }

    /// World size of one shadow texel at `world` (which must be in front of the light).
    pub fn shadow_texel_world_size(&self, world: Vec3) -> f32 {
        if let Light::Point(point) = self.light {
            if let [lower, upper] = self.cascades.as_slice() {
                // Dual paraboloids: the lower hemisphere holds y at or below the light.
                let hemisphere = if world.y <= point.position.y { lower } else { upper };
                let offset = hemisphere.light_from_world.transform_point3(world);
                return paraboloid_texel_world_size(offset, self.shadow_resolution);
            }
            return cube_texel_world_size(world - point.position, self.shadow_resolution);
        }
        let distance = -self.light_projection.light_from_world.transform_point3(world).z;
        self.light_projection.texel_world_size(self.shadow_resolution, distance)
    }
}

/// The renderer: pass pipelines and layouts, reused across frames.
pub struct Renderer<'g> {
    gpu: &'g Gpu,
    layouts: Layouts,
    shadow_pass: ShadowPass,
    lighting_pass: LightingPass,
    screen_space: ScreenSpacePass,
    moment_pass: MomentPass,
    depth_reduce: DepthReducePass,
    map_preview: MapPreviewPass,
    depth_baseline: DepthBaselinePass,
    compare_sampler: wgpu::Sampler,
    compare_nearest_sampler: wgpu::Sampler,
    gather_sampler: wgpu::Sampler,
    moment_sampler: wgpu::Sampler,
    /// Bound in place of a moment map for the depth-comparison techniques.
    placeholder_moments: wgpu::TextureView,
    /// Bound in place of a cube map for the lights that are not point lights.
    placeholder_cube: wgpu::TextureView,
    /// Bound in place of the shadow mask on the forward path and in the mask pass.
    placeholder_mask: wgpu::TextureView,
}

impl<'g> Renderer<'g> {
    pub fn new(gpu: &'g Gpu) -> Result<Self, RenderError> {
        gpu.checked("creating the renderer", || Self::new_unchecked(gpu))
    }

    fn new_unchecked(gpu: &'g Gpu) -> Self {
        let device = &gpu.device;
        let layouts = Layouts::new(device);
        let compare_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow compare"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            // Lit when the receiver's depth ≤ the stored occluder depth.
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let compare_nearest_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow compare, nearest"),
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let gather_sampler = device
            .create_sampler(&wgpu::SamplerDescriptor { label: Some("shadow gather"), ..Default::default() });
        let placeholder_cube = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("no cube map"),
                size: wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: 6 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: SHADOW_FORMAT,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
            .create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::Cube),
                ..Default::default()
            });
        let moment_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("moment map"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let placeholder_moments = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("no moment map"),
                size: wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
            .create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            });
        let placeholder_mask = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("no shadow mask"),
                size: wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: screen_space::MASK_FORMAT,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
            .create_view(&Default::default());
        Self {
            gpu,
            shadow_pass: ShadowPass::new(device, &layouts),
            lighting_pass: LightingPass::new(device, &layouts),
            screen_space: ScreenSpacePass::new(device, &layouts),
            moment_pass: MomentPass::new(device),
            depth_reduce: DepthReducePass::new(device),
            map_preview: MapPreviewPass::new(device),
            depth_baseline: DepthBaselinePass::new(device),
            layouts,
            compare_sampler,
            compare_nearest_sampler,
            gather_sampler,
            moment_sampler,
            placeholder_moments,
            placeholder_cube,
            placeholder_mask,
        }
    }

    pub fn gpu(&self) -> &Gpu {
        self.gpu
    }

    /// Uploads `scene` and renders it. To render one scene many times, upload it once
    /// with [`Renderer::upload`] and call [`Renderer::render_uploaded`].
    pub fn render(
        &mut self,
        scene: &Scene,
        settings: &Settings,
        request: &OutputRequest,
    ) -> Result<Frame, RenderError> {
        settings.validate()?;
        let uploaded = self.upload(scene)?;
        self.render_uploaded(&uploaded, scene, settings, request)
    }

    /// Uploads a scene's geometry, instances and textures.
    pub fn upload(&self, scene: &Scene) -> Result<GpuScene, RenderError> {
        GpuScene::upload(self.gpu, scene, &self.layouts)
    }

    /// Checks `settings` against the device's limits.
    pub fn check_limits(&self, settings: &Settings) -> Result<(), RenderError> {
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
        self.moment_format(settings)?;
        let needed = lighting::target_bytes_per_pixel();
        if limits.max_color_attachment_bytes_per_sample < needed {
            return Err(RenderError::AttachmentsTooLarge {
                available: limits.max_color_attachment_bytes_per_sample,
                needed,
                adapter,
            });
        }
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
    pub fn render_uploaded(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        request: &OutputRequest,
    ) -> Result<Frame, RenderError> {
        let submitted = self.submit(
            uploaded,
            scene,
            settings,
            true,
            request.shadow_map,
            request.fixed_layout.as_ref(),
            None,
        )?;
        self.read_frame(submitted, settings)
    }

    /// Renders an uploaded scene and leaves the image and the shadow map on the GPU,
    /// for a window to draw ([`LiveFrame`]).
    pub fn render_live(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
    ) -> Result<LiveFrame, RenderError> {
        let submitted = self.submit(uploaded, scene, settings, false, false, None, None)?;
        Ok(LiveFrame {
            color: submitted.color,
            shadow_map: submitted.shadow_map,
            camera: submitted.camera,
            light: submitted.light,
            layout: submitted.layout,
            timings: submitted.timings,
            stats: submitted.stats,
            lights: submitted.lights,
            shadow_mask: submitted.shadow_mask,
        })
    }

    /// The shadow map of `frame`, every layer side by side in grayscale (near black,
    /// far white; perspective layers linearized), each `tile` pixels square: an
    /// `Rgba8Unorm` texture for a UI to show.
    pub fn preview_shadow_map(&self, frame: &LiveFrame, tile: u32) -> Result<wgpu::Texture, RenderError> {
        let gpu = self.gpu;
        gpu.checked("drawing the shadow map preview", || {
            self.map_preview.draw(
                &gpu.device,
                &gpu.queue,
                &frame.shadow_map,
                &frame.layout.projections,
                tile.max(8),
            )
        })
    }

    /// Renders an uploaded scene for its pass times and draw counts alone: nothing is
    /// read back but the timestamps, so timing loops don't pay for image copies.
    pub fn time_passes(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        clock: ClockChoice,
    ) -> Result<FrameCost, RenderError> {
        let submitted = self.submit(uploaded, scene, settings, false, false, None, Some(clock))?;
        Ok(FrameCost {
            timings: submitted.timings,
            passes: submitted.passes,
            stats: submitted.stats,
            lights: submitted.lights,
            cpu: submitted.cpu,
        })
    }

    /// Uploads the depth-only baseline's geometry for `scene`: every caster flattened
    /// into world space ([`Renderer::time_depth_baseline`]).
    pub fn upload_depth_baseline(&self, scene: &Scene) -> Result<DepthBaselineScene, RenderError> {
        DepthBaselineScene::upload(self.gpu, scene)
    }

    /// Times the depth-only baseline drawing the shadow maps this frame would draw
    /// (the same layers, resolution, cull mode and depth clamp): per light, the time
    /// of all its layers; None for a dual-paraboloid map, which no matrix can draw.
    pub fn time_depth_baseline(
        &mut self,
        baseline: &DepthBaselineScene,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        clock: ClockChoice,
    ) -> Result<Vec<Option<f64>>, RenderError> {
        let run = self.record_depth_baseline(baseline, uploaded, scene, settings, Some(clock), false)?;
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
    /// (as [`ShadowMapImage::depth`] lays them out): to check that it draws what the
    /// shadow pass draws.
    pub fn depth_baseline_map(
        &mut self,
        baseline: &DepthBaselineScene,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
    ) -> Result<Vec<f32>, RenderError> {
        let run = self.record_depth_baseline(baseline, uploaded, scene, settings, None, true)?;
        run.shown_map.ok_or_else(|| RenderError::Gpu {
            during: "drawing the depth-only baseline",
            message: "a dual-paraboloid map has no baseline".into(),
        })
    }

    /// Records and submits the baseline's maps for the frame `settings` plans; returns
    /// their times (with `clock`), the reported light's first layer (if `read_shown`)
    /// and the number of lights.
    fn record_depth_baseline(
        &mut self,
        baseline: &DepthBaselineScene,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        clock: Option<ClockChoice>,
        read_shown: bool,
    ) -> Result<BaselineRun, RenderError> {
        settings.validate()?;
        self.check_limits(settings)?;
        let plan = self.plan_frame(uploaded, scene, settings, None)?;
        let gpu = self.gpu;
        let device = &gpu.device;
        let layers: u32 = plan.plans.iter().map(|p| p.layout.projections.len() as u32).sum();
        let (pending_times, pending_map) = gpu.checked("drawing the depth-only baseline", || {
            let mut clock = PassClock::new(gpu, layers, clock.is_some(), clock == Some(ClockChoice::Cpu));
            let mut encoder = device.create_command_encoder(&Default::default());
            let mut pending_map = None;
            for (index, light) in plan.plans.iter().enumerate() {
                let target = match depth_target(light) {
                    // No matrix draws a paraboloid: the baseline has none.
                    DepthTarget::Paraboloid => continue,
                    target @ (DepthTarget::Projected | DepthTarget::CubeFace) => target,
                };
                let resolution = light.settings.shadow.map.resolution;
                let count = light.layout.projections.len() as u32;
                let map = device.create_texture(&wgpu::TextureDescriptor {
                    label: Some("baseline depth"),
                    size: wgpu::Extent3d {
                        width: resolution,
                        height: resolution,
                        depth_or_array_layers: count,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: SHADOW_FORMAT,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                });
                for layer in 0..count {
                    let view = map.create_view(&wgpu::TextureViewDescriptor {
                        dimension: Some(wgpu::TextureViewDimension::D2),
                        base_array_layer: layer,
                        array_layer_count: Some(1),
                        ..Default::default()
                    });
                    let slot =
                        clock.begin(gpu, &mut encoder, PassKind::Shadow, Some(index as u32), Some(layer));
                    self.depth_baseline.record(
                        device,
                        &mut encoder,
                        baseline,
                        light.light_gpu.cascade_clip_from_world[layer as usize],
                        BaselineRaster {
                            bias: &light.settings.shadow.bias,
                            depth_range: DepthRange::clamped_if(light.layout.depth_clamp),
                            target,
                        },
                        &view,
                        clock.render_writes(slot),
                    );
                    clock.end(gpu, &mut encoder, slot);
                }
                if read_shown && index == plan.shown {
                    pending_map =
                        Some(readback::record(device, &mut encoder, &map, wgpu::TextureAspect::DepthOnly));
                }
            }
            let pending_times = clock.resolve(gpu, &mut encoder);
            gpu.queue.submit([encoder.finish()]);
            (pending_times, pending_map)
        })?;
        let times = pending_times.read(gpu)?;
        let map = match pending_map {
            Some(p) => Some(p.read::<f32>(gpu)?),
            None => None,
        };
        Ok(BaselineRun { times, shown_map: map, lights: plan.plans.len() })
    }

    /// Everything about a frame that is decided before recording: the camera, and
    /// each light's settings, layout (fitted, or `fixed_layout` for the reported
    /// light) and uniform.
    fn plan_frame(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        fixed_layout: Option<&ShadowLayout>,
    ) -> Result<FramePlan, RenderError> {
        let camera = settings.resolve_camera(scene)?;
        let resolved = settings.resolve_lights(scene)?;
        let mask_path = settings.uses_shadow_mask(&resolved)?;
        let shown = if settings.light.kind == LightKind::All { settings.light.light_index } else { 0 };
        let (width, height) = (settings.image.width, settings.image.height);
        let aspect = width as f32 / height as f32;
        let depth_clamp = self.gpu.device.features().contains(wgpu::Features::DEPTH_CLIP_CONTROL);

        // Everything about each light that is decided before recording.
        let mut plans = Vec::with_capacity(resolved.len());
        for (index, r) in resolved.into_iter().enumerate() {
            let light_settings = Settings { shadow: r.shadow.clone(), ..settings.clone() };
            self.check_limits(&light_settings)?;
            let shadow = &light_settings.shadow;
            let layout = match fixed_layout {
                Some(layout) if index == shown => layout.clone(),
                _ => {
                    let sampled = match (&r.light, shadow.partition, shadow.cascades.sdsm) {
                        (Light::Directional(sun), Partition::Cascades, true) => self.sample_distribution(
                            uploaded,
                            sun.direction,
                            &light_settings,
                            &camera,
                            aspect,
                        )?,
                        _ => None,
                    };
                    shadow_layout(
                        &uploaded.bounds,
                        &r.light,
                        &camera,
                        aspect,
                        &light_settings,
                        sampled.as_ref(),
                        depth_clamp,
                    )
                }
            };
            let technique = techniques::lookup(shadow.filter.technique);
            let filterable_map = technique.filterable_map(&shadow.filter);
            let moment_format = self.moment_format(&light_settings)?;
            let precision = match moment_format {
                wgpu::TextureFormat::Rgba16Float => techniques::MapPrecision::Half,
                _ => techniques::MapPrecision::Single,
            };
            let mut light_gpu = light_uniform(
                scene,
                &r.light,
                &layout,
                &light_settings,
                technique.params(&shadow.filter, precision),
                filterable_map,
            );
            if index > 0 {
                // Ambient light is added once, by the first light's pass.
                light_gpu.ambient = Vec4::ZERO;
            }
            plans.push(LightPlan {
                name: r.name,
                light: r.light,
                settings: light_settings,
                layout,
                filterable_map,
                moment_format,
                light_gpu,
            });
        }
        Ok(FramePlan { camera, aspect, mask_path, shown, plans })
    }

    /// Records and submits every light's shadow and lighting passes, copying the
    /// render targets (and the reported light's shadow map) out when asked, and reads
    /// the pass times: timestamps where the device has them, and with `clock`, the
    /// CPU wall clock where it has none.
    #[allow(clippy::too_many_arguments)]
    fn submit(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        read_images: bool,
        read_shadow_map: bool,
        fixed_layout: Option<&ShadowLayout>,
        clock: Option<ClockChoice>,
    ) -> Result<Submitted, RenderError> {
        let started = Instant::now();
        settings.validate()?;
        self.check_limits(settings)?;
        let FramePlan { camera, aspect, mask_path, shown, mut plans } =
            self.plan_frame(uploaded, scene, settings, fixed_layout)?;
        let (width, height) = (settings.image.width, settings.image.height);

        let clip_from_view = camera.clip_from_view(aspect);
        let camera_gpu = CameraGpu {
            clip_from_world: camera.clip_from_world(aspect),
            view_from_world: camera.view_from_world(),
            world_from_view: camera.view_from_world().inverse(),
            eye: camera.eye.extend(1.0),
            debug: Vec4::new((settings.image.debug_view == DebugView::Cascades) as u8 as f32, 0.0, 0.0, 0.0),
            projection: Vec4::new(clip_from_view.x_axis.x, clip_from_view.y_axis.y, camera.near, camera.far),
            viewport: Vec4::new(width as f32, height as f32, 1.0 / width as f32, 1.0 / height as f32),
        };

        let planned = Instant::now();

        // Cull for every layer of every light, and for the camera, in parallel.
        let camera_view = CullView {
            frustum: Frustum::from_clip_from_world(camera.clip_from_world(aspect)),
            near: true,
            casters_only: false,
        };
        let layer_views = plans.iter().flat_map(|plan| {
            plan.layout.projections.iter().map(|projection| CullView {
                frustum: Frustum::from_clip_from_world(projection.clip_from_world()),
                // A pass that clamps depth draws the casters before its near plane too.
                near: !plan.layout.depth_clamp,
                casters_only: true,
            })
        });
        let views: Vec<CullView> = std::iter::once(camera_view).chain(layer_views).collect();
        let mut culled = uploaded.cull(&views).into_iter();
        let camera_visible = culled.next().expect("the camera's view was culled");
        let layer_visible: Vec<Vec<Visible>> =
            plans.iter().map(|plan| culled.by_ref().take(plan.layout.projections.len()).collect()).collect();
        let cull_done = Instant::now();

        let gpu = self.gpu;
        let device = &gpu.device;
        // Every layer of every light, each light's filter, mask and lighting, and the prepass.
        let timed_passes = plans.iter().map(|p| p.layout.projections.len() as u32 + 3).sum::<u32>() + 1;
        let (pending, shadow_pending, pending_times, stats, color, shown_map, submitted_at) =
            gpu.checked("rendering the frame", || {
                let camera_buffer = uniform_buffer(device, "camera", &camera_gpu);
                let camera_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("camera"),
                    layout: &self.layouts.camera,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: camera_buffer.as_entire_binding(),
                    }],
                });
                let mut clock =
                    PassClock::new(gpu, timed_passes, clock.is_some(), clock == Some(ClockChoice::Cpu));
                let mut encoder = device.create_command_encoder(&Default::default());
                let mut stats = DrawStats::default();
                let mut shadow_pending = None;
                let mut shown_map = None;
                // On the mask path, one layer of the mask per light.
                let mask_layers: Vec<wgpu::TextureView> = if mask_path {
                    let mask = device.create_texture(&wgpu::TextureDescriptor {
                        label: Some("shadow mask"),
                        size: wgpu::Extent3d { width, height, depth_or_array_layers: plans.len() as u32 },
                        mip_level_count: 1,
                        sample_count: 1,
                        dimension: wgpu::TextureDimension::D2,
                        format: screen_space::MASK_FORMAT,
                        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                        view_formats: &[],
                    });
                    (0..plans.len() as u32)
                        .map(|layer| {
                            mask.create_view(&wgpu::TextureViewDescriptor {
                                dimension: Some(wgpu::TextureViewDimension::D2),
                                base_array_layer: layer,
                                array_layer_count: Some(1),
                                ..Default::default()
                            })
                        })
                        .collect()
                } else {
                    Vec::new()
                };
                // Each light's shadow map(s), then its bind groups for the lighting pass
                // (and on the mask path, for its mask pass).
                let mut lit = Vec::with_capacity(plans.len());
                for (index, plan) in plans.iter().enumerate() {
                    let shadow_map = self.record_shadow_maps(
                        &mut encoder,
                        uploaded,
                        plan,
                        &layer_visible[index],
                        &mut clock,
                        index as u32,
                        &mut stats,
                    );
                    if index == shown {
                        shown_map = Some(shadow_map.clone());
                    }
                    if read_shadow_map && index == shown {
                        shadow_pending = Some(readback::record(
                            device,
                            &mut encoder,
                            &shadow_map,
                            wgpu::TextureAspect::DepthOnly,
                        ));
                    }
                    let (light_buffer, scene_group) = self.scene_group(uploaded, &plan.light_gpu);
                    let shadow_view = shadow_map.create_view(&wgpu::TextureViewDescriptor {
                        dimension: Some(wgpu::TextureViewDimension::D2Array),
                        ..Default::default()
                    });
                    let shadow = &plan.settings.shadow;
                    let moment_map = plan.filterable_map.map(|map| {
                        let slot = clock.begin(gpu, &mut encoder, PassKind::Filter, Some(index as u32), None);
                        let moment_map = self.moment_pass.record(
                            device,
                            &mut encoder,
                            shadow.filter.technique,
                            map,
                            &shadow.filter.moments,
                            plan.moment_format,
                            shadow.map.resolution,
                            plan.layout.projections.len() as u32,
                            &shadow_view,
                            &light_buffer,
                            clock.compute_writes(slot),
                        );
                        clock.end(gpu, &mut encoder, slot);
                        moment_map
                    });
                    let lookup = lookup_of(plan);
                    let cube_view = (lookup == Lookup::Cube).then(|| {
                        shadow_map.create_view(&wgpu::TextureViewDescriptor {
                            dimension: Some(wgpu::TextureViewDimension::Cube),
                            ..Default::default()
                        })
                    });
                    let moment_view = moment_map.as_ref().map_or(&self.placeholder_moments, |m| &m.view);
                    let shadow_group = |mask: &wgpu::TextureView| {
                        device.create_bind_group(&wgpu::BindGroupDescriptor {
                            label: Some("shadow map"),
                            layout: &self.layouts.shadow,
                            entries: &[
                                wgpu::BindGroupEntry {
                                    binding: 0,
                                    resource: wgpu::BindingResource::TextureView(&shadow_view),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 1,
                                    resource: wgpu::BindingResource::Sampler(&self.compare_sampler),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 2,
                                    resource: wgpu::BindingResource::TextureView(moment_view),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 3,
                                    resource: wgpu::BindingResource::Sampler(&self.moment_sampler),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 4,
                                    resource: wgpu::BindingResource::TextureView(
                                        cube_view.as_ref().unwrap_or(&self.placeholder_cube),
                                    ),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 5,
                                    resource: wgpu::BindingResource::Sampler(&self.compare_nearest_sampler),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 6,
                                    resource: wgpu::BindingResource::Sampler(&self.gather_sampler),
                                },
                                wgpu::BindGroupEntry {
                                    binding: 7,
                                    resource: wgpu::BindingResource::TextureView(mask),
                                },
                            ],
                        })
                    };
                    // The mask pass writes the layer its light's lighting pass reads.
                    let (lighting_group, mask_group) = match mask_layers.get(index) {
                        Some(layer) => (shadow_group(layer), Some(shadow_group(&self.placeholder_mask))),
                        None => (shadow_group(&self.placeholder_mask), None),
                    };
                    lit.push((scene_group, lighting_group, mask_group, lookup));
                }

                let targets: Vec<wgpu::Texture> = lighting::TARGETS
                    .iter()
                    .map(|&format| {
                        render_target(
                            device,
                            width,
                            height,
                            format,
                            wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::TEXTURE_BINDING,
                        )
                    })
                    .collect();
                let target_views: Vec<wgpu::TextureView> =
                    targets.iter().map(|t| t.create_view(&Default::default())).collect();
                let depth = render_target(
                    device,
                    width,
                    height,
                    lighting::DEPTH_FORMAT,
                    wgpu::TextureUsages::empty(),
                );
                let depth_view = depth.create_view(&Default::default());
                if mask_path {
                    self.record_screen_space(
                        &mut encoder,
                        uploaded,
                        &camera_visible,
                        &plans,
                        &lit,
                        &camera_buffer,
                        &camera_group,
                        &depth_view,
                        &mask_layers,
                        &mut clock,
                        &mut stats,
                    );
                }
                for (index, (plan, (scene_group, shadow_group, _, lookup))) in
                    plans.iter().zip(&lit).enumerate()
                {
                    let first = index == 0;
                    let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = target_views
                        .iter()
                        .enumerate()
                        .map(|(i, view)| {
                            // The colour image gets an opaque sky; the data targets zero
                            // (object id 0 marks background). Later lights add to them.
                            let clear = if i == 0 { SKY } else { wgpu::Color::TRANSPARENT };
                            Some(wgpu::RenderPassColorAttachment {
                                view,
                                depth_slice: None,
                                resolve_target: None,
                                ops: wgpu::Operations {
                                    load: if first { wgpu::LoadOp::Clear(clear) } else { wgpu::LoadOp::Load },
                                    store: wgpu::StoreOp::Store,
                                },
                            })
                        })
                        .collect();
                    let last = index + 1 == plans.len();
                    let slot = clock.begin(gpu, &mut encoder, PassKind::Lighting, Some(index as u32), None);
                    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                        label: Some("lighting"),
                        color_attachments: &attachments,
                        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                            view: &depth_view,
                            depth_ops: Some(wgpu::Operations {
                                load: if first && !mask_path {
                                    wgpu::LoadOp::Clear(1.0)
                                } else {
                                    wgpu::LoadOp::Load
                                },
                                store: if last { wgpu::StoreOp::Discard } else { wgpu::StoreOp::Store },
                            }),
                            stencil_ops: None,
                        }),
                        timestamp_writes: clock.render_writes(slot),
                        occlusion_query_set: None,
                        multiview_mask: None,
                    });
                    let key = LightingKey {
                        technique: plan.settings.shadow.filter.technique,
                        lookup: if mask_path { Lookup::Mask } else { *lookup },
                        role: if first {
                            LightingRole::First
                        } else {
                            LightingRole::Added { visibility: index == shown }
                        },
                    };
                    pass.set_pipeline(self.lighting_pass.pipeline(device, key));
                    pass.set_bind_group(0, scene_group, &[]);
                    pass.set_bind_group(1, &camera_group, &[]);
                    pass.set_bind_group(2, shadow_group, &[]);
                    stats.pipeline_changes += 1;
                    stats.bind_group_changes += 3;
                    let (draws, binds) = uploaded.draw_visible(&mut pass, &camera_visible, 3);
                    stats.lighting_draws += draws;
                    stats.lighting_instances += camera_visible.instances();
                    stats.bind_group_changes += binds;
                    drop(pass);
                    clock.end(gpu, &mut encoder, slot);
                }
                let pending: Vec<_> = if read_images {
                    targets
                        .iter()
                        .map(|t| readback::record(device, &mut encoder, t, wgpu::TextureAspect::All))
                        .collect()
                } else {
                    Vec::new()
                };
                let pending_times = clock.resolve(gpu, &mut encoder);
                gpu.queue.submit([encoder.finish()]);
                let submitted_at = Instant::now();
                let shown_map = shown_map.expect("the reported light is one of the lights");
                (pending, shadow_pending, pending_times, stats, targets[0].clone(), shown_map, submitted_at)
            })?;
        let cpu = CpuTimings {
            plan_ms: (planned - started).as_secs_f64() * 1e3,
            cull_ms: (cull_done - planned).as_secs_f64() * 1e3,
            record_ms: (submitted_at - cull_done).as_secs_f64() * 1e3,
            submit_ms: (submitted_at - started).as_secs_f64() * 1e3,
        };

        let times = pending_times.read(gpu)?;
        let passes = times.as_ref().map_or_else(Vec::new, |t| t.passes.clone());
        let time_of = |kind: PassKind, light: usize| -> Option<f64> {
            let mut matching =
                passes.iter().filter(|p| p.kind == kind && p.light == Some(light as u32)).peekable();
            matching.peek()?;
            Some(matching.map(|p| p.ms).sum())
        };
        let lights: Vec<LightStats> = plans
            .iter()
            .zip(&layer_visible)
            .enumerate()
            .map(|(index, (plan, layers))| LightStats {
                name: plan.name.clone(),
                kind: plan.light.type_name(),
                technique: plan.settings.shadow.filter.technique,
                resolution: plan.settings.shadow.map.resolution,
                layer_draws: layers.iter().map(|v| v.runs.len() as u32).collect(),
                layer_instances: layers.iter().map(Visible::instances).collect(),
                layer_ms: passes
                    .iter()
                    .filter(|p| p.kind == PassKind::Shadow && p.light == Some(index as u32))
                    .map(|p| p.ms)
                    .collect(),
                shadow_ms: time_of(PassKind::Shadow, index),
                filter_ms: time_of(PassKind::Filter, index),
                lighting_ms: time_of(PassKind::Lighting, index),
                mask_ms: time_of(PassKind::Mask, index),
            })
            .collect();
        let timings = times.as_ref().map(|t| {
            let sum = |f: fn(&LightStats) -> Option<f64>| lights.iter().filter_map(f).sum::<f64>();
            let any = |f: fn(&LightStats) -> Option<f64>| lights.iter().any(|l| f(l).is_some());
            PassTimings {
                shadow_ms: sum(|l| l.shadow_ms),
                filter_ms: any(|l| l.filter_ms).then(|| sum(|l| l.filter_ms)),
                lighting_ms: sum(|l| l.lighting_ms),
                prepass_ms: passes.iter().find(|p| p.kind == PassKind::Prepass).map(|p| p.ms),
                mask_ms: any(|l| l.mask_ms).then(|| sum(|l| l.mask_ms)),
                frame_ms: t.frame_ms,
                source: t.source,
            }
        });
        let plan = plans.swap_remove(shown);
        Ok(Submitted {
            pending,
            shadow_pending,
            color,
            shadow_map: shown_map,
            timings,
            passes,
            cpu,
            stats,
            lights,
            camera,
            light: plan.light,
            resolution: plan.settings.shadow.map.resolution,
            layout: plan.layout,
            moment_format: plan.filterable_map.is_some().then_some(plan.moment_format),
            shadow_mask: mask_path,
        })
    }

    /// Draws a light's shadow map, one depth pass per layer (cascade or cube face),
    /// each drawing the casters culled for that layer (`layers`), each timed alone.
    /// Returns the map.
    #[allow(clippy::too_many_arguments)]
    fn record_shadow_maps(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        plan: &LightPlan,
        layers: &[Visible],
        clock: &mut PassClock,
        light_index: u32,
        stats: &mut DrawStats,
    ) -> wgpu::Texture {
        let gpu = self.gpu;
        let device = &gpu.device;
        let resolution = plan.settings.shadow.map.resolution;
        let target = depth_target(plan);
        let shadow_map = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow map"),
            size: wgpu::Extent3d {
                width: resolution,
                height: resolution,
                depth_or_array_layers: layers.len() as u32,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: SHADOW_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        for (layer, visible) in layers.iter().enumerate() {
            let layer_light =
                LightGpu { clip_from_world: plan.light_gpu.cascade_clip_from_world[layer], ..plan.light_gpu };
            let (_, layer_group) = self.scene_group(uploaded, &layer_light);
            let layer_view = shadow_map.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: layer as u32,
                array_layer_count: Some(1),
                ..Default::default()
            });
            let slot = clock.begin(gpu, encoder, PassKind::Shadow, Some(light_index), Some(layer as u32));
            let drawn = self.record_depth_pass(
                encoder,
                uploaded,
                &plan.settings,
                &layer_group,
                &layer_view,
                visible,
                target,
                plan.layout.depth_clamp,
                clock.render_writes(slot),
            );
            clock.end(gpu, encoder, slot);
            stats.add(&drawn);
        }
        shadow_map
    }

    /// The mask path's screen-space passes: the depth-and-normal prepass into `depth`,
    /// then each light's mask pass into its layer of the mask.
    #[allow(clippy::too_many_arguments)]
    fn record_screen_space(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        camera_visible: &Visible,
        plans: &[LightPlan],
        lit: &[LitGroups],
        camera_buffer: &wgpu::Buffer,
        camera_group: &wgpu::BindGroup,
        depth: &wgpu::TextureView,
        mask_layers: &[wgpu::TextureView],
        clock: &mut PassClock,
        stats: &mut DrawStats,
    ) {
        let gpu = self.gpu;
        let device = &gpu.device;
        let (width, height) = (depth.texture().width(), depth.texture().height());
        let prepass_target =
            |format| render_target(device, width, height, format, wgpu::TextureUsages::TEXTURE_BINDING);
        let normals = prepass_target(screen_space::NORMALS_FORMAT).create_view(&Default::default());
        let view_depth = prepass_target(screen_space::VIEW_DEPTH_FORMAT).create_view(&Default::default());
        {
            let cleared = |view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    // View depth 0 marks the background.
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })
            };
            let slot = clock.begin(gpu, encoder, PassKind::Prepass, None, None);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("prepass"),
                color_attachments: &[cleared(&normals), cleared(&view_depth)],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: clock.render_writes(slot),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(self.screen_space.prepass());
            // The light plays no part in the prepass; any light's group carries the
            // instances.
            pass.set_bind_group(0, &lit[0].0, &[]);
            pass.set_bind_group(1, camera_group, &[]);
            stats.pipeline_changes += 1;
            stats.bind_group_changes += 2;
            let (draws, binds) = uploaded.draw_visible(&mut pass, camera_visible, 3);
            stats.prepass_draws += draws;
            stats.bind_group_changes += binds;
            drop(pass);
            clock.end(gpu, encoder, slot);
        }
        let screen_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("screen"),
            layout: &self.layouts.screen,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: camera_buffer.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&view_depth),
                },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&normals) },
            ],
        });
        for (index, ((plan, (scene_group, _, mask_group, lookup)), layer)) in
            plans.iter().zip(lit).zip(mask_layers).enumerate()
        {
            let mask_group = mask_group.as_ref().expect("a mask pass group on the mask path");
            let slot = clock.begin(gpu, encoder, PassKind::Mask, Some(index as u32), None);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow mask"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: layer,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::WHITE),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: clock.render_writes(slot),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let key = MaskKey { technique: plan.settings.shadow.filter.technique, lookup: *lookup };
            pass.set_pipeline(self.screen_space.mask(device, key));
            pass.set_bind_group(0, scene_group, &[]);
            pass.set_bind_group(1, &screen_group, &[]);
            pass.set_bind_group(2, mask_group, &[]);
            stats.pipeline_changes += 1;
            stats.bind_group_changes += 3;
            pass.draw(0..3, 0..1);
            drop(pass);
            clock.end(gpu, encoder, slot);
        }
    }

    /// Reads a submitted frame's images back and assembles the [`Frame`].
    fn read_frame(&self, submitted: Submitted, settings: &Settings) -> Result<Frame, RenderError> {
        let gpu = self.gpu;
        let Submitted {
            pending,
            shadow_pending,
            color: _,
            shadow_map: _,
            timings,
            passes: _,
            cpu: _,
            stats,
            lights,
            camera,
            light,
            resolution,
            layout,
            moment_format,
            shadow_mask,
        } = submitted;
        let (width, height) = (settings.image.width, settings.image.height);
        let mut pending = pending.into_iter();
        let mut next = || pending.next().expect("one readback per target");
        let color: Vec<u8> = next().read(gpu)?;
        let mut visibility: Vec<f32> = next().read(gpu)?;
        let position_w: Vec<Vec4> = next().read(gpu)?;
        let normal_w: Vec<Vec4> = next().read(gpu)?;
        let object_id: Vec<u32> = next().read(gpu)?;
        let shadow_map = match shadow_pending {
            Some(p) => {
                let depth: Vec<f32> = p.read(gpu)?;
                let layers = (depth.len() / (resolution * resolution) as usize) as u32;
                Some(ShadowMapImage { resolution, layers, depth })
            }
            None => None,
        };

        // Background pixels get NaN, as documented, decided by the object id (0).
        let nan3 = Vec3::splat(f32::NAN);
        let mut position = Vec::with_capacity(position_w.len());
        let mut depth = Vec::with_capacity(position_w.len());
        for (i, p) in position_w.iter().enumerate() {
            if object_id[i] == 0 {
                visibility[i] = f32::NAN;
                position.push(nan3);
                depth.push(f32::NAN);
            } else {
                position.push(p.truncate());
                depth.push(p.w);
            }
        }
        let normal = normal_w
            .iter()
            .zip(&object_id)
            .map(|(n, &id)| if id == 0 { nan3 } else { n.truncate() })
            .collect();
        Ok(Frame {
            width,
            height,
            color,
            visibility,
            position,
            normal,
            depth,
            object_id,
            camera,
            light,
            light_projection: layout.projections[0],
            cascades: layout.projections,
            cascade_splits: layout.splits,
            shadow_depth_clamp: layout.depth_clamp,
            shadow_resolution: resolution,
            shadow_map,
            timings,
            stats,
            lights,
            moment_format,
            shadow_mask,
        })
    }

    /// SDSM's sample distribution: draws the scene's depth from the camera and
    /// reduces it on the GPU to the nearest and farthest view depth seen, then, with
    /// --sdsm-bounds, to each cascade's light-space bounds of the samples it serves.
    /// Blocks on the results, which the cascades' fit needs before the shadow pass.
    fn sample_distribution(
        &mut self,
        uploaded: &GpuScene,
        sun_direction: Vec3,
        settings: &Settings,
        camera: &Camera,
        aspect: f32,
    ) -> Result<Option<SampleDistribution>, RenderError> {
        let gpu = self.gpu;
        let device = &gpu.device;
        let (depth, pending) = gpu.checked("reducing the camera's depth (SDSM)", || {
            let (width, height) = (settings.image.width, settings.image.height);
            let depth = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("camera depth prepass"),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: SHADOW_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            });
            // The shadow pass's pipelines draw it, with the camera's projection and no
            // bias, receivers that cast no shadow included.
            let camera_as_light =
                LightGpu { clip_from_world: camera.clip_from_world(aspect), ..Default::default() };
            let (_, group) = self.scene_group(uploaded, &camera_as_light);
            let mut prepass = settings.clone();
            prepass.shadow.bias = BiasSettings::none();
            let mut encoder = device.create_command_encoder(&Default::default());
            let seen = uploaded.cull(&[CullView {
                frustum: Frustum::from_clip_from_world(camera.clip_from_world(aspect)),
                near: true,
                casters_only: false,
            }]);
            self.record_depth_pass(
                &mut encoder,
                uploaded,
                &prepass,
                &group,
                &depth.create_view(&Default::default()),
                &seen[0],
                DepthTarget::Projected,
                false,
                None,
            );
            let pending = self.depth_reduce.record(device, &mut encoder, &depth, camera.near, camera.far);
            gpu.queue.submit([encoder.finish()]);
            (depth, pending)
        })?;
        let Some((near, far)) = pending.read(gpu)? else { return Ok(None) };
        let c = &settings.shadow.cascades;
        let light_bounds = match cascade_splits(&uploaded.bounds, camera, aspect, settings, Some((near, far)))
        {
            Some(splits) if c.sdsm_bounds => {
                let blend = match c.cascade_selection {
                    CascadeSelection::Depth => c.cascade_blend,
                    CascadeSelection::Projection => 0.0,
                };
                let request = BoundsRequest {
                    world_from_clip: camera.clip_from_world(aspect).inverse(),
                    light_from_world: directional_light_view(sun_direction, &uploaded.bounds),
                    near: camera.near,
                    far: camera.far,
                    splits: &splits,
                    blend,
                };
                let pending = gpu.checked("bounding the camera's samples in light space (SDSM)", || {
                    let mut encoder = device.create_command_encoder(&Default::default());
                    let pending = self.depth_reduce.record_bounds(device, &mut encoder, &depth, &request);
                    gpu.queue.submit([encoder.finish()]);
                    pending
                })?;
                Some(pending.read(gpu)?)
            }
            _ => None,
        };
        Ok(Some(SampleDistribution { near, far, light_bounds }))
    }

    /// Group 0 of the geometry passes: the instances and a uniform buffer holding
    /// `light` (returned too, for the passes that bind it elsewhere).
    fn scene_group(&self, uploaded: &GpuScene, light: &LightGpu) -> (wgpu::Buffer, wgpu::BindGroup) {
        let buffer = uniform_buffer(&self.gpu.device, "light", light);
        let group = self.gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout: &self.layouts.scene,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uploaded.instances.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: buffer.as_entire_binding() },
            ],
        });
        (buffer, group)
    }

    /// Records a depth-only pass through `scene_group`'s projection with the shadow
    /// pipelines, drawing the runs `visible` holds: a shadow-map layer's casters, or
    /// what the camera sees for SDSM's prepass. `unclipped` clamps depth instead of
    /// clipping it. Returns the stats of what it recorded.
    #[allow(clippy::too_many_arguments)]
    fn record_depth_pass(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        settings: &Settings,
        scene_group: &wgpu::BindGroup,
        shadow_view: &wgpu::TextureView,
        visible: &Visible,
        target: DepthTarget,
        unclipped: bool,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites>,
    ) -> DrawStats {
        let device = &self.gpu.device;
        let shadow = &settings.shadow;
        let mut stats = DrawStats::default();
        let mut pass = begin_depth_pass(encoder, "shadow", shadow_view, timestamp_writes);
        pass.set_bind_group(0, scene_group, &[]);
        stats.bind_group_changes += 1;
        // The runs come opaque first (no bind group changes at all), then the
        // alpha-masked ones, texture by texture: the pipeline and the material's bind
        // group change only between batches that need it.
        let mut pipeline: Option<ShadowPipelineKey> = None;
        let mut stream: Option<VertexStream> = None;
        let mut bound = None;
        for (batch, run) in &visible.runs {
            let batch = &uploaded.batches[*batch as usize];
            let key = ShadowPipelineKey::new(
                &shadow.bias,
                if batch.double_sided { Sides::Double } else { Sides::Single },
                if batch.masked { Coverage::Masked } else { Coverage::Opaque },
                DepthRange::clamped_if(unclipped),
                target,
            );
            if pipeline != Some(key) {
                let wanted = ShadowPipelineShape::of(&key).stream;
                match stream {
                    None => uploaded.bind_geometry(&mut pass, wanted),
                    Some(bound_stream) if bound_stream != wanted => uploaded.bind_stream(&mut pass, wanted),
                    Some(_) => {}
                }
                stream = Some(wanted);
                pass.set_pipeline(self.shadow_pass.pipeline(device, &key));
                pipeline = Some(key);
                stats.pipeline_changes += 1;
            }
            if batch.masked && bound != Some(batch.material_group) {
                pass.set_bind_group(1, &uploaded.material_groups[batch.material_group], &[]);
                bound = Some(batch.material_group);
                stats.bind_group_changes += 1;
            }
            GpuScene::draw_run(&mut pass, batch, run.clone());
            stats.shadow_draws += 1;
            stats.shadow_instances += run.end - run.start;
        }
        stats
    }
}

fn uniform_buffer<T: bytemuck::Pod>(device: &wgpu::Device, label: &str, contents: &T) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::bytes_of(contents),
        usage: wgpu::BufferUsages::UNIFORM,
    })
}

/// Background colour of the image, linear RGB.
const SKY: wgpu::Color = wgpu::Color { r: 0.42, g: 0.55, b: 0.72, a: 1.0 };

/// A light's bind groups for its passes from the camera: the scene (with its light),
/// the lighting pass's shadow group, the mask pass's (on the mask path), and how its
/// map is looked up.
type LitGroups = (wgpu::BindGroup, wgpu::BindGroup, Option<wgpu::BindGroup>, Lookup);

/// A frame submitted to the GPU, waiting to be read back.
struct Submitted {
    pending: Vec<readback::PendingReadback>,
    shadow_pending: Option<readback::PendingReadback>,
    /// The colour target and the reported light's shadow map, for [`LiveFrame`].
    color: wgpu::Texture,
    shadow_map: wgpu::Texture,
    timings: Option<PassTimings>,
    passes: Vec<PassTime>,
    cpu: CpuTimings,
    stats: DrawStats,
    lights: Vec<LightStats>,
    camera: Camera,
    /// The reported light, its map's resolution, layout and moment format.
    light: Light,
    resolution: u32,
    layout: ShadowLayout,
    moment_format: Option<wgpu::TextureFormat>,
    shadow_mask: bool,
}

/// A camera-sized attachment, with `usage` besides being rendered to (copied out for
/// a readback, or sampled by a later pass).
fn render_target(
    device: &wgpu::Device,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("render target"),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | usage,
        view_formats: &[],
    })
}

/// What a light's shadow pass stores.
fn depth_target(plan: &LightPlan) -> DepthTarget {
    match (plan.light, plan.settings.shadow.map.omni) {
        (Light::Point(_), OmniMap::Cube) => DepthTarget::CubeFace,
        (Light::Point(_), OmniMap::Paraboloid) => DepthTarget::Paraboloid,
        (Light::Directional(_) | Light::Spot(_), _) => DepthTarget::Projected,
    }
}

/// How the lighting pass looks a light's map up.
fn lookup_of(plan: &LightPlan) -> Lookup {
    match (plan.light, plan.settings.shadow.map.omni) {
        (Light::Point(_), OmniMap::Cube) => Lookup::Cube,
        (Light::Point(_), OmniMap::Paraboloid) => Lookup::Paraboloid,
        _ => Lookup::Map,
    }
}

fn light_uniform(
    scene: &Scene,
    light: &Light,
    layout: &ShadowLayout,
    settings: &Settings,
    params: [Vec4; 2],
    filterable_map: Option<techniques::FilterableMap>,
) -> LightGpu {
    let projection = &layout.projections[0];
    let resolution = settings.shadow.map.resolution;
    let mut cascade_clip_from_world = [projection.clip_from_world(); MAX_CASCADES];
    let mut cascade_texel = [Vec4::ZERO; MAX_CASCADES];
    for (i, p) in layout.projections.iter().enumerate() {
        cascade_clip_from_world[i] = p.clip_from_world();
        // y flags a warped layer, whose texel size the shader measures locally, by
        // differences z world units apart (about a texel at the far edge).
        let warped = matches!(p.kind, ProjectionKind::Warped { .. });
        let texel = p.texel_size_coefficients(resolution).0;
        cascade_texel[i] = Vec4::new(texel, warped as u8 as f32, texel, 0.0);
    }
    let mut splits = [0.0f32; 12];
    for (slot, z) in splits.iter_mut().zip(&layout.splits) {
        *slot = z.min(f32::MAX);
    }
    let c = &settings.shadow.cascades;
    let (texel_ortho, texel_per_distance) = projection.texel_size_coefficients(resolution);
    let f = &settings.shadow.filter;
    let contact = &settings.shadow.contact;
    // PCSS's light size, the same quantity the reference's area light uses.
    let light_size = match light {
        Light::Directional(sun) => (0.5 * sun.angular_diameter_degrees.to_radians()).tan(),
        Light::Spot(spot) => spot.radius,
        Light::Point(point) => point.radius,
    };
    let common = LightGpu {
        clip_from_world: projection.clip_from_world(),
        light_from_world: projection.light_from_world,
        texel: Vec4::new(
            texel_ortho,
            texel_per_distance,
            settings.shadow.bias.normal_offset,
            resolution as f32,
        ),
        kernel: Vec4::new(
            f.pcf_kernel,
            (f.kernel_unit == KernelUnit::World) as u8 as f32,
            f.poisson_samples.min(techniques::POISSON_DISK_SIZE as u32) as f32,
            f.receiver_plane_bias as u8 as f32,
        ),
        pcss: Vec4::new(
            light_size,
            f.pcss.blocker_samples.min(techniques::POISSON_DISK_SIZE as u32) as f32,
            f.pcss.max_radius,
            0.0,
        ),
        params,
        ambient: scene.ambient.extend(0.0),
        cascade_clip_from_world,
        cascade_texel,
        cascade_splits: [
            Vec4::from_slice(&splits[0..4]),
            Vec4::from_slice(&splits[4..8]),
            Vec4::from_slice(&splits[8..12]),
        ],
        cascades: Vec4::new(
            layout.projections.len() as f32,
            (c.cascade_selection == CascadeSelection::Projection) as u8 as f32,
            c.cascade_blend,
            filterable_map.map_or(1, |m| m.layers) as f32,
        ),
        cone: Vec4::new(1.0, -1.0, projection.near, projection.far),
        raster_bias: Vec4::new(
            settings.shadow.bias.depth_bias as f32,
            settings.shadow.bias.slope_bias,
            0.0,
            0.0,
        ),
        contact: if contact.contact_shadows {
            Vec4::new(
                contact.contact_length,
                contact.contact_steps as f32,
                contact.contact_thickness,
                contact.contact_bias,
            )
        } else {
            Vec4::ZERO
        },
        contact_range: Vec4::new(contact.contact_distance, 0.0, 0.0, 0.0),
        ..Default::default()
    };
    match light {
        Light::Directional(sun) => LightGpu {
            radiance: (sun.color * sun.intensity).extend(0.0),
            direction: sun.direction.normalize().extend(0.0),
            ..common
        },
        Light::Spot(spot) => LightGpu {
            radiance: (spot.color * spot.intensity).extend(0.0),
            direction: spot.direction.normalize().extend(1.0),
            position: spot.position.extend(spot.range),
            cone: Vec4::new(
                spot.inner_angle_degrees.to_radians().cos(),
                spot.outer_angle_degrees.to_radians().cos(),
                projection.near,
                projection.far,
            ),
            ..common
        },
        Light::Point(point) => {
            let lit = LightGpu {
                radiance: (point.color * point.intensity).extend(0.0),
                direction: Vec4::new(0.0, 0.0, 0.0, 2.0),
                position: point.position.extend(point.range),
                ..common
            };
            if settings.shadow.map.omni == OmniMap::Cube {
                return lit;
            }
            // The paraboloid passes read each hemisphere's frame, not a projection;
            // its texels are 4 / resolution radians wide on the axis, the largest.
            let mut frames = lit.cascade_clip_from_world;
            for (frame, p) in frames.iter_mut().zip(&layout.projections) {
                *frame = p.light_from_world;
            }
            LightGpu {
                cascade_clip_from_world: frames,
                cascade_texel: [Vec4::ZERO; MAX_CASCADES],
                texel: Vec4::new(0.0, 4.0 / resolution as f32, lit.texel.z, lit.texel.w),
                ..lit
            }
        }
    }
}

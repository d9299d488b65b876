//! Recording a frame: culling every layer and the camera, then each light's shadow
//! maps (one depth pass per layer) and moment map, the screen-space passes on the
//! mask path, and each light's lighting pass, into one command buffer. Every
//! resource comes from the renderer's pool.

use std::time::Instant;

use gnomon_math::screen_bounds::Viewport;
use gnomon_scene::{
    Scene, Settings,
    settings::{Lighting, Refine},
};

use super::{
    Renderer,
    bindings::{ShadowViews, scene_group},
    cull::{Culled, cull},
    light_passes::{MaskInputs, SharedLighting},
    outputs::{DrawStats, FrameReadbacks, Submitted, TimedLights},
    plan::{FramePlan, LightPlan},
    screen::MaskStart,
};
use crate::{
    GpuScene, RenderError,
    gpu_scene::{IndexOrder, Visible},
    gpu_types::VertexStream,
    layout::ShadowLayout,
    passes::{
        begin_depth_pass,
        lighting::MapLookup,
        moments::MomentInput,
        shadow::{Coverage, DepthRange, DepthTarget, ShadowPipelineKey, ShadowPipelineShape},
    },
    pool::{Binding, ViewKey},
    rays::{self, RefineLists},
    readback,
    timing::{ClockChoice, PassClock, PassKind, PendingTimes},
    uniforms::{CameraGpu, LightGpu},
};

/// What a submission copies back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Readback {
    /// The render targets: colour, visibility, position, normal, object id.
    pub images: bool,
    /// The reported light's shadow map, every layer.
    pub shadow_map: bool,
}

impl Readback {
    pub const NONE: Readback = Readback { images: false, shadow_map: false };
}

/// What a submission is asked for besides the image.
pub(super) struct SubmitRequest<'a> {
    pub readback: Readback,
    /// The reported light's layout, instead of fitting one.
    pub fixed_layout: Option<&'a ShadowLayout>,
    /// How to time the passes; None leaves them untimed (but timestamps, where the
    /// device has them, are still taken).
    pub clock: Option<ClockChoice>,
    pub times: TimesWanted,
}

/// When the frame's pass times are read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum TimesWanted {
    /// Before the call returns: it waits for the GPU to finish the frame.
    Now,
    /// A frame or two later, without waiting ([`super::late::LateTimes`]).
    Late,
}

/// What every recording step appends to: the encoder (the renderer's own, or the
/// host's), the pass clock and the counts.
pub(super) struct Recording<'e> {
    pub encoder: &'e mut wgpu::CommandEncoder,
    pub clock: PassClock,
    pub stats: DrawStats,
}

/// A light's groups for its passes from the camera.
pub(super) struct LightBindings {
    /// Group 0: the instances and the light's uniform.
    pub scene: wgpu::BindGroup,
    /// Its uniform, which the mask pass's groups bind too.
    pub lighting: wgpu::BindGroup,
    /// The mask pass's shadow group, on the mask path.
    pub mask: Option<wgpu::BindGroup>,
    pub lookup: MapLookup,
}

/// A light's uniform and the views of its maps, for the passes from the camera.
pub(super) struct LightMaps {
    pub light_buffer: wgpu::Buffer,
    /// The depth map, every layer.
    pub map: wgpu::TextureView,
    /// The filterable techniques' moment map.
    pub moments: Option<wgpu::TextureView>,
    /// A point light's map as a cube.
    pub cube: Option<wgpu::TextureView>,
    pub lookup: MapLookup,
}

impl LightMaps {
    /// The views of a shadow group, with the light's layer of the mask where it has one.
    pub fn views<'a>(&'a self, mask: Option<&'a wgpu::TextureView>) -> ShadowViews<'a> {
        ShadowViews { map: &self.map, moments: self.moments.as_ref(), cube: self.cube.as_ref(), mask }
    }
}

/// One depth-only pass: a shadow-map layer, or SDSM's camera prepass.
pub(super) struct DepthPass<'a> {
    pub settings: &'a Settings,
    /// The uniform whose `clip_from_world` projects the geometry.
    pub light: &'a LightGpu,
    pub target_view: &'a wgpu::TextureView,
    pub visible: &'a Visible,
    pub target: DepthTarget,
    /// Clamp depth instead of clipping it.
    pub unclipped: bool,
    /// What the pass starts from.
    pub start: DepthStart,
    /// Where it draws.
    pub area: DepthArea,
}

/// Where a depth pass draws.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) enum DepthArea {
    /// The whole target.
    Whole,
    /// These rectangles of it only: every run is drawn once into each.
    Strips(Vec<ScissorRect>),
}

/// A rectangle of a target, in texels from its top-left corner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct ScissorRect {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl ScissorRect {
    /// The projection of the part of a `resolution`² target that this rectangle
    /// covers, widened by a texel each way, when the whole is `clip_from_world`: its
    /// clip volume is the rectangle's, for culling what it may draw.
    pub fn clip_from_world(&self, clip_from_world: glam::Mat4, resolution: u32) -> glam::Mat4 {
        let r = resolution as f32;
        // NDC x runs with texel columns; NDC y against texel rows.
        let (x0, x1) = (self.x as f32 - 1.0, (self.x + self.width) as f32 + 1.0);
        let (y0, y1) = (self.y as f32 - 1.0, (self.y + self.height) as f32 + 1.0);
        let (left, right) = (2.0 * x0 / r - 1.0, 2.0 * x1 / r - 1.0);
        let (bottom, top) = (1.0 - 2.0 * y1 / r, 1.0 - 2.0 * y0 / r);
        let (cx, cy) = (0.5 * (left + right), 0.5 * (bottom + top));
        let (hx, hy) = (0.5 * (right - left), 0.5 * (top - bottom));
        // x' = (x − cx·w) / hx, y' = (y − cy·w) / hy: the rectangle's NDC onto [−1, 1].
        let onto = glam::Mat4::from_cols(
            glam::Vec4::new(1.0 / hx, 0.0, 0.0, 0.0),
            glam::Vec4::new(0.0, 1.0 / hy, 0.0, 0.0),
            glam::Vec4::Z,
            glam::Vec4::new(-cx / hx, -cy / hy, 0.0, 1.0),
        );
        onto * clip_from_world
    }
}

/// What a depth pass starts from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum DepthStart {
    /// Cleared to the far plane.
    Clear,
    /// What the target holds: a copy of a kept layer, to draw moving casters over.
    Keep,
}

impl Renderer {
    /// Plans, culls, records and submits a frame, and reads its pass times.
    pub(super) fn submit(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        request: SubmitRequest,
    ) -> Result<Submitted, RenderError> {
        let started = Instant::now();
        self.pool.end_frame();
        settings.validate()?;
        self.check_limits(settings)?;
        let mut plan = self.plan_frame(uploaded, scene, settings, request.fixed_layout)?;
        let fallback = self.prepare_rays(uploaded, scene, settings, &mut plan)?;
        let planned = Instant::now();
        let culled = cull(uploaded, &plan);
        let cull_done = Instant::now();
        let gpu = self.gpu.clone();
        let mut recorded = gpu.checked("rendering the frame", || {
            self.record_frame(uploaded, settings, &plan, &culled, &request)
        })?;
        let cpu = super::CpuTimings {
            plan_ms: (planned - started).as_secs_f64() * 1e3,
            cull_ms: (cull_done - planned).as_secs_f64() * 1e3,
            record_ms: (recorded.submitted_at - cull_done).as_secs_f64() * 1e3,
            submit_ms: (recorded.submitted_at - started).as_secs_f64() * 1e3,
        };
        let untimed = TimedLights::untimed(&plan, &culled, self.map_cache.uses());
        let times = recorded.times.take().map(PendingTimes::submitted);
        let mut timed = match (request.times, times) {
            (_, None) => untimed,
            (TimesWanted::Now, Some(times)) => untimed.timed(times.read(&gpu)?),
            (TimesWanted::Late, Some(times)) => self.late_times.push(&gpu, &mut self.pool, times, untimed)?,
        };
        let counters = recorded.readbacks.refine_counters.take();
        let traced = match request.times {
            // A frame waited for reports the pixels each light traced.
            TimesWanted::Now => counters,
            TimesWanted::Late => None,
        };
        super::refine::report(&gpu, &plan, &mut timed, fallback, traced)?;
        Ok(Submitted::new(plan, recorded, timed, cpu))
    }

    /// Records every pass of the frame and submits it.
    fn record_frame(
        &mut self,
        uploaded: &GpuScene,
        settings: &Settings,
        plan: &FramePlan,
        culled: &Culled,
        request: &SubmitRequest,
    ) -> Recorded {
        let gpu = self.gpu.clone();
        // Every layer of every light, each light's filter, mask, trace, penumbra filter
        // and lighting, and the prepass.
        let timed_passes = plan.lights.iter().map(|p| p.layers() + 5).sum::<u32>() + 1;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let mut rec = Recording {
            encoder: &mut encoder,
            clock: PassClock::new(&gpu, &mut self.pool, timed_passes, request.clock),
            stats: DrawStats::default(),
        };
        self.map_cache.begin_frame(plan.lights.len());
        let drawn = self.record_passes(&mut rec, uploaded, settings, plan, culled, request.readback);
        let Recording { clock, stats, .. } = rec;
        let times = clock.resolve(&mut self.pool, &mut encoder);
        gpu.queue.submit([encoder.finish()]);
        Recorded {
            readbacks: drawn.readbacks,
            times: Some(times),
            stats,
            color: drawn.color,
            shadow_map: drawn.shadow_map,
            submitted_at: Instant::now(),
        }
    }

    /// Records every pass of a frame into `rec`: each light's shadow maps and moment
    /// map, the screen-space passes on the mask path, each light's lighting, and the
    /// copies `readback` asks for.
    pub(super) fn record_passes(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        settings: &Settings,
        plan: &FramePlan,
        culled: &Culled,
        readback: Readback,
    ) -> Drawn {
        let gpu = self.gpu.clone();
        let (width, height) = (settings.image.width, settings.image.height);
        let camera_gpu = CameraGpu::new(&plan.camera, width, height, settings.image.debug_view);
        let camera_buffer = self.pool.uniform(&gpu.queue, "camera", &camera_gpu);
        let camera_group =
            self.pool.bind_group("camera", &self.layouts.camera, &[Binding::Buffer(camera_buffer.clone())]);
        // On the mask path, one layer of the mask per light.
        let mask_layers = if plan.mask_path { self.mask_layers(plan, width, height) } else { vec![] };
        let mut readbacks = FrameReadbacks::default();
        let mut lit = Vec::with_capacity(plan.lights.len());
        let mut shown_map = None;
        for (index, light) in plan.lights.iter().enumerate() {
            let map = self.record_shadow_maps(rec, uploaded, light, &culled.layers[index], index as u32);
            if index == plan.shown {
                if readback.shadow_map {
                    let aspect = wgpu::TextureAspect::DepthOnly;
                    readbacks.shadow_map = Some(readback::record(&mut self.pool, rec.encoder, &map, aspect));
                }
                shown_map = Some(map.clone());
            }
            lit.push(self.light_bindings(rec, uploaded, light, index as u32, &map, mask_layers.get(index)));
        }
        let targets = self.lighting_targets(width, height);
        let viewport = Viewport { width, height };
        let tiles = plan.mask_path.then(|| plan.light_tiles(viewport));
        let mask = mask_layers.first().map(|layer| {
            self.pool.view(layer.texture(), ViewKey::whole(wgpu::TextureViewDimension::D2Array))
        });
        if let Some(tiles) = &tiles {
            let mask_rects = (0..plan.lights.len()).map(|i| plan.mask_rect(tiles, i, viewport)).collect();
            let screen = super::screen::ScreenInputs {
                camera_visible: &culled.camera,
                camera_buffer: &camera_buffer,
                camera_group: &camera_group,
                depth: &targets.depth,
                mask_layers: &mask_layers,
                mask_rects,
                mask_start: match plan.lighting {
                    Lighting::LightList => MaskStart::Keep,
                    Lighting::PerLight => MaskStart::Clear,
                },
            };
            let lists = self.record_screen_space(rec, uploaded, plan, &lit, &screen);
            // Each light's count of the pixels its rays decided.
            readbacks.refine_counters =
                lists.map(|lists| RefineLists::copy_counters(&lists.counters, &mut self.pool, rec.encoder));
        }
        // On the forward path, the lights that refine trace in their lighting pass
        // (uncounted: rays/refine_forward.wgsl says why).
        let refines = plan.lights.iter().any(|l| l.refine != Refine::Off);
        let tracing = uploaded
            .rays()
            .filter(|_| !plan.mask_path && refines)
            .map(|bvh| rays::forward_group(&mut self.pool, &self.layouts.forward_rays, &camera_buffer, bvh));
        let shared = SharedLighting {
            plan,
            camera_group: &camera_group,
            tracing_group: tracing.as_ref(),
            targets: &targets,
            visible: &culled.camera,
            masks: mask.as_ref().zip(tiles.as_ref()).map(|(mask, tiles)| MaskInputs { mask, tiles }),
        };
        self.record_lights(rec, uploaded, &shared, &lit);
        if readback.images {
            readbacks.targets = targets
                .textures
                .iter()
                .map(|t| readback::record(&mut self.pool, rec.encoder, t, wgpu::TextureAspect::All))
                .collect();
        }
        Drawn {
            readbacks,
            color: targets.textures[0].clone(),
            shadow_map: shown_map.expect("the reported light is one of the lights"),
        }
    }

    /// A light's uniform and its maps as the passes from the camera read them: the
    /// depth map (drawn already), its moment map (recorded here) and its cube view.
    pub(super) fn light_maps(
        &mut self,
        rec: &mut Recording,
        light: &LightPlan,
        index: u32,
        map: &wgpu::Texture,
    ) -> LightMaps {
        let gpu = self.gpu.clone();
        let light_buffer = self.pool.uniform(&gpu.queue, "light", &light.light_gpu);
        let map_view = self.pool.view(map, ViewKey::whole(wgpu::TextureViewDimension::D2Array));
        let shadow = &light.settings.shadow;
        let moments = light.filterable_map.map(|filterable| {
            let input = MomentInput {
                technique: light.technique,
                map: filterable,
                settings: &shadow.filter.moments,
                format: light.moment_format,
                resolution: shadow.map.resolution,
                cascades: light.layers(),
                depth_view: &map_view,
                light_buffer: &light_buffer,
            };
            let slot = rec.clock.begin(&gpu, rec.encoder, PassKind::Filter, Some(index), None);
            let writes = rec.clock.compute_writes(slot);
            let moments =
                self.passes.moments.record(&gpu.device, &mut self.pool, rec.encoder, &input, writes);
            rec.clock.end(&gpu, rec.encoder, slot);
            moments.view
        });
        let lookup = light.lookup();
        let cube = (lookup == MapLookup::Cube)
            .then(|| self.pool.view(map, ViewKey::whole(wgpu::TextureViewDimension::Cube)));
        LightMaps { light_buffer, map: map_view, moments, cube, lookup }
    }

    /// A light's uniform, its moment map (recorded here) and its groups for the passes
    /// from the camera.
    fn light_bindings(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        light: &LightPlan,
        index: u32,
        map: &wgpu::Texture,
        mask_layer: Option<&wgpu::TextureView>,
    ) -> LightBindings {
        let maps = self.light_maps(rec, light, index, map);
        let scene = scene_group(&mut self.pool, &self.layouts, uploaded, &maps.light_buffer);
        // The mask pass writes the layer its light's lighting pass reads.
        let lighting = self.fixed.shadow_group(&mut self.pool, &self.layouts, maps.views(mask_layer));
        let mask =
            mask_layer.map(|_| self.fixed.shadow_group(&mut self.pool, &self.layouts, maps.views(None)));
        LightBindings { scene, lighting, mask, lookup: maps.lookup }
    }

    /// Records a depth-only pass with the shadow pipelines, drawing the runs
    /// `pass.visible` holds: a shadow-map layer's casters, or what the camera sees for
    /// SDSM's prepass. Returns the stats of what it recorded.
    pub(super) fn record_depth_pass(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        depth: &DepthPass,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites>,
    ) -> DrawStats {
        let gpu = &self.gpu;
        let light_buffer = self.pool.uniform(&gpu.queue, "light", depth.light);
        let group = scene_group(&mut self.pool, &self.layouts, uploaded, &light_buffer);
        let bias = &depth.settings.shadow.bias;
        let mut stats = DrawStats::default();
        let load = match depth.start {
            DepthStart::Clear => wgpu::LoadOp::Clear(1.0),
            DepthStart::Keep => wgpu::LoadOp::Load,
        };
        let mut pass = begin_depth_pass(encoder, "shadow", depth.target_view, load, timestamp_writes);
        pass.set_bind_group(0, &group, &[]);
        stats.bind_group_changes += 1;
        // The runs come opaque first (no bind group changes at all), then the
        // alpha-masked ones, texture by texture: the pipeline and the material's bind
        // group change only between batches that need it.
        let mut pipeline: Option<ShadowPipelineKey> = None;
        let mut stream: Option<VertexStream> = None;
        let mut bound = None;
        let rects: Vec<Option<ScissorRect>> = match &depth.area {
            DepthArea::Whole => vec![None],
            DepthArea::Strips(strips) => strips.iter().copied().map(Some).collect(),
        };
        let runs = rects
            .iter()
            .flat_map(|rect| depth.visible.runs.iter().enumerate().map(move |(i, run)| (*rect, i, run)));
        for (rect, index, run) in runs {
            if let (Some(rect), 0) = (rect, index) {
                pass.set_scissor_rect(rect.x, rect.y, rect.width, rect.height);
            }
            let batch = &uploaded.batches[run.batch as usize];
            let key = ShadowPipelineKey::new(
                bias,
                batch.sides,
                if batch.masked { Coverage::Masked } else { Coverage::Opaque },
                DepthRange::clamped_if(depth.unclipped),
                depth.target,
            );
            if pipeline != Some(key) {
                let wanted = ShadowPipelineShape::of(&key).stream;
                match stream {
                    None => uploaded.bind_geometry(&mut pass, wanted, IndexOrder::Clusters),
                    Some(bound_stream) if bound_stream != wanted => uploaded.bind_stream(&mut pass, wanted),
                    Some(_) => {}
                }
                stream = Some(wanted);
                pass.set_pipeline(self.passes.shadow.pipeline(&gpu.device, &key));
                pipeline = Some(key);
                stats.pipeline_changes += 1;
            }
            if batch.masked && bound != Some(batch.material_group) {
                pass.set_bind_group(1, &uploaded.material_groups[batch.material_group], &[]);
                bound = Some(batch.material_group);
                stats.bind_group_changes += 1;
            }
            GpuScene::draw_run(&mut pass, batch, run);
            stats.shadow_draws += 1;
        }
        stats.shadow_instances = depth.visible.instances();
        stats.shadow_triangles = depth.visible.triangles();
        stats
    }
}

/// What a frame's passes drew.
pub(super) struct Drawn {
    pub readbacks: FrameReadbacks,
    /// The colour image.
    pub color: wgpu::Texture,
    /// The reported light's shadow map.
    pub shadow_map: wgpu::Texture,
}

/// What recording left for the frame to read.
pub(super) struct Recorded {
    pub readbacks: FrameReadbacks,
    /// Taken by the frame's timing once submitted.
    pub times: Option<PendingTimes>,
    pub stats: DrawStats,
    pub color: wgpu::Texture,
    pub shadow_map: wgpu::Texture,
    pub submitted_at: Instant,
}

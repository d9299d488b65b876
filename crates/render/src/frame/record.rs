//! Recording a frame: culling every layer and the camera, then each light's shadow
//! maps (one depth pass per layer, `depth_pass.rs`) and moment map, the screen-space
//! passes on the mask path, and the lighting (`light_passes.rs`), into one command
//! buffer. Every resource comes from the renderer's pool.

use web_time::Instant;

use gnomon_math::screen_bounds::Viewport;
use gnomon_scene::{
    Scene, Settings,
    settings::{Lighting, MapCache as MapCacheSetting, Refine},
};

use super::{
    Renderer,
    bindings::{CameraDraws, camera_arguments, scene_group},
    cull::Culled,
    derived_cache::DerivedPlan,
    light_passes::{MaskInputs, SharedLighting},
    moment_cache::{MomentKey, MomentPlan},
    outputs::{Submitted, TimedLights},
    penumbra_history::{HistoryFrame, HistoryKey},
    plan::{FramePlan, LightPlan},
    recording::{
        DrawStats, FrameReadbacks, LayerCommands, LightBindings, LightMaps, PyramidViews, Recorded, Recording,
    },
    screen::MaskStart,
};
use crate::{
    GpuScene, RenderError,
    layout::ShadowLayout,
    passes::{
        SHADOW_FORMAT,
        lighting::MapLookup,
        moments::{MomentInput, MomentLayout, MomentTarget},
    },
    pool::{Binding, ViewKey},
    rays::{
        self, GpuBvh, PyramidInput, PyramidLayout, PyramidParams, RefineLists, Touched, TouchedInput,
        TouchedLayout, touched::Timed,
    },
    readback,
    timing::{ClockChoice, PassClock, PassKind, PendingTimes},
    uniforms::CameraGpu,
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

impl Renderer {
    /// Plans, culls, records and submits a frame, and reads its pass times.
    pub(super) async fn submit(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        request: SubmitRequest<'_>,
    ) -> Result<Submitted, RenderError> {
        let started = Instant::now();
        self.pool.end_frame();
        settings.validate()?;
        self.check_limits(settings)?;
        self.check_frame_memory(scene, settings)?;
        let mut plan = self.plan_frame(uploaded, scene, settings, request.fixed_layout).await?;
        let fallbacks = self.prepare_rays(uploaded, scene, settings, &mut plan)?;
        let planned = Instant::now();
        let culled = self.cull_frame(uploaded, &plan)?;
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
        let mut untimed =
            TimedLights::untimed(&plan, &culled, self.map_cache.uses(), &recorded.layer_commands);
        for (stats, frames) in untimed.lights.iter_mut().zip(&recorded.penumbra_frames) {
            stats.penumbra_frames = *frames;
        }
        let times = recorded.times.take().map(PendingTimes::submitted);
        let mut timed = match (request.times, times) {
            (_, None) => untimed,
            (TimesWanted::Now, Some(times)) => untimed.timed(times.read(&gpu).await?),
            (TimesWanted::Late, Some(times)) => {
                self.late_times.push(&gpu, &mut self.pool, times, untimed).await?
            }
        };
        let counters = recorded.readbacks.refine_counters.take();
        let traced = match request.times {
            // A frame waited for reports the pixels each light traced.
            TimesWanted::Now => counters,
            TimesWanted::Late => None,
        };
        super::refine::report(&gpu, &plan, &mut timed, fallbacks, traced).await?;
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
        // Every layer of every light, each light's filter, depth pyramid, mask, trace,
        // penumbra filter and lighting, and the prepass.
        let timed_passes = plan.lights.iter().map(|p| p.layers() + 6).sum::<u32>() + 1;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let mut rec = Recording {
            encoder: &mut encoder,
            clock: PassClock::new(&gpu, &mut self.pool, timed_passes, request.clock),
            stats: DrawStats::default(),
            layer_commands: LayerCommands::default(),
        };
        self.map_cache.begin_frame(plan.lights.len());
        let drawn = self.record_passes(&mut rec, uploaded, settings, plan, culled, request.readback);
        let Recording { clock, stats, layer_commands, .. } = rec;
        let times = clock.resolve(&mut self.pool, &mut encoder);
        gpu.queue.submit([encoder.finish()]);
        Recorded {
            readbacks: drawn.readbacks,
            times: Some(times),
            stats,
            layer_commands,
            color: drawn.color,
            shadow_map: drawn.shadow_map,
            penumbra_frames: drawn.penumbra_frames,
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
        let histories = self.penumbra_histories(uploaded, plan, &camera_gpu, [width, height]);
        let maps = LightMapInputs { culled, mask_layers: &mask_layers, histories: &histories, readback };
        let LitLights { lit, shown_map, shown_map_readback } =
            self.record_light_maps(rec, uploaded, plan, maps);
        let mut readbacks = FrameReadbacks { shadow_map: shown_map_readback, ..Default::default() };
        let targets = self.lighting_targets(width, height);
        let viewport = Viewport { width, height };
        let tiles = plan.mask_path.then(|| plan.light_tiles(viewport));
        let mask = mask_layers.first().map(|layer| {
            self.pool.view(layer.texture(), ViewKey::whole(wgpu::TextureViewDimension::D2Array))
        });
        let submission = settings.shadow.map.draw_submission;
        let camera = CameraDraws {
            visible: &culled.camera,
            arguments: camera_arguments(&mut self.pool, &gpu, uploaded, &culled.camera, submission),
        };
        let mut surface_group = None;
        if let Some(tiles) = &tiles {
            let mask_rects = (0..plan.lights.len()).map(|i| plan.mask_rect(tiles, i, viewport)).collect();
            let screen = super::screen::ScreenInputs {
                camera: &camera,
                camera_buffer: &camera_buffer,
                camera_group: &camera_group,
                depth: &targets.depth,
                mask_layers: &mask_layers,
                mask_rects,
                histories: &histories,
                mask_start: match plan.lighting {
                    Lighting::LightList => MaskStart::Keep,
                    Lighting::PerLight => MaskStart::Clear,
                },
            };
            let outputs = self.record_screen_space(rec, uploaded, plan, &lit, &screen);
            // Each light's count of the pixels its rays decided.
            readbacks.refine_counters = outputs
                .lists
                .map(|lists| RefineLists::copy_counters(&lists.counters, &mut self.pool, rec.encoder));
            surface_group = Some(outputs.surface_group);
        }
        // On the forward path, the lights that refine trace in their lighting pass
        // (uncounted: rays/refine_forward.wgsl says why).
        let refines = plan.lights.iter().any(|l| l.refine != Refine::Off);
        let tracing = uploaded.rays().filter(|_| !plan.mask_path && refines).map(|bvh| {
            rays::forward_group(
                &mut self.pool,
                &self.layouts.forward_rays,
                &camera_buffer,
                bvh,
                plan.traversal,
            )
        });
        let shared = SharedLighting {
            plan,
            camera_group: &camera_group,
            tracing_group: tracing.as_ref(),
            targets: &targets,
            camera: &camera,
            masks: mask
                .as_ref()
                .zip(tiles.as_ref())
                .zip(surface_group.as_ref())
                .map(|((mask, tiles), surface_group)| MaskInputs { mask, tiles, surface_group }),
        };
        self.record_lights(rec, uploaded, &shared, &lit);
        if readback.images {
            readbacks.targets = targets
                .textures
                .iter()
                .map(|t| readback::record(&mut self.pool, rec.encoder, t, wgpu::TextureAspect::All))
                .collect();
        }
        let penumbra_frames = histories.iter().map(|h| h.as_ref().map(|h| h.frame)).collect();
        Drawn { readbacks, color: targets.textures[0].clone(), shadow_map: shown_map, penumbra_frames }
    }

    /// Each light's penumbra history this frame: one for each light whose mask pass
    /// classifies its penumbrae (`frame/penumbra_history.rs`), none for the others,
    /// which keep none.
    fn penumbra_histories(
        &mut self,
        uploaded: &GpuScene,
        plan: &FramePlan,
        camera: &CameraGpu,
        size: [u32; 2],
    ) -> Vec<Option<HistoryFrame>> {
        let device = self.gpu.device.clone();
        (0..plan.lights.len())
            .map(|index| {
                let light = &plan.lights[index];
                if plan.mask_path && light.classifies_penumbrae() {
                    let key = HistoryKey::of(light, camera, uploaded.caster_generation);
                    Some(self.penumbra_histories.begin(&device, index, key, size))
                } else {
                    self.penumbra_histories.forget(index);
                    None
                }
            })
            .collect()
    }

    /// The first passes: each light's shadow maps (and moment map), and its bindings
    /// for the passes from the camera; the reported light's map copied out when asked.
    fn record_light_maps(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        plan: &FramePlan,
        inputs: LightMapInputs,
    ) -> LitLights {
        let mut lit = Vec::with_capacity(plan.lights.len());
        let mut shown_map = None;
        let mut shown_map_readback = None;
        for (index, light) in plan.lights.iter().enumerate() {
            let map =
                self.record_shadow_maps(rec, uploaded, light, &inputs.culled.layers[index], index as u32);
            if index == plan.shown {
                if inputs.readback.shadow_map {
                    let aspect = wgpu::TextureAspect::DepthOnly;
                    shown_map_readback = Some(readback::record(&mut self.pool, rec.encoder, &map, aspect));
                }
                shown_map = Some(map.clone());
            }
            let mask = inputs.mask_layers.get(index);
            let history = inputs.histories[index].as_ref();
            let drawn = DrawnLight { index: index as u32, map: &map, mask_layer: mask, history };
            lit.push(self.light_bindings(rec, uploaded, light, drawn));
        }
        let shown_map = shown_map.expect("the reported light is one of the lights");
        LitLights { lit, shown_map, shown_map_readback }
    }

    /// A light's uniform and its maps as the passes from the camera read them: the
    /// depth map (drawn already), its moment map (recorded here) and its cube view,
    /// its pyramid where its penumbra `history` classifies, and its touched layer
    /// where its rays refine a 2D map, drawn from the casters' `bvh`.
    pub(super) fn light_maps(
        &mut self,
        rec: &mut Recording,
        light: &LightPlan,
        index: u32,
        map: &wgpu::Texture,
        derived: DerivedInputs,
    ) -> LightMaps {
        let DerivedInputs { history, bvh } = derived;
        let gpu = self.gpu.clone();
        // The history's state this frame, which the penumbra passes read.
        let mut uniform = light.light_gpu;
        if let Some(history) = history {
            uniform.rays.history = u32::from(history.held);
            uniform.rays.frame = history.frame;
        }
        let light_buffer = self.pool.uniform(&gpu.queue, "light", &uniform);
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
            // Kept across frames along with the depth map; filtered again only where
            // the depths or what the filter reads changed (`moment_cache.rs`).
            let kept = match shadow.map.cache {
                MapCacheSetting::StillCasters => {
                    let (key, layout) = (MomentKey::of(light, &input), MomentLayout::of(&input));
                    let depths_kept = self.map_cache.kept_whole(index as usize);
                    Some(self.map_cache.moments.plan(&gpu.device, index as usize, key, layout, depths_kept))
                }
                MapCacheSetting::Off => {
                    self.map_cache.moments.forget(index as usize);
                    None
                }
            };
            let whole = ViewKey::whole(wgpu::TextureViewDimension::D2Array);
            let target = match &kept {
                Some(MomentPlan::Keep(texture)) => return self.pool.view(texture, whole),
                Some(MomentPlan::Filter(texture)) => MomentTarget::Kept(texture),
                None => MomentTarget::Pooled,
            };
            let slot = rec.clock.begin(&gpu, rec.encoder, PassKind::Filter, Some(index), None);
            let writes = rec.clock.compute_writes(slot);
            let moments =
                self.passes.moments.record(&gpu.device, &mut self.pool, rec.encoder, &input, target, writes);
            rec.clock.end(&gpu, rec.encoder, slot);
            moments.view
        });
        let lookup = light.lookup();
        let cube = (lookup == MapLookup::Cube)
            .then(|| self.pool.view(map, ViewKey::whole(wgpu::TextureViewDimension::Cube)));
        let virtual_map =
            light.virtual_map.as_ref().map(|plan| Self::virtual_buffers(&mut self.pool, &gpu.queue, plan));
        let pyramid = match history {
            Some(_) => Some(self.depth_pyramid(rec, light, index, &map_view)),
            None => {
                self.map_cache.pyramids.forget(index as usize);
                None
            }
        };
        let touched = match bvh {
            Some(bvh) if history.is_none() && rays::reads_touched(light.refine, lookup) => Some(
                self.touched_layer(rec, light, index, &light_buffer, TouchedFrom { map: &map_view, bvh }),
            ),
            Some(_) | None => {
                self.map_cache.touched.forget(index as usize);
                None
            }
        };
        LightMaps { light_buffer, map: map_view, moments, cube, virtual_map, pyramid, touched, lookup }
    }

    /// Light `index`'s touched layer (`rays/touched.rs`), drawn beside its map from
    /// the casters of `drawn` with its uniform `light_buffer`, or kept where its
    /// depth map was kept whole and still casters keep maps (the same casters, seen
    /// the same way).
    fn touched_layer(
        &mut self,
        rec: &mut Recording,
        light: &LightPlan,
        index: u32,
        light_buffer: &wgpu::Buffer,
        drawn: TouchedFrom,
    ) -> wgpu::TextureView {
        let gpu = self.gpu.clone();
        let layout = TouchedLayout { resolution: light.map_resolution(), layers: light.layers() };
        // Kept with a kept map; without kept maps, a pooled texture drawn every frame,
        // found again whatever the map's size was last frame.
        let (touched, draw) = match light.settings.shadow.map.cache {
            MapCacheSetting::StillCasters => {
                let kept = self.map_cache.kept_whole(index as usize);
                match self.map_cache.touched.plan(&gpu.device, index as usize, layout, kept) {
                    DerivedPlan::Keep(touched) => (touched, false),
                    DerivedPlan::Build(touched) => (touched, true),
                }
            }
            MapCacheSetting::Off => {
                self.map_cache.touched.forget(index as usize);
                let texture =
                    self.pool.texture("touched layer", layout.size(), SHADOW_FORMAT, TouchedLayout::USAGE);
                (Touched { texture }, true)
            }
        };
        if draw {
            let slot = rec.clock.begin(&gpu, rec.encoder, PassKind::Filter, Some(index), None);
            let (triangles, count, queue) =
                (drawn.bvh.triangle_buffer(), drawn.bvh.triangles as u32, &gpu.queue);
            let input = TouchedInput { light: light_buffer, triangles, count, map: drawn.map, layout, queue };
            let timed = Some(Timed { clock: &rec.clock, slot });
            self.passes.touched.record(&mut self.pool, rec.encoder, input, &touched, timed);
            rec.clock.end(&gpu, rec.encoder, slot);
        }
        self.pool.view(&touched.texture, ViewKey::whole(wgpu::TextureViewDimension::D2Array))
    }

    /// Light `index`'s depth pyramid, built from `map` (`rays/pyramid.rs`), or kept
    /// where its depth map was kept whole and still casters keep maps.
    fn depth_pyramid(
        &mut self,
        rec: &mut Recording,
        light: &LightPlan,
        index: u32,
        map: &wgpu::TextureView,
    ) -> PyramidViews {
        let gpu = self.gpu.clone();
        let layout = PyramidLayout::of(light.map_resolution(), light.layers());
        let kept = light.settings.shadow.map.cache == MapCacheSetting::StillCasters
            && self.map_cache.kept_whole(index as usize);
        let pyramid = match self.map_cache.pyramids.plan(&gpu.device, index as usize, layout, kept) {
            DerivedPlan::Keep(pyramid) => pyramid,
            DerivedPlan::Build(pyramid) => {
                let slot = rec.clock.begin(&gpu, rec.encoder, PassKind::Filter, Some(index), None);
                let mut pass = rec.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("depth pyramid"),
                    timestamp_writes: rec.clock.compute_writes(slot),
                });
                let cube = light.lookup() == MapLookup::Cube;
                let params = PyramidParams {
                    cube: u32::from(cube),
                    range: light.light_gpu.emitter.range,
                    near: light.light_gpu.map.near,
                    _pad: 0,
                };
                let input = PyramidInput { map, params, queue: &gpu.queue, layout };
                self.passes.pyramid.record(&mut self.pool, &mut pass, input, &pyramid);
                drop(pass);
                rec.clock.end(&gpu, rec.encoder, slot);
                pyramid
            }
        };
        let whole = ViewKey::whole(wgpu::TextureViewDimension::D2Array);
        PyramidViews {
            planes: self.pool.view(&pyramid.planes, whole),
            ranges: self.pool.view(&pyramid.ranges, whole),
        }
    }

    /// A light's uniform, its moment map (recorded here) and its groups for the passes
    /// from the camera.
    fn light_bindings(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        light: &LightPlan,
        drawn: DrawnLight,
    ) -> LightBindings {
        let DrawnLight { index, map, mask_layer, history } = drawn;
        let maps = self.light_maps(rec, light, index, map, DerivedInputs { history, bvh: uploaded.rays() });
        let scene = scene_group(&mut self.pool, &self.layouts, uploaded, &maps.light_buffer);
        // The mask pass writes the layer its light's lighting pass reads.
        let lighting = self.fixed.shadow_group(&mut self.pool, &self.layouts, maps.views(mask_layer));
        let mask =
            mask_layer.map(|_| self.fixed.shadow_group(&mut self.pool, &self.layouts, maps.views(None)));
        LightBindings { scene, lighting, mask, lookup: maps.lookup }
    }
}

/// One light as its maps were drawn: its index, its map, the mask layer its lighting
/// pass reads (on the mask path) and its penumbra history.
struct DrawnLight<'a> {
    index: u32,
    map: &'a wgpu::Texture,
    mask_layer: Option<&'a wgpu::TextureView>,
    history: Option<&'a HistoryFrame>,
}

/// What a light's derived textures are made from: its penumbra history, where its
/// mask pass classifies penumbrae (then its map's pyramid is built), and the
/// casters' BVH, where rays refine the frame (its triangles draw the touched layer).
pub(super) struct DerivedInputs<'a> {
    pub history: Option<&'a HistoryFrame>,
    pub bvh: Option<&'a GpuBvh>,
}

/// What a light's touched layer is drawn from: its map (every layer), whose tiny
/// triangles it holds itself, and the casters' BVH.
struct TouchedFrom<'a> {
    map: &'a wgpu::TextureView,
    bvh: &'a GpuBvh,
}

/// What the first passes read besides the plan: the culled layers, the mask's layers,
/// each light's penumbra history, and what to copy out.
struct LightMapInputs<'a> {
    culled: &'a Culled,
    mask_layers: &'a [wgpu::TextureView],
    histories: &'a [Option<HistoryFrame>],
    readback: Readback,
}

/// Each light's bindings for the passes from the camera, and the reported light's map.
struct LitLights {
    lit: Vec<LightBindings>,
    shown_map: wgpu::Texture,
    /// The reported light's map being copied out, when the frame asked for it.
    shown_map_readback: Option<crate::readback::PendingReadback>,
}

/// What a frame's passes drew.
pub(super) struct Drawn {
    pub readbacks: FrameReadbacks,
    /// The colour image.
    pub color: wgpu::Texture,
    /// The reported light's shadow map.
    pub shadow_map: wgpu::Texture,
    /// Frames each light's penumbra history holds.
    pub penumbra_frames: Vec<Option<u32>>,
}

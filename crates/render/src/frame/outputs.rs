//! What a frame gives back: the images and maps read from the GPU ([`Frame`]), the
//! textures left on it for a window ([`LiveFrame`]), and what each pass drew and cost
//! ([`DrawStats`], [`LightStats`], [`PassTimings`], [`CpuTimings`], [`FrameCost`]).

use glam::{Vec3, Vec4};
use gnomon_math::{
    LightProjection,
    omni::{cube_texel_world_size, paraboloid_texel_world_size},
};
use gnomon_scene::{
    Camera, Light,
    lights::ShadowView,
    settings::{DrawSubmission, Technique},
};

use super::recording::{DrawStats, FrameReadbacks, LayerCommands, Recorded};
use crate::{
    Gpu, RenderError,
    gpu_scene::Visible,
    layout::ShadowLayout,
    timing::{FrameTimes, PassKind, PassTime, TimingSource},
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
    /// Texels per side of each (square) layer.
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
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
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
    /// World-space unit normal of the visible triangle's plane, facing the camera;
    /// NaN for background. With `position`, the surface a shadow ray from the pixel
    /// leaves (`gnomon compare` traces its reference from them).
    pub geometric_normal: Vec<Vec3>,
    /// View-space depth (distance along the camera's axis); NaN for background.
    pub depth: Vec<f32>,
    /// Instance index + 1 of the visible surface; 0 for background.
    pub object_id: Vec<u32>,
    /// The camera the frame was drawn with: the scene's, with the settings' overrides.
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
    /// Texels per side of each layer of the reported light's map.
    pub shadow_resolution: u32,
    /// The reported light's virtual map's levels (`--partition virtual`), in the
    /// place of the layout above, which such a light fits but does not draw.
    pub virtual_levels: Option<super::VirtualLevels>,
    /// The reported light's map read back, when [`OutputRequest::shadow_map`] asked for it.
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
    /// The camera the frame was drawn with: the scene's, with the settings' overrides.
    pub camera: Camera,
    /// The light whose shadow map `shadow_map` is (as [`Frame::light`]).
    pub light: Light,
    /// The reported light's layers and cascade splits.
    pub layout: ShadowLayout,
    /// The pass times of the previous live frame (None for the first): a live frame
    /// does not wait for the GPU to finish it.
    pub timings: Option<PassTimings>,
    /// How many frames before this one `timings` and `lights`' times were taken.
    pub timings_age: u32,
    /// Draw calls and state changes of this frame, every light together.
    pub stats: DrawStats,
    /// What each light drew (this frame) and cost (`timings_age` frames ago).
    pub lights: Vec<LightStats>,
    /// Shadows were resolved in a screen-space mask, not per fragment (as [`Frame::shadow_mask`]).
    pub shadow_mask: bool,
}

/// What one light of a frame drew and cost.
#[derive(Clone, Debug, PartialEq)]
pub struct LightStats {
    /// The light's name in the scene's list, or its type for a single light.
    pub name: String,
    /// "sun", "spot" or "point".
    pub kind: &'static str,
    /// The shadow technique the light was drawn with (its own settings, with `--light all`).
    pub technique: Technique,
    /// Texels per side of each of its layers (1 for a technique that reads no map).
    pub resolution: u32,
    /// Draws into each layer of its map (one per cascade, six for a cube): the
    /// casters that survived the CPU's culling against that layer's frustum. A layer
    /// culled on the GPU (`DrawSubmission::GpuCulled`) reports the CPU's count, whose
    /// casters are the ones the GPU keeps (`render/tests/gpu/gpu_culling.rs` holds their
    /// maps equal); the GPU issues one draw per kept cluster where the CPU merges
    /// neighbouring ones.
    pub layer_draws: Vec<u32>,
    /// Draw commands this frame recorded into each layer: one per draw, or one per
    /// multi-draw of draws that share a pipeline (`DrawSubmission::Indirect`), or one
    /// per bucket of shadow items whose count the GPU wrote (`GpuCulled`); 0 for a
    /// kept layer.
    pub layer_commands: Vec<u32>,
    /// Texels each layer's passes rasterized this frame: the area of every pass that
    /// cleared the layer or drew into it (the whole layer, the strips a scrolled
    /// layer newly covers); 0 for a kept layer with no moving caster. What a
    /// fill-bound GPU pays for, whatever the casters cover.
    pub layer_texels: Vec<u64>,
    /// Instances drawn into each layer: those whose bounds reach into its frustum.
    pub layer_instances: Vec<u32>,
    /// Triangles drawn into each layer: every triangle of those instances, less the
    /// clusters of large meshes outside its frustum or turned the way it culls
    /// (`--caster-culling`).
    pub layer_triangles: Vec<u64>,
    /// What each layer did with its kept map (`--map-cache`): a kept layer without
    /// moving casters draws nothing, and has no time in [`LightStats::layer_ms`].
    pub layer_cache: Vec<super::map_cache::LayerCache>,
    /// The time of each layer's shadow pass, where the frame was timed.
    pub layer_ms: Vec<f64>,
    /// Time of its shadow passes (every layer), moment pass and lighting pass, where
    /// the frame was timed.
    pub shadow_ms: Option<f64>,
    /// GPU time of what it derives from its map, where the frame was timed: the
    /// moment pass of a filterable technique, the depth pyramid of a light with an
    /// area, the touched layer of a 2D map its rays refine (`rays/touched.rs`).
    pub filter_ms: Option<f64>,
    /// GPU time of its lighting pass, where the frame was timed.
    pub lighting_ms: Option<f64>,
    /// GPU time of its shadow-mask pass, on the mask path.
    pub mask_ms: Option<f64>,
    /// GPU time of its trace pass, where it refines its shadow by rays.
    pub trace_ms: Option<f64>,
    /// The refinement by rays it got: `auto` resolved, `off` where it fell back.
    pub refine: gnomon_scene::settings::Refine,
    /// Pixels its shadow was refined at, where it refines by rays on the mask path and
    /// the frame was waited for (not a live frame's). The forward path traces in the
    /// lighting pass and counts nothing (`rays/refine_forward.wgsl` says why).
    pub traced_pixels: Option<u32>,
    /// Pixels whose shadow rays decide, this frame or before, where it refines by rays
    /// on the mask path and the frame was waited for: the traced ones, and under a
    /// light with an area whose penumbrae its mask pass classifies, those filled from
    /// their neighbours and those their penumbra history answered.
    pub unsure_pixels: Option<u32>,
    /// Shadow rays each refined pixel asks for on the mask path: 1 under a hard light;
    /// under a light with an area, a penumbra beam's samples
    /// (`gnomon_math::light_masks::SAMPLES`), whatever the settings' `penumbra_rays`
    /// (which the forward path's rays follow).
    pub rays_per_pixel: u32,
    /// Why its shadow was drawn unrefined where it asked to be refined by rays: the
    /// device cannot trace this scene or an image this large.
    pub refine_fallback: Option<crate::rays::RaysUnavailable>,
    /// Frames its penumbra history holds, this one counted, where its mask pass
    /// classifies its penumbrae (rays/penumbra_mask.wgsl): 1 on the first frame, or
    /// the first after the camera, the light or a caster moved; a still view's unsure
    /// pixels have gathered a beam every fourth frame since. None for a light with no
    /// penumbra history.
    pub penumbra_frames: Option<u32>,
    /// Why its layers were culled on the CPU where its settings asked for the GPU
    /// (`DrawSubmission::GpuCulled`): the same maps, at the CPU's cost.
    pub cull_fallback: Option<crate::GpuCullUnavailable>,
    /// How its rays traversed the casters, where it traced any (`screen.tracer`
    /// resolved on the device).
    pub traversal: Option<crate::rays::Traversal>,
    /// Why its rays traversed the shader's BVH where `screen.tracer` asked for ray
    /// queries: the device has none, or cannot take the scene in its structures.
    pub tracer_fallback: Option<crate::rays::RayQueriesUnavailable>,
    /// A virtual map's pages this frame (`--partition virtual`).
    pub pages: Option<super::virtual_pages::PageStats>,
}

impl LightStats {
    /// Draw calls into its map, every layer together.
    pub fn shadow_draws(&self) -> u32 {
        self.layer_draws.iter().sum()
    }

    /// Shadow rays its refinement asked for: the pixels traced times the rays of
    /// each, where it refines by rays.
    pub fn traced_rays(&self) -> Option<u64> {
        self.traced_pixels.map(|pixels| u64::from(pixels) * u64::from(self.rays_per_pixel))
    }
}

/// What a frame cost the CPU, in milliseconds: fitting the lights' projections,
/// culling (every layer and the camera, in parallel), and recording and submitting
/// the commands. `submit_ms` is the whole, from the call to the queue's submit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CpuTimings {
    /// Planning: resolving the camera and lights and fitting every light's projection.
    pub plan_ms: f64,
    /// Culling every map layer and the camera against the instances.
    pub cull_ms: f64,
    /// Recording the passes' commands, up to and including the submit.
    pub record_ms: f64,
    /// The whole, from the call to the queue's submit: plan, cull and record together.
    pub submit_ms: f64,
}

/// What timing one frame measured: the summary, each pass, the draws and the CPU
/// cost ([`crate::Renderer::time_passes`]).
#[derive(Clone, Debug)]
pub struct FrameCost {
    /// None only when the frame was not timed.
    pub timings: Option<PassTimings>,
    /// Each pass's time: every layer of every light's map, filters, screen-space
    /// passes and lighting.
    pub passes: Vec<PassTime>,
    /// Draw calls and state changes, every light together.
    pub stats: DrawStats,
    /// What each light drew and cost, in the order they were drawn.
    pub lights: Vec<LightStats>,
    /// The frame's CPU cost.
    pub cpu: CpuTimings,
}

/// GPU time per pass, in milliseconds, from timestamp queries; with many lights,
/// each kind of pass summed over the lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassTimings {
    /// The shadow passes: every layer of every light's map.
    pub shadow_ms: f64,
    /// What the lights derive from their maps: the moment pass (encoding, blur,
    /// mipmaps) of the filterable techniques, the depth pyramids of lights with an
    /// area, the touched layers of 2D maps that rays refine.
    pub filter_ms: Option<f64>,
    /// The lighting passes, every light's.
    pub lighting_ms: f64,
    /// On the mask path: the depth-and-normal prepass, and the mask passes.
    pub prepass_ms: Option<f64>,
    /// On the mask path: the shadow-mask passes, every light's.
    pub mask_ms: Option<f64>,
    /// With refinement by rays: the trace passes, every refining light's.
    pub trace_ms: Option<f64>,
    /// The whole frame on the GPU, from the first shadow pass's start to the last
    /// lighting pass's end (SDSM's prepass not included).
    pub frame_ms: f64,
    /// GPU timestamps, or the CPU wall clock where the adapter has none.
    pub source: TimingSource,
}

impl Frame {
    /// Number of pixels, `width × height`: the length of every per-pixel vector.
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
        if let ShadowView::Omni { position, .. } = self.light.shadow_view() {
            if let [lower, upper] = self.cascades.as_slice() {
                // Dual paraboloids: the lower hemisphere holds y at or below the light.
                let hemisphere = if world.y <= position.y { lower } else { upper };
                let offset = hemisphere.light_from_world.transform_point3(world);
                return paraboloid_texel_world_size(offset, self.shadow_resolution);
            }
            return cube_texel_world_size(world - position, self.shadow_resolution);
        }
        let distance = -self.light_projection.light_from_world.transform_point3(world).z;
        self.light_projection.texel_world_size(self.shadow_resolution, distance)
    }
}

/// A frame submitted to the GPU, its pass times read, its images waiting.
pub(super) struct Submitted {
    readbacks: FrameReadbacks,
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
    virtual_levels: Option<super::VirtualLevels>,
    shadow_mask: bool,
}

impl Submitted {
    /// Reads the pass times of a recorded frame and gathers what it reports.
    pub(super) fn new(
        plan: super::plan::FramePlan,
        recorded: Recorded,
        timed: TimedLights,
        cpu: CpuTimings,
    ) -> Self {
        let super::plan::FramePlan { camera, mask_path, shown, lights: mut plans, .. } = plan;
        let shown = plans.swap_remove(shown);
        Submitted {
            readbacks: recorded.readbacks,
            color: recorded.color,
            shadow_map: recorded.shadow_map,
            timings: timed.timings,
            passes: timed.passes,
            cpu,
            stats: recorded.stats,
            lights: timed.lights,
            camera,
            light: shown.light,
            resolution: shown.map_resolution(),
            layout: shown.layout,
            moment_format: shown.filterable_map.is_some().then_some(shown.moment_format),
            virtual_levels: shown.virtual_map.as_ref().map(|plan| plan.levels()),
            shadow_mask: mask_path,
        }
    }

    /// Whether every virtual light's pages along shadow edges had settled: the last
    /// frame's traced pixels asked for no page it had not drawn
    /// ([`crate::PageStats::edges_new`]).
    /// Whether every light's penumbra history holds `frames` frames or more (a light
    /// with none has nothing to gather).
    pub(super) fn penumbrae_gathered(&self, frames: u32) -> bool {
        self.lights.iter().filter_map(|light| light.penumbra_frames).all(|held| held >= frames)
    }

    pub(super) fn edges_settled(&self) -> bool {
        let pages = self.lights.iter().filter_map(|light| light.pages);
        pages.filter(|p| p.edge_levels > 0).all(|p| p.edges_new == Some(0))
    }

    /// The frame left on the GPU; its times are `timings_age` frames old.
    pub(super) fn live(self, timings_age: u32) -> LiveFrame {
        LiveFrame {
            timings_age,
            color: self.color,
            shadow_map: self.shadow_map,
            camera: self.camera,
            light: self.light,
            layout: self.layout,
            timings: self.timings,
            stats: self.stats,
            lights: self.lights,
            shadow_mask: self.shadow_mask,
        }
    }

    /// What the frame cost.
    pub(super) fn cost(self) -> FrameCost {
        FrameCost {
            timings: self.timings,
            passes: self.passes,
            stats: self.stats,
            lights: self.lights,
            cpu: self.cpu,
        }
    }

    /// Reads the frame's images back and assembles the [`Frame`].
    pub(super) async fn read(
        self,
        gpu: &Gpu,
        settings: &gnomon_scene::Settings,
    ) -> Result<Frame, RenderError> {
        let (width, height) = (settings.image.width, settings.image.height);
        let resolution = self.resolution;
        let mut pending = self.readbacks.targets.into_iter();
        let mut next = || pending.next().expect("one readback per target");
        let color: Vec<u8> = next().read(gpu).await?;
        let mut visibility: Vec<f32> = next().read(gpu).await?;
        let position_w: Vec<Vec4> = next().read(gpu).await?;
        let normal_w: Vec<Vec4> = next().read(gpu).await?;
        let object_id: Vec<u32> = next().read(gpu).await?;
        let shadow_map = match self.readbacks.shadow_map {
            Some(p) => {
                let depth: Vec<f32> = p.read(gpu).await?;
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
        // Both normals come octahedron-encoded (lighting_common.wgsl).
        let decoded = |pick: fn(Vec4) -> glam::Vec2| -> Vec<Vec3> {
            normal_w
                .iter()
                .zip(&object_id)
                .map(|(n, &id)| if id == 0 { nan3 } else { gnomon_math::octahedron::decode(pick(*n)) })
                .collect()
        };
        let normal = decoded(|n| n.truncate().truncate());
        let geometric_normal = decoded(|n| glam::Vec2::new(n.z, n.w));
        let layout = self.layout;
        Ok(Frame {
            width,
            height,
            color,
            visibility,
            position,
            normal,
            geometric_normal,
            depth,
            object_id,
            camera: self.camera,
            light: self.light,
            light_projection: layout.projections[0],
            cascades: layout.projections,
            cascade_splits: layout.splits,
            shadow_depth_clamp: layout.depth_clamp,
            shadow_resolution: resolution,
            virtual_levels: self.virtual_levels,
            shadow_map,
            timings: self.timings,
            stats: self.stats,
            lights: self.lights,
            moment_format: self.moment_format,
            shadow_mask: self.shadow_mask,
        })
    }
}

/// The sum over the lights of a time some of them have; None when none has it.
fn sum_of(lights: &[LightStats], time: fn(&LightStats) -> Option<f64>) -> Option<f64> {
    let times: Vec<f64> = lights.iter().filter_map(time).collect();
    (!times.is_empty()).then(|| times.iter().sum())
}

/// What each light of a frame drew, with the frame's pass times once they are read.
#[derive(Clone)]
pub(super) struct TimedLights {
    pub lights: Vec<LightStats>,
    pub passes: Vec<PassTime>,
    pub timings: Option<PassTimings>,
}

impl TimedLights {
    /// What each light drew (its culled casters per layer), not yet timed.
    pub fn untimed(
        plan: &super::plan::FramePlan,
        culled: &super::cull::Culled,
        cache_uses: &[Vec<super::map_cache::LayerCache>],
        commands: &LayerCommands,
    ) -> Self {
        let lights = plan
            .lights
            .iter()
            .zip(&culled.layers)
            .zip(cache_uses)
            .enumerate()
            .map(|(index, ((light, layers), cache))| LightStats {
                name: light.name.clone(),
                kind: light.light.type_name(),
                technique: light.technique.technique(),
                resolution: light.map_resolution(),
                layer_draws: layers.iter().map(|v| v.runs.len() as u32).collect(),
                layer_commands: commands.of(index, layers.len()).iter().map(|w| w.commands).collect(),
                layer_texels: commands.of(index, layers.len()).iter().map(|w| w.texels).collect(),
                layer_instances: layers.iter().map(Visible::instances).collect(),
                layer_triangles: layers.iter().map(Visible::triangles).collect(),
                layer_cache: cache.clone(),
                layer_ms: Vec::new(),
                shadow_ms: None,
                filter_ms: None,
                lighting_ms: None,
                mask_ms: None,
                trace_ms: None,
                refine: light.refine,
                traced_pixels: None,
                unsure_pixels: None,
                rays_per_pixel: 1,
                refine_fallback: None,
                penumbra_frames: None,
                cull_fallback: culled
                    .gpu_cull_fallback
                    .clone()
                    .filter(|_| light.settings.shadow.map.draw_submission == DrawSubmission::GpuCulled),
                traversal: None,
                tracer_fallback: None,
                pages: light.virtual_map.as_ref().map(|v| v.stats),
            })
            .collect();
        TimedLights { lights, passes: Vec::new(), timings: None }
    }

    /// With the frame's pass times (None when it was not timed).
    pub fn timed(mut self, times: Option<FrameTimes>) -> Self {
        let Some(times) = times else { return self };
        for (index, light) in self.lights.iter_mut().enumerate() {
            let index = Some(index as u32);
            let of_kind =
                |kind: PassKind| times.passes.iter().filter(move |p| p.kind == kind && p.light == index);
            let time_of = |kind: PassKind| {
                let ms: Vec<f64> = of_kind(kind).map(|p| p.ms).collect();
                (!ms.is_empty()).then(|| ms.iter().sum())
            };
            light.layer_ms = of_kind(PassKind::Shadow).map(|p| p.ms).collect();
            light.shadow_ms = time_of(PassKind::Shadow);
            light.filter_ms = time_of(PassKind::Filter);
            light.lighting_ms = time_of(PassKind::Lighting);
            light.mask_ms = time_of(PassKind::Mask);
            light.trace_ms = time_of(PassKind::Trace);
        }
        let lights = &self.lights;
        self.timings = Some(PassTimings {
            shadow_ms: sum_of(lights, |l| l.shadow_ms).unwrap_or(0.0),
            filter_ms: sum_of(lights, |l| l.filter_ms),
            // Every lighting pass: each light's, or the light list's one for them all.
            lighting_ms: times.passes.iter().filter(|p| p.kind == PassKind::Lighting).map(|p| p.ms).sum(),
            prepass_ms: times.passes.iter().find(|p| p.kind == PassKind::Prepass).map(|p| p.ms),
            mask_ms: sum_of(lights, |l| l.mask_ms),
            trace_ms: sum_of(lights, |l| l.trace_ms),
            frame_ms: times.frame_ms,
            source: times.source,
        });
        self.passes = times.passes;
        self
    }
}

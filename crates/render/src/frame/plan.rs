//! Frame planning: everything decided before recording. The camera, each light's
//! settings, shadow layout (fitted, frozen, or from SDSM's sample distribution),
//! map formats and uniform, and how its map is drawn and looked up.

use glam::Vec3;
use gnomon_math::{culling::Frustum, fitting::directional_light_view};
use gnomon_scene::{
    Camera, Light, Scene, Settings,
    lights::ShadowView,
    settings::{
        BiasSettings, CascadeSelection, FilterSettings, KernelUnit, LightKind, Lighting, MAX_KERNEL_TEXELS,
        Partition, RayUse, Refine,
    },
};

use super::{Renderer, virtual_pages::VirtualLight};
use crate::virtual_map::AreaSearch;
use crate::{
    GpuScene, RenderError,
    gpu_scene::{CullView, Granularity},
    layout::{MapDrawing, SampleDistribution, ShadowLayout, cascade_splits, shadow_layout},
    passes::{
        SHADOW_FORMAT,
        depth_reduce::{BoundsRequest, Planes},
        lighting::MapLookup,
        shadow::DepthTarget,
    },
    pool::ViewKey,
    rays,
    techniques::{self, TechniqueRef},
    uniforms::{LightGpu, LightInputs},
};

impl Renderer {
    /// Records a depth prepass from the camera (`clip_from_world`) of everything it
    /// sees, receivers that cast no shadow included, with the shadow pass's
    /// pipelines and no bias: what SDSM reduces and a virtual map's pages are
    /// requested from. Returns its depth, `settings.image`'s size.
    pub(super) fn camera_depth_prepass(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        uploaded: &GpuScene,
        settings: &Settings,
        clip_from_world: glam::Mat4,
    ) -> wgpu::Texture {
        let (width, height) = (settings.image.width, settings.image.height);
        let depth = self.pool.texture(
            "camera depth prepass",
            wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            SHADOW_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let camera_as_light = LightGpu { clip_from_world, ..Default::default() };
        let mut prepass = settings.clone();
        prepass.shadow.bias = BiasSettings::none();
        let seen = uploaded.cull(&[CullView {
            frustum: Frustum::from_clip_from_world(clip_from_world),
            near: true,
            casters_only: false,
            granularity: Granularity::Instances,
        }]);
        let view = self.pool.view(&depth, ViewKey::default());
        let pass = super::depth_pass::DepthPass {
            settings: &prepass,
            light: &camera_as_light,
            target_view: &view,
            visible: &seen[0],
            target: DepthTarget::Projected,
            unclipped: false,
            start: super::depth_pass::DepthStart::Clear,
            area: super::depth_pass::DepthArea::Whole,
            culling: None,
        };
        self.record_depth_pass(encoder, uploaded, &pass, None);
        depth
    }
}

/// A frame, as decided before recording.
pub(super) struct FramePlan {
    pub camera: Camera,
    pub aspect: f32,
    /// Whether the lights' shadows go through the screen-space mask path.
    pub mask_path: bool,
    /// How the lights are lit: from a light list on the mask path when the settings
    /// say so and there are several, one pass per light otherwise.
    pub lighting: Lighting,
    /// The reported light's index.
    pub shown: usize,
    pub lights: Vec<LightPlan>,
    /// How the frame's shadow rays traverse the casters (`prepare_rays` resolves it).
    pub traversal: crate::rays::Traversal,
}

/// One light of a frame, as decided before recording.
pub(super) struct LightPlan {
    pub name: String,
    pub light: Light,
    /// The render's settings with this light's shadow settings.
    pub settings: Settings,
    pub layout: ShadowLayout,
    /// Its technique, checked against the light and its map.
    pub technique: TechniqueRef,
    pub filterable_map: Option<techniques::FilterableMap>,
    pub moment_format: wgpu::TextureFormat,
    pub light_gpu: LightGpu,
    /// Which of its pixels trace a shadow ray (on the mask path; off for a light with
    /// an area).
    pub refine: Refine,
    /// Its virtual map's pages this frame (`--partition virtual`).
    pub virtual_map: Option<super::virtual_pages::VirtualPlan>,
}

/// What a light's layout is fitted for (`Renderer::fit_layout`).
struct LayoutFit<'a> {
    light: &'a Light,
    /// The render's settings with this light's shadow settings.
    settings: &'a Settings,
    technique: TechniqueRef,
    /// [`MapDrawing::penumbra_slope`].
    penumbra_slope: Option<f32>,
}

/// The tangent of a sun's angular radius, where it has one: how far past its
/// receivers a map whose penumbrae are classified must reach, per unit of depth.
fn sun_penumbra_slope(light: &Light) -> Option<f32> {
    match light {
        Light::Directional(sun) if sun.angular_diameter_degrees > 0.0 => {
            Some((0.5 * sun.angular_diameter_degrees.to_radians()).tan())
        }
        Light::Directional(_) | Light::Spot(_) | Light::Point(_) => None,
    }
}

impl LightPlan {
    /// What its shadow pass stores.
    pub fn depth_target(&self) -> DepthTarget {
        match self.lookup() {
            MapLookup::Cube => DepthTarget::CubeFace,
            MapLookup::Paraboloid => DepthTarget::Paraboloid,
            MapLookup::Map | MapLookup::Virtual => DepthTarget::Projected,
        }
    }

    /// How the lighting pass looks its map up.
    pub fn lookup(&self) -> MapLookup {
        MapLookup::of(&self.light, &self.settings.shadow)
    }

    /// Whether its mask pass, on the mask path, classifies its penumbrae by its map's
    /// min-max pyramid, which the frame then builds (`rays::classifies_penumbrae`).
    pub fn classifies_penumbrae(&self) -> bool {
        rays::classifies_penumbrae(self.refine, self.lookup(), rays::LightSize::of(&self.light))
    }

    /// Layers of its map.
    pub fn layers(&self) -> u32 {
        self.layout.projections.len() as u32
    }

    /// Its map's resolution: the settings', or one texel where the technique is rays
    /// and reads no map (`techniques/raytraced.rs`), which keeps its bindings valid
    /// without holding `resolution`² texels per layer for nothing; a virtual map's
    /// pool of page tiles, which is what its map texture is.
    pub fn map_resolution(&self) -> u32 {
        if let Some(pages) = &self.virtual_map {
            return pages.uniform.pool_pages_per_side * pages.uniform.page_texels;
        }
        match self.technique.rays() {
            RayUse::AsSettingsSay => self.settings.shadow.map.resolution,
            RayUse::EveryPixel => 1,
        }
    }

    /// Its map's size: [`Self::map_resolution`]² texels, one array layer per layout layer.
    pub fn map_size(&self) -> wgpu::Extent3d {
        let resolution = self.map_resolution();
        wgpu::Extent3d { width: resolution, height: resolution, depth_or_array_layers: self.layers() }
    }
}

/// Levels finer than its pixels' footprints that a virtual light's pages along
/// shadow edges may be: none unless the frame lists the pixels it traces (the mask
/// path, refinement on), whose list asks for them (`virtual_map/edges.rs`).
fn edge_levels(mask_path: bool, refine: Refine, shadow: &gnomon_scene::settings::ShadowSettings) -> u32 {
    if !mask_path {
        return 0;
    }
    match refine {
        Refine::Off => 0,
        Refine::Auto | Refine::Rays | Refine::EveryPixel => shadow.virtual_map.edge_levels,
    }
}

/// How far a technique's lookup reads on a virtual map beyond its bilinear tap
/// ([`techniques::ShadowTechnique::virtual_reach`]): a kernel in world units is as
/// many texels as the finest level makes it, at most `MAX_KERNEL_TEXELS` (the
/// shader's clamp, `virtual_kernel_width_texels`).
fn virtual_lookup_reach(
    technique: techniques::TechniqueRef,
    filter: &FilterSettings,
) -> techniques::VirtualReach {
    let kernel = match filter.kernel_unit {
        KernelUnit::Texels => filter.pcf_kernel,
        KernelUnit::World => MAX_KERNEL_TEXELS,
    };
    technique.virtual_reach(filter, kernel)
}

/// The refinement's search over the cone to a virtual light's area, which its page
/// requests ask for: where rays refine the penumbrae of a light with a size (the
/// classification's `REFINE_PENUMBRAE`), none otherwise.
fn virtual_area_search(refine: Refine, light: &Light, filter: &FilterSettings) -> Option<AreaSearch> {
    let searched = match refine {
        Refine::Rays | Refine::Auto => rays::LightSize::of(light) == rays::LightSize::Area,
        Refine::Off | Refine::EveryPixel => false,
    };
    searched
        .then(|| AreaSearch { light_size: light.emission().area.size(), cap_texels: filter.pcss.max_radius })
}

impl Renderer {
    /// The most levels finer than their footprints that the pages along shadow edges
    /// of `settings`' lights in `scene` may be ([`edge_levels`]): how many frames a
    /// still view takes to settle.
    pub(super) fn settling_frames(&self, scene: &Scene, settings: &Settings) -> Result<u32, RenderError> {
        let resolved = self.techniques.resolve_lights(settings, scene)?;
        let mask_path = settings.uses_shadow_mask(&resolved)?;
        let levels = resolved.iter().filter(|r| r.shadow.partition == Partition::Virtual).map(|r| {
            let refine = rays::light_refine(settings.light_refine(r));
            edge_levels(mask_path, refine, &r.shadow)
        });
        Ok(levels.max().unwrap_or(0))
    }

    /// Everything about a frame that is decided before recording: the camera, and
    /// each light's settings, layout (fitted, or `fixed_layout` for the reported
    /// light) and uniform.
    pub(super) async fn plan_frame(
        &mut self,
        uploaded: &GpuScene,
        scene: &Scene,
        settings: &Settings,
        fixed_layout: Option<&ShadowLayout>,
    ) -> Result<FramePlan, RenderError> {
        let camera = settings.resolve_camera(scene)?;
        let resolved = self.techniques.resolve_lights(settings, scene)?;
        let mask_path = settings.uses_shadow_mask(&resolved)?;
        let shown = if settings.light.kind == LightKind::All { settings.light.light_index } else { 0 };
        let aspect = settings.image.width as f32 / settings.image.height as f32;
        let mut lights = Vec::with_capacity(resolved.len());
        for (index, r) in resolved.into_iter().enumerate() {
            let refine = if mask_path {
                rays::light_refine(settings.light_refine(&r))
            } else {
                rays::forward_light_refine(settings.light_refine(&r))
            };
            let mut light_settings = Settings { shadow: r.shadow.clone(), ..settings.clone() };
            let lookup = MapLookup::of(&r.light, &r.shadow);
            let classified = rays::classifies_penumbrae(refine, lookup, rays::LightSize::of(&r.light));
            if classified {
                // The classification reads where the casters are (penumbra_classify.wgsl),
                // and no technique looks the map up: a rasterizer's bias would store a
                // caster seen steeply from the light behind a receiver it shadows.
                light_settings.shadow.bias = light_settings.shadow.bias.without_depth_offsets();
                // Nor may a caster nearer the light than the map's near plane be
                // pancaked onto it: a floor reaching toward a low sun would store its
                // far part flat at the near plane, where no plane of the pyramid fits
                // it, and every receiver's search through it would find a caster.
                light_settings.shadow.map.depth_clamp = false;
            }
            self.check_map_limits(&light_settings)?;
            let technique = self.techniques.check_light(&r.shadow, &r.light, &r.name)?;
            let layout = match fixed_layout {
                Some(layout) if index == shown => layout.clone(),
                _ => {
                    let fitting = LayoutFit {
                        light: &r.light,
                        settings: &light_settings,
                        technique,
                        penumbra_slope: if classified { sun_penumbra_slope(&r.light) } else { None },
                    };
                    self.fit_layout(uploaded, fitting, &camera, aspect).await?
                }
            };
            let shadow = &light_settings.shadow;
            let filterable_map = technique.filterable_map(&shadow.filter);
            let moment_format = self.moment_format(&light_settings)?;
            let precision = match moment_format {
                wgpu::TextureFormat::Rgba16Float => techniques::MapPrecision::Half,
                _ => techniques::MapPrecision::Single,
            };
            let mut light_gpu = LightGpu::new(&LightInputs {
                scene,
                light: &r.light,
                layout: &layout,
                settings: &light_settings,
                params: technique.params(&shadow.filter, precision),
                filterable_map,
            });
            if index > 0 {
                // Ambient light is added once, by the first light's pass.
                light_gpu.ambient = Vec3::ZERO;
            }
            let virtual_map = match MapLookup::of(&r.light, shadow) {
                MapLookup::Virtual => {
                    let light = VirtualLight {
                        index,
                        edge_levels: edge_levels(mask_path, refine, shadow),
                        reach: virtual_lookup_reach(technique, &shadow.filter),
                        area_search: virtual_area_search(refine, &r.light, &shadow.filter),
                    };
                    Some(self.plan_virtual(uploaded, &r.light, &light_settings, &camera, light).await?)
                }
                MapLookup::Map | MapLookup::Cube | MapLookup::Paraboloid => None,
            };
            lights.push(LightPlan {
                virtual_map,
                refine,
                name: r.name,
                light: r.light,
                settings: light_settings,
                layout,
                technique,
                filterable_map,
                moment_format,
                light_gpu,
            });
        }
        let virtual_lights: Vec<bool> = lights.iter().map(|l| l.virtual_map.is_some()).collect();
        self.virtual_lights.keep_only(&virtual_lights);
        // One light's own pass is its list: the list's walk would only add to it.
        let lighting =
            if mask_path && lights.len() > 1 { settings.screen.lighting } else { Lighting::PerLight };
        // The shader's BVH until `prepare_rays` knows what the frame traces with.
        let traversal = crate::rays::Traversal::Shader;
        Ok(FramePlan { camera, aspect, mask_path, lighting, shown, lights, traversal })
    }

    /// A light's layout fitted to the camera (and for a sun's SDSM cascades, to the
    /// depths the camera sees).
    async fn fit_layout(
        &mut self,
        uploaded: &GpuScene,
        fitting: LayoutFit<'_>,
        camera: &Camera,
        aspect: f32,
    ) -> Result<ShadowLayout, RenderError> {
        let LayoutFit { light, settings, technique, penumbra_slope } = fitting;
        let shadow = &settings.shadow;
        // SDSM fits a sun's cascades to the depths the camera sees.
        let sdsm = shadow.partition == Partition::Cascades && shadow.cascades.sdsm;
        let sampled = match light.shadow_view() {
            ShadowView::Parallel { travel } if sdsm => {
                self.sample_distribution(uploaded, travel, settings, camera, aspect).await?
            }
            ShadowView::Parallel { .. } | ShadowView::Frustum { .. } | ShadowView::Omni { .. } => None,
        };
        let unclipped_depth = self.gpu.device.features().contains(wgpu::Features::DEPTH_CLIP_CONTROL);
        let drawing = MapDrawing { technique, unclipped_depth, penumbra_slope };
        Ok(shadow_layout(&uploaded.bounds, light, camera, aspect, settings, sampled.as_ref(), drawing))
    }

    /// SDSM's sample distribution: draws the scene's depth from the camera and
    /// reduces it on the GPU to the nearest and farthest view depth seen, then, with
    /// SDSM bounds, to each cascade's light-space bounds of the samples it serves.
    /// Waits for the results, which the cascades' fit needs before the shadow pass.
    async fn sample_distribution(
        &mut self,
        uploaded: &GpuScene,
        sun_direction: Vec3,
        settings: &Settings,
        camera: &Camera,
        aspect: f32,
    ) -> Result<Option<SampleDistribution>, RenderError> {
        let gpu = self.gpu.clone();
        let clip_from_world = camera.clip_from_world(aspect);
        let (depth, pending) = gpu.checked("reducing the camera's depth (SDSM)", || {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let depth = self.camera_depth_prepass(&mut encoder, uploaded, settings, clip_from_world);
            let planes = Planes::new(camera.near, camera.far);
            let pending =
                self.passes.depth_reduce.record(&mut self.pool, &gpu.queue, &mut encoder, &depth, planes);
            gpu.queue.submit([encoder.finish()]);
            (depth, pending)
        })?;
        let Some((near, far)) = pending.read(&gpu).await? else { return Ok(None) };
        let c = &settings.shadow.cascades;
        let splits = cascade_splits(&uploaded.bounds, camera, aspect, settings, Some((near, far)));
        let light_bounds = match splits {
            Some(splits) if c.sdsm_bounds => {
                let blend = match c.cascade_selection {
                    CascadeSelection::Depth => c.cascade_blend,
                    CascadeSelection::Projection => 0.0,
                };
                let request = BoundsRequest {
                    // In f64: an f32 inverse of a perspective matrix bends rays by parts in 10⁵.
                    world_from_clip: clip_from_world.as_dmat4().inverse().as_mat4(),
                    light_from_world: directional_light_view(sun_direction, &uploaded.bounds),
                    near: camera.near,
                    far: camera.far,
                    splits: &splits,
                    blend,
                };
                let pending = gpu.checked("bounding the camera's samples in light space (SDSM)", || {
                    let mut encoder = gpu.device.create_command_encoder(&Default::default());
                    let pending = self.passes.depth_reduce.record_bounds(
                        &mut self.pool,
                        &gpu.queue,
                        &mut encoder,
                        &depth,
                        &request,
                    );
                    gpu.queue.submit([encoder.finish()]);
                    pending
                })?;
                Some(pending.read(&gpu).await?)
            }
            _ => None,
        };
        Ok(Some(SampleDistribution { near, far, light_bounds }))
    }
}

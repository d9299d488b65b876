//! A light's virtual shadow map in the frame (`--partition virtual`, issue 53): a
//! sun's, a spot's or a point light's.
//!
//! Before recording, [`Renderer::plan_virtual`] draws a depth prepass from the
//! camera, asks the GPU which pages of the clipmap its pixels read
//! (`virtual_map/page_requests.wgsl`), waits for the answer, marks stale the pages
//! that the light's turn or a moving caster changed, and grants the requests their
//! tiles in the light's kept pool ([`VirtualPages`]), coarse levels first. Recording
//! ([`Renderer::record_virtual_pages`]) clears and draws only the pages new or stale
//! this frame, neighbouring pages in neighbouring tiles as one run through one
//! projection, its casters culled against the run alone, with the shadow pass's
//! pipelines: alpha-tested casters, clusters and bias as any layer.
//! The lighting, mask and refinement passes then read the pool through the page
//! table (`virtual_map/virtual_visibility.wgsl`, `rays/refine_virtual.wgsl`).

use glam::Mat4;
use gnomon_math::{
    Aabb, spot_light_projection,
    virtual_map::{
        Clipmap, ClipmapShape, MapProjection, PageKey,
        runs::{PageRun, runs},
    },
};
use gnomon_scene::{Camera, Light, Settings, lights::ShadowView, settings::BiasSettings};

use super::Renderer;
use crate::{
    GpuScene, RenderError,
    techniques::VirtualReach,
    virtual_map::{
        AreaSearch, CameraDepth, ConeReach, EdgeFeedback, EdgeRequests, PageRequestParams, PageRequests,
        PixelReach, PoolSize, VirtualMapGpu, VirtualPages,
    },
};

/// Texels a pcf2x2 lookup and its refinement's footprint test reach from the lookup's
/// point: the bilinear 2×2 (texels from ⌊p − ½⌋ to one past it) and the test's ring
/// around it, so up to 1.5 + ring texels, and half a texel more for a level chosen
/// at a pixel's edge. (The normal offset's reach is added to it.)
const LOOKUP_REACH_TEXELS: f32 = 2.0 + crate::rays::refine::UNSURE_RING_TEXELS as f32;

/// Levels above each requested page of the coarser page asked for with it, so that a
/// pool too small for the view still holds a page over every pixel: the pool grants
/// coarse levels first, and a refused page's pixels read the nearest coarser
/// resident page (`virtual_texel` in page_lookup.wgsl). One such page stands for
/// 4³ = 64 pages below it. Asked for only when the pool has no room for every page
/// the pixels read: each covers much of the scene, so drawing it costs as much as
/// many pages.
const FALLBACK_LEVELS: u32 = 3;

/// Each light's kept pool of pages, and the request pass they share.
#[derive(Default)]
pub(super) struct VirtualLights {
    kept: Vec<Option<KeptPages>>,
    requests: Option<PageRequests>,
    /// The pass that asks for the pages along shadow edges, built on first use.
    edge_pass: Option<EdgeRequests>,
}

/// A light's pool of page tiles, and what its resident pages were drawn under.
struct KeptPages {
    pages: VirtualPages,
    drawn_under: Option<DrawnUnder>,
    /// The moving casters' bounds when the pages were last drawn: where their
    /// shadows were.
    moving_before: Vec<Aabb>,
    /// The pages along shadow edges asked for, where the light's pixels ask.
    edges: Option<EdgeFeedback>,
}

/// What every resident page's depths depend on besides its casters: any change
/// draws every page again.
#[derive(Clone, Debug, PartialEq)]
struct DrawnUnder {
    light_from_world: Mat4,
    projection: MapProjection,
    finest_texel: f32,
    levels: u32,
    near: f32,
    far: f32,
    bias: BiasSettings,
    still_generation: u64,
}

/// A virtual map's pages in one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PageStats {
    /// Pages asked for: those the pixels read, and a coarser page over each of
    /// them for their fallback.
    pub requested: u32,
    /// Pages drawn: new this frame, or stale (the light turned, a caster over them
    /// moved).
    pub drawn: u32,
    /// The runs the pages drawn were drawn in: neighbouring pages in neighbouring
    /// tiles drawn as one ([`gnomon_math::virtual_map::runs`]).
    pub runs: u32,
    /// Pages asked for and kept from an earlier frame, drawn nothing.
    pub kept: u32,
    /// Pages asked for along shadow edges, finer than the pixels' footprints
    /// (`shadow.virtual_map.edge_levels`), and granted with the others.
    pub edges: u32,
    /// Pages along shadow edges that the last frame's traced pixels asked for and no
    /// frame had before: `Some(0)` once a still view has settled; `None` where no
    /// earlier frame asked (the first since the light moved).
    pub edges_new: Option<u32>,
    /// Levels finer than the footprint's that the pages along edges may be: 0 where
    /// the light asks for none (`shadow.virtual_map.edge_levels` 0, or the frame
    /// traces no list of pixels: refinement off, or the forward path).
    pub edge_levels: u32,
    /// Pages asked for that the full pool had no tile for: their pixels read a
    /// coarser resident page (a fallback, blurrier).
    pub refused: u32,
    /// Pages resident in the pool after the frame.
    pub resident: u32,
    /// Tiles in the pool.
    pub capacity: u32,
    /// Texels per side of a page.
    pub page_size: u32,
    /// Wall-clock milliseconds from the camera prepass's recording to the requests'
    /// arrival on the CPU: the prepass, the request pass and the wait for them, a
    /// cost the shadow passes' time leaves out.
    pub request_ms: f64,
}

/// Which light a virtual map is planned for, and what its frame asks of it.
pub(super) struct VirtualLight {
    /// The light's index in the frame.
    pub index: usize,
    /// Levels finer than the footprint's that its pages along shadow edges may be;
    /// 0 where the frame lists no traced pixels.
    pub edge_levels: u32,
    /// How far its technique's lookup reads.
    pub reach: VirtualReach,
    /// The refinement's search over a sun's cone, where rays refine its penumbrae.
    pub area_search: Option<AreaSearch>,
}

/// A virtual light's frame, as decided before recording.
pub(crate) struct VirtualPlan {
    pub clipmap: Clipmap,
    /// The pages to draw (new or stale), in runs drawn as one.
    pub runs: Vec<PageRun>,
    /// The sampling passes' uniform.
    pub uniform: VirtualMapGpu,
    /// The page table's words (`TableEntry`).
    pub table: Vec<u32>,
    /// Whether the pool keeps nothing this frame (every resident page drawn or
    /// stale): its pages were laid out anew for drawing in runs
    /// ([`gnomon_math::virtual_map::pages::PagePool::pack`]), and the layers they
    /// are drawn into are cleared by their passes' loads, not tile by tile.
    pub clear_layers: bool,
    /// The parameters of the pass that asks for the pages along shadow edges after
    /// the light's trace pass; `None` where `edge_levels` is 0.
    pub edge_params: Option<PageRequestParams>,
    pub stats: PageStats,
}

/// A virtual map's clipmap levels as a frame reports them
/// ([`crate::Frame::virtual_levels`]): each level's whole window as a layer, and what
/// picks a pixel's level, so that what measures a cascade's texels per pixel
/// measures a level's.
#[derive(Clone, Debug, PartialEq)]
pub struct VirtualLevels {
    /// The projection of the window of each of the clipmap's layers
    /// ([`Clipmap::layer_window`]): each level's window, finest first; for a point
    /// light, each level's six faces.
    pub projections: Vec<gnomon_math::LightProjection>,
    /// The frame's clipmap: a pixel reads the level [`Clipmap::level_for_point`]
    /// gives its footprint (along shadow edges, up to
    /// `shadow.virtual_map.edge_levels` finer).
    pub clipmap: Clipmap,
    /// A pixel's footprint in world units per unit of view depth, as the page
    /// requests take it (the lod bias included).
    pub footprint_per_depth: f32,
    /// Texels per side of each layer's window.
    pub resolution: u32,
}

impl VirtualPlan {
    /// The clipmap's levels, as the frame reports them.
    pub fn levels(&self) -> VirtualLevels {
        let clipmap = &self.clipmap;
        let side = clipmap.shape.pages_per_side();
        let projections = clipmap
            .layers()
            .iter()
            .map(|layer| clipmap.rect_projection(&clipmap.layer_window(layer)))
            .collect();
        VirtualLevels {
            projections,
            clipmap: clipmap.clone(),
            footprint_per_depth: self.uniform.footprint_per_depth,
            resolution: side * clipmap.shape.page_size,
        }
    }
}

impl Renderer {
    /// A virtual light's pages for this frame: requested by the pixels of a camera
    /// prepass over their filter's reach, and along shadow edges by the pixels the
    /// last frames traced, granted in the light's pool. Waits for the requests.
    pub(super) async fn plan_virtual(
        &mut self,
        uploaded: &GpuScene,
        light: &Light,
        settings: &Settings,
        camera: &Camera,
        VirtualLight { index, edge_levels, reach, area_search }: VirtualLight,
    ) -> Result<VirtualPlan, RenderError> {
        let started = web_time::Instant::now();
        let gpu = self.gpu.clone();
        let (width, height) = (settings.image.width, settings.image.height);
        let aspect = width as f32 / height as f32;
        // A pixel's footprint per unit of view depth, each level of bias halving the
        // texels it reads (and so the level its footprint picks).
        let lod_bias = settings.shadow.virtual_map.lod_bias;
        let footprint_per_depth =
            2.0 * (0.5 * camera.fov_y_degrees.to_radians()).tan() / height as f32 / (1u32 << lod_bias) as f32;
        // The farthest pixel the camera can see: at the scene's farthest corner.
        let farthest = uploaded.bounds.corners().iter().map(|c| c.distance(camera.eye)).fold(0.0, f32::max);
        let shape = ClipmapShape {
            virtual_resolution: settings.shadow.virtual_map.level_resolution,
            ..ClipmapShape::DEFAULT
        };
        let clipmap = match light.shadow_view() {
            ShadowView::Parallel { travel } => {
                Clipmap::new(shape, travel, camera.eye, &uploaded.bounds, farthest * footprint_per_depth)
            }
            // The spot's 2D map's frustum, paged: the same depths where both have texels.
            ShadowView::Frustum { position, axis, half_angle, near, far } => {
                let frustum = spot_light_projection(position, axis, half_angle, near, far);
                Clipmap::spot(shape, frustum.light_from_world, half_angle.tan(), near, far)
            }
            // Six spot-like chains round the cube map's faces, from the same range.
            ShadowView::Omni { position, near, far } => Clipmap::point(shape, position, near, far),
        };
        let (filter_reach_texels, cone) = match reach {
            VirtualReach::Texels(texels) => (texels, None),
            // A search over a cone reaches at least a texel round the receiver, even
            // where the light has no size and its cone none.
            VirtualReach::Cone { level_cap, reach_cap } => {
                let light_size = light.emission().area.size();
                let cone = (light_size > 0.0).then_some(ConeReach {
                    light_size,
                    level_cap_texels: level_cap,
                    reach_cap_texels: reach_cap,
                });
                (1.0, cone)
            }
        };
        let reach = PixelReach {
            footprint_per_depth,
            reach_texels: LOOKUP_REACH_TEXELS + filter_reach_texels + settings.shadow.bias.normal_offset,
            area_search,
            cone,
        };
        let clip_from_world = camera.clip_from_world(aspect);
        let depth = gpu.checked("drawing the camera's depth for a virtual map's pages", || {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let depth = self.camera_depth_prepass(&mut encoder, uploaded, settings, clip_from_world);
            gpu.queue.submit([encoder.finish()]);
            depth
        })?;
        if self.virtual_lights.requests.is_none() {
            self.virtual_lights.requests = Some(PageRequests::new(&gpu)?);
        }
        let requests = self.virtual_lights.requests.as_mut().expect("made above");
        let camera_depth =
            CameraDepth { depth: &depth, clip_from_world, view_from_world: camera.view_from_world() };
        let requested = requests.request_from_depth(&gpu, camera_depth, &clipmap, reach).await?;
        let request_ms = started.elapsed().as_secs_f64() * 1e3;
        let size = PoolSize::new(shape.page_size, settings.shadow.virtual_map.pool_side);
        // A pool with room for every page asked for needs no fallback; one without
        // grants the coarse fallbacks first. (A coarse page covers much of the scene:
        // drawing fallbacks nobody reads would cost as much as the pages read.)
        let capacity = size.pages_per_side * size.pages_per_side;
        let requested = if requested.len() > capacity as usize {
            with_fallbacks(requested, clipmap.shape.levels)
        } else {
            requested
        };
        if edge_levels > 0 && self.virtual_lights.edge_pass.is_none() {
            self.virtual_lights.edge_pass = Some(EdgeRequests::new(&gpu, &self.layouts.trace_screen)?);
        }
        let kept = self.virtual_lights.kept_for(&gpu, index, size)?;
        let under = DrawnUnder {
            light_from_world: clipmap.light_from_world,
            projection: clipmap.projection,
            finest_texel: clipmap.finest_texel,
            levels: clipmap.shape.levels,
            near: clipmap.near,
            far: clipmap.far,
            bias: settings.shadow.bias.clone(),
            still_generation: uploaded.still_generation,
        };
        let moved = kept.mark_stale(under, &clipmap, uploaded.moving_caster_bounds());
        let edges = kept
            .edge_pages(&gpu, &clipmap, EdgeAsk { edge_levels, moved, requested: &requested, capacity })
            .await?;
        let asked = requested.len() as u32;
        let mut requested = requested;
        requested.extend(&edges.pages);
        let mut allocation = kept.pages.allocate(&requested);
        let clear_layers = kept.pages.pack(&mut allocation);
        let table = kept.pages.page_table(&clipmap).iter().map(|entry| entry.0).collect();
        let uniform = VirtualMapGpu::new(&clipmap, size, footprint_per_depth, edge_levels);
        let edge_params =
            (edge_levels > 0).then(|| PageRequestParams::new(&clipmap, reach, (width, height), edge_levels));
        let to_draw: Vec<_> = allocation.to_draw().copied().collect();
        let runs = runs(&to_draw, size.pages_per_side, |page| clipmap.starts_layer(page));
        let drawn = to_draw.len() as u32;
        let stats = PageStats {
            requested: asked,
            edges: edges.pages.len() as u32,
            edges_new: edges.new,
            edge_levels,
            drawn,
            runs: runs.len() as u32,
            kept: allocation.granted.len() as u32 - drawn,
            refused: allocation.refused.len() as u32,
            resident: kept.pages.resident() as u32,
            capacity,
            page_size: size.page_size,
            request_ms,
        };
        Ok(VirtualPlan { clipmap, runs, uniform, table, clear_layers, edge_params, stats })
    }
}

/// `requested` with each page's ancestor [`FALLBACK_LEVELS`] levels up (or at the
/// coarsest of `levels`), each page once, in order.
fn with_fallbacks(mut requested: Vec<PageKey>, levels: u32) -> Vec<PageKey> {
    let fallbacks: Vec<_> = requested
        .iter()
        .map(|&page| {
            let mut coarse = page;
            while coarse.level < (page.level + FALLBACK_LEVELS).min(levels - 1) {
                coarse = coarse.coarser();
            }
            coarse
        })
        .collect();
    requested.extend(fallbacks);
    requested.sort_unstable();
    requested.dedup();
    requested
}

/// What a frame asks of a light's pages along shadow edges ([`KeptPages::edge_pages`]).
struct EdgeAsk<'a> {
    /// Levels finer than the footprint's the pages may be; 0 asks for none.
    edge_levels: u32,
    /// Whether the light or the map's levels changed since the last frame.
    moved: bool,
    /// The pages the pixels ask for, in [`PageKey`] order.
    requested: &'a [PageKey],
    /// Tiles in the pool.
    capacity: u32,
}

/// The pages along shadow edges a frame draws with those its pixels ask for.
struct EdgePages {
    /// Those not asked for already, coarse levels first, as many as the pool has
    /// room for.
    pages: Vec<PageKey>,
    /// How many pages the last frame's traced pixels added ([`PageStats::edges_new`]).
    new: Option<u32>,
}

impl KeptPages {
    /// The pages along shadow edges to draw this frame: those the traced pixels of
    /// the frames since the light last moved asked for, read back from the last
    /// frame's pass. None when the light moved (they are forgotten), when `edge_levels`
    /// is 0, or when the pool has no room left.
    async fn edge_pages(
        &mut self,
        gpu: &crate::Gpu,
        clipmap: &Clipmap,
        ask: EdgeAsk<'_>,
    ) -> Result<EdgePages, RenderError> {
        if ask.edge_levels == 0 {
            self.edges = None;
            return Ok(EdgePages { pages: vec![], new: None });
        }
        let edges = match &mut self.edges {
            Some(edges) if edges.fits(clipmap) => edges,
            slot => slot.insert(EdgeFeedback::new(gpu, clipmap)),
        };
        if ask.moved {
            edges.forget();
        }
        let new = edges.collect(gpu).await?;
        let room = (ask.capacity as usize).saturating_sub(ask.requested.len());
        Ok(EdgePages { pages: edges.pages_to_add(clipmap, ask.requested, room), new })
    }

    /// The light's pages along shadow edges, where it has any.
    pub(super) fn edge_feedback(&mut self) -> Option<&mut EdgeFeedback> {
        self.edges.as_mut()
    }

    /// Marks stale every resident page when what they were drawn under changed
    /// (`under`), and those under a moving caster (bounds `moving`), where it was
    /// and where it is. Returns whether what they were drawn under changed.
    fn mark_stale(&mut self, under: DrawnUnder, clipmap: &Clipmap, moving: Vec<Aabb>) -> bool {
        let moved = self.drawn_under.as_ref() != Some(&under);
        if moved {
            self.pages.invalidate_all();
        }
        self.drawn_under = Some(under);
        let levels = clipmap.shape.levels;
        let stale: Vec<_> = moving
            .iter()
            .chain(&self.moving_before)
            .flat_map(|bounds| (0..levels).flat_map(|level| clipmap.pages_under(level, bounds)))
            .collect();
        if !stale.is_empty() {
            self.pages.invalidate(|page| stale.iter().any(|rect| rect.contains(page)));
        }
        self.moving_before = moving;
        moved
    }
}

impl VirtualLights {
    /// Light `index`'s pool, made (or made again) at `size`.
    fn kept_for(
        &mut self,
        gpu: &crate::Gpu,
        index: usize,
        size: PoolSize,
    ) -> Result<&mut KeptPages, RenderError> {
        if self.kept.len() <= index {
            self.kept.resize_with(index + 1, || None);
        }
        let slot = &mut self.kept[index];
        if slot.as_ref().is_none_or(|k| k.pages.size() != size) {
            *slot = Some(KeptPages {
                pages: VirtualPages::new(gpu, size)?,
                drawn_under: None,
                moving_before: vec![],
                edges: None,
            });
        }
        Ok(slot.as_mut().expect("made above"))
    }

    /// Light `index`'s pool, planned this frame.
    pub fn pages(&mut self, index: usize) -> &mut VirtualPages {
        &mut self.kept[index].as_mut().expect("planned this frame").pages
    }

    /// The edge-page pass and light `index`'s feedback, where the light asks for
    /// pages along edges this frame (its plan built the pass).
    pub fn edge_pass(&mut self, index: usize) -> Option<(&mut EdgeRequests, &mut EdgeFeedback)> {
        let feedback = self.kept.get_mut(index)?.as_mut()?.edge_feedback()?;
        Some((self.edge_pass.as_mut()?, feedback))
    }

    /// Forgets the pools of the lights past the first `lights`, and of those not
    /// virtual this frame (`virtual_lights[i]` false), once a frame; the edge-page
    /// pass's uniforms of the last frame may be handed out again.
    pub fn keep_only(&mut self, virtual_lights: &[bool]) {
        if let Some(pass) = &mut self.edge_pass {
            pass.end_frame();
        }
        self.kept.truncate(virtual_lights.len());
        for (kept, &is_virtual) in self.kept.iter_mut().zip(virtual_lights) {
            if !is_virtual {
                *kept = None;
            }
        }
    }
}

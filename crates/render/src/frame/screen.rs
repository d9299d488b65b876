//! The mask path's screen-space passes: a depth-and-normal prepass from the camera,
//! then one shadow-mask pass per light (the technique's lookup and contact shadows,
//! per pixel) into its layer of the mask, which the lighting passes then read; where
//! a light refines its shadow by rays, its trace pass follows its mask pass.

use super::{
    Renderer,
    bindings::CameraDraws,
    penumbra_history::HistoryFrame,
    plan::{FramePlan, LightPlan},
    recording::{LightBindings, Recording},
    virtual_record::EdgeList,
};
use crate::{
    GpuScene,
    passes::screen_space::{self, MaskKey},
    pool::{Binding, ViewKey},
    rays::{HISTORY_FORMAT, LightSize, ListAccess, RefineLists, TraceGroups, TraceStage, Traversal},
    timing::PassKind,
};
use gnomon_math::screen_bounds::PixelRect;
use gnomon_scene::settings::Refine;

/// What the screen-space passes draw into and read.
/// What the mask path's passes leave for the lighting passes and the frame.
pub(super) struct ScreenOutputs {
    /// The refinement's lists, whose counters say how many pixels each light traced.
    pub lists: Option<RefineLists>,
    /// Group 1 of the lighting passes on the mask path: the camera and the prepass's
    /// surface, normals and object, the surface each pixel shades (seen_prepass.wgsl).
    pub surface_group: wgpu::BindGroup,
}

pub(super) struct ScreenInputs<'a> {
    /// What the camera sees, and how its draws go out.
    pub camera: &'a CameraDraws<'a>,
    pub camera_buffer: &'a wgpu::Buffer,
    pub camera_group: &'a wgpu::BindGroup,
    /// The lighting passes' depth buffer, which the prepass fills.
    pub depth: &'a wgpu::TextureView,
    /// One layer of the mask per light.
    pub mask_layers: &'a [wgpu::TextureView],
    /// The pixels each light's mask pass covers; `None` for none.
    pub mask_rects: Vec<Option<PixelRect>>,
    /// Each light's penumbra history, for those whose mask pass classifies their
    /// penumbrae.
    pub histories: &'a [Option<HistoryFrame>],
    pub mask_start: MaskStart,
}

/// Groups 1 and 3 of a light's mask pass.
struct MaskScreen<'a> {
    group: &'a wgpu::BindGroup,
    /// The light's counters in the group of a refining pass; none in the plain one.
    counter_offset: Option<u32>,
    /// Its penumbra history, read and written, where it classifies penumbrae.
    history: Option<wgpu::BindGroup>,
}

/// A frame's refinement by rays: the lists, group 1 as the mask passes (which
/// append) and the trace passes (which read) bind it, and the copy of a light's layer
/// of the mask that its penumbra filter reads.
struct Refining {
    lists: RefineLists,
    append: wgpu::BindGroup,
    read: wgpu::BindGroup,
    traced: wgpu::TextureView,
    /// Written in place of a penumbra history by the trace passes of lights that keep
    /// none.
    no_history: wgpu::TextureView,
}

/// Where a light's mask pass draws: its layer of the mask and the pixels of it that
/// the pass covers.
struct MaskTarget<'a> {
    layer: &'a wgpu::TextureView,
    rect: Option<PixelRect>,
    start: MaskStart,
}

/// What a light's layer of the mask holds outside the pixels its pass covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum MaskStart {
    /// Lit: the per-light lighting passes read every pixel of every layer.
    Clear,
    /// Whatever it held: the light list reads a layer only in the tiles that list its
    /// light, which the pass covers, so the clear would be wasted (a layer's worth of
    /// writes per light).
    Keep,
}

/// What a penumbra fill copies: the light's layer of the mask (a view of one layer
/// of the frame's mask texture) into the frame's `traced` texture.
struct PenumbraCopy<'a> {
    layer: &'a wgpu::TextureView,
    traced: &'a wgpu::TextureView,
}

/// A cleared colour attachment.
fn cleared(view: &wgpu::TextureView, clear: wgpu::Color) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store },
    })
}

impl Renderer {
    /// The depth-and-normal prepass into `inputs.depth`, then each light's mask pass
    /// into its layer of the mask, followed, where the light refines its shadow by
    /// rays, by its trace pass. Returns the refinement's lists, whose counters say
    /// how many pixels each light traced, and the group of the prepass's outputs,
    /// which the lighting passes shade from.
    pub(super) fn record_screen_space(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        plan: &FramePlan,
        lit: &[LightBindings],
        inputs: &ScreenInputs,
    ) -> ScreenOutputs {
        let (width, height) = (inputs.depth.texture().width(), inputs.depth.texture().height());
        let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let normals = self.pool.texture("prepass normals", size, screen_space::NORMALS_FORMAT, usage);
        let normals = self.pool.view(&normals, ViewKey::default());
        let surface = self.pool.texture("prepass surface", size, screen_space::SURFACE_FORMAT, usage);
        let surface = self.pool.view(&surface, ViewKey::default());
        let object = self.pool.texture("prepass object", size, screen_space::OBJECT_FORMAT, usage);
        let object = self.pool.view(&object, ViewKey::default());
        self.record_prepass(rec, uploaded, &lit[0].scene, inputs, [&normals, &surface, &object]);
        let screen_group = self.pool.bind_group(
            "screen",
            &self.layouts.screen,
            &[
                Binding::Buffer(inputs.camera_buffer.clone()),
                Binding::View(surface.clone()),
                Binding::View(normals.clone()),
                Binding::View(object.clone()),
            ],
        );
        // The list of unsure pixels and each light's counters, cleared: zero
        // workgroups until a mask pass lists a pixel.
        let refining =
            plan.lights.iter().any(|l| l.refine != Refine::Off).then(|| {
                self.refining(rec, size, plan.lights.len(), inputs.camera_buffer, [&surface, &normals])
            });
        for (index, ((light, bindings), layer)) in
            plan.lights.iter().zip(lit).zip(inputs.mask_layers).enumerate()
        {
            let refined = match (&refining, light.refine) {
                (_, Refine::Off) | (None, _) => None,
                (Some(refining), Refine::Auto | Refine::Rays | Refine::EveryPixel) => Some(refining),
            };
            let history = inputs.histories[index].as_ref();
            let history_views = history
                .map(|h| [&h.read, &h.write].map(|texture| self.pool.view(texture, ViewKey::default())));
            let screen = match refined {
                Some(refining) => MaskScreen {
                    group: &refining.append,
                    counter_offset: Some(RefineLists::counter_offset(index as u32)),
                    history: history_views.as_ref().map(|[read, write]| {
                        self.pool.bind_group(
                            "penumbra history",
                            &self.layouts.penumbra_history,
                            &[Binding::View(read.clone()), Binding::View(write.clone())],
                        )
                    }),
                },
                None => MaskScreen { group: &screen_group, counter_offset: None, history: None },
            };
            // A penumbra fill reads the neighbours of its pixels, which may lie outside
            // the light's rectangle: they must hold this frame's values.
            let start = match refined {
                Some(_) if light.light_gpu.rays.penumbra_rays > 0 => MaskStart::Clear,
                Some(_) | None => inputs.mask_start,
            };
            let target = MaskTarget { layer, rect: inputs.mask_rects[index], start };
            self.record_mask(rec, light, bindings, target, &screen, index as u32);
            if let Some(Refining { lists, read, traced, no_history, .. }) = refined {
                let written = history_views.as_ref().map_or(no_history, |[_, write]| write);
                let mask = RefineLists::mask_group(&mut self.pool, &self.layouts, layer, traced, written);
                let bvh = uploaded.rays().expect("the casters' BVH, built when the frame was planned");
                let size = LightSize::of(&light.light);
                // A light with an area is beamed, which walks the shader's BVH whatever
                // traces the hard rays (penumbra_beam.wgsl).
                let traversal = match size {
                    LightSize::Hard => plan.traversal,
                    LightSize::Area => Traversal::Shader,
                };
                let groups = TraceGroups {
                    scene: &bindings.scene,
                    screen: read,
                    mask: &mask,
                    bvh: bvh.group(traversal),
                    traversal,
                    size,
                    counters: &lists.counters,
                };
                self.record_trace(rec, TraceStage::Trace, &groups, index as u32);
                if history.is_some() {
                    self.record_penumbra_fill(rec, &groups, PenumbraCopy { layer, traced }, index as u32);
                }
                if let Some(plan) = &light.virtual_map {
                    let list = EdgeList { screen: read, counters: &lists.counters };
                    self.record_edge_requests(rec, plan, list, index as u32);
                }
            }
        }
        ScreenOutputs { lists: refining.map(|refining| refining.lists), surface_group: screen_group }
    }

    /// The list of unsure pixels and each light's counters, cleared (zero workgroups
    /// until a mask pass lists a pixel), their groups over the camera and the
    /// prepass's `surface` and `normals`, and the traced mask.
    fn refining(
        &mut self,
        rec: &mut Recording,
        size: wgpu::Extent3d,
        lights: usize,
        camera: &wgpu::Buffer,
        prepass: [&wgpu::TextureView; 2],
    ) -> Refining {
        let lists = RefineLists::new(&mut self.pool, size.width, size.height, lights);
        rec.encoder.clear_buffer(&lists.counters, 0, None);
        let append = lists.group(&mut self.pool, &self.layouts, ListAccess::Append, camera, prepass);
        let read = lists.group(&mut self.pool, &self.layouts, ListAccess::Read, camera, prepass);
        let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
        let traced = self.pool.texture("traced shadow mask", size, screen_space::MASK_FORMAT, usage);
        let traced = self.pool.view(&traced, ViewKey::default());
        let one = wgpu::Extent3d { width: 1, height: 1, depth_or_array_layers: 1 };
        let no_history = self.pool.texture(
            "no penumbra history",
            one,
            HISTORY_FORMAT,
            wgpu::TextureUsages::STORAGE_BINDING,
        );
        let no_history = self.pool.view(&no_history, ViewKey::default());
        Refining { lists, append, read, traced, no_history }
    }

    /// Light `index`'s mask pass into its `target` layer of the mask, with group 1
    /// `screen`. Pixels outside the target's rectangle are not the light's to shade:
    /// it cannot reach them.
    fn record_mask(
        &mut self,
        rec: &mut Recording,
        light: &LightPlan,
        bindings: &LightBindings,
        target: MaskTarget,
        screen: &MaskScreen,
        index: u32,
    ) {
        let gpu = &self.gpu;
        let mask_group = bindings.mask.as_ref().expect("a mask pass group on the mask path");
        let slot = rec.clock.begin(gpu, rec.encoder, PassKind::Mask, Some(index), None);
        let mut pass = rec.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shadow mask"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target.layer,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: match target.start {
                        MaskStart::Clear => wgpu::LoadOp::Clear(wgpu::Color::WHITE),
                        MaskStart::Keep => wgpu::LoadOp::Load,
                    },
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: rec.clock.render_writes(slot),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let key = MaskKey {
            technique: light.technique,
            lookup: bindings.lookup,
            refine: light.refine,
            size: LightSize::of(&light.light),
        };
        pass.set_pipeline(self.passes.screen_space.mask(&gpu.device, key));
        pass.set_bind_group(0, &bindings.scene, &[]);
        pass.set_bind_group(1, screen.group, screen.counter_offset.as_slice());
        pass.set_bind_group(2, mask_group, &[]);
        if let Some(history) = &screen.history {
            pass.set_bind_group(3, history, &[]);
        }
        rec.stats.pipeline_changes += 1;
        rec.stats.bind_group_changes += 3 + u32::from(screen.history.is_some());
        if let Some(rect) = target.rect {
            pass.set_scissor_rect(rect.x, rect.y, rect.width, rect.height);
            pass.draw(0..3, 0..1);
        }
        drop(pass);
        rec.clock.end(gpu, rec.encoder, slot);
    }

    /// Light `index`'s `stage` over the pixels its mask pass listed (the trace: a ray
    /// for each), timed as trace work.
    fn record_trace(&mut self, rec: &mut Recording, stage: TraceStage, groups: &TraceGroups, index: u32) {
        let gpu = &self.gpu;
        let slot = rec.clock.begin(gpu, rec.encoder, PassKind::Trace, Some(index), None);
        let mut pass = rec.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(stage.label()),
            timestamp_writes: rec.clock.compute_writes(slot),
        });
        self.passes
            .trace
            .get(&gpu.device, &self.layouts, groups.traversal, groups.size)
            .record(&mut pass, stage, groups, index);
        rec.stats.pipeline_changes += 1;
        rec.stats.bind_group_changes += 4;
        drop(pass);
        rec.clock.end(gpu, rec.encoder, slot);
    }

    /// Light `index`'s penumbra fill, after its trace pass under a light with an area
    /// whose penumbrae its mask pass classified: its layer of the mask is copied as
    /// traced, then each unsure pixel no beam answered takes the mean of its answered
    /// neighbours on the same surface in that copy.
    fn record_penumbra_fill(
        &mut self,
        rec: &mut Recording,
        groups: &TraceGroups,
        copy: PenumbraCopy,
        index: u32,
    ) {
        let (mask, traced) = (copy.layer.texture(), copy.traced.texture());
        rec.encoder.copy_texture_to_texture(
            wgpu::TexelCopyTextureInfo {
                texture: mask,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: 0, z: index },
                aspect: wgpu::TextureAspect::All,
            },
            traced.as_image_copy(),
            wgpu::Extent3d { width: traced.width(), height: traced.height(), depth_or_array_layers: 1 },
        );
        self.record_trace(rec, TraceStage::PenumbraFill, groups, index);
    }

    /// The camera's depth, normals, surface (world point and view depth) and object.
    fn record_prepass(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        scene_group: &wgpu::BindGroup,
        inputs: &ScreenInputs,
        [normals, surface, object]: [&wgpu::TextureView; 3],
    ) {
        let gpu = &self.gpu;
        let slot = rec.clock.begin(gpu, rec.encoder, PassKind::Prepass, None, None);
        // View depth 0 (the surface's w) marks the background.
        let mut pass = rec.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("prepass"),
            color_attachments: &[
                cleared(normals, wgpu::Color::TRANSPARENT),
                cleared(surface, wgpu::Color::TRANSPARENT),
                cleared(object, wgpu::Color::TRANSPARENT),
            ],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: inputs.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: rec.clock.render_writes(slot),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(self.passes.screen_space.prepass(&gpu.device));
        // The light plays no part in the prepass; any light's group carries the
        // instances.
        pass.set_bind_group(0, scene_group, &[]);
        pass.set_bind_group(1, inputs.camera_group, &[]);
        rec.stats.pipeline_changes += 1;
        rec.stats.bind_group_changes += 2;
        let camera = inputs.camera;
        let (draws, binds) = uploaded.draw_visible(&mut pass, camera.visible, 3, camera.arguments.as_ref());
        rec.stats.prepass_draws += draws;
        rec.stats.bind_group_changes += binds;
        drop(pass);
        rec.clock.end(gpu, rec.encoder, slot);
    }

    /// One layer of the shadow mask per light of `plan`, writable by the trace passes
    /// (and copied by the penumbra filters) where a light refines by rays.
    pub(super) fn mask_layers(
        &mut self,
        plan: &FramePlan,
        width: u32,
        height: u32,
    ) -> Vec<wgpu::TextureView> {
        let refining = plan.lights.iter().any(|l| l.refine != Refine::Off);
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        // The trace passes write it; a penumbra filter copies a layer of it first.
        let writable = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_SRC;
        let usage = if refining { usage | writable } else { usage };
        let lights = plan.lights.len() as u32;
        let mask = self.pool.texture(
            "shadow mask",
            wgpu::Extent3d { width, height, depth_or_array_layers: lights },
            screen_space::MASK_FORMAT,
            usage,
        );
        (0..lights).map(|layer| self.pool.view(&mask, ViewKey::layer(layer))).collect()
    }
}

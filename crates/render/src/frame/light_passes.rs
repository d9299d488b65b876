//! The lighting passes: the targets they write, and either one pass per light (each
//! drawing the scene again and adding its light) or, on the mask path, one pass over
//! the tiled light list ([`crate::passes::light_list`]) that sums them all. On the
//! mask path each light's mask pass covers only the pixels its range can reach: the
//! rectangle its tiles list it in.

use gnomon_math::screen_bounds::{PerspectiveCamera, PixelRect, Viewport};
use gnomon_scene::settings::{Lighting, Refine};

use super::{
    Renderer,
    bindings::CameraDraws,
    plan::FramePlan,
    recording::{LightBindings, Recording},
};
use crate::{
    GpuScene,
    passes::{
        light_list::{LightListGpu, LightTiles, Reach},
        lighting::{self, LightingKey, LightingRole, Lookup},
    },
    pool::{Binding, ViewKey},
    rays::LightSize,
    timing::PassKind,
};

/// The camera-sized render targets of the lighting passes.
pub(super) struct LightingTargets {
    /// One per `lighting::TARGETS`, the colour image first.
    pub textures: Vec<wgpu::Texture>,
    pub views: Vec<wgpu::TextureView>,
    pub depth: wgpu::TextureView,
}

/// What every light's lighting pass shares.
pub(super) struct SharedLighting<'a> {
    pub plan: &'a FramePlan,
    pub camera_group: &'a wgpu::BindGroup,
    /// On the forward path, where a light traces rays in its lighting pass: the
    /// camera's group with the casters' BVH.
    pub tracing_group: Option<&'a wgpu::BindGroup>,
    pub targets: &'a LightingTargets,
    /// What the camera sees, and how its draws go out.
    pub camera: &'a CameraDraws<'a>,
    /// On the mask path: every light's layer of the mask, and the tiles' light lists.
    pub masks: Option<MaskInputs<'a>>,
}

/// What the lighting on the mask path reads besides each light's groups.
#[derive(Clone, Copy)]
pub(super) struct MaskInputs<'a> {
    /// The whole mask, a layer per light.
    pub mask: &'a wgpu::TextureView,
    pub tiles: &'a LightTiles,
    /// Group 1 of the lighting passes here: the camera and the prepass's outputs.
    pub surface_group: &'a wgpu::BindGroup,
}

/// Background colour of the image, linear RGB.
const SKY: wgpu::Color = wgpu::Color { r: 0.42, g: 0.55, b: 0.72, a: 1.0 };

/// How a lighting pass starts on the targets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum TargetStart {
    /// Cleared: the colour image to the sky, the data targets to zero (object id 0
    /// marks the background).
    Clear,
    /// With what earlier lights wrote, to add to.
    Keep,
}

/// The colour attachments of a lighting pass, in `lighting::TARGETS` order.
fn target_attachments(
    targets: &LightingTargets,
    start: TargetStart,
) -> Vec<Option<wgpu::RenderPassColorAttachment<'_>>> {
    targets
        .views
        .iter()
        .enumerate()
        .map(|(i, view)| {
            let clear = if i == 0 { SKY } else { wgpu::Color::TRANSPARENT };
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: match start {
                        TargetStart::Clear => wgpu::LoadOp::Clear(clear),
                        TargetStart::Keep => wgpu::LoadOp::Load,
                    },
                    store: wgpu::StoreOp::Store,
                },
            })
        })
        .collect()
}

impl FramePlan {
    /// The frame's camera as the screen bounds of lights see it.
    pub fn perspective(&self, viewport: Viewport) -> PerspectiveCamera {
        PerspectiveCamera {
            view_from_world: self.camera.view_from_world(),
            fov_y: self.camera.fov_y_degrees.to_radians(),
            near: self.camera.near,
            viewport,
        }
    }

    /// Which tiles of a `viewport` image each light can reach.
    pub fn light_tiles(&self, viewport: Viewport) -> LightTiles {
        let reaches: Vec<Reach> = self.lights.iter().map(|l| Reach::of(&l.light)).collect();
        LightTiles::new(&self.perspective(viewport), &reaches)
    }

    /// The pixels light `index`'s mask pass covers: those its range reaches, or every
    /// pixel for the reported light, whose visibility the frame writes out whole.
    pub fn mask_rect(&self, tiles: &LightTiles, index: usize, viewport: Viewport) -> Option<PixelRect> {
        if index == self.shown { Some(PixelRect::whole(viewport)) } else { tiles.rects[index] }
    }
}

impl Renderer {
    /// Every light's lighting: one pass over the light list, or a pass per light.
    pub(super) fn record_lights(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        shared: &SharedLighting,
        lit: &[LightBindings],
    ) {
        match (shared.plan.lighting, shared.masks) {
            (Lighting::LightList, Some(masks)) => {
                self.record_light_list(rec, uploaded, shared, &lit[0], masks)
            }
            (Lighting::LightList, None) | (Lighting::PerLight, _) => {
                for (index, bindings) in lit.iter().enumerate() {
                    self.record_lighting(rec, uploaded, shared, index, bindings);
                }
            }
        }
    }

    /// The one lighting pass of the mask path's light list: the scene drawn once,
    /// each pixel summing the lights its tile lists. `first` holds the instances and
    /// the first light's uniform.
    fn record_light_list(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        shared: &SharedLighting,
        first: &LightBindings,
        masks: MaskInputs,
    ) {
        let plan = shared.plan;
        let gpu = self.gpu.clone();
        let emitters: Vec<crate::uniforms::EmitterGpu> =
            plan.lights.iter().map(|l| l.light_gpu.emitter).collect();
        let uniform = LightListGpu {
            ambient: plan.lights[0].light_gpu.ambient,
            shown: plan.shown as u32,
            tiles_x: masks.tiles.tiles_x,
            ..Default::default()
        };
        let uniform = self.pool.uniform(&gpu.queue, "light list", &uniform);
        let none = wgpu::BufferUsages::empty();
        let emitters = self.pool.storage(&gpu.queue, "light list emitters", &emitters, none);
        let bits = self.pool.storage(&gpu.queue, "light list tiles", &masks.tiles.bits, none);
        let group = self.pool.bind_group(
            "light list",
            &self.passes.light_list.group_layout,
            &[
                Binding::Buffer(uniform),
                Binding::Buffer(emitters),
                Binding::Buffer(bits),
                Binding::View(masks.mask.clone()),
            ],
        );
        let attachments = target_attachments(shared.targets, TargetStart::Clear);
        let slot = rec.clock.begin(&gpu, rec.encoder, PassKind::Lighting, None, None);
        let mut pass = rec.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("light list"),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &shared.targets.depth,
                // The prepass drew it.
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Discard }),
                stencil_ops: None,
            }),
            timestamp_writes: rec.clock.render_writes(slot),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(self.passes.light_list.pipeline(&gpu.device));
        pass.set_bind_group(0, &first.scene, &[]);
        pass.set_bind_group(1, masks.surface_group, &[]);
        pass.set_bind_group(2, &group, &[]);
        rec.stats.pipeline_changes += 1;
        rec.stats.bind_group_changes += 3;
        let camera = shared.camera;
        let (draws, binds) = uploaded.draw_visible(&mut pass, camera.visible, 3, camera.arguments.as_ref());
        rec.stats.lighting_draws += draws;
        rec.stats.lighting_instances += camera.visible.instances();
        rec.stats.bind_group_changes += binds;
        drop(pass);
        rec.clock.end(&gpu, rec.encoder, slot);
    }

    /// The colour and data targets of the lighting passes, and their depth buffer.
    pub(super) fn lighting_targets(&mut self, width: u32, height: u32) -> LightingTargets {
        let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let textures: Vec<wgpu::Texture> = lighting::TARGETS
            .iter()
            .map(|&format| {
                let usage = attachment | wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::TEXTURE_BINDING;
                self.pool.texture("render target", size, format, usage)
            })
            .collect();
        let views = textures.iter().map(|t| self.pool.view(t, ViewKey::default())).collect();
        let depth = self.pool.texture("depth", size, lighting::DEPTH_FORMAT, attachment);
        let depth = self.pool.view(&depth, ViewKey::default());
        LightingTargets { textures, views, depth }
    }

    /// One light's lighting pass, adding its light to the targets (the first light
    /// clears them).
    fn record_lighting(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        shared: &SharedLighting,
        index: usize,
        bindings: &LightBindings,
    ) {
        let SharedLighting { plan, camera_group, tracing_group, targets, camera, masks } = *shared;
        let light = &plan.lights[index];
        let first = index == 0;
        let last = index + 1 == plan.lights.len();
        let start = if first { TargetStart::Clear } else { TargetStart::Keep };
        let attachments = target_attachments(targets, start);
        let gpu = &self.gpu;
        let slot = rec.clock.begin(gpu, rec.encoder, PassKind::Lighting, Some(index as u32), None);
        let mut pass = rec.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("lighting"),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &targets.depth,
                depth_ops: Some(wgpu::Operations {
                    // The mask path's prepass has drawn the depth already.
                    load: if first && !plan.mask_path {
                        wgpu::LoadOp::Clear(1.0)
                    } else {
                        wgpu::LoadOp::Load
                    },
                    store: if last { wgpu::StoreOp::Discard } else { wgpu::StoreOp::Store },
                }),
                stencil_ops: None,
            }),
            timestamp_writes: rec.clock.render_writes(slot),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let key = LightingKey {
            technique: light.technique,
            lookup: if plan.mask_path { Lookup::Mask } else { Lookup::Own(bindings.lookup) },
            role: if first {
                LightingRole::First
            } else {
                LightingRole::Added { visibility: index == plan.shown }
            },
            // Only a forward frame with the BVH built has a group to trace with.
            refine: if tracing_group.is_some() { light.refine } else { Refine::Off },
            size: LightSize::of(&light.light),
            traversal: plan.traversal,
        };
        pass.set_pipeline(self.passes.lighting.pipeline(&gpu.device, key));
        pass.set_bind_group(0, &bindings.scene, &[]);
        // Group 1: the camera, with the prepass's outputs on the mask path or the
        // casters' BVH where the forward pass traces.
        let camera_group = match (key.lookup, masks) {
            (Lookup::Mask, Some(masks)) => masks.surface_group,
            (Lookup::Mask, None) => unreachable!("the mask path records its screen-space passes first"),
            (Lookup::Own(_), _) => {
                tracing_group.filter(|_| key.refine != Refine::Off).unwrap_or(camera_group)
            }
        };
        pass.set_bind_group(1, camera_group, &[]);
        pass.set_bind_group(2, &bindings.lighting, &[]);
        rec.stats.pipeline_changes += 1;
        rec.stats.bind_group_changes += 3;
        let (draws, binds) = uploaded.draw_visible(&mut pass, camera.visible, 3, camera.arguments.as_ref());
        rec.stats.lighting_draws += draws;
        rec.stats.lighting_instances += camera.visible.instances();
        rec.stats.bind_group_changes += binds;
        drop(pass);
        rec.clock.end(gpu, rec.encoder, slot);
    }
}

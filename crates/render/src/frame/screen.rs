//! The mask path's screen-space passes: a depth-and-normal prepass from the camera,
//! then one shadow-mask pass per light (the technique's lookup and contact shadows,
//! per pixel) into its layer of the mask, which the lighting passes then read.

use super::{
    Renderer,
    plan::FramePlan,
    record::{LightBindings, Recording},
};
use crate::{
    GpuScene,
    gpu_scene::Visible,
    passes::screen_space::{self, MaskKey},
    pool::{Binding, ViewKey},
    rays,
    timing::PassKind,
};
use gnomon_scene::settings::Refine;

/// What the screen-space passes draw into and read.
pub(super) struct ScreenInputs<'a> {
    pub camera_visible: &'a Visible,
    pub camera_buffer: &'a wgpu::Buffer,
    pub camera_group: &'a wgpu::BindGroup,
    /// The lighting passes' depth buffer, which the prepass fills.
    pub depth: &'a wgpu::TextureView,
    /// One layer of the mask per light.
    pub mask_layers: &'a [wgpu::TextureView],
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
    /// into its layer of the mask.
    pub(super) fn record_screen_space(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        plan: &FramePlan,
        lit: &[LightBindings],
        inputs: &ScreenInputs,
    ) {
        let (width, height) = (inputs.depth.texture().width(), inputs.depth.texture().height());
        let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let normals = self.pool.texture("prepass normals", size, screen_space::NORMALS_FORMAT, usage);
        let normals = self.pool.view(&normals, ViewKey::default());
        let view_depth =
            self.pool.texture("prepass view depth", size, screen_space::VIEW_DEPTH_FORMAT, usage);
        let view_depth = self.pool.view(&view_depth, ViewKey::default());
        self.record_prepass(rec, uploaded, &lit[0].scene, inputs, [&normals, &view_depth]);
        let screen_group = self.pool.bind_group(
            "screen",
            &self.layouts.screen,
            &[
                Binding::Buffer(inputs.camera_buffer.clone()),
                Binding::View(view_depth),
                Binding::View(normals),
            ],
        );
        let gpu = &self.gpu;
        for (index, ((light, bindings), layer)) in
            plan.lights.iter().zip(lit).zip(inputs.mask_layers).enumerate()
        {
            let mask_group = bindings.mask.as_ref().expect("a mask pass group on the mask path");
            let slot = rec.clock.begin(gpu, rec.encoder, PassKind::Mask, Some(index as u32), None);
            let mut pass = rec.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow mask"),
                color_attachments: &[cleared(layer, wgpu::Color::WHITE)],
                depth_stencil_attachment: None,
                timestamp_writes: rec.clock.render_writes(slot),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let key = MaskKey { technique: light.technique, lookup: bindings.lookup, refine: light.refine };
            pass.set_pipeline(self.passes.screen_space.mask(&gpu.device, key));
            pass.set_bind_group(0, &bindings.scene, &[]);
            pass.set_bind_group(1, &screen_group, &[]);
            pass.set_bind_group(2, mask_group, &[]);
            rec.stats.pipeline_changes += 1;
            rec.stats.bind_group_changes += 3;
            if light.refine != Refine::Off {
                let bvh = uploaded.rays().expect("the casters' BVH, built when the frame was planned");
                pass.set_bind_group(rays::GROUP, &bvh.group, &[]);
                rec.stats.bind_group_changes += 1;
            }
            pass.draw(0..3, 0..1);
            drop(pass);
            rec.clock.end(gpu, rec.encoder, slot);
        }
    }

    /// The camera's depth, normals and view depth.
    fn record_prepass(
        &mut self,
        rec: &mut Recording,
        uploaded: &GpuScene,
        scene_group: &wgpu::BindGroup,
        inputs: &ScreenInputs,
        [normals, view_depth]: [&wgpu::TextureView; 2],
    ) {
        let gpu = &self.gpu;
        let slot = rec.clock.begin(gpu, rec.encoder, PassKind::Prepass, None, None);
        // View depth 0 marks the background.
        let mut pass = rec.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("prepass"),
            color_attachments: &[
                cleared(normals, wgpu::Color::TRANSPARENT),
                cleared(view_depth, wgpu::Color::TRANSPARENT),
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
        pass.set_pipeline(self.passes.screen_space.prepass());
        // The light plays no part in the prepass; any light's group carries the
        // instances.
        pass.set_bind_group(0, scene_group, &[]);
        pass.set_bind_group(1, inputs.camera_group, &[]);
        rec.stats.pipeline_changes += 1;
        rec.stats.bind_group_changes += 2;
        let (draws, binds) = uploaded.draw_visible(&mut pass, inputs.camera_visible, 3);
        rec.stats.prepass_draws += draws;
        rec.stats.bind_group_changes += binds;
        drop(pass);
        rec.clock.end(gpu, rec.encoder, slot);
    }
}

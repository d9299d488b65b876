//! Painting: the live frame and the debug pictures handed to egui as textures, and
//! egui's output drawn into the window (and into a texture for a screenshot).

use gnomon_render::{LiveFrame, wgpu};

use super::live::Live;
use crate::{debug_views, status_line};

/// Side of each shadow-map layer in the preview, in pixels.
const MAP_PREVIEW_TILE: u32 = 256;

/// Hands a live frame's textures to egui.
pub(super) fn show_live_frame(live: &mut Live, frame: &LiveFrame, show_maps: bool) {
    let device = &live.gpu.device;
    let view = frame.color.create_view(&Default::default());
    let size = [frame.color.width(), frame.color.height()];
    live.view_texture = Some(match live.view_texture {
        Some(id) => {
            live.painter.update_egui_texture_from_wgpu_texture(device, &view, wgpu::FilterMode::Linear, id);
            id
        }
        None => live.painter.register_native_texture(device, &view, wgpu::FilterMode::Linear),
    });
    live.images.view = live.view_texture.map(|id| (id, size));
    if !show_maps {
        return;
    }
    let Some(workshop) = live.workshop.as_mut() else { return };
    match workshop.renderer.preview_shadow_map(frame, MAP_PREVIEW_TILE) {
        Ok(maps) => {
            let view = maps.create_view(&Default::default());
            live.maps_texture = Some(match live.maps_texture {
                Some(id) => {
                    live.painter.update_egui_texture_from_wgpu_texture(
                        device,
                        &view,
                        wgpu::FilterMode::Nearest,
                        id,
                    );
                    id
                }
                None => live.painter.register_native_texture(device, &view, wgpu::FilterMode::Nearest),
            });
            live.images.maps = live.maps_texture.map(|id| (id, [maps.width(), maps.height()]));
        }
        Err(e) => status_line::say(&e.to_string()),
    }
}

/// Uploads a CPU picture to egui when it changed.
pub(super) fn refresh_picture(
    ctx: &egui::Context,
    picture: Option<&debug_views::Picture>,
    handle: &mut Option<egui::TextureHandle>,
) {
    let Some(picture) = picture else {
        *handle = None;
        return;
    };
    let size = [picture.width as usize, picture.height as usize];
    let name = format!("picture {}", picture.id);
    let stale = handle.as_ref().is_none_or(|h| h.name() != name);
    if stale {
        let image = egui::ColorImage::from_rgba_unmultiplied(size, &picture.rgba);
        // Named by the picture's id: a new picture replaces the texture even when its
        // size and summary are those of the old one.
        let mut options = egui::TextureOptions::LINEAR;
        options.magnification = egui::TextureFilter::Nearest;
        *handle = Some(ctx.load_texture(name, image, options));
    }
}

/// The format the window is painted in: an sRGB view of the surface (the scene's
/// image and egui's colours are sRGB-encoded).
pub(super) fn target_format(config: &wgpu::SurfaceConfiguration) -> wgpu::TextureFormat {
    config.view_formats.first().copied().unwrap_or(config.format)
}

/// Paints the panels' `output` into the window, and into a texture that can be copied
/// out where `shoot` asks for a screenshot: returns that texture.
pub(super) fn paint(
    live: &mut Live,
    ctx: &egui::Context,
    mut output: egui::FullOutput,
    shoot: bool,
) -> Option<wgpu::Texture> {
    let gpu = live.gpu.clone();
    let (device, queue) = (&gpu.device, &gpu.queue);
    let jobs = ctx.tessellate(output.shapes, output.pixels_per_point);
    for (id, deltas) in &output.textures_delta.set {
        for delta in deltas {
            live.painter.update_texture(device, queue, *id, delta);
        }
    }
    let screen = egui_wgpu::ScreenDescriptor {
        size_in_pixels: [live.config.width, live.config.height],
        pixels_per_point: output.pixels_per_point,
    };
    let surface_texture = match live.surface.get_current_texture() {
        wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => Some(t),
        wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
            live.surface.configure(device, &live.config);
            None
        }
        _ => None,
    };
    // Screenshots paint the same jobs into a texture that can be copied out.
    let shot_texture = shoot.then(|| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("screenshot"),
            size: wgpu::Extent3d {
                width: screen.size_in_pixels[0],
                height: screen.size_in_pixels[1],
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: target_format(&live.config),
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    let buffers = live.painter.update_buffers(device, queue, &mut encoder, &jobs, &screen);
    let mut targets: Vec<wgpu::TextureView> = Vec::new();
    if let Some(t) = &surface_texture {
        let format = Some(target_format(&live.config));
        targets.push(t.texture.create_view(&wgpu::TextureViewDescriptor { format, ..Default::default() }));
    }
    if let Some(t) = &shot_texture {
        targets.push(t.create_view(&Default::default()));
    }
    for view in &targets {
        let mut pass = encoder
            .begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r: 0.06, g: 0.06, b: 0.07, a: 1.0 }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            })
            .forget_lifetime();
        live.painter.render(&mut pass, &jobs, &screen);
    }
    queue.submit(buffers.into_iter().chain([encoder.finish()]));
    if let Some(t) = surface_texture {
        live.window.pre_present_notify();
        queue.present(t);
    }
    for id in &output.textures_delta.free {
        live.painter.free_texture(id);
    }
    // Applied above; egui insists that they are drained.
    output.textures_delta.clear();
    shot_texture
}

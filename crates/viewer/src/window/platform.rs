//! What differs between a desktop window and a browser's canvas, in one place: how
//! the event loop runs, which window is drawn into, how work that waits for the GPU
//! runs, where the error view's truth comes from, and whether
//! a screenshot can be written to a file.

use std::future::Future;

use winit::{
    event_loop::{ActiveEventLoop, EventLoop},
    window::WindowAttributes,
};

use super::{App, Arrived};
use crate::debug_views::ErrorJob;

#[cfg(not(target_arch = "wasm32"))]
pub(crate) use desktop::*;
#[cfg(target_arch = "wasm32")]
pub(crate) use web::*;

/// Runs `work` to its end and hands what it made to `app`.
pub(super) fn spawn(
    app: &mut App,
    event_loop: &ActiveEventLoop,
    work: impl Future<Output = Arrived> + 'static,
) {
    spawn_on(app, event_loop, work)
}

#[cfg(not(target_arch = "wasm32"))]
mod desktop {
    use super::*;

    /// The desktop's own: nothing beyond the event loop.
    pub(crate) struct Host;

    /// The error view's truth is the CPU reference, on a thread of its own, not
    /// the GPU's `raytraced`.
    pub(crate) const COMPARES_WITH_RAYTRACED: bool = false;

    /// The error view's job for `frame`: the CPU reference, traced on a thread.
    pub(crate) fn error_job(
        scene: &gnomon_scene::Scene,
        frame: gnomon_render::Frame,
        _traced: Option<gnomon_render::Frame>,
        settings: gnomon_scene::Settings,
    ) -> Result<ErrorJob, String> {
        ErrorJob::start(scene, frame, settings)
    }

    pub(super) fn spawn_on(app: &mut App, event_loop: &ActiveEventLoop, work: impl Future<Output = Arrived>) {
        // The desktop waits for the GPU: the work is done before the frame goes on.
        let arrived = pollster::block_on(work);
        app.arrive(event_loop, arrived);
    }

    pub(crate) fn window_attributes(_host: &Host, attributes: WindowAttributes) -> WindowAttributes {
        attributes
    }

    /// Runs the event loop until the window closes.
    pub(crate) fn run_loop(event_loop: EventLoop<Arrived>, app: &mut App) -> anyhow::Result<()> {
        use anyhow::Context;
        event_loop.run_app(app).context("the window's event loop failed")
    }

    /// Puts `text` on the clipboard (egui-winit's, the system's).
    pub(crate) fn copy_text(ctx: &egui::Context, text: &str) {
        ctx.copy_text(text.to_string());
    }

    /// Writes `text` to the file `path`, whole or not at all; says what it did.
    pub(crate) fn save_text(path: &std::path::Path, text: String) -> anyhow::Result<String> {
        use anyhow::Context;
        crate::reproduce::write_whole(path, |temporary| {
            std::fs::write(temporary, text).with_context(|| format!("{}: cannot write", path.display()))
        })?;
        Ok(format!("saved {}", path.display()))
    }

    /// Saves `texture` (the painted window) as a PNG at each of `paths`.
    pub(crate) fn save_screenshots(
        gpu: &gnomon_render::Gpu,
        texture: &gnomon_render::wgpu::Texture,
        paths: &[std::path::PathBuf],
    ) -> anyhow::Result<()> {
        let texels: Vec<u8> = gnomon_render::read_texture(gpu, texture)?;
        let rgba = to_rgba(texels, texture.format());
        for path in paths {
            crate::reproduce::save_png(path, texture.width(), texture.height(), &rgba)?;
        }
        Ok(())
    }

    /// Texels of an 8-bit colour texture as RGBA.
    fn to_rgba(mut texels: Vec<u8>, format: gnomon_render::wgpu::TextureFormat) -> Vec<u8> {
        if matches!(
            format,
            gnomon_render::wgpu::TextureFormat::Bgra8Unorm
                | gnomon_render::wgpu::TextureFormat::Bgra8UnormSrgb
        ) {
            for px in texels.chunks_exact_mut(4) {
                px.swap(0, 2);
            }
        }
        texels
    }
}

#[cfg(target_arch = "wasm32")]
mod web {
    use winit::{event_loop::EventLoopProxy, platform::web::WindowAttributesExtWebSys};

    use super::*;

    /// The page's: the canvas drawn into, and the way back into the event loop for
    /// work that ran as a browser task.
    pub(crate) struct Host {
        pub canvas: web_sys::HtmlCanvasElement,
        pub proxy: Option<EventLoopProxy<Arrived>>,
    }

    /// The error view's truth is the GPU's `raytraced`: a browser has no threads
    /// for the CPU reference.
    pub(crate) const COMPARES_WITH_RAYTRACED: bool = true;

    /// The error view's job for `frame`: against `traced`, the view drawn by `raytraced`.
    pub(crate) fn error_job(
        _scene: &gnomon_scene::Scene,
        frame: gnomon_render::Frame,
        traced: Option<gnomon_render::Frame>,
        settings: gnomon_scene::Settings,
    ) -> Result<ErrorJob, String> {
        let traced = traced.ok_or("`raytraced` was not drawn")?;
        Ok(ErrorJob::against_raytraced(&frame, traced, settings))
    }

    pub(super) fn spawn_on(
        app: &mut App,
        _event_loop: &ActiveEventLoop,
        work: impl Future<Output = Arrived> + 'static,
    ) {
        let Some(proxy) = app.host.proxy.clone() else {
            app.model.say("the viewer's event loop is not running");
            return;
        };
        // A browser cannot wait for the GPU: the work runs as a task, and what it
        // made comes back through the event loop.
        wasm_bindgen_futures::spawn_local(async move {
            // Refused only once the page closed the loop: nothing is left to show it.
            let _ = proxy.send_event(work.await);
        });
    }

    pub(crate) fn window_attributes(host: &Host, attributes: WindowAttributes) -> WindowAttributes {
        attributes.with_canvas(Some(host.canvas.clone())).with_prevent_default(true).with_focusable(true)
    }

    /// Starts the event loop and returns the way into it: the browser runs it.
    pub(crate) fn run_loop(event_loop: EventLoop<Arrived>, mut app: App) -> EventLoopProxy<Arrived> {
        use winit::platform::web::EventLoopExtWebSys;
        let proxy = event_loop.create_proxy();
        app.host.proxy = Some(proxy.clone());
        event_loop.spawn_app(app);
        proxy
    }

    /// Puts `text` on the system's clipboard, through the page (egui-winit's own
    /// clipboard stays inside the canvas there).
    pub(crate) fn copy_text(ctx: &egui::Context, text: &str) {
        ctx.copy_text(text.to_string());
        if let Some(window) = web_sys::window() {
            // A promise: refused only where the page may not write the clipboard,
            // and the status line shows the text anyway.
            let _ = window.navigator().clipboard().write_text(text);
        }
    }

    /// A page has no files: `text` is offered as a download named as `path`.
    pub(crate) fn save_text(path: &std::path::Path, text: String) -> anyhow::Result<String> {
        use wasm_bindgen::JsCast;
        let name = path.file_name().map_or("view.toml".into(), |n| n.to_string_lossy().into_owned());
        let failed = |what: &str| anyhow::anyhow!("{name}: cannot offer it as a download ({what})");
        let document = web_sys::window().and_then(|w| w.document()).ok_or_else(|| failed("no document"))?;
        let parts = js_sys::Array::of1(&text.into());
        let options = web_sys::BlobPropertyBag::new();
        options.set_type("application/toml");
        let blob = web_sys::Blob::new_with_str_sequence_and_options(&parts, &options)
            .map_err(|_| failed("no Blob"))?;
        let url = web_sys::Url::create_object_url_with_blob(&blob).map_err(|_| failed("no object URL"))?;
        let link: web_sys::HtmlAnchorElement = document
            .create_element("a")
            .map_err(|_| failed("no link"))?
            .dyn_into()
            .map_err(|_| failed("no link"))?;
        link.set_href(&url);
        link.set_download(&name);
        link.click();
        // The click has started the download; the URL is no longer needed.
        let _ = web_sys::Url::revoke_object_url(&url);
        Ok(format!("offered {name} as a download"))
    }

    /// A page has no files: the browser saves the canvas itself.
    pub(crate) fn save_screenshots(
        _gpu: &gnomon_render::Gpu,
        _texture: &gnomon_render::wgpu::Texture,
        _paths: &[std::path::PathBuf],
    ) -> anyhow::Result<()> {
        anyhow::bail!(
            "a page cannot write files: save the canvas from the browser (right-click, Save image as)"
        )
    }
}

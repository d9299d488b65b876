//! Renders a glTF file to a PNG through the library, with no window:
//! `cargo run -p gnomon-examples --example headless -- scene.gltf out.png`.
//! The file's camera and lights are used where it has them; otherwise the camera is
//! fitted to the model and a default sun placed.

use anyhow::Context;
use gnomon_render::{Gpu, OutputRequest, Renderer};
use gnomon_scene::{Settings, gltf_loader};

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let (input, output) = match (args.next(), args.next()) {
        (Some(input), Some(output)) => (input, output),
        _ => anyhow::bail!("usage: headless SCENE.gltf OUT.png"),
    };
    let (scene, _) = gltf_loader::load(input.as_ref())?;
    let gpu = Gpu::new_headless()?;
    let mut renderer = Renderer::new(&gpu)?;
    let mut settings = Settings::default();
    (settings.image.width, settings.image.height) = (640, 360);
    let frame = renderer.render(&scene, &settings, &OutputRequest::default())?;
    let lit = frame.visibility.iter().filter(|v| **v > 0.5).count();
    let shadowed = frame.visibility.iter().filter(|v| **v <= 0.5).count();
    image::save_buffer(&output, &frame.color, frame.width, frame.height, image::ColorType::Rgba8)
        .with_context(|| format!("cannot write {output}"))?;
    println!("{output}: {lit} lit and {shadowed} shadowed pixels of {}", frame.pixel_count());
    Ok(())
}

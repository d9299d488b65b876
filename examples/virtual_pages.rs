//! How many pages a virtual shadow map would draw for one view, measured with the
//! library's page-request pass (`gnomon_render::virtual_map`) on the surfaces the
//! renderer saw: the texels a moving sun would pay for each frame, against
//! cascades' fixed layers.
//!
//! `cargo run --release -p gnomon-examples --example virtual_pages -- SCENE.glb [FLAG=VALUE …]`
//!
//! The flags are the command line's settings flags without their dashes
//! (`camera-eye=-85,12,-4 sun-elevation=70`); the light must be the sun.

use anyhow::Context;
use gnomon_math::virtual_map::{Clipmap, ClipmapShape};
use gnomon_render::{
    Gpu, OutputRequest, Renderer,
    virtual_map::{PageRequests, PixelReach},
};
use gnomon_scene::{
    flags::{Flag, settings_from_flags},
    gltf_loader,
    lights::Origin,
};

/// Texels a `pcf2x2` lookup reaches from its point: a bilinear footprint (one texel)
/// and a normal offset of about one texel.
const PCF2X2_REACH_TEXELS: f32 = 2.0;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let input = args.next().context("usage: virtual_pages SCENE.glb [FLAG=VALUE …]")?;
    let flags = args
        .map(|a| {
            let (name, value) = a.split_once('=').with_context(|| format!("`{a}`: give FLAG=VALUE"))?;
            Ok(Flag { name: name.to_string(), value: value.to_string() })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let settings = settings_from_flags(&flags)?;
    let (scene, _) = gltf_loader::load(input.as_ref())?;
    let gpu = Gpu::new_headless()?;
    let mut renderer = Renderer::new(&gpu)?;
    let frame = renderer.render(&scene, &settings, &OutputRequest::default())?;
    let Origin::Infinite { travel } = frame.light.emission().origin else {
        anyhow::bail!("a virtual map here is a sun's: give light=sun");
    };
    let fov = frame.camera.fov_y_degrees.to_radians();
    let reach = PixelReach {
        footprint_per_depth: 2.0 * (0.5 * fov).tan() / frame.height as f32,
        reach_texels: PCF2X2_REACH_TEXELS,
        // Only refinement under a sun with an angular size searches its cone.
        area_search: None,
        // Only PCSS reads the sun's cone in coarser levels.
        cone: None,
    };
    // The farthest pixel the camera can see: at the scene's farthest corner.
    let bounds = scene.bounds();
    let farthest = bounds.corners().iter().map(|c| c.distance(frame.camera.eye)).fold(0.0, f32::max);
    let clipmap = Clipmap::new(
        ClipmapShape::DEFAULT,
        travel,
        frame.camera.eye,
        &bounds,
        farthest * reach.footprint_per_depth,
    );
    let pages =
        pollster::block_on(PageRequests::new(&gpu)?.request_for_frame(&gpu, &frame, &clipmap, reach))?;
    let page_texels = u64::from(clipmap.shape.page_size).pow(2);
    println!(
        "{}: {}×{}, {} pages of {}² texels requested",
        scene.name,
        frame.width,
        frame.height,
        pages.len(),
        clipmap.shape.page_size
    );
    println!("| level | texel (world units) | pages |");
    println!("|---|---|---|");
    for level in 0..clipmap.shape.levels {
        let count = pages.iter().filter(|p| p.level == level).count();
        if count > 0 {
            println!("| {level} | {:.5} | {count} |", clipmap.texel_size(level));
        }
    }
    let texels = pages.len() as u64 * page_texels;
    let cascades = 4 * 2048u64 * 2048;
    println!(
        "virtual map: {:.2} M texels to draw when every page is new or dirty; 4×2048² cascades: {:.2} M ({:.2}×)",
        texels as f64 / 1e6,
        cascades as f64 / 1e6,
        texels as f64 / cascades as f64
    );
    Ok(())
}

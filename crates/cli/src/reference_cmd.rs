//! `gnomon reference`: the ray-traced visibility of the light, as an image.

use std::path::PathBuf;

use clap::Args;
use gnomon_scene::Settings;

use crate::{lab, output};

#[derive(Args, Debug)]
pub struct ReferenceArgs {
    #[command(flatten)]
    pub scene: crate::lab::SceneArgs,
    /// Output: `.exr` (float visibility, channel `Y`, NaN background), `.npy` (the
    /// same floats, height × width) or `.png` (8-bit gray visibility, background dark
    /// blue-grey).
    #[arg(long, short, default_value = "reference.png", help_heading = "Outputs")]
    pub out: PathBuf,
    /// Also write the per-pixel standard error of the estimate (`.exr` or `.npy`).
    #[arg(long, value_name = "FILE.exr|FILE.npy", help_heading = "Outputs")]
    pub std_error_out: Option<PathBuf>,
    /// Trace again even when a cached reference exists.
    #[arg(long)]
    pub no_cache: bool,
    #[command(flatten)]
    pub settings: Settings,
}

pub fn run(args: &ReferenceArgs) -> anyhow::Result<()> {
    args.settings.validate()?;
    let (scene, settings) = lab::load(&args.scene, &args.settings)?;
    output::check_file(&args.out, &["exr", "npy", "png"], "--out")?;
    if let Some(p) = &args.std_error_out {
        output::check_file(p, &["exr", "npy"], "--std-error-out")?;
        output::refuse_shared_destinations(&[
            output::Planned { flag: "--out".into(), path: &args.out },
            output::Planned { flag: "--std-error-out".into(), path: p },
        ])?;
    }
    let reference = lab::reference(&scene, &settings, !args.no_cache)?;
    let image = &reference.image;
    let (w, h) = (image.width, image.height);
    let mut staged = output::Staged::default();
    // `float_image` writes .exr or .npy by the extension; a .png is 8-bit gray.
    if args.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        staged.png_rgba(&args.out, w, h, &output::visibility_rgba(&image.visibility))?;
    } else {
        staged.float_image(&args.out, w, h, &image.visibility)?;
    }
    if let Some(p) = &args.std_error_out {
        staged.float_image(p, w, h, &image.std_error)?;
    }
    for path in staged.commit()? {
        println!("{}", path.display());
    }
    let surface: Vec<usize> = (0..image.pixel_count()).filter(|&i| image.object_id[i] != 0).collect();
    let mean_se =
        surface.iter().map(|&i| image.std_error[i] as f64).sum::<f64>() / surface.len().max(1) as f64;
    let max_se = surface.iter().map(|&i| image.std_error[i]).fold(0.0f32, f32::max);
    eprint!("gnomon: {} triangles, {w}×{h}, {} samples per pixel", scene.triangle_count(), image.samples);
    if image.samples > 1 {
        eprint!(", standard error mean {mean_se:.4}, max {max_se:.4}");
    }
    match reference.timing {
        Some(t) => eprintln!(
            ", BVH built in {:.2} s, {} rays traced in {:.2} s: {:.2} Mrays/s",
            t.build_seconds,
            image.rays,
            t.trace_seconds,
            image.rays as f64 / t.trace_seconds / 1e6
        ),
        None => eprintln!(" (cached)"),
    }
    Ok(())
}

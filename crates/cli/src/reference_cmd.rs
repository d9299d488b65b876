//! `gnomon reference`: the ray-traced visibility of the light, as an image: through
//! the camera's pixel centres, or from the surfaces a frame drew (`--surfaces`, an
//! `--aov-out` folder of any renderer's frame).

use std::path::PathBuf;

use clap::Args;
use gnomon_scene::Settings;

use crate::{lab, output, surfaces_in};

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
    /// Trace from the surfaces a frame drew instead of through the camera's pixel
    /// centres: the `position.npy` and `geometric_normal.npy` of this folder (as
    /// `gnomon render --aov-out DIR --aov-format npy` writes them, or any renderer's
    /// frame in that form). The image is theirs: its size and camera flags are not
    /// used; the truth at each pixel is the light's visibility from the very point
    /// the frame shows (0 where its surface faces away, NaN where it shows none).
    #[arg(long, value_name = "DIR", help_heading = "Scene")]
    pub surfaces: Option<PathBuf>,
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
    if let Some(dir) = &args.surfaces {
        let surfaces = surfaces_in::read_surfaces(dir)?;
        let truth = lab::drawn_truth_at(&scene, &settings, &surfaces)?;
        let written =
            Written { width: surfaces.width, height: surfaces.height, visibility: &truth.visibility };
        write_outputs(args, written, &truth.std_error)?;
        eprintln!(
            "gnomon: {} triangles, truth at the {}×{} surfaces of {}: {} samples per pixel, {} rays",
            scene.triangle_count(),
            surfaces.width,
            surfaces.height,
            dir.display(),
            truth.samples,
            truth.rays
        );
        return Ok(());
    }
    let reference = lab::reference(&scene, &settings, !args.no_cache)?;
    let image = &reference.image;
    let (w, h) = (image.width, image.height);
    write_outputs(args, Written { width: w, height: h, visibility: &image.visibility }, &image.std_error)?;
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

/// A visibility image to write.
struct Written<'a> {
    width: u32,
    height: u32,
    visibility: &'a [f32],
}

/// `--out` (PNG, or `float_image`'s .exr or .npy by the extension) and
/// `--std-error-out`, moved into place together.
fn write_outputs(args: &ReferenceArgs, image: Written, std_error: &[f32]) -> anyhow::Result<()> {
    let Written { width: w, height: h, visibility } = image;
    let mut staged = output::Staged::default();
    if args.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        staged.png_rgba(&args.out, w, h, &output::visibility_rgba(visibility))?;
    } else {
        staged.float_image(&args.out, w, h, visibility)?;
    }
    if let Some(p) = &args.std_error_out {
        staged.float_image(p, w, h, std_error)?;
    }
    for path in staged.commit()? {
        println!("{}", path.display());
    }
    Ok(())
}

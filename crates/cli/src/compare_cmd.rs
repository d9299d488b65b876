//! `gnomon compare`: render each technique and the ray-traced reference, measure the
//! differences, and write a labelled grid, heat-maps, `metrics.json` and `metrics.md`.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use gnomon_reference::{
    aliasing,
    drawn::DrawnMetrics,
    flicker::{Flicker, FlickerCounter, PathFrame},
    heatmap,
    metrics::{self, Metrics, PixelClass, RasterView},
};
use gnomon_render::{Frame, Gpu, GpuScene, OutputRequest, Renderer, timing::ClockChoice};
use gnomon_scene::settings::LightKind;
use gnomon_scene::{
    Scene, Settings,
    camera_path::{CameraPathKind, camera_on_path},
    settings::{CameraSettings, Technique},
};
use image::RgbaImage;

use crate::{
    compare_report::{AliasingSummary, PathReport, Report, Row, markdown_table},
    grid::{self, Downscale, Tile},
    lab, output,
};

#[derive(Args, Debug)]
pub struct CompareArgs {
    #[command(flatten)]
    pub scene: crate::lab::SceneArgs,
    /// Techniques to compare, comma-separated (see `gnomon techniques`).
    #[arg(long, value_enum, value_delimiter = ',', default_value = "hard,pcf2x2,pcf")]
    pub techniques: Vec<Technique>,
    /// Output directory (created if missing): grid.png, metrics.json, metrics.md,
    /// reference.png, aliasing.png (the heat-map of m), and TECHNIQUE.png and
    /// TECHNIQUE-error.png per technique.
    #[arg(long, short, default_value = "compare", help_heading = "Outputs")]
    pub out: PathBuf,
    /// Frames rendered per technique to time its passes (the median is reported); 1 to 100.
    #[arg(long, value_name = "N", default_value_t = 5)]
    pub timing_frames: u32,
    /// Trace the reference again even when a cached one exists.
    #[arg(long)]
    pub no_cache: bool,
    /// Print the adapter, driver and backend.
    #[arg(long, short)]
    pub verbose: bool,
    /// Also measure temporal flicker: render every technique and the reference at
    /// `--path-frames` frames along this camera path (the scene and light still), and
    /// report how many pixels flip between shadow and light from frame to frame beyond
    /// the reference's own flips.
    #[arg(long, value_enum, help_heading = "Camera path")]
    pub camera_path: Option<CameraPathKind>,
    /// Frames along the camera path, 2 to 240.
    #[arg(long, value_name = "K", default_value_t = 16, help_heading = "Camera path")]
    pub path_frames: u32,
    /// How far the eye travels over the whole path, as a fraction of its distance to
    /// the target (an orbit's arc: that angle in radians); in (0, 1].
    #[arg(long, value_name = "FRACTION", default_value_t = 0.05, help_heading = "Camera path")]
    pub path_travel: f32,
    #[command(flatten)]
    pub settings: Settings,
}

/// One technique's frame, and the median GPU milliseconds of its (shadow, lighting)
/// passes where the adapter has timestamps.
struct Rendered {
    technique: Technique,
    frame: Frame,
    timing: Option<(f64, Option<f64>, f64)>,
}

pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    args.settings.validate()?;
    anyhow::ensure!(
        (1..=100).contains(&args.timing_frames),
        "--timing-frames = {} is invalid: 1 to 100",
        args.timing_frames
    );
    anyhow::ensure!(
        !args.techniques.is_empty(),
        "--techniques is empty: name at least one of `gnomon techniques`"
    );
    // Each technique's files are named after it: a repeated one would overwrite its own.
    if let Some((i, repeated)) =
        args.techniques.iter().enumerate().find(|(i, t)| args.techniques[..*i].contains(t))
    {
        anyhow::bail!(
            "--techniques names `{}` twice (at {} and {}): name each once",
            repeated.name(),
            args.techniques.iter().position(|t| t == repeated).unwrap_or(0) + 1,
            i + 1
        );
    }
    anyhow::ensure!(
        (2..=240).contains(&args.path_frames),
        "--path-frames = {} is invalid: 2 to 240",
        args.path_frames
    );
    anyhow::ensure!(
        args.path_travel > 0.0 && args.path_travel <= 1.0,
        "--path-travel = {} is invalid: a fraction in (0, 1]",
        args.path_travel
    );
    let (mut scene, mut settings) = lab::load(&args.scene, &args.settings)?;
    if settings.light.kind == LightKind::All {
        single_out_light(&mut scene, &mut settings)?;
    }
    let settings = &settings;
    output::check_dir(&args.out, "--out")?;

    let gpu = Gpu::new_headless()?;
    if args.verbose {
        eprintln!("gnomon: {}", gpu.info);
        eprintln!("gnomon: {}", crate::render_cmd::open_casters_line(&scene, settings.shadow.bias.cull));
    }
    let mut renderer = Renderer::new(&gpu)?;
    renderer.check_limits(settings)?;
    let uploaded = renderer.upload(&scene)?;

    let mut frames: Vec<Rendered> = Vec::new();
    for technique in &args.techniques {
        let mut s = settings.clone();
        s.shadow.filter.technique = technique.clone();
        let frame = renderer.render_uploaded(&uploaded, &scene, &s, &OutputRequest::default())?;
        crate::render_cmd::warn_fallbacks(&frame.lights);
        let (mut shadow, mut filter, mut lighting) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..args.timing_frames {
            if let Some(t) = renderer.time_passes(&uploaded, &scene, &s, ClockChoice::Auto)?.timings {
                shadow.push(t.shadow_ms);
                filter.extend(t.filter_ms);
                lighting.push(t.lighting_ms);
            }
        }
        let timing = (!shadow.is_empty()).then(|| {
            let filter = (!filter.is_empty()).then(|| median(&mut filter));
            (median(&mut shadow), filter, median(&mut lighting))
        });
        frames.push(Rendered { technique: technique.clone(), frame, timing });
    }

    let flicker = match args.camera_path {
        Some(kind) => measure_flicker(args, kind, &mut renderer, &uploaded, &scene, settings)?,
        None => vec![None; args.techniques.len()],
    };
    let aliasing = gnomon_viewer::measure_aliasing(&frames[0].frame, settings);

    let reference = lab::reference(&scene, settings, !args.no_cache)?.image;
    let drawn = lab::drawn_metrics(&scene, settings, &frames.iter().map(|r| &r.frame).collect::<Vec<_>>())?;
    let soft = reference.samples > 1;
    let (w, h) = (reference.width, reference.height);

    let mut rows = Vec::new();
    let mut tiles = vec![vec![Tile {
        image: rgba(w, h, output::visibility_rgba(&reference.visibility)),
        caption: caption_reference(&reference),
        downscale: Downscale::Smooth,
    }]];
    let mut staged = output::Staged::default();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("--out: cannot create {}", args.out.display()))?;
    staged.png_rgba(
        &args.out.join("reference.png"),
        w,
        h,
        &output::visibility_rgba(&reference.visibility),
    )?;
    staged.png_rgba(&args.out.join("aliasing.png"), w, h, &aliasing::heatmap(&aliasing))?;
    for ((Rendered { technique, frame, timing }, flicker), drawn) in frames.iter().zip(flicker).zip(drawn) {
        let raster =
            RasterView { visibility: &frame.visibility, object_id: &frame.object_id, depth: &frame.depth };
        let classes: Vec<PixelClass> = metrics::classify(raster, &reference);
        let m = metrics::measure(raster, &reference, &classes);
        let error = if soft {
            heatmap::soft(&frame.visibility, &reference, &classes)
        } else {
            heatmap::hard(&frame.visibility, &reference, &classes)
        };
        let name = technique.name();
        staged.png_rgba(&args.out.join(format!("{name}.png")), w, h, &frame.color)?;
        staged.png_rgba(&args.out.join(format!("{name}-error.png")), w, h, &error)?;
        let summary = edge_caption(&m, &drawn, soft);
        let mut caption = vec![name.to_string()];
        if let Some((s, f, l)) = timing {
            caption.push(format!("shadow pass {s:.2} ms"));
            if let Some(f) = f {
                caption.push(format!("moment pass {f:.2} ms"));
            }
            caption.push(format!("lighting pass {l:.2} ms"));
        }
        tiles.push(vec![
            Tile { image: rgba(w, h, frame.color.clone()), caption, downscale: Downscale::Smooth },
            Tile {
                image: rgba(w, h, error),
                caption: summary
                    .into_iter()
                    .chain([
                        format!("false shadow {:.3}%", 100.0 * m.false_shadow_rate),
                        format!("false lit {:.3}%", 100.0 * m.false_lit_rate),
                        format!("all surfaces: mismatch {:.3}%", 100.0 * m.surface_mismatch_rate),
                    ])
                    .collect(),
                downscale: Downscale::Salient(if soft { soft_priority } else { hard_priority }),
            },
        ]);
        rows.push(Row {
            technique: name.to_owned(),
            drawn,
            metrics: m,
            shadow_ms: timing.map(|t| t.0),
            filter_ms: timing.and_then(|t| t.1),
            lighting_ms: timing.map(|t| t.2),
            moment_format: frame.moment_format.map(|f| format!("{f:?}").to_lowercase()),
            flicker,
        });
    }
    let legend: Vec<(String, [u8; 3])> = if soft {
        [0.0f32, 0.25, 0.5, 0.75, 1.0].iter().map(|&e| (format!("|V-R| {e}"), heatmap::ramp(e))).collect()
    } else {
        heatmap::HARD_LEGEND.iter().map(|(l, c)| (l.to_string(), *c)).collect()
    };
    // Many techniques go two to a row, so the grid stays a page, not a scroll.
    if tiles.len() > 5 {
        let mut techniques = tiles.split_off(1);
        while !techniques.is_empty() {
            let n = techniques.len().min(2);
            tiles.push(techniques.drain(..n).flatten().collect());
        }
    }
    let grid = grid::compose(&tiles, 480, &legend);
    staged.png_rgba(&args.out.join("grid.png"), grid.width(), grid.height(), grid.as_raw())?;

    let report = Report {
        scene: &scene.name,
        width: w,
        height: h,
        shadow_resolution: settings.shadow.map.resolution,
        light: format!("{:?}", settings.resolve_light(&scene)?),
        reference_samples: reference.samples,
        adapter: gpu.info.adapter.clone(),
        backend: gpu.info.backend.clone(),
        aliasing: AliasingSummary { mean: aliasing.mean, max: aliasing.max },
        camera_path: args.camera_path.map(|kind| PathReport {
            kind,
            frames: args.path_frames,
            travel: args.path_travel,
            frozen_cascades: settings.shadow.cascades.freeze,
        }),
        denominators: metrics::DENOMINATORS.iter().copied().collect(),
        rows,
    };
    let table = markdown_table(&report, soft);
    staged.text(&args.out.join("metrics.json"), &serde_json::to_string_pretty(&report)?)?;
    staged.text(&args.out.join("metrics.md"), &table)?;
    let written = staged.commit()?;
    print!("{table}");
    eprintln!("gnomon: wrote {} files to {}", written.len(), args.out.display());
    Ok(())
}

/// Renders every technique and the reference along the camera path and counts, for
/// each technique, the shadow flips between consecutive frames.
fn measure_flicker(
    args: &CompareArgs,
    kind: CameraPathKind,
    renderer: &mut Renderer,
    uploaded: &GpuScene,
    scene: &Scene,
    settings: &Settings,
) -> anyhow::Result<Vec<Option<Flicker>>> {
    let start = settings.resolve_camera(scene)?;
    let mut counters = vec![FlickerCounter::default(); args.techniques.len()];
    let mut previous: Vec<Option<PathFrame>> = vec![None; args.techniques.len()];
    let mut frozen = None;
    let bar = indicatif::ProgressBar::new(args.path_frames as u64).with_style(
        indicatif::ProgressStyle::with_template("camera path {bar:40} {pos}/{len} frames, {eta} left")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    for k in 0..args.path_frames {
        let fraction = k as f32 / (args.path_frames - 1) as f32;
        let camera = camera_on_path(&start, kind, args.path_travel, fraction);
        let mut s = settings.clone();
        s.camera = CameraSettings::pinned(&camera);
        let reference = bar.suspend(|| lab::reference(scene, &s, !args.no_cache))?.image;
        for (t, technique) in args.techniques.iter().enumerate() {
            s.shadow.filter.technique = technique.clone();
            let request = OutputRequest { fixed_layout: frozen.clone(), ..Default::default() };
            let frame = renderer.render_uploaded(uploaded, scene, &s, &request)?;
            crate::render_cmd::warn_fallbacks(&frame.lights);
            if settings.shadow.cascades.freeze && frozen.is_none() {
                frozen = Some(frame.shadow_layout());
            }
            let raster = RasterView {
                visibility: &frame.visibility,
                object_id: &frame.object_id,
                depth: &frame.depth,
            };
            let current = PathFrame::new(
                &frame.camera,
                frame.width,
                frame.height,
                raster,
                frame.position.clone(),
                &reference,
            );
            if let Some(before) = &previous[t] {
                counters[t].add_pair(before, &current);
            }
            previous[t] = Some(current);
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(counters.iter().map(|c| Some(c.result())).collect())
}

/// The first lines of an error tile's caption (each under the tile's 30 characters),
/// each figure named for its denominator: under an area light, the MAE over all
/// compared pixels, over the penumbra, and the penumbra width error with its bias;
/// under a point-like light, the mismatch rate over every drawn pixel and the MAE over
/// the edge band.
fn edge_caption(m: &Metrics, drawn: &DrawnMetrics, soft: bool) -> Vec<String> {
    if soft {
        let width = match (m.penumbra.width.error_px, m.penumbra.width.bias_px) {
            (Some(e), Some(b)) => format!("width error {e:.1} px ({b:+.1})"),
            _ => "width error: none resolved".to_string(),
        };
        vec![format!("MAE {:.4} all", m.mae), format!("MAE {:.4} penumbra", m.penumbra.error.mae), width]
    } else {
        vec![
            format!("mismatch {:.3}% every pixel", 100.0 * drawn.mismatch_rate),
            format!("edge MAE {:.3} within 2 px", m.edge.mae),
        ]
    }
}

/// Wrong pixels outrank silhouettes, which outrank correct ones.
fn hard_priority(p: [u8; 4]) -> u32 {
    let c = [p[0], p[1], p[2]];
    if c == heatmap::FALSE_SHADOW || c == heatmap::FALSE_LIT {
        2
    } else {
        u32::from(c == heatmap::SILHOUETTE)
    }
}

/// Larger errors are brighter on the ramp.
fn soft_priority(p: [u8; 4]) -> u32 {
    3 * p[0] as u32 + 6 * p[1] as u32 + p[2] as u32
}

fn rgba(w: u32, h: u32, data: Vec<u8>) -> RgbaImage {
    RgbaImage::from_raw(w, h, data).unwrap_or_else(|| RgbaImage::new(w, h))
}

fn caption_reference(r: &gnomon_reference::ReferenceImage) -> Vec<String> {
    let kind = if r.samples > 1 { format!("{} samples/pixel", r.samples) } else { "exact".to_string() };
    vec!["reference (ray traced)".into(), kind]
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// With `--light all`, a comparison measures one light, the one at `--light-index`,
/// as the scene's only light: the reference traces that light alone, the timings are
/// its passes', and each compared technique replaces the technique its own shadow
/// settings name (its other settings, such as its resolution, stay).
fn single_out_light(
    scene: &mut gnomon_scene::Scene,
    settings: &mut gnomon_scene::Settings,
) -> anyhow::Result<()> {
    settings.resolve_light(scene)?;
    let mut light = scene.lights.swap_remove(settings.light.light_index);
    if let Some(overrides) = light.shadow.as_mut() {
        overrides.filter.technique = None;
    }
    eprintln!(
        "gnomon: comparing light {} `{}` ({})",
        settings.light.light_index,
        light.name,
        light.light.type_name()
    );
    scene.lights = vec![light];
    settings.light.light_index = 0;
    Ok(())
}

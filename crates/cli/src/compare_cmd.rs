//! `gnomon compare`: render each technique and the ray-traced reference, measure the
//! differences, and write a labelled grid, heat-maps, `metrics.json` and `metrics.md`.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use gnomon_reference::{
    heatmap,
    metrics::{self, Metrics, PixelClass, RasterView},
};
use gnomon_render::{Frame, Gpu, OutputRequest, Renderer};
use gnomon_scene::{Settings, settings::Technique};
use image::RgbaImage;
use serde::Serialize;

use crate::{
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
    /// reference.png, and TECHNIQUE.png and TECHNIQUE-error.png per technique.
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

/// One technique's row of the report.
#[derive(Serialize)]
struct Row {
    technique: &'static str,
    #[serde(flatten)]
    metrics: Metrics,
    /// Median GPU milliseconds of the shadow pass, where the adapter has timestamps.
    shadow_ms: Option<f64>,
    /// Median GPU milliseconds of the moment pass (encoding, blur, mipmaps) of the
    /// filterable techniques.
    filter_ms: Option<f64>,
    /// The moment map's texel format, for the filterable techniques.
    moment_format: Option<String>,
    /// Median GPU milliseconds of the lighting pass.
    lighting_ms: Option<f64>,
}

#[derive(Serialize)]
struct Report<'a> {
    scene: &'a str,
    width: u32,
    height: u32,
    shadow_resolution: u32,
    light: String,
    reference_samples: u32,
    adapter: String,
    backend: String,
    rows: Vec<Row>,
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
    let (scene, settings) = lab::load(&args.scene, &args.settings)?;
    let settings = &settings;
    output::check_dir(&args.out, "--out")?;

    let gpu = Gpu::new_headless()?;
    if args.verbose {
        eprintln!("gnomon: {}", gpu.info);
    }
    let mut renderer = Renderer::new(&gpu)?;
    renderer.check_limits(settings)?;
    let uploaded = renderer.upload(&scene)?;

    let mut frames: Vec<Rendered> = Vec::new();
    for &technique in &args.techniques {
        let mut s = settings.clone();
        s.shadow.filter.technique = technique;
        let frame = renderer.render_uploaded(&uploaded, &scene, &s, &OutputRequest::default())?;
        let (mut shadow, mut filter, mut lighting) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..args.timing_frames {
            if let (Some(t), _) = renderer.time_passes(&uploaded, &scene, &s)? {
                shadow.push(t.shadow_ms);
                filter.extend(t.filter_ms);
                lighting.push(t.lighting_ms);
            }
        }
        let timing = (!shadow.is_empty()).then(|| {
            let filter = (!filter.is_empty()).then(|| median(&mut filter));
            (median(&mut shadow), filter, median(&mut lighting))
        });
        frames.push(Rendered { technique, frame, timing });
    }

    let reference = lab::reference(&scene, settings, !args.no_cache)?.image;
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
    for Rendered { technique, frame, timing } in &frames {
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
        let summary = if soft {
            format!("MAE {:.4}  p99 {:.3}", m.mae, m.p99)
        } else {
            format!("mismatch {:.3}%", 100.0 * m.mismatch_rate)
        };
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
                caption: vec![
                    summary,
                    format!("false shadow {:.3}%", 100.0 * m.false_shadow_rate),
                    format!("false lit {:.3}%", 100.0 * m.false_lit_rate),
                ],
                downscale: Downscale::Salient(if soft { soft_priority } else { hard_priority }),
            },
        ]);
        rows.push(Row {
            technique: name,
            metrics: m,
            shadow_ms: timing.map(|t| t.0),
            filter_ms: timing.and_then(|t| t.1),
            lighting_ms: timing.map(|t| t.2),
            moment_format: frame.moment_format.map(|f| format!("{f:?}").to_lowercase()),
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

/// The technique's name, with its moment map's format when that is not 32-bit float.
fn technique_label(r: &Row) -> String {
    match &r.moment_format {
        Some(f) if f != "rgba32float" => format!("{} ({f})", r.technique),
        _ => r.technique.to_string(),
    }
}

fn markdown_table(report: &Report, soft: bool) -> String {
    let mut s = format!(
        "`{}` at {}×{}, shadow map {}², reference {} on {} ({})\n\n",
        report.scene,
        report.width,
        report.height,
        report.shadow_resolution,
        if soft { format!("{} samples/pixel", report.reference_samples) } else { "exact".into() },
        report.adapter,
        report.backend
    );
    s.push_str("| technique | mismatch | false shadow | false lit | MAE | RMSE | p99 | compared | silhouette | shadow ms | filter ms | lighting ms |\n");
    s.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    let ms = |v: Option<f64>| v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "n/a".into());
    for r in &report.rows {
        let m = &r.metrics;
        s.push_str(&format!(
            "| {} | {:.3}% | {:.3}% | {:.3}% | {:.4} | {:.4} | {:.3} | {} | {} | {} | {} | {} |\n",
            technique_label(r),
            100.0 * m.mismatch_rate,
            100.0 * m.false_shadow_rate,
            100.0 * m.false_lit_rate,
            m.mae,
            m.rmse,
            m.p99,
            m.compared,
            m.silhouette,
            ms(r.shadow_ms),
            if r.filter_ms.is_some() { ms(r.filter_ms) } else { "–".into() },
            ms(r.lighting_ms)
        ));
    }
    s
}

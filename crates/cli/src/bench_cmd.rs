//! `gnomon bench`: what each pass costs. For every technique (and every value of a
//! swept setting) it renders warm-up frames, then times N frames: the GPU time of
//! every pass (each layer of each light's map, filters, screen-space passes,
//! lighting), the GPU frame, the CPU's submission time (fitting, culling,
//! recording), and optionally the depth-only baseline the shadow pass is measured
//! against. It reports the median and 95th percentile of each, as JSON and markdown,
//! with the adapter and driver that measured them.

use std::{collections::BTreeMap, path::PathBuf, time::Instant};

use anyhow::Context;
use clap::{Args, ValueEnum};
use gnomon_render::{FrameCost, Gpu, GpuInfo, Renderer, timing::ClockChoice};
use gnomon_scene::{Settings, settings::Technique};
use gnomon_viewer::settings_form::SettingsForm;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

use crate::output::{self, Staged};

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    pub scene: crate::lab::SceneArgs,
    /// Techniques to time, comma-separated (see `gnomon techniques`) [default: the
    /// one the settings choose].
    #[arg(long, value_enum, value_delimiter = ',', help_heading = "Benchmark")]
    pub techniques: Vec<Technique>,
    /// Timed frames per configuration, 1 to 100000.
    #[arg(long, value_name = "N", default_value_t = 60, help_heading = "Benchmark")]
    pub frames: u32,
    /// Untimed frames first, so that pipelines are built and caches warm; 0 to 10000.
    #[arg(long, value_name = "N", default_value_t = 10, help_heading = "Benchmark")]
    pub warmup: u32,
    /// The former spelling of --width and --height, as WIDTHxHEIGHT; every command
    /// takes --width and --height.
    #[arg(long, value_name = "WxH", value_parser = parse_size, hide = true, conflicts_with_all = ["width", "height"])]
    pub size: Option<(u32, u32)>,
    /// Time every value of one setting: FLAG=V1,V2,… with FLAG a settings flag
    /// without its dashes, e.g. `shadow-res=512,1024,2048,4096`.
    #[arg(long, value_name = "FLAG=V1,V2,…", help_heading = "Benchmark")]
    pub sweep: Option<String>,
    /// Also time the depth-only baseline (every caster pre-transformed, one draw, a
    /// vertex-only pipeline) into the same maps, and report the shadow pass's time as
    /// a ratio of it.
    #[arg(long, help_heading = "Benchmark")]
    pub depth_only: bool,
    /// Sway N instances (spread over the scene's list) by a hundredth of the scene's
    /// size every frame, and time how long the renderer takes to follow them (`CPU
    /// move`: transforms, culling trees and, with rays, the BVH refitted).
    #[arg(long, value_name = "N", help_heading = "Benchmark")]
    pub moving: Option<usize>,
    /// How to time passes: GPU timestamps where the adapter has them (else the CPU
    /// wall clock), or the CPU wall clock always.
    #[arg(long, value_enum, default_value_t = ClockArg::Auto, help_heading = "Benchmark")]
    pub clock: ClockArg,
    /// Output directory (created if missing): bench.json and bench.md.
    #[arg(long, short, default_value = "bench", help_heading = "Outputs")]
    pub out: PathBuf,
    /// Print the adapter, driver and backend.
    #[arg(long, short)]
    pub verbose: bool,
    #[command(flatten)]
    pub settings: Settings,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ClockArg {
    Auto,
    Cpu,
}

fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let invalid = || format!("`{text}`: give WIDTHxHEIGHT, e.g. 1280x720, each 1 to 16384");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(invalid)?;
    let (w, h): (u32, u32) =
        (w.trim().parse().map_err(|_| invalid())?, h.trim().parse().map_err(|_| invalid())?);
    if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
        return Err(invalid());
    }
    Ok((w, h))
}

/// One configuration to time: a technique, and the swept setting's value.
struct Config {
    technique: Technique,
    sweep_value: Option<String>,
    settings: Settings,
}

/// The median and 95th percentile of one measured quantity, in milliseconds, and every
/// frame's value in the order the frames were timed (for re-analysis: frame i of one
/// quantity and frame i of another were measured in the same frame).
#[derive(Serialize, Clone, Debug)]
struct Summary {
    name: String,
    median_ms: f64,
    p95_ms: f64,
    samples: usize,
    values_ms: Vec<f64>,
}

#[derive(Serialize, Debug)]
struct ConfigReport {
    technique: String,
    sweep_value: Option<String>,
    /// Per pass (shadow, filter, prepass, mask, lighting: every light together),
    /// then the frame totals (GPU frame, CPU submission and its parts, wall clock).
    passes: Vec<Summary>,
    /// Each light's each layer: "shadow L0 layer 1".
    layers: Vec<Summary>,
    /// Instances and draw calls of one frame.
    shadow_draws: u32,
    shadow_instances: u32,
    lighting_draws: u32,
    lighting_instances: u32,
    /// With --depth-only: the baseline's time, and the median over frames of the
    /// shadow pass's time over the baseline's (lights the baseline can draw).
    depth_only: Option<Summary>,
    shadow_over_depth_only: Option<f64>,
    /// With refinement by rays, in the last frame: the pixels traced as a share of
    /// the screen (every refining light together, in %), and the rays cast.
    traced_percent: Option<f64>,
    rays: Option<u64>,
}

#[derive(Serialize, Debug)]
struct Report {
    adapter: String,
    backend: String,
    device_type: String,
    driver: String,
    driver_info: String,
    timing: &'static str,
    scene: String,
    instances: usize,
    triangles: usize,
    width: u32,
    height: u32,
    warmup: u32,
    frames: u32,
    sweep: Option<String>,
    /// With --moving: how many instances moved every frame, and the time to build
    /// the casters' BVH afresh, for scale against the refits in `CPU move`.
    moving: Option<usize>,
    rebuild_ms: Option<f64>,
    command: String,
    configs: Vec<ConfigReport>,
}

pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    anyhow::ensure!((1..=100_000).contains(&args.frames), "--frames {}: give 1 to 100000", args.frames);
    anyhow::ensure!(args.warmup <= 10_000, "--warmup {}: give 0 to 10000", args.warmup);
    args.settings.validate()?;
    output::check_dir(&args.out, "--out")?;
    let (mut scene, mut base) = crate::lab::load(&args.scene, &args.settings)?;
    let mover = args.moving.map(|count| crate::bench_moving::Mover::new(&scene, count)).transpose()?;
    if let Some((width, height)) = args.size {
        base.image.width = width;
        base.image.height = height;
    }
    base.validate()?;
    let configs = configurations(args, &base)?;

    let gpu = Gpu::new_headless()?;
    if args.verbose {
        eprintln!("gnomon: {}", gpu.info);
    }
    let mut renderer = Renderer::new(&gpu)?;
    // Every configuration must fit the device before any is timed.
    for config in &configs {
        renderer.check_limits(&config.settings).with_context(|| config_name(args, config))?;
    }
    let mut uploaded = renderer.upload(&scene)?;
    let baseline = if args.depth_only { Some(renderer.upload_depth_baseline(&scene)?) } else { None };
    let clock = match args.clock {
        ClockArg::Auto => ClockChoice::Auto,
        ClockArg::Cpu => ClockChoice::Cpu,
    };

    let per_config = u64::from(args.warmup + args.frames);
    let progress = ProgressBar::new(per_config * configs.len() as u64);
    progress.set_style(
        ProgressStyle::with_template("{prefix:>28} [{bar:30}] {pos}/{len} frames, {eta} left")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    let mut reports = Vec::with_capacity(configs.len());
    let mut source = None;
    for config in &configs {
        progress.set_prefix(config_name(args, config));
        let settings = &config.settings;
        let mut frame = 0;
        for _ in 0..args.warmup {
            if let Some(mover) = &mover {
                mover.step(&renderer, &mut uploaded, &mut scene, frame)?;
                frame += 1;
            }
            renderer.time_passes(&uploaded, &scene, settings, clock)?;
            if let Some(baseline) = &baseline {
                renderer.time_depth_baseline(baseline, &uploaded, &scene, settings, clock)?;
            }
            progress.inc(1);
        }
        let mut series: BTreeMap<String, Vec<f64>> = BTreeMap::new();
        let mut order: Vec<String> = Vec::new();
        let mut push = |name: String, ms: f64| {
            if !series.contains_key(&name) {
                order.push(name.clone());
            }
            series.entry(name).or_default().push(ms);
        };
        let mut last: Option<FrameCost> = None;
        for _ in 0..args.frames {
            if let Some(mover) = &mover {
                push("CPU move".into(), mover.step(&renderer, &mut uploaded, &mut scene, frame)?);
                frame += 1;
            }
            let started = Instant::now();
            let cost = renderer.time_passes(&uploaded, &scene, settings, clock)?;
            let wall_ms = started.elapsed().as_secs_f64() * 1e3;
            let timings = cost.timings.context("the frame was not timed")?;
            source = Some(timings.source);
            push("shadow".into(), timings.shadow_ms);
            if let Some(ms) = timings.filter_ms {
                push("filter".into(), ms);
            }
            if let Some(ms) = timings.prepass_ms {
                push("prepass".into(), ms);
            }
            if let Some(ms) = timings.mask_ms {
                push("mask".into(), ms);
            }
            if let Some(ms) = timings.trace_ms {
                push("trace".into(), ms);
            }
            push("lighting".into(), timings.lighting_ms);
            push("GPU frame".into(), timings.frame_ms);
            push("CPU submit".into(), cost.cpu.submit_ms);
            push("CPU fit".into(), cost.cpu.plan_ms);
            push("CPU cull".into(), cost.cpu.cull_ms);
            push("CPU record".into(), cost.cpu.record_ms);
            push("wall frame".into(), wall_ms);
            // What the frame costs beyond its GPU work and the CPU's submission: resource
            // creation, stalls and readback waits. 1 means nothing is wasted.
            push("wall ÷ (GPU + CPU)".into(), wall_ms / (timings.frame_ms + cost.cpu.submit_ms));
            for (light, stats) in cost.lights.iter().enumerate() {
                for (layer, ms) in stats.layer_ms.iter().enumerate() {
                    push(format!("shadow L{light} layer {layer}"), *ms);
                }
            }
            if let Some(baseline) = &baseline {
                let times = renderer.time_depth_baseline(baseline, &uploaded, &scene, settings, clock)?;
                // Only lights the baseline can draw (not dual-paraboloid maps) compare.
                let drawn: Vec<usize> = (0..times.len()).filter(|&i| times[i].is_some()).collect();
                let baseline_ms: f64 = drawn.iter().filter_map(|&i| times[i]).sum();
                let ours_ms: f64 = drawn.iter().filter_map(|&i| cost.lights[i].shadow_ms).sum();
                push("depth-only".into(), baseline_ms);
                // The ratio frame by frame: both were timed back to back, so a slow
                // spell of the machine affects both alike.
                push("shadow ÷ depth-only".into(), ours_ms / baseline_ms);
            }
            last = Some(cost);
            progress.inc(1);
        }
        let summary = |name: &str| series.get(name).map(|values| summarize(name, values));
        let last = last.expect("at least one frame");
        crate::render_cmd::warn_unrefined(&last.lights);
        let is_layer = |name: &String| name.starts_with("shadow L");
        let depth_only = summary("depth-only");
        let ratio = summary("shadow ÷ depth-only").map(|r| r.median_ms);
        let refined: Vec<&gnomon_render::LightStats> =
            last.lights.iter().filter(|l| l.traced_pixels.is_some()).collect();
        let traced = (!refined.is_empty())
            .then(|| refined.iter().filter_map(|l| l.traced_pixels).map(u64::from).sum::<u64>());
        let rays = (!refined.is_empty()).then(|| refined.iter().filter_map(|l| l.traced_rays()).sum::<u64>());
        let pixels = f64::from(settings.image.width) * f64::from(settings.image.height);
        reports.push(ConfigReport {
            technique: config.technique.name().to_string(),
            sweep_value: config.sweep_value.clone(),
            passes: order
                .iter()
                .filter(|n| !is_layer(n) && !n.contains("depth-only"))
                .filter_map(|n| summary(n))
                .collect(),
            layers: order.iter().filter(|n| is_layer(n)).filter_map(|n| summary(n)).collect(),
            shadow_draws: last.stats.shadow_draws,
            shadow_instances: last.stats.shadow_instances,
            lighting_draws: last.stats.lighting_draws,
            lighting_instances: last.stats.lighting_instances,
            depth_only,
            shadow_over_depth_only: ratio,
            traced_percent: traced.map(|t| 100.0 * t as f64 / pixels),
            rays,
        });
    }
    progress.finish_and_clear();

    let report = Report {
        adapter: gpu.info.adapter.clone(),
        backend: gpu.info.backend.clone(),
        device_type: gpu.info.device_type.clone(),
        driver: gpu.info.driver.clone(),
        driver_info: gpu.info.driver_info.clone(),
        timing: match source {
            Some(gnomon_render::timing::TimingSource::GpuTimestamps) => "GPU timestamps",
            _ => "CPU wall clock (each pass submitted and waited for alone)",
        },
        scene: scene.name.clone(),
        instances: uploaded.instance_count(),
        triangles: scene.triangle_count(),
        width: base.image.width,
        height: base.image.height,
        warmup: args.warmup,
        frames: args.frames,
        sweep: args.sweep.clone(),
        moving: mover.as_ref().map(|m| m.count()),
        rebuild_ms: mover
            .as_ref()
            .map(|_| crate::bench_moving::Mover::rebuild_ms(&gpu, &scene))
            .transpose()?,
        command: std::env::args().collect::<Vec<_>>().join(" "),
        configs: reports,
    };
    let markdown = markdown(&report, &gpu.info);
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut staged = Staged::default();
    staged.text(&args.out.join("bench.json"), &(serde_json::to_string_pretty(&report)? + "\n"))?;
    staged.text(&args.out.join("bench.md"), &markdown)?;
    let written = staged.commit()?;
    print!("{markdown}");
    for path in written {
        eprintln!("gnomon: wrote {}", path.display());
    }
    Ok(())
}

/// The techniques × sweep values to time, each with its settings checked.
fn configurations(args: &BenchArgs, base: &Settings) -> anyhow::Result<Vec<Config>> {
    let techniques = if args.techniques.is_empty() {
        vec![base.shadow.filter.technique.clone()]
    } else {
        args.techniques.clone()
    };
    let sweep = match &args.sweep {
        None => None,
        Some(text) => Some(parse_sweep(text)?),
    };
    let form = SettingsForm::new();
    let mut configs = Vec::new();
    for technique in techniques {
        let mut settings = base.clone();
        settings.shadow.filter.technique = technique.clone();
        match &sweep {
            None => configs.push(Config { technique, sweep_value: None, settings }),
            Some((flag, values)) => {
                let field =
                    form.fields().iter().find(|f| f.long == *flag || f.id == *flag).with_context(|| {
                        format!(
                            "--sweep {flag}=…: no such setting; sweep one of the settings flags, e.g. \
                             shadow-res, pcf-kernel, cascades, technique (see `gnomon render --help`)"
                        )
                    })?;
                for value in values {
                    let swept = form
                        .set(&settings, &field.id, Some(value))
                        .map_err(|e| anyhow::anyhow!("--sweep {flag}={value}: {e}"))?;
                    configs.push(Config {
                        technique: technique.clone(),
                        sweep_value: Some(value.clone()),
                        settings: swept,
                    });
                }
            }
        }
    }
    Ok(configs)
}

/// `FLAG=V1,V2,…` as the flag (without dashes) and its values.
fn parse_sweep(text: &str) -> anyhow::Result<(String, Vec<String>)> {
    let (flag, values) = text
        .split_once('=')
        .with_context(|| format!("--sweep {text}: give FLAG=V1,V2,…, e.g. shadow-res=512,1024,2048"))?;
    let flag = flag.trim().trim_start_matches('-').to_string();
    let values: Vec<String> =
        values.split(',').map(|v| v.trim().to_string()).filter(|v| !v.is_empty()).collect();
    anyhow::ensure!(!values.is_empty(), "--sweep {text}: no values after `=`");
    Ok((flag, values))
}

fn config_name(args: &BenchArgs, config: &Config) -> String {
    match (&config.sweep_value, &args.sweep) {
        (Some(value), Some(sweep)) => {
            let flag = sweep.split('=').next().unwrap_or_default().trim_start_matches('-');
            format!("{} {flag}={value}", config.technique.name())
        }
        _ => config.technique.name().to_string(),
    }
}

/// Median and 95th percentile (nearest rank) of `values`.
fn summarize(name: &str, values: &[f64]) -> Summary {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let rank = |q: f64| sorted[((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1];
    let median = if sorted.len() % 2 == 1 {
        sorted[sorted.len() / 2]
    } else {
        0.5 * (sorted[sorted.len() / 2 - 1] + sorted[sorted.len() / 2])
    };
    Summary {
        name: name.to_string(),
        median_ms: median,
        p95_ms: rank(0.95),
        samples: sorted.len(),
        values_ms: values.to_vec(),
    }
}

/// The report as markdown: the device, then a table of passes per configuration,
/// then each layer's time where a light has several.
fn markdown(report: &Report, info: &GpuInfo) -> String {
    use std::fmt::Write;
    let mut md = String::new();
    let _ = writeln!(md, "# gnomon bench: {}\n", report.scene);
    let _ = writeln!(
        md,
        "- adapter: {} ({}, {}), driver: {} {}\n- timing: {}\n- {} instances{}, {} triangles; image {}×{}; \
         {} warm-up and {} timed frames per row; times in ms, median (p95)\n- command: `{}`\n",
        info.adapter,
        info.device_type,
        info.backend,
        info.driver,
        info.driver_info,
        report.timing,
        report.instances,
        match (report.moving, report.rebuild_ms) {
            (Some(n), Some(ms)) => format!(
                " ({n} moving every frame: `CPU move`; building the casters' BVH afresh takes {ms:.1} ms)"
            ),
            _ => String::new(),
        },
        report.triangles,
        report.width,
        report.height,
        report.warmup,
        report.frames,
        report.command,
    );
    let mut columns: Vec<String> = Vec::new();
    for config in &report.configs {
        for pass in &config.passes {
            if !columns.contains(&pass.name) {
                columns.push(pass.name.clone());
            }
        }
    }
    // In frame order, whichever configurations have them.
    const ORDER: [&str; 14] = [
        "shadow",
        "filter",
        "prepass",
        "mask",
        "trace",
        "lighting",
        "GPU frame",
        "CPU move",
        "CPU submit",
        "CPU fit",
        "CPU cull",
        "CPU record",
        "wall frame",
        "wall ÷ (GPU + CPU)",
    ];
    columns.sort_by_key(|c| ORDER.iter().position(|o| o == c).unwrap_or(ORDER.len()));
    let sweep = report.sweep.as_deref().and_then(|s| s.split('=').next()).map(|f| f.trim_start_matches('-'));
    let has_baseline = report.configs.iter().any(|c| c.depth_only.is_some());
    let has_rays = report.configs.iter().any(|c| c.rays.is_some());
    let _ = write!(md, "| technique |");
    if let Some(flag) = sweep {
        let _ = write!(md, " {flag} |");
    }
    for c in &columns {
        let _ = write!(md, " {c} |");
    }
    if has_baseline {
        let _ = write!(md, " depth-only | shadow ÷ depth-only |");
    }
    if has_rays {
        let _ = write!(md, " traced, % of screen (rays) |");
    }
    let _ = writeln!(md, " shadow draws (instances) | lighting draws (instances) |");
    let cells = columns.len()
        + 3
        + usize::from(sweep.is_some())
        + 2 * usize::from(has_baseline)
        + usize::from(has_rays);
    let _ = writeln!(md, "|{}", "---|".repeat(cells));
    let cell = |s: Option<&Summary>| {
        s.map_or("–".to_string(), |s| format!("{:.3} ({:.3})", s.median_ms, s.p95_ms))
    };
    for config in &report.configs {
        let _ = write!(md, "| {} |", config.technique);
        if sweep.is_some() {
            let _ = write!(md, " {} |", config.sweep_value.as_deref().unwrap_or(""));
        }
        for c in &columns {
            let _ = write!(md, " {} |", cell(config.passes.iter().find(|p| &p.name == c)));
        }
        if has_baseline {
            let ratio = config.shadow_over_depth_only.map_or("–".into(), |r| format!("{r:.3}"));
            let _ = write!(md, " {} | {ratio} |", cell(config.depth_only.as_ref()));
        }
        if has_rays {
            let traced = match (config.traced_percent, config.rays) {
                (Some(percent), Some(rays)) => format!("{percent:.2} ({rays})"),
                _ => "–".into(),
            };
            let _ = write!(md, " {traced} |");
        }
        let _ = writeln!(
            md,
            " {} ({}) | {} ({}) |",
            config.shadow_draws, config.shadow_instances, config.lighting_draws, config.lighting_instances
        );
    }
    if report.configs.iter().any(|c| c.layers.len() > 1) {
        let _ = writeln!(md, "\nEach shadow-map layer (light L, layer: cascade or cube face):\n");
        let _ = writeln!(md, "| technique | layer | median (p95) |\n|---|---|---|");
        for config in &report.configs {
            let label = match &config.sweep_value {
                Some(v) => format!("{} {}={v}", config.technique, sweep.unwrap_or("")),
                None => config.technique.clone(),
            };
            for layer in &config.layers {
                let _ = writeln!(
                    md,
                    "| {label} | {} | {} |",
                    layer.name.trim_start_matches("shadow "),
                    cell(Some(layer))
                );
            }
        }
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summaries_take_the_median_and_the_nearest_rank_p95() {
        let values: Vec<f64> = (1..=100).map(f64::from).collect();
        let s = summarize("x", &values);
        assert_eq!((s.median_ms, s.p95_ms, s.samples), (50.5, 95.0, 100));
        let s = summarize("x", &[3.0, 1.0, 2.0]);
        assert_eq!((s.median_ms, s.p95_ms), (2.0, 3.0));
    }

    #[test]
    fn sizes_and_sweeps_parse_or_say_what_is_valid() {
        assert_eq!(parse_size("640x360"), Ok((640, 360)));
        assert!(parse_size("640").unwrap_err().contains("WIDTHxHEIGHT"));
        assert!(parse_size("0x5").is_err());
        let (flag, values) = parse_sweep("--shadow-res=512, 1024,2048").unwrap();
        assert_eq!((flag.as_str(), values.len()), ("shadow-res", 3));
        assert!(parse_sweep("shadow-res").is_err());
        assert!(parse_sweep("shadow-res=").is_err());
    }
}

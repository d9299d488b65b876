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
use gnomon_render::{
    DepthBaselineScene, FrameCost, Gpu, GpuScene, LayerCache, Renderer,
    timing::{ClockChoice, TimingSource},
};
use gnomon_scene::{
    Scene, Settings,
    camera_path::{CameraPathKind, camera_on_path},
    settings::{LightKind, Technique},
};
use gnomon_viewer::settings_form::SettingsForm;
use indicatif::{ProgressBar, ProgressStyle};

use crate::{
    bench_lights::{LightPaths, PointPathKind, SpotPathKind, SunPathKind},
    bench_report::{ConfigReport, LayerDrawn, Report, Summary, markdown, summarize},
    output::{self, Staged},
};

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
    /// move`: transforms, culling trees and, with rays, the BVH refitted). They are
    /// declared moving (`Motion::Dynamic`), so kept shadow maps draw them over their
    /// still casters every frame.
    #[arg(long, value_name = "N", help_heading = "Benchmark")]
    pub moving: Option<usize>,
    /// Move the camera along this path over the warm-up and timed frames (the scene
    /// and light still), to time what a moving view costs: with `--map-cache`, the
    /// layers whose projection moved are drawn again, the others kept.
    #[arg(long, value_enum, help_heading = "Benchmark")]
    pub camera_path: Option<CameraPathKind>,
    /// How far the eye travels over the whole path, as a fraction of its distance to
    /// the target (an orbit's arc: that angle in radians); in (0, 1].
    #[arg(long, value_name = "FRACTION", default_value_t = 0.05, help_heading = "Benchmark")]
    pub path_travel: f32,
    /// Move the sun every frame along this path over the warm-up and timed frames
    /// (overriding --sun-elevation and --sun-azimuth), so that no kept map is valid:
    /// `day` runs from 7 h to 17 h of an equinox at 45° N, the sun 10.5° to 45° high.
    /// Needs the sun (`--light sun`).
    #[arg(long, value_enum, help_heading = "Benchmark")]
    pub sun_path: Option<SunPathKind>,
    /// Move the spot every frame along this path over the warm-up and timed frames
    /// (overriding --spot-target), so that no kept map is valid: `sweep` swings its
    /// aim 30° across, about the vertical through it, as a flashlight's. Needs the
    /// spot (`--light spot`).
    #[arg(long, value_enum, help_heading = "Benchmark")]
    pub spot_path: Option<SpotPathKind>,
    /// Move the point light every frame along this path over the warm-up and timed
    /// frames (overriding --point-position), so that no kept map is valid: `sway`
    /// carries it across a twentieth of its range along x, as a hanging lantern
    /// swings. Needs the point light (`--light point`).
    #[arg(long, value_enum, help_heading = "Benchmark")]
    pub point_path: Option<PointPathKind>,
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

impl BenchArgs {
    /// The paths its flags move the light along.
    fn light_paths(&self) -> crate::bench_lights::LightPathArgs {
        crate::bench_lights::LightPathArgs {
            sun: self.sun_path,
            spot: self.spot_path,
            point: self.point_path,
        }
    }
}

/// Refuses values of the bench's own flags out of their ranges, naming the flag and
/// what is valid.
fn check_args(args: &BenchArgs) -> anyhow::Result<()> {
    anyhow::ensure!((1..=100_000).contains(&args.frames), "--frames {}: give 1 to 100000", args.frames);
    anyhow::ensure!(args.warmup <= 10_000, "--warmup {}: give 0 to 10000", args.warmup);
    anyhow::ensure!(
        args.path_travel > 0.0 && args.path_travel <= 1.0,
        "--path-travel = {} is invalid: a fraction in (0, 1]",
        args.path_travel
    );
    args.settings.validate()?;
    anyhow::ensure!(
        args.sun_path.is_none() || args.settings.light.kind == LightKind::Sun,
        "--sun-path moves the sun: give it with --light sun (the default), not another light"
    );
    anyhow::ensure!(
        args.spot_path.is_none() || args.settings.light.kind == LightKind::Spot,
        "--spot-path moves the spot: give it with --light spot, not another light"
    );
    anyhow::ensure!(
        args.point_path.is_none() || args.settings.light.kind == LightKind::Point,
        "--point-path moves the point light: give it with --light point, not another light"
    );
    Ok(())
}

/// One configuration to time: a technique, and the swept setting's value.
struct Config {
    technique: Technique,
    sweep_value: Option<String>,
    settings: Settings,
}

pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    check_args(args)?;
    output::check_dir(&args.out, "--out")?;
    let (mut scene, mut base) = crate::lab::load(&args.scene, &args.settings)?;
    let mover = args.moving.map(|count| crate::bench_moving::Mover::new(&scene, count)).transpose()?;
    if let Some(mover) = &mover {
        // Declared as an application would before it uploads: kept shadow maps draw
        // them over their still casters every frame.
        mover.declare_dynamic(&mut scene);
    }
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
    let renderer = Renderer::new(&gpu)?;
    // Every configuration must fit the device before any is timed.
    for config in &configs {
        renderer.check_limits(&config.settings).with_context(|| config_name(args, config))?;
    }
    let uploaded = renderer.upload(&scene)?;
    let baseline = if args.depth_only { Some(renderer.upload_depth_baseline(&scene)?) } else { None };
    let clock = match args.clock {
        ClockArg::Auto => ClockChoice::Auto,
        ClockArg::Cpu => ClockChoice::Cpu,
    };
    let mut bench = Bench { args, renderer, uploaded, scene, baseline, mover, clock, source: None };

    let per_config = u64::from(args.warmup + args.frames);
    let progress = ProgressBar::new(per_config * configs.len() as u64);
    progress.set_style(
        ProgressStyle::with_template("{prefix:>28} [{bar:30}] {pos}/{len} frames, {eta} left")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    let mut reports = Vec::with_capacity(configs.len());
    for config in &configs {
        progress.set_prefix(config_name(args, config));
        reports.push(bench.config(config, &progress)?);
    }
    progress.finish_and_clear();
    let Bench { scene, uploaded, mover, source, .. } = bench;

    let report = Report {
        adapter: gpu.info.adapter.clone(),
        backend: gpu.info.backend.clone(),
        device_type: gpu.info.device_type.clone(),
        driver: gpu.info.driver.clone(),
        driver_info: gpu.info.driver_info.clone(),
        timing: match source {
            Some(TimingSource::GpuTimestamps) => "GPU timestamps",
            Some(TimingSource::CpuWallClock) | None => {
                "CPU wall clock (each pass submitted and waited for alone)"
            }
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

/// What every configuration's frames are drawn with.
struct Bench<'a> {
    args: &'a BenchArgs,
    renderer: Renderer,
    uploaded: GpuScene,
    scene: Scene,
    baseline: Option<DepthBaselineScene>,
    /// With --moving: what sways the instances every frame.
    mover: Option<crate::bench_moving::Mover>,
    clock: ClockChoice,
    /// How the last timed frame was timed.
    source: Option<TimingSource>,
}

/// One configuration's measured quantities, each frame's value in order, listed in
/// the order they were first measured.
#[derive(Default)]
struct Series {
    values: BTreeMap<String, Vec<f64>>,
    order: Vec<String>,
}

impl Series {
    fn push(&mut self, name: impl Into<String>, ms: f64) {
        let name = name.into();
        if !self.values.contains_key(&name) {
            self.order.push(name.clone());
        }
        self.values.entry(name).or_default().push(ms);
    }

    fn summary(&self, name: &str) -> Option<Summary> {
        self.values.get(name).map(|values| summarize(name, values))
    }
}

impl Bench<'_> {
    /// Warms up, then times `--frames` frames of one configuration.
    fn config(&mut self, config: &Config, progress: &ProgressBar) -> anyhow::Result<ConfigReport> {
        let mut settings = config.settings.clone();
        let start = settings.resolve_camera(&self.scene)?;
        let frames = self.args.warmup + self.args.frames;
        let path = self.args.camera_path;
        let travel = self.args.path_travel;
        let first = settings.resolve_lights(&self.scene)?.first().map(|resolved| resolved.light);
        let lights = LightPaths::new(self.args.light_paths(), first);
        // The camera and the light of frame `i` of the warm-up and timed frames together.
        let place = |settings: &mut Settings, i: u32| {
            let fraction = i as f32 / (frames - 1).max(1) as f32;
            if let Some(kind) = path {
                let camera = camera_on_path(&start, kind, travel, fraction);
                settings.camera.eye = Some(camera.eye);
                settings.camera.target = Some(camera.target);
            }
            lights.place(settings, fraction);
        };
        let settings = &mut settings;
        let mut frame = 0;
        for i in 0..self.args.warmup {
            place(settings, i);
            if let Some(mover) = &self.mover {
                mover.step(&self.renderer, &mut self.uploaded, &mut self.scene, frame)?;
                frame += 1;
            }
            self.renderer.time_passes(&self.uploaded, &self.scene, settings, self.clock)?;
            if let Some(baseline) = &self.baseline {
                self.renderer.time_depth_baseline(
                    baseline,
                    &self.uploaded,
                    &self.scene,
                    settings,
                    self.clock,
                )?;
            }
            progress.inc(1);
        }
        let mut series = Series::default();
        let mut last: Option<FrameCost> = None;
        for i in 0..self.args.frames {
            place(settings, self.args.warmup + i);
            if let Some(mover) = &self.mover {
                series.push(
                    "CPU move",
                    mover.step(&self.renderer, &mut self.uploaded, &mut self.scene, frame)?,
                );
                frame += 1;
            }
            last = Some(self.timed_frame(settings, &mut series)?);
            progress.inc(1);
        }
        let last = last.expect("at least one frame");
        crate::render_cmd::warn_fallbacks(&last.lights);
        Ok(config_report(config, &series, &last))
    }

    /// One timed frame, its quantities pushed onto `series`.
    fn timed_frame(&mut self, settings: &Settings, series: &mut Series) -> anyhow::Result<FrameCost> {
        let started = Instant::now();
        let cost = self.renderer.time_passes(&self.uploaded, &self.scene, settings, self.clock)?;
        let wall_ms = started.elapsed().as_secs_f64() * 1e3;
        let timings = cost.timings.context("the frame was not timed")?;
        self.source = Some(timings.source);
        series.push("shadow", timings.shadow_ms);
        let optional = [
            ("filter", timings.filter_ms),
            ("prepass", timings.prepass_ms),
            ("mask", timings.mask_ms),
            ("trace", timings.trace_ms),
        ];
        for (name, ms) in optional {
            if let Some(ms) = ms {
                series.push(name, ms);
            }
        }
        series.push("lighting", timings.lighting_ms);
        series.push("GPU frame", timings.frame_ms);
        series.push("CPU submit", cost.cpu.submit_ms);
        series.push("CPU fit", cost.cpu.plan_ms);
        series.push("CPU cull", cost.cpu.cull_ms);
        series.push("CPU record", cost.cpu.record_ms);
        series.push("wall frame", wall_ms);
        // What a fill-bound GPU pays for: the texels the shadow passes cleared or
        // drew into, in millions.
        let texels: u64 = cost.lights.iter().flat_map(|l| l.layer_texels.iter()).sum();
        series.push("shadow Mtexels", texels as f64 / 1e6);
        // A virtual map's pages drawn, and what asking for them cost before the
        // shadow passes (a camera prepass, the request pass, the wait).
        let pages: Vec<_> = cost.lights.iter().filter_map(|l| l.pages).collect();
        if !pages.is_empty() {
            series.push("pages drawn", pages.iter().map(|p| f64::from(p.drawn)).sum());
            series.push("page runs drawn", pages.iter().map(|p| f64::from(p.runs)).sum());
            series.push("pages refused", pages.iter().map(|p| f64::from(p.refused)).sum());
            series.push("page requests (wall)", pages.iter().map(|p| p.request_ms).sum());
        }
        // What the frame costs beyond its GPU work and the CPU's submission: resource
        // creation, stalls and readback waits. 1 means nothing is wasted.
        series.push("wall ÷ (GPU + CPU)", wall_ms / (timings.frame_ms + cost.cpu.submit_ms));
        // With kept maps: how many layers each frame kept, scrolled or drew again.
        let uses: Vec<LayerCache> = cost.lights.iter().flat_map(|l| l.layer_cache.iter().copied()).collect();
        if uses.iter().any(|&u| u != LayerCache::Off) {
            let count = |state: LayerCache| uses.iter().filter(|&&u| u == state).count() as f64;
            series.push("layers kept", count(LayerCache::Kept));
            series.push("layers scrolled", count(LayerCache::Scrolled));
            series.push("layers drawn", count(LayerCache::Drawn));
        }
        for (light, stats) in cost.lights.iter().enumerate() {
            for (layer, ms) in stats.layer_ms.iter().enumerate() {
                series.push(format!("shadow L{light} layer {layer}"), *ms);
            }
        }
        if let Some(baseline) = &self.baseline {
            let times = self.renderer.time_depth_baseline(
                baseline,
                &self.uploaded,
                &self.scene,
                settings,
                self.clock,
            )?;
            // Only lights the baseline can draw (not dual-paraboloid maps) compare.
            let drawn: Vec<usize> = (0..times.len()).filter(|&i| times[i].is_some()).collect();
            let baseline_ms: f64 = drawn.iter().filter_map(|&i| times[i]).sum();
            let ours_ms: f64 = drawn.iter().filter_map(|&i| cost.lights[i].shadow_ms).sum();
            series.push("depth-only", baseline_ms);
            // The ratio frame by frame: both were timed back to back, so a slow spell
            // of the machine affects both alike.
            series.push("shadow ÷ depth-only", ours_ms / baseline_ms);
        }
        Ok(cost)
    }
}

/// One configuration's report, from its series and its last frame (for the draws
/// and the pixels traced).
fn config_report(config: &Config, series: &Series, last: &FrameCost) -> ConfigReport {
    let is_layer = |name: &&String| name.starts_with("shadow L");
    let refined: Vec<&gnomon_render::LightStats> =
        last.lights.iter().filter(|l| l.traced_pixels.is_some()).collect();
    let traced = (!refined.is_empty())
        .then(|| refined.iter().filter_map(|l| l.traced_pixels).map(u64::from).sum::<u64>());
    let rays = (!refined.is_empty()).then(|| refined.iter().filter_map(|l| l.traced_rays()).sum::<u64>());
    let image = &config.settings.image;
    let pixels = f64::from(image.width) * f64::from(image.height);
    ConfigReport {
        technique: config.technique.name().to_string(),
        sweep_value: config.sweep_value.clone(),
        passes: series
            .order
            .iter()
            .filter(|n| !is_layer(n) && !n.contains("depth-only"))
            .filter_map(|n| series.summary(n))
            .collect(),
        layers: series.order.iter().filter(is_layer).filter_map(|n| series.summary(n)).collect(),
        shadow_draws: last.stats.shadow_draws,
        shadow_commands: last.stats.shadow_commands,
        shadow_instances: last.stats.shadow_instances,
        shadow_triangles: last.stats.shadow_triangles,
        layer_drawn: last
            .lights
            .iter()
            .filter(|light| !light.layer_ms.is_empty())
            .flat_map(|light| {
                light
                    .layer_draws
                    .iter()
                    .zip(&light.layer_commands)
                    .zip(&light.layer_triangles)
                    .map(|((&draws, &commands), &triangles)| LayerDrawn { draws, commands, triangles })
            })
            .collect(),
        lighting_draws: last.stats.lighting_draws,
        lighting_instances: last.stats.lighting_instances,
        depth_only: series.summary("depth-only"),
        shadow_over_depth_only: series.summary("shadow ÷ depth-only").map(|r| r.median_ms),
        traced_percent: traced.map(|t| 100.0 * t as f64 / pixels),
        rays,
    }
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

#[cfg(test)]
mod tests {
    use super::*;

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

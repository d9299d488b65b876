//! `gnomon compare`: render each technique and the ray-traced reference, measure the
//! differences, and write a labelled grid, heat-maps, `metrics.json` and `metrics.md`.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use gnomon_reference::{
    flicker::{Flicker, FlickerCounter, PathFrame},
    metrics::{self, RasterView},
};
use gnomon_render::{Frame, Gpu, GpuScene, OutputRequest, Renderer, timing::ClockChoice};
use gnomon_scene::settings::LightKind;
use gnomon_scene::{
    Scene, Settings,
    camera_path::{CameraPathKind, camera_on_path},
    settings::{CameraSettings, Technique},
};

use crate::{
    compare_report::{AliasingSummary, PathReport, Report, markdown_table},
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
    /// Also measure each frame of a sequence of `--path-frames` live frames over which
    /// the light moves, the casters move, or nothing does, each against its own
    /// reference: the error of a single frame of a moving scene (every one the first
    /// after a cut), or a still view's convergence. Writes motion.png and
    /// motion-error.png (the last frame) and a table per frame.
    #[arg(long, value_enum, help_heading = "Motion")]
    pub motion: Option<crate::compare_motion::Motion>,
    #[command(flatten)]
    pub settings: Settings,
}

/// One technique's frame, and the median GPU time of its passes where the adapter
/// has timestamps.
pub(crate) struct Rendered {
    pub technique: Technique,
    pub frame: Frame,
    pub timing: Option<PassMedians>,
}

/// The median GPU milliseconds of a technique's passes over `--timing-frames` frames.
#[derive(Clone, Copy)]
pub(crate) struct PassMedians {
    pub shadow_ms: f64,
    /// The moment map's filter pass, for the filterable techniques.
    pub filter_ms: Option<f64>,
    pub lighting_ms: f64,
}

pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    check_args(args)?;
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
    let frames = render_techniques(args, &mut renderer, &uploaded, &scene, settings)?;
    let flicker = match args.camera_path {
        Some(kind) => measure_flicker(args, kind, &mut renderer, &uploaded, &scene, settings)?,
        None => vec![None; args.techniques.len()],
    };
    let motion = match args.motion {
        Some(motion) => {
            let run = crate::compare_motion::MotionRun {
                motion,
                frames: args.path_frames,
                techniques: &args.techniques,
                use_cache: !args.no_cache,
            };
            let mut moved = scene.clone();
            Some(crate::compare_motion::measure(&run, &mut renderer, &mut moved, settings)?)
        }
        None => None,
    };
    let aliasing = gnomon_viewer::measure_aliasing(&frames[0].frame, settings);
    let virtual_levels = frames[0].frame.virtual_levels.as_ref();
    let reference = lab::reference(&scene, settings, !args.no_cache)?.image;
    let drawn = lab::drawn_metrics(&scene, settings, &frames.iter().map(|r| &r.frame).collect::<Vec<_>>())?;

    let mut staged = output::Staged::default();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("--out: cannot create {}", args.out.display()))?;
    let measured = crate::compare_outputs::Measured {
        reference: &reference,
        aliasing: &aliasing,
        frames: &frames,
        flicker,
        drawn,
    };
    let rows = crate::compare_outputs::stage(&mut staged, &args.out, measured)?;
    if let Some(measured) = &motion {
        crate::compare_outputs::stage_motion(&mut staged, &args.out, &measured.last, &measured.reference)?;
    }
    let report = Report {
        scene: &scene.name,
        width: reference.width,
        height: reference.height,
        shadow_resolution: virtual_levels.map_or(settings.shadow.map.resolution, |l| l.resolution),
        virtual_levels: virtual_levels.map(|l| l.clipmap.shape.levels),
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
        motion: motion.as_ref().map(|m| m.series.clone()),
    };
    let mut table = markdown_table(&report, reference.samples > 1);
    if let (Some(kind), Some(measured)) = (args.motion, &motion) {
        table.push_str(&crate::compare_motion::markdown(kind, &measured.series));
    }
    staged.text(&args.out.join("metrics.json"), &serde_json::to_string_pretty(&report)?)?;
    staged.text(&args.out.join("metrics.md"), &table)?;
    let written = staged.commit()?;
    print!("{table}");
    eprintln!("gnomon: wrote {} files to {}", written.len(), args.out.display());
    Ok(())
}

/// The flags `Settings` does not check: the timing frames, the techniques (each
/// named once, since its files are named after it) and the camera path.
fn check_args(args: &CompareArgs) -> anyhow::Result<()> {
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
    Ok(())
}

/// Each technique's frame, and its passes timed over `--timing-frames` frames.
fn render_techniques(
    args: &CompareArgs,
    renderer: &mut Renderer,
    uploaded: &GpuScene,
    scene: &Scene,
    settings: &Settings,
) -> anyhow::Result<Vec<Rendered>> {
    let mut frames = Vec::new();
    for technique in &args.techniques {
        let mut s = settings.clone();
        s.shadow.filter.technique = technique.clone();
        let frame = renderer.render_uploaded(uploaded, scene, &s, &OutputRequest::default())?;
        crate::render_cmd::warn_fallbacks(&frame.lights);
        let (mut shadow, mut filter, mut lighting) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..args.timing_frames {
            if let Some(t) = renderer.time_passes(uploaded, scene, &s, ClockChoice::Auto)?.timings {
                shadow.push(t.shadow_ms);
                filter.extend(t.filter_ms);
                lighting.push(t.lighting_ms);
            }
        }
        let timing = (!shadow.is_empty()).then(|| PassMedians {
            shadow_ms: median(&mut shadow),
            filter_ms: (!filter.is_empty()).then(|| median(&mut filter)),
            lighting_ms: median(&mut lighting),
        });
        frames.push(Rendered { technique: technique.clone(), frame, timing });
    }
    Ok(frames)
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

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// With `--light all`, a comparison measures one light, the one at `--light-index`,
/// as the scene's only listed light (each kind's default stays, unused by `--light
/// all`): the reference traces that light alone, the timings are
/// its passes', and each compared technique replaces the technique its own shadow
/// settings name (its other settings, such as its resolution, stay).
fn single_out_light(
    scene: &mut gnomon_scene::Scene,
    settings: &mut gnomon_scene::Settings,
) -> anyhow::Result<()> {
    settings.resolve_light(scene)?;
    let index = settings.light.light_index;
    // `resolve_light` checked the index against the listed lights.
    let Some(mut light) = scene.listed_lights().nth(index).cloned() else {
        anyhow::bail!("scene `{}` lists no light at index {index}", scene.name);
    };
    if let Some(overrides) = light.shadow.as_mut() {
        overrides.filter.technique = None;
    }
    eprintln!(
        "gnomon: comparing light {} `{}` ({})",
        settings.light.light_index,
        light.name,
        light.light.type_name()
    );
    scene.replace_listed_lights([light]);
    settings.light.light_index = 0;
    Ok(())
}

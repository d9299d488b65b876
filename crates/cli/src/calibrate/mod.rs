//! `gnomon calibrate`: sweep the settings that move one technique's shadow (depth
//! bias, slope bias, normal offset, and the PCF kernel where it has one; see
//! [`plan`]) over a scene's views, measure each setting against the ray-traced
//! reference on the light-facing pixels, and report the Pareto front of false shadow
//! against false lit, the setting with the least total mismatch, and that setting's
//! error on held-out views it was not chosen on, next to the defaults'.
//!
//! The views are a scene file's `[[view]]`s when it has two or more, else views
//! generated along an orbit of the scene's camera; every other view is held out.

mod plan;
mod plot;
mod sweep;

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use gnomon_reference::metrics::{self, RasterView};
use gnomon_render::{Gpu, GpuScene, OutputRequest, Renderer, techniques::TechniqueRegistry};
use gnomon_scene::{
    Camera, Scene, Settings,
    camera_path::{CameraPathKind, camera_on_path},
    scene_file,
    settings::{BiasSettings, CameraSettings, Refine},
};
use indicatif::{ProgressBar, ProgressStyle};
use plan::Tuned;
use sweep::{Measured, SweepRange};

use crate::{lab, output};

#[derive(Args, Debug)]
pub struct CalibrateArgs {
    #[command(flatten)]
    pub scene: lab::SceneArgs,
    /// Depth-bias values to sweep, LOW..HIGH:STEPS (rasterizer units) [default: the
    /// settings' depth bias, not swept].
    #[arg(long, value_name = "RANGE")]
    pub sweep_depth_bias: Option<SweepRange>,
    /// Slope-bias values to sweep, LOW..HIGH:STEPS [default: 0..4:9].
    #[arg(long, value_name = "RANGE")]
    pub sweep_slope_bias: Option<SweepRange>,
    /// Normal-offset values to sweep, LOW..HIGH:STEPS (shadow texels) [default: 0..2:9].
    #[arg(long, value_name = "RANGE")]
    pub sweep_normal_offset: Option<SweepRange>,
    /// PCF kernel widths to sweep, LOW..HIGH:STEPS, in the kernel's unit, for the
    /// techniques with a kernel [default: 1..9:5 for a kernel in texels; else the
    /// settings' kernel, not swept].
    #[arg(long, value_name = "RANGE")]
    pub sweep_kernel: Option<SweepRange>,
    /// Views generated along an orbit of the scene's camera when the scene is not a
    /// scene file with two or more `[[view]]`s; every other view is held out
    /// (calibration never sees it). 2 to 64.
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub views: u32,
    /// The orbit's arc over the generated views, in radians.
    #[arg(long, value_name = "RADIANS", default_value_t = 1.5)]
    pub orbit: f32,
    /// Output directory: front.png, calibration.json, calibration.md.
    #[arg(long, short, default_value = "calibrate", help_heading = "Outputs")]
    pub out: PathBuf,
    /// Store the chosen setting in this scene file's `[settings]` (created if missing).
    #[arg(long, value_name = "FILE.toml", help_heading = "Outputs")]
    pub write: Option<PathBuf>,
    /// Trace references again even when cached ones exist.
    #[arg(long)]
    pub no_cache: bool,
    #[command(flatten)]
    pub settings: Settings,
}

/// One view's camera and its reference.
struct View {
    settings: Settings,
    reference: gnomon_reference::ReferenceImage,
}

/// Light-facing wrong pixels pooled over views.
#[derive(Clone, Copy, Default)]
struct Pooled {
    compared: usize,
    false_shadow: usize,
    false_lit: usize,
}

impl Pooled {
    fn rates<S>(&self, setting: S) -> Measured<S> {
        let n = self.compared.max(1) as f64;
        Measured { setting, false_shadow: self.false_shadow as f64 / n, false_lit: self.false_lit as f64 / n }
    }
}

pub fn run(args: &CalibrateArgs) -> anyhow::Result<()> {
    let (scene, mut settings) = lab::load(&args.scene, &args.settings)?;
    // The bias is the map's: calibration measures the map's own answer, unless rays
    // were asked for by name. The default's rays would correct most of what the bias
    // moves, leaving little to choose between settings.
    if settings.screen.refine == Refine::Auto {
        settings.screen.refine = Refine::Off;
    }
    anyhow::ensure!(
        args.views >= 2 && args.views <= 64,
        "--views = {} is invalid: 2 to 64 (half are held out)",
        args.views
    );
    anyhow::ensure!(
        args.orbit.is_finite() && args.orbit > 0.0 && args.orbit <= std::f32::consts::TAU,
        "--orbit = {} is invalid: an arc in (0, 2π] radians",
        args.orbit
    );
    settings.resolve_light(&scene).with_context(|| format!("{}: calibration needs a light", scene.name))?;
    output::check_dir(&args.out, "--out")?;
    if let Some(path) = &args.write {
        output::check_file(path, &["toml"], "--write")?;
    }
    let requested = plan::Requested {
        depth_bias: args.sweep_depth_bias,
        slope_bias: args.sweep_slope_bias,
        normal_offset: args.sweep_normal_offset,
        kernel: args.sweep_kernel,
    };
    let filter = &settings.shadow.filter;
    let base = Tuned { bias: settings.shadow.bias.clone(), pcf_kernel: filter.pcf_kernel };
    let grid =
        plan::grid(&requested, &TechniqueRegistry::builtin(), &filter.technique, &base, filter.kernel_unit)?;

    let views: Vec<Settings> = view_cameras(args, &scene, &settings)?
        .into_iter()
        .map(|camera| {
            let mut s = settings.clone();
            s.camera = CameraSettings::pinned(&camera);
            s
        })
        .collect();
    let views: Vec<View> = views
        .into_iter()
        .map(|s| Ok(View { reference: lab::reference(&scene, &s, !args.no_cache)?.image, settings: s }))
        .collect::<anyhow::Result<_>>()?;
    // Every other view is held out: calibration never sees it.
    let calibration: Vec<&View> = views.iter().step_by(2).collect();
    let held_out: Vec<&View> = views.iter().skip(1).step_by(2).collect();

    let gpu = Gpu::new_headless()?;
    let mut renderer = Renderer::new(&gpu)?;
    renderer.check_limits(&settings)?;
    let uploaded = renderer.upload(&scene)?;
    let bar = ProgressBar::new((grid.len() * calibration.len()) as u64).with_style(
        ProgressStyle::with_template("calibrate {bar:40} {pos}/{len} renders, {eta} left")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut points = Vec::with_capacity(grid.len());
    for tuned in &grid {
        let pooled = measure(&mut renderer, &uploaded, &scene, &calibration, tuned, &bar)?;
        points.push(pooled.rates(tuned.clone()));
    }
    bar.finish_and_clear();
    let front = sweep::pareto_front(&points);
    let chosen = sweep::least_mismatch(&points).context("an empty sweep")?;
    let defaults = measure(&mut renderer, &uploaded, &scene, &calibration, &base, &bar)?.rates(base.clone());
    let held_chosen = measure(&mut renderer, &uploaded, &scene, &held_out, &points[chosen].setting, &bar)?
        .rates(points[chosen].setting.clone());
    let held_default = measure(&mut renderer, &uploaded, &scene, &held_out, &base, &bar)?.rates(base.clone());

    let technique = settings.shadow.filter.technique.name();
    let swept_kernel = grid.iter().any(|t| t.pcf_kernel != base.pcf_kernel);
    let title = format!(
        "{}: {technique} {} sweep",
        scene.name,
        if swept_kernel { "bias and kernel" } else { "bias" }
    );
    let rgb = plot::draw(&plot::PlotInput {
        title: &title,
        points: &points,
        front: &front,
        chosen,
        defaults: (defaults.false_shadow, defaults.false_lit),
    })?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("--out: cannot create {}", args.out.display()))?;
    let mut staged = output::Staged::default();
    let (w, h) = plot::PLOT_SIZE;
    let rgba: Vec<u8> = rgb.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect();
    staged.png_rgba(&args.out.join("front.png"), w, h, &rgba)?;
    let report = report_markdown(&points, &front, chosen, (&defaults, &held_chosen, &held_default));
    staged.text(&args.out.join("calibration.md"), &report)?;
    staged.commit()?;
    print!("{report}");
    if let Some(path) = &args.write {
        let tuned = &points[chosen].setting;
        write_settings(path, &tuned.bias, swept_kernel.then_some(tuned.pcf_kernel))?;
    }
    Ok(())
}

/// The cameras to calibrate and check on: a scene file's views when it has two or
/// more, else `--views` along an orbit of `--orbit` radians.
fn view_cameras(args: &CalibrateArgs, scene: &Scene, settings: &Settings) -> anyhow::Result<Vec<Camera>> {
    let path = std::path::Path::new(&args.scene.scene);
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml")) {
        let names = scene_file::load(path, None)?.view_names;
        if names.len() >= 2 {
            return names.iter().map(|name| Ok(scene_file::load(path, Some(name))?.scene.camera)).collect();
        }
    }
    let start = settings.resolve_camera(scene)?;
    Ok((0..args.views)
        .map(|k| {
            camera_on_path(&start, CameraPathKind::Orbit, args.orbit, k as f32 / (args.views - 1) as f32)
        })
        .collect())
}

/// Renders `views` with the `tuned` settings and pools their light-facing mismatches.
fn measure(
    renderer: &mut Renderer,
    uploaded: &GpuScene,
    scene: &Scene,
    views: &[&View],
    tuned: &Tuned,
    bar: &ProgressBar,
) -> anyhow::Result<Pooled> {
    let mut pooled = Pooled::default();
    for view in views {
        let mut s = view.settings.clone();
        s.shadow.bias = tuned.bias.clone();
        s.shadow.filter.pcf_kernel = tuned.pcf_kernel;
        let frame = renderer.render_uploaded(uploaded, scene, &s, &OutputRequest::default())?;
        let raster =
            RasterView { visibility: &frame.visibility, object_id: &frame.object_id, depth: &frame.depth };
        let m = metrics::measure(raster, &view.reference, &metrics::classify(raster, &view.reference));
        pooled.compared += m.compared;
        pooled.false_shadow += m.false_shadow;
        pooled.false_lit += m.false_lit;
        bar.inc(1);
    }
    Ok(pooled)
}

fn report_markdown(
    points: &[Measured<Tuned>],
    front: &[usize],
    chosen: usize,
    (defaults, held_chosen, held_default): (&Measured<Tuned>, &Measured<Tuned>, &Measured<Tuned>),
) -> String {
    let pct = |v: f64| format!("{:.3}%", 100.0 * v);
    let row = |label: &str, p: &Measured<Tuned>| {
        let b = &p.setting.bias;
        format!(
            "| {label} | {} | {} | {} | {} | {} | {} | {} |\n",
            b.depth_bias,
            b.slope_bias,
            b.normal_offset,
            p.setting.pcf_kernel,
            pct(p.false_shadow),
            pct(p.false_lit),
            pct(p.mismatch())
        )
    };
    let mut s = String::from(
        "Rates over light-facing pixels, pooled over the views.\n\n| setting | depth bias | slope bias | normal offset | PCF kernel | false shadow | false lit | mismatch |\n|---|---|---|---|---|---|---|---|\n",
    );
    for &i in front {
        s += &row(if i == chosen { "**chosen**" } else { "front" }, &points[i]);
    }
    s += &row("defaults", defaults);
    s += &format!(
        "\nHeld-out views: chosen {} mismatch, defaults {}.\n",
        pct(held_chosen.mismatch()),
        pct(held_default.mismatch())
    );
    s
}

/// Stores `bias` in `path`'s `[settings.shadow.bias]`, and `kernel` (when it was
/// swept) as its `settings.shadow.filter.pcf_kernel`, keeping the rest of the file.
fn write_settings(path: &std::path::Path, bias: &BiasSettings, kernel: Option<f32>) -> anyhow::Result<()> {
    let text = if path.is_file() { std::fs::read_to_string(path)? } else { String::new() };
    let mut doc: toml::Table =
        toml::from_str(&text).with_context(|| format!("--write {}: not TOML", path.display()))?;
    let settings = doc.entry("settings").or_insert_with(|| toml::Table::new().into());
    let table = settings.as_table_mut().context("--write: `settings` is not a table")?;
    let shadow = table.entry("shadow").or_insert_with(|| toml::Table::new().into());
    let shadow = shadow.as_table_mut().context("--write: `settings.shadow` is not a table")?;
    shadow.insert("bias".into(), toml::Value::try_from(bias)?);
    if let Some(kernel) = kernel {
        let filter = shadow.entry("filter").or_insert_with(|| toml::Table::new().into());
        let filter = filter.as_table_mut().context("--write: `settings.shadow.filter` is not a table")?;
        filter.insert("pcf_kernel".into(), toml::Value::Float(kernel.into()));
    }
    let temp = path.with_extension("toml.tmp");
    std::fs::write(&temp, toml::to_string_pretty(&doc)?)?;
    std::fs::rename(&temp, path)?;
    Ok(())
}

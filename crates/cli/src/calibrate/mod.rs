//! `gnomon calibrate`: sweep the settings that move one technique's shadow (depth
//! bias, slope bias, normal offset, and the PCF kernel where it has one; see
//! [`plan`]) over a scene's views, measure each setting against the ray-traced
//! reference on the light-facing pixels, and report the Pareto front of false shadow
//! against false lit, the setting with the least total mismatch, and that setting's
//! error on held-out views it was not chosen on, next to the defaults'. It measures
//! the map alone unless rays are asked for by name; under the default refinement,
//! the defaults as they render, rays included, are measured on the held-out views
//! too.
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
    // moves, leaving little to choose between settings; the defaults as they render,
    // rays included, are measured on the held-out views for comparison.
    let renders_refined = settings.screen.refine == Refine::Auto;
    if renders_refined {
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
        // A file the run could not edit at its end is refused before the sweep.
        settings_file_text(path, &settings.shadow.bias, None)
            .with_context(|| format!("--write {}", path.display()))?;
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
    let extra = 2 * held_out.len() + calibration.len() + if renders_refined { held_out.len() } else { 0 };
    let bar = ProgressBar::new((grid.len() * calibration.len() + extra) as u64).with_style(
        ProgressStyle::with_template("calibrate {bar:40} {pos}/{len} renders, {eta} left")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut measuring = Measuring { renderer: &mut renderer, uploaded: &uploaded, scene: &scene, bar: &bar };
    // The map alone, or with the rays asked for by name.
    let refine = settings.screen.refine;
    let mut points = Vec::with_capacity(grid.len());
    for tuned in &grid {
        let pooled = measuring.measure(&calibration, tuned, refine)?;
        // A bias chosen from no pixel is no measurement (an empty or flattened view).
        anyhow::ensure!(
            pooled.compared > 0,
            "{}: no light-facing pixel to measure in the calibration views: nothing to choose a bias from",
            scene.name
        );
        points.push(pooled.rates(tuned.clone()));
    }
    let front = sweep::pareto_front(&points);
    let chosen = sweep::least_mismatch(&points).context("an empty sweep")?;
    let results = Results {
        defaults: measuring.measure(&calibration, &base, refine)?.rates(base.clone()),
        held_chosen: measuring
            .measure(&held_out, &points[chosen].setting, refine)?
            .rates(points[chosen].setting.clone()),
        held_default: measuring.measure(&held_out, &base, refine)?.rates(base.clone()),
        held_default_refined: renders_refined
            .then(|| {
                Ok::<_, anyhow::Error>(measuring.measure(&held_out, &base, Refine::Auto)?.rates(base.clone()))
            })
            .transpose()?,
        refine,
        points,
        front,
        chosen,
    };
    bar.finish_and_clear();
    write_outputs(args, &scene, &settings, &results)
}

/// Everything a calibration measured.
struct Results {
    /// The refinement every setting was measured with: off (the map alone), unless
    /// rays were asked for by name.
    refine: Refine,
    /// Every setting of the sweep, on the calibration views.
    points: Vec<Measured<Tuned>>,
    /// Indices into `points` of the Pareto front.
    front: Vec<usize>,
    /// Index into `points` of the least total mismatch.
    chosen: usize,
    /// The settings' own bias and kernel, on the calibration views.
    defaults: Measured<Tuned>,
    /// The chosen setting on the held-out views.
    held_chosen: Measured<Tuned>,
    /// The settings' own bias and kernel on the held-out views.
    held_default: Measured<Tuned>,
    /// The same refined by rays where the map is unsure, as the defaults render
    /// (`--refine auto`); `None` when rays were asked for, or refused, by name.
    held_default_refined: Option<Measured<Tuned>>,
}

/// Draws the front, writes the report and the JSON beside it (all or nothing), and
/// the chosen setting into `--write`'s scene file.
fn write_outputs(
    args: &CalibrateArgs,
    scene: &Scene,
    settings: &Settings,
    r: &Results,
) -> anyhow::Result<()> {
    let technique = settings.shadow.filter.technique.name();
    let swept_kernel = r.points.iter().any(|t| t.setting.pcf_kernel != r.defaults.setting.pcf_kernel);
    let title = format!(
        "{}: {technique} {} sweep",
        scene.name,
        if swept_kernel { "bias and kernel" } else { "bias" }
    );
    let rgb = plot::draw(&plot::PlotInput {
        title: &title,
        points: &r.points,
        front: &r.front,
        chosen: r.chosen,
        defaults: (r.defaults.false_shadow, r.defaults.false_lit),
    })?;
    // A folder this run creates is removed again if its outputs fail: all or nothing.
    let created = !args.out.exists();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("--out: cannot create {}", args.out.display()))?;
    let written = stage_and_commit(args, scene, technique, r, &rgb);
    if written.is_err() && created {
        let _ = std::fs::remove_dir(&args.out);
    }
    written
}

/// The report, the plot and `--write`'s scene file, staged and moved into place
/// together.
fn stage_and_commit(
    args: &CalibrateArgs,
    scene: &Scene,
    technique: &str,
    r: &Results,
    rgb: &[u8],
) -> anyhow::Result<()> {
    let swept_kernel = r.points.iter().any(|t| t.setting.pcf_kernel != r.defaults.setting.pcf_kernel);
    let mut staged = output::Staged::default();
    let (w, h) = plot::PLOT_SIZE;
    let rgba: Vec<u8> = rgb.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect();
    staged.png_rgba(&args.out.join("front.png"), w, h, &rgba)?;
    let report = report_markdown(r);
    staged.text(&args.out.join("calibration.md"), &report)?;
    let json = serde_json::to_string_pretty(&report_json(scene, technique, r))?;
    staged.text(&args.out.join("calibration.json"), &json)?;
    // The scene file's new text, staged with the rest: all of them are written, or
    // none (a scene file that cannot be edited leaves the report unwritten too).
    if let Some(path) = &args.write {
        let tuned = &r.points[r.chosen].setting;
        let text = settings_file_text(path, &tuned.bias, swept_kernel.then_some(tuned.pcf_kernel))
            .with_context(|| format!("--write {}", path.display()))?;
        staged.text(path, &text)?;
    }
    staged.commit()?;
    print!("{report}");
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

/// What every measurement of a calibration renders with.
struct Measuring<'a> {
    renderer: &'a mut Renderer,
    uploaded: &'a GpuScene,
    scene: &'a Scene,
    bar: &'a ProgressBar,
}

impl Measuring<'_> {
    /// Renders `views` with the `tuned` settings and `refine`, and pools their
    /// light-facing mismatches.
    fn measure(&mut self, views: &[&View], tuned: &Tuned, refine: Refine) -> anyhow::Result<Pooled> {
        let mut pooled = Pooled::default();
        for view in views {
            let mut s = view.settings.clone();
            s.shadow.bias = tuned.bias.clone();
            s.shadow.filter.pcf_kernel = tuned.pcf_kernel;
            s.screen.refine = refine;
            let frame =
                self.renderer.render_uploaded(self.uploaded, self.scene, &s, &OutputRequest::default())?;
            let raster = RasterView {
                visibility: &frame.visibility,
                object_id: &frame.object_id,
                depth: &frame.depth,
            };
            let m = metrics::measure(raster, &view.reference, &metrics::classify(raster, &view.reference));
            pooled.compared += m.compared;
            pooled.false_shadow += m.false_shadow;
            pooled.false_lit += m.false_lit;
            self.bar.inc(1);
        }
        Ok(pooled)
    }
}

fn report_markdown(r: &Results) -> String {
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
    let mut s = format!(
        "Rates over light-facing pixels, pooled over the views, with --refine {}.\n\n| setting | depth bias | slope bias | normal offset | PCF kernel | false shadow | false lit | mismatch |\n|---|---|---|---|---|---|---|---|\n",
        gnomon_scene::settings::value_name(&r.refine)
    );
    for &i in &r.front {
        s += &row(if i == r.chosen { "**chosen**" } else { "front" }, &r.points[i]);
    }
    s += &row("defaults", &r.defaults);
    s += &format!(
        "\nHeld-out views: chosen {} mismatch, defaults {}.\n",
        pct(r.held_chosen.mismatch()),
        pct(r.held_default.mismatch())
    );
    if let Some(refined) = &r.held_default_refined {
        s += &format!(
            "The defaults as they render, refined by rays where the map is unsure (--refine auto): {} on the held-out views.\n",
            pct(refined.mismatch())
        );
    }
    s
}

/// The report as JSON: every setting measured, the front, the choice and the
/// held-out check.
fn report_json(scene: &Scene, technique: &str, r: &Results) -> serde_json::Value {
    let entry = |p: &Measured<Tuned>| {
        serde_json::json!({
            "depth_bias": p.setting.bias.depth_bias,
            "slope_bias": p.setting.bias.slope_bias,
            "normal_offset": p.setting.bias.normal_offset,
            "pcf_kernel": p.setting.pcf_kernel,
            "false_shadow": p.false_shadow,
            "false_lit": p.false_lit,
            "mismatch": p.mismatch(),
        })
    };
    serde_json::json!({
        "scene": scene.name,
        "technique": technique,
        "denominator": "light-facing pixels, pooled over the views",
        "refine": gnomon_scene::settings::value_name(&r.refine),
        "points": r.points.iter().map(entry).collect::<Vec<_>>(),
        "front": r.front,
        "chosen": entry(&r.points[r.chosen]),
        "defaults": entry(&r.defaults),
        "held_out": {
            "chosen": entry(&r.held_chosen),
            "defaults": entry(&r.held_default),
            "defaults_refined_by_rays": r.held_default_refined.as_ref().map(entry),
        },
    })
}

/// `path`'s text with `bias` as its `[settings.shadow.bias]` and `kernel` (when it was
/// swept) as its `settings.shadow.filter.pcf_kernel`: edited in place (`toml_edit`),
/// so that the file's comments, the order of its keys and its layout stay as its
/// author wrote them. A file that does not exist yet is created.
fn settings_file_text(
    path: &std::path::Path,
    bias: &BiasSettings,
    kernel: Option<f32>,
) -> anyhow::Result<String> {
    let text = match std::fs::metadata(path) {
        Ok(metadata) if metadata.is_file() => std::fs::read_to_string(path).context("cannot read it")?,
        Ok(_) => anyhow::bail!("is not a regular file"),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
        Err(e) => return Err(anyhow::Error::new(e).context("cannot read it")),
    };
    let mut doc: toml_edit::DocumentMut = text.parse().context("is not TOML")?;
    let table = |item: &mut toml_edit::Item, key: &str| -> anyhow::Result<()> {
        if item.is_none() {
            *item = toml_edit::table();
        }
        anyhow::ensure!(item.is_table_like(), "`{key}` is not a table");
        Ok(())
    };
    table(&mut doc["settings"], "settings")?;
    table(&mut doc["settings"]["shadow"], "settings.shadow")?;
    // The bias as the settings' own serializer writes it, then as an editable table.
    let bias_doc: toml_edit::DocumentMut = toml::to_string(bias)?.parse().context("the bias")?;
    doc["settings"]["shadow"]["bias"] = toml_edit::Item::Table(bias_doc.as_table().clone());
    if let Some(kernel) = kernel {
        table(&mut doc["settings"]["shadow"]["filter"], "settings.shadow.filter")?;
        doc["settings"]["shadow"]["filter"]["pcf_kernel"] = toml_edit::value(f64::from(kernel));
    }
    Ok(doc.to_string())
}

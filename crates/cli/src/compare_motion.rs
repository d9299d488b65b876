//! `gnomon compare --motion`: each technique's frames over a sequence in which the
//! light moves, casters move or nothing does, each frame a live one (one submission,
//! with the renderer's penumbra history going on from the frame before wherever
//! nothing it depends on moved), each measured against its own reference. It shows
//! what a single frame of a moving scene gets right (a moving light or caster throws
//! the history away every frame, so every frame is the first after a cut), and how a
//! still view converges frame by frame.

use clap::ValueEnum;
use gnomon_reference::{
    ReferenceImage,
    metrics::{self, RasterView},
};
use gnomon_render::{Frame, OutputRequest, Renderer};
use gnomon_scene::{Scene, Settings, settings::Technique};
use serde::Serialize;

use crate::{
    bench_lights::{LightPathArgs, LightPaths, PointPathKind, SpotPathKind, SunPathKind},
    bench_moving::Mover,
    lab,
};

/// What moves over `--path-frames` frames of `--motion`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Motion {
    /// Nothing: a still view, whose penumbrae gather their beams frame by frame.
    Still,
    /// The sun along a day's arc (`bench --sun-path day`): from 7 h to 17 h over the
    /// frames.
    SunDay,
    /// The spot's aim swung 30° across (`bench --spot-path sweep`).
    SpotSweep,
    /// The point light carried a twentieth of its range (`bench --point-path sway`).
    PointSway,
    /// The casters: every instance but the largest (the ground, as a rule) swayed by
    /// a hundredth of the scene's size, as `bench --moving` sways them.
    Casters,
}

/// One frame of a technique's sequence.
#[derive(Clone, Debug, Serialize)]
pub struct MotionFrame {
    /// 1 for the first.
    pub frame: u32,
    /// Mean |V − R| over the reference's penumbra (None under a point-like light).
    pub penumbra_mae: Option<f64>,
    /// Mean |V − R| over every compared pixel.
    pub mae: f64,
    /// Light-facing pixels whose shadow disagrees with the reference's.
    pub mismatch_rate: f64,
    /// Frames the light's penumbra history held (None: it keeps none).
    pub penumbra_frames: Option<u32>,
}

/// A technique's sequence.
#[derive(Clone, Debug, Serialize)]
pub struct MotionSeries {
    pub technique: String,
    pub frames: Vec<MotionFrame>,
}

impl MotionSeries {
    /// The worst penumbra error of its frames.
    pub fn worst_penumbra(&self) -> Option<f64> {
        self.frames.iter().filter_map(|f| f.penumbra_mae).reduce(f64::max)
    }
}

/// The sequence's setup: what moves, over how many frames, with which reference.
pub struct MotionRun<'a> {
    pub motion: Motion,
    pub frames: u32,
    pub techniques: &'a [Technique],
    pub use_cache: bool,
}

/// What a sequence measured: each technique's frames, and the last frame of the last
/// technique with its reference, for a picture.
pub struct Measured {
    pub series: Vec<MotionSeries>,
    pub last: Frame,
    pub reference: ReferenceImage,
}

/// Renders each technique's sequence and measures its frames.
pub fn measure(
    run: &MotionRun,
    renderer: &mut Renderer,
    scene: &mut Scene,
    settings: &Settings,
) -> anyhow::Result<Measured> {
    let first = settings.resolve_light(scene).ok();
    let paths = LightPaths::new(light_paths(run.motion), first);
    let mover = match run.motion {
        Motion::Casters => {
            let mover = Mover::all_but_the_largest(scene)?;
            mover.declare_dynamic(scene);
            Some(mover)
        }
        Motion::Still | Motion::SunDay | Motion::SpotSweep | Motion::PointSway => None,
    };
    let mut uploaded = renderer.upload(scene)?;
    let bar = indicatif::ProgressBar::new(u64::from(run.frames) * run.techniques.len() as u64).with_style(
        indicatif::ProgressStyle::with_template("motion {bar:40} {pos}/{len} frames, {eta} left")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let mut series = Vec::new();
    let mut last = None;
    for technique in run.techniques {
        // Each technique starts after a cut.
        renderer.forget_penumbra_history();
        let mut frames = Vec::new();
        for k in 0..run.frames {
            let fraction = k as f32 / (run.frames - 1).max(1) as f32;
            let mut s = settings.clone();
            s.shadow.filter.technique = technique.clone();
            // One frame a call: a live frame, read back.
            s.screen.penumbra_frames = 1;
            paths.place(&mut s, fraction);
            if let Some(mover) = &mover {
                mover.step(renderer, &mut uploaded, scene, k)?;
            }
            let frame = renderer.render_uploaded(&uploaded, scene, &s, &OutputRequest::default())?;
            let reference = bar.suspend(|| lab::reference(scene, &s, run.use_cache))?.image;
            frames.push(measure_frame(k + 1, &frame, &reference));
            last = Some((frame, reference));
            bar.inc(1);
        }
        series.push(MotionSeries { technique: technique.name().to_owned(), frames });
    }
    bar.finish_and_clear();
    let (last, reference) =
        last.ok_or_else(|| anyhow::anyhow!("--techniques is empty: name at least one"))?;
    Ok(Measured { series, last, reference })
}

/// The light paths `motion` asks for.
fn light_paths(motion: Motion) -> LightPathArgs {
    let none = LightPathArgs { sun: None, spot: None, point: None };
    match motion {
        Motion::SunDay => LightPathArgs { sun: Some(SunPathKind::Day), ..none },
        Motion::SpotSweep => LightPathArgs { spot: Some(SpotPathKind::Sweep), ..none },
        Motion::PointSway => LightPathArgs { point: Some(PointPathKind::Sway), ..none },
        Motion::Still | Motion::Casters => none,
    }
}

fn measure_frame(index: u32, frame: &Frame, reference: &ReferenceImage) -> MotionFrame {
    let raster =
        RasterView { visibility: &frame.visibility, object_id: &frame.object_id, depth: &frame.depth };
    let classes = metrics::classify(raster, reference);
    let m = metrics::measure(raster, reference, &classes);
    MotionFrame {
        frame: index,
        penumbra_mae: (m.penumbra.error.pixels > 0).then_some(m.penumbra.error.mae),
        mae: m.mae,
        mismatch_rate: m.mismatch_rate,
        penumbra_frames: frame.lights.first().and_then(|l| l.penumbra_frames),
    }
}

/// The sequences as a markdown table: one row per frame, one column per technique.
pub fn markdown(motion: Motion, series: &[MotionSeries]) -> String {
    let mut s = format!(
        "\nMotion `{}`: each frame a live one, against its own reference. Penumbra MAE (mean |V − R| where the reference lies strictly between 0 and 1 beyond its standard error), and in brackets the frames the penumbra history held (1: the first after a cut)\n\n",
        motion.to_possible_value().map_or_else(String::new, |v| v.get_name().to_owned())
    );
    s.push_str("| frame |");
    for t in series {
        s.push_str(&format!(" {} |", t.technique));
    }
    s.push_str("\n|---|");
    s.push_str(&"---|".repeat(series.len()));
    s.push('\n');
    let frames = series.first().map_or(0, |t| t.frames.len());
    for k in 0..frames {
        s.push_str(&format!("| {} |", k + 1));
        for t in series {
            let f = &t.frames[k];
            let mae = f.penumbra_mae.map_or_else(|| "–".to_owned(), |m| format!("{m:.4}"));
            let held = f.penumbra_frames.map_or_else(String::new, |h| format!(" ({h})"));
            s.push_str(&format!(" {mae}{held} |"));
        }
        s.push('\n');
    }
    s.push_str("| worst |");
    for t in series {
        s.push_str(&t.worst_penumbra().map_or_else(|| " – |".to_owned(), |w| format!(" **{w:.4}** |")));
    }
    s.push('\n');
    s
}

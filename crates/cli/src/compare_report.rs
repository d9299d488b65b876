//! `gnomon compare`'s report: one row of figures per technique, and the JSON and
//! Markdown forms of the whole, each figure named for what it divides by.

use gnomon_reference::{drawn::DrawnMetrics, flicker::Flicker, metrics::Metrics};
use gnomon_scene::camera_path::CameraPathKind;
use serde::Serialize;

/// One technique's row of the report.
#[derive(Serialize)]
pub struct Row {
    pub technique: String,
    /// Against the truth at the surfaces the frame drew: every light-facing pixel.
    pub drawn: DrawnMetrics,
    /// Against the reference through the pixel centres, where both see one surface.
    #[serde(flatten)]
    pub metrics: Metrics,
    /// Median GPU milliseconds of the shadow pass, where the adapter has timestamps.
    pub shadow_ms: Option<f64>,
    /// Median GPU milliseconds of the moment pass (encoding, blur, mipmaps) of the
    /// filterable techniques.
    pub filter_ms: Option<f64>,
    /// The moment map's texel format, for the filterable techniques.
    pub moment_format: Option<String>,
    /// Median GPU milliseconds of the lighting pass.
    pub lighting_ms: Option<f64>,
    /// Flicker along `--camera-path`, when one was given.
    pub flicker: Option<Flicker>,
}

/// Perspective aliasing of the shadow layout at the first frame (the same for every
/// technique: the layout does not depend on the filter).
#[derive(Serialize)]
pub struct AliasingSummary {
    /// Mean over the shaded pixels of m, the screen pixels one shadow texel covers.
    pub mean: f32,
    pub max: f32,
}

/// The camera path of a flicker measurement.
#[derive(Serialize)]
pub struct PathReport {
    pub kind: CameraPathKind,
    pub frames: u32,
    pub travel: f32,
    pub frozen_cascades: bool,
}

#[derive(Serialize)]
pub struct Report<'a> {
    pub scene: &'a str,
    pub width: u32,
    pub height: u32,
    /// Texels per side of each layer (each level's window, for a virtual map).
    pub shadow_resolution: u32,
    /// A virtual map's levels (`--partition virtual`); `None` for a 2D or cube map.
    pub virtual_levels: Option<u32>,
    pub light: String,
    pub reference_samples: u32,
    pub adapter: String,
    pub backend: String,
    pub aliasing: AliasingSummary,
    pub camera_path: Option<PathReport>,
    /// What each metric divides by (`metrics::DENOMINATORS`).
    pub denominators: std::collections::BTreeMap<&'static str, &'static str>,
    pub rows: Vec<Row>,
    /// Each technique's frames over `--motion`'s sequence.
    pub motion: Option<Vec<crate::compare_motion::MotionSeries>>,
}

/// The technique's name, with its moment map's format when that is not 32-bit float.
fn technique_label(r: &Row) -> String {
    match &r.moment_format {
        Some(f) if f != "rgba32float" => format!("{} ({f})", r.technique),
        _ => r.technique.to_string(),
    }
}

/// `metrics.md`: the header, the table over the compared pixels and the table over
/// the edge ([`edge_table`]).
pub fn markdown_table(report: &Report, soft: bool) -> String {
    let map = match report.virtual_levels {
        Some(levels) => format!("virtual map of {levels} levels of {}²", report.shadow_resolution),
        None => format!("shadow map {}²", report.shadow_resolution),
    };
    let mut s = format!(
        "`{}` at {}×{}, {map}, reference {} on {} ({})\n\n",
        report.scene,
        report.width,
        report.height,
        if soft { format!("{} samples/pixel", report.reference_samples) } else { "exact".into() },
        report.adapter,
        report.backend
    );
    s.push_str(&format!(
        "Perspective aliasing m (pixels one shadow texel spans; 1 is ideal): mean {:.3}, max {:.1}\n\n",
        report.aliasing.mean, report.aliasing.max
    ));
    if let Some(p) = &report.camera_path {
        s.push_str(&format!(
            "Flicker along a {:?} path of {} frames, the eye travelling {} of its distance to the target{}. Flips: the pixels that change between shadow and light from frame to frame, the technique's rate minus the reference's. Shimmer: of the pixels that reproject onto the same surface point of the previous frame, those that flip while the reference does not\n\n",
            p.kind,
            p.frames,
            p.travel,
            if p.frozen_cascades { ", cascades frozen at the first frame" } else { "" }
        ));
    }
    s.push_str(&drawn_table(report));
    s.push_str(
        "Against the reference through the pixel centres (the figure before the drawn one above; kept so that the history stays readable): mismatch, false shadow, false lit, MAE, RMSE and p99 are over the compared pixels, those where both images see the same surface and it faces the light (geometric N·L > 0) inside its cone and range. All-surface mismatch divides by every surface pixel both see, light-facing or not (compared + unlit)\n\n",
    );
    let path = report.camera_path.is_some();
    s.push_str("| technique | mismatch | false shadow | false lit | MAE | RMSE | p99 | compared | all-surface mismatch | unlit | silhouette | shadow ms | filter ms | lighting ms |");
    s.push_str(if path { " flips − reference | shimmer |\n" } else { "\n" });
    s.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    s.push_str(if path { "---|---|\n" } else { "\n" });
    let ms = |v: Option<f64>| v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "n/a".into());
    for r in &report.rows {
        let m = &r.metrics;
        s.push_str(&format!(
            "| {} | {:.3}% | {:.3}% | {:.3}% | {:.4} | {:.4} | {:.3} | {} | {:.3}% | {} | {} | {} | {} | {} |\n",
            technique_label(r),
            100.0 * m.mismatch_rate,
            100.0 * m.false_shadow_rate,
            100.0 * m.false_lit_rate,
            m.mae,
            m.rmse,
            m.p99,
            m.compared,
            100.0 * m.surface_mismatch_rate,
            m.unlit,
            m.silhouette,
            ms(r.shadow_ms),
            if r.filter_ms.is_some() { ms(r.filter_ms) } else { "–".into() },
            ms(r.lighting_ms)
        ));
        if let Some(f) = &r.flicker {
            s.pop();
            s.push_str(&format!(
                " {:+.4}% of {:.4}% | {:.4}% |\n",
                100.0 * f.excess_flip_rate,
                100.0 * f.reference_flip_rate,
                100.0 * f.shimmer_rate
            ));
        }
    }
    s.push('\n');
    s.push_str(&edge_table(report, soft));
    s
}

/// Every light-facing pixel the frame shows, against the truth traced from its own
/// surface: the headline figure.
fn drawn_table(report: &Report) -> String {
    let mut s = String::from(
        "Against the truth at the drawn surfaces: every pixel the frame shows whose surface faces the light inside its cone and range, traced from the frame's own point and normal. Ambiguous: the truth changes when its ray starts 10⁻⁵ of the scene's extent higher (a caster touching the receiver); counted apart, not in the rates\n\n",
    );
    s.push_str("| technique | mismatch | false shadow | false lit | MAE | compared | ambiguous |\n");
    s.push_str("|---|---|---|---|---|---|---|\n");
    for r in &report.rows {
        let d = &r.drawn;
        s.push_str(&format!(
            "| {} | {:.3}% | {:.3}% | {:.3}% | {:.4} | {} | {} ({:.3}%) |\n",
            technique_label(r),
            100.0 * d.mismatch_rate,
            100.0 * d.false_shadow_rate,
            100.0 * d.false_lit_rate,
            d.mae,
            d.compared,
            d.ambiguous,
            100.0 * d.ambiguous_rate
        ));
    }
    s.push('\n');
    s
}

/// The error where the shadow's edge is, beside the all-pixel MAE it refines: over the
/// reference's penumbra, with the width error of its transitions, under an area
/// light; over the ±2-pixel band around its boundary under a point-like one.
fn edge_table(report: &Report, soft: bool) -> String {
    let px = |v: Option<f64>| v.map(|x| format!("{x:.2}")).unwrap_or_else(|| "n/a".into());
    let mut s = String::new();
    if soft {
        s.push_str(
            "Penumbra: the compared pixels where the reference lies strictly between 0 and 1 by more than its own standard error. Width: along edge profiles (lines through the reference's 0.5 isoline along its gradient), the 10 %–90 % transition widths of the technique and the reference; the error is the mean |difference| in pixels, the bias its mean sign (positive: too wide), over the profiles where both transitions were found (unresolved: the technique's was not)\n\n",
        );
        s.push_str("| technique | MAE, all compared | MAE, penumbra | RMSE, penumbra | penumbra pixels | width error px | width bias px | reference width px | profiles (unresolved) |\n");
        s.push_str("|---|---|---|---|---|---|---|---|---|\n");
        for r in &report.rows {
            let (m, p) = (&r.metrics, &r.metrics.penumbra);
            s.push_str(&format!(
                "| {} | {:.4} | {:.4} | {:.4} | {} | {} | {} | {} | {} ({}) |\n",
                technique_label(r),
                m.mae,
                p.error.mae,
                p.error.rmse,
                p.error.pixels,
                px(p.width.error_px),
                px(p.width.bias_px),
                px(p.width.reference_px),
                p.width.profiles,
                p.width.unresolved
            ));
        }
    } else {
        s.push_str(
            "Edge band: the compared pixels within 2 pixels of the reference's shadow boundary, where a hard shadow's filtering and misplacement show\n\n",
        );
        s.push_str("| technique | MAE, all compared | MAE, edge band | RMSE, edge band | edge pixels |\n");
        s.push_str("|---|---|---|---|---|\n");
        for r in &report.rows {
            let (m, e) = (&r.metrics, &r.metrics.edge);
            s.push_str(&format!(
                "| {} | {:.4} | {:.4} | {:.4} | {} |\n",
                technique_label(r),
                m.mae,
                e.mae,
                e.rmse,
                e.pixels
            ));
        }
    }
    s
}

//! `gnomon bench`'s report: what each configuration measured, summarized (median
//! and 95th percentile), as the JSON and markdown it writes.

use gnomon_render::GpuInfo;
use serde::Serialize;

/// The median and 95th percentile of one measured quantity, in milliseconds, and every
/// frame's value in the order the frames were timed (for re-analysis: frame i of one
/// quantity and frame i of another were measured in the same frame).
#[derive(Serialize, Clone, Debug)]
pub(crate) struct Summary {
    pub(crate) name: String,
    pub(crate) median_ms: f64,
    pub(crate) p95_ms: f64,
    pub(crate) samples: usize,
    pub(crate) values_ms: Vec<f64>,
}

/// What one shadow-map layer drew in a frame.
#[derive(Clone, Copy, Debug, Serialize)]
pub(crate) struct LayerDrawn {
    pub(crate) draws: u32,
    /// Draw commands recorded for them: one per draw, or one per multi-draw.
    pub(crate) commands: u32,
    pub(crate) triangles: u64,
}

#[derive(Serialize, Debug)]
pub(crate) struct ConfigReport {
    pub(crate) technique: String,
    pub(crate) sweep_value: Option<String>,
    /// Per pass (shadow, filter, prepass, mask, lighting: every light together),
    /// then the frame totals (GPU frame, CPU submission and its parts, wall clock).
    pub(crate) passes: Vec<Summary>,
    /// Each light's each layer: "shadow L0 layer 1".
    pub(crate) layers: Vec<Summary>,
    /// Draw calls, instances and triangles of one frame.
    pub(crate) shadow_draws: u32,
    pub(crate) shadow_commands: u32,
    pub(crate) shadow_instances: u32,
    pub(crate) shadow_triangles: u64,
    /// What each of `layers` drew in the last frame, in the same order.
    pub(crate) layer_drawn: Vec<LayerDrawn>,
    pub(crate) lighting_draws: u32,
    pub(crate) lighting_instances: u32,
    /// With --depth-only: the baseline's time, and the median over frames of the
    /// shadow pass's time over the baseline's (lights the baseline can draw).
    pub(crate) depth_only: Option<Summary>,
    pub(crate) shadow_over_depth_only: Option<f64>,
    /// With refinement by rays, in the last frame: the pixels traced as a share of
    /// the screen (every refining light together, in %), and the rays cast.
    pub(crate) traced_percent: Option<f64>,
    pub(crate) rays: Option<u64>,
}

#[derive(Serialize, Debug)]
pub(crate) struct Report {
    pub(crate) adapter: String,
    pub(crate) backend: String,
    pub(crate) device_type: String,
    pub(crate) driver: String,
    pub(crate) driver_info: String,
    pub(crate) timing: &'static str,
    pub(crate) scene: String,
    pub(crate) instances: usize,
    pub(crate) triangles: usize,
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) warmup: u32,
    pub(crate) frames: u32,
    pub(crate) sweep: Option<String>,
    /// With --moving: how many instances moved every frame, and the time to build
    /// the casters' BVH afresh, for scale against the refits in `CPU move`.
    pub(crate) moving: Option<usize>,
    pub(crate) rebuild_ms: Option<f64>,
    pub(crate) command: String,
    pub(crate) configs: Vec<ConfigReport>,
}

/// Median and 95th percentile (nearest rank) of `values`.
pub(crate) fn summarize(name: &str, values: &[f64]) -> Summary {
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
pub(crate) fn markdown(report: &Report, info: &GpuInfo) -> String {
    let mut md = String::new();
    header(&mut md, report, info);
    let sweep = report.sweep.as_deref().and_then(|s| s.split('=').next()).map(|f| f.trim_start_matches('-'));
    pass_table(&mut md, report, sweep);
    if report.configs.iter().any(|c| c.layers.len() > 1) {
        layer_table(&mut md, report, sweep);
    }
    md
}

/// A row's cell: the median and, in brackets, the 95th percentile.
fn cell(s: Option<&Summary>) -> String {
    s.map_or("–".to_string(), |s| format!("{:.3} ({:.3})", s.median_ms, s.p95_ms))
}

/// The title and the device, the scene, the frames timed and the command.
fn header(md: &mut String, report: &Report, info: &GpuInfo) {
    use std::fmt::Write;
    let _ = writeln!(md, "# gnomon bench: {}\n", report.scene);
    let _ = writeln!(
        md,
        "- adapter: {} ({}, {}), driver: {} {}\n- timing: {}\n- {} instances{}, {} triangles; image {}×{}; \
         {} warm-up and {} timed frames per row; times in ms (the layer counts of kept maps in layers, `shadow Mtexels` in millions of texels the shadow passes cleared or drew), median (p95)\n- command: `{}`\n",
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
}

/// One row per configuration: each pass's time, in frame order, and its draws.
fn pass_table(md: &mut String, report: &Report, sweep: Option<&str>) {
    use std::fmt::Write;
    let mut columns: Vec<String> = Vec::new();
    for config in &report.configs {
        for pass in &config.passes {
            if !columns.contains(&pass.name) {
                columns.push(pass.name.clone());
            }
        }
    }
    // In frame order, whichever configurations have them.
    const ORDER: [&str; 17] = [
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
        "layers kept",
        "layers scrolled",
        "layers drawn",
    ];
    columns.sort_by_key(|c| ORDER.iter().position(|o| o == c).unwrap_or(ORDER.len()));
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
    let _ = writeln!(
        md,
        " shadow draws (instances, triangles) | shadow draw commands | lighting draws (instances) |"
    );
    let cells = columns.len()
        + 4
        + usize::from(sweep.is_some())
        + 2 * usize::from(has_baseline)
        + usize::from(has_rays);
    let _ = writeln!(md, "|{}", "---|".repeat(cells));
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
            " {} ({}, {}) | {} | {} ({}) |",
            config.shadow_draws,
            config.shadow_instances,
            config.shadow_triangles,
            config.shadow_commands,
            config.lighting_draws,
            config.lighting_instances
        );
    }
}

/// Each shadow-map layer's time and draws, where a light has several.
fn layer_table(md: &mut String, report: &Report, sweep: Option<&str>) {
    use std::fmt::Write;
    let _ = writeln!(md, "\nEach shadow-map layer (light L, layer: cascade or cube face):\n");
    let _ = writeln!(
        md,
        "| technique | layer | median (p95) | draws | commands | triangles |\n|---|---|---|---|---|---|"
    );
    for config in &report.configs {
        let label = match &config.sweep_value {
            Some(v) => format!("{} {}={v}", config.technique, sweep.unwrap_or("")),
            None => config.technique.clone(),
        };
        for (index, layer) in config.layers.iter().enumerate() {
            let drawn = config.layer_drawn.get(index);
            let count = |n: Option<u64>| n.map_or("–".to_string(), |n| n.to_string());
            let _ = writeln!(
                md,
                "| {label} | {} | {} | {} | {} | {} |",
                layer.name.trim_start_matches("shadow "),
                cell(Some(layer)),
                count(drawn.map(|d| u64::from(d.draws))),
                count(drawn.map(|d| u64::from(d.commands))),
                count(drawn.map(|d| d.triangles)),
            );
        }
    }
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
}

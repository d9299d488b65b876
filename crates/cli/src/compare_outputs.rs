//! `gnomon compare`'s images and table rows: the reference and aliasing images, each
//! technique's frame and error heat-map, the labelled grid of them all, and one
//! [`Row`] of metrics per technique, staged to be written together.

use std::path::Path;

use gnomon_reference::{
    ReferenceImage,
    aliasing::{self, AliasingImage},
    drawn::DrawnMetrics,
    flicker::Flicker,
    heatmap,
    metrics::{self, Metrics, PixelClass, RasterView},
};
use image::RgbaImage;

use crate::{
    compare_cmd::Rendered,
    compare_report::Row,
    grid::{self, Downscale, Tile},
    output,
};

/// What a comparison measured: the reference, the first frame's aliasing, each
/// technique's frame, its flicker along the camera path and its metrics at the
/// surfaces it drew.
pub(crate) struct Measured<'a> {
    pub reference: &'a ReferenceImage,
    pub aliasing: &'a AliasingImage,
    pub frames: &'a [Rendered],
    pub flicker: Vec<Option<Flicker>>,
    pub drawn: Vec<DrawnMetrics>,
}

/// Stages reference.png, aliasing.png, each technique's TECHNIQUE.png and
/// TECHNIQUE-error.png, and grid.png in `out`; returns each technique's row.
pub(crate) fn stage(staged: &mut output::Staged, out: &Path, measured: Measured) -> anyhow::Result<Vec<Row>> {
    let Measured { reference, aliasing, frames, flicker, drawn } = measured;
    let soft = reference.samples > 1;
    let (w, h) = (reference.width, reference.height);
    let mut rows = Vec::new();
    let mut tiles = vec![vec![Tile {
        image: rgba(w, h, output::visibility_rgba(&reference.visibility)),
        caption: caption_reference(reference),
        downscale: Downscale::Smooth,
    }]];
    staged.png_rgba(&out.join("reference.png"), w, h, &output::visibility_rgba(&reference.visibility))?;
    staged.png_rgba(&out.join("aliasing.png"), w, h, &aliasing::heatmap(aliasing))?;
    for ((Rendered { technique, frame, timing }, flicker), drawn) in frames.iter().zip(flicker).zip(drawn) {
        let raster =
            RasterView { visibility: &frame.visibility, object_id: &frame.object_id, depth: &frame.depth };
        let classes: Vec<PixelClass> = metrics::classify(raster, reference);
        let m = metrics::measure(raster, reference, &classes);
        let error = if soft {
            heatmap::soft(&frame.visibility, reference, &classes)
        } else {
            heatmap::hard(&frame.visibility, reference, &classes)
        };
        let name = technique.name();
        staged.png_rgba(&out.join(format!("{name}.png")), w, h, &frame.color)?;
        staged.png_rgba(&out.join(format!("{name}-error.png")), w, h, &error)?;
        let mut caption = vec![name.to_string()];
        if let Some(t) = timing {
            caption.push(format!("shadow pass {:.2} ms", t.shadow_ms));
            if let Some(f) = t.filter_ms {
                caption.push(format!("derived maps {f:.2} ms"));
            }
            caption.push(format!("lighting pass {:.2} ms", t.lighting_ms));
        }
        let error_caption = edge_caption(&m, &drawn, soft)
            .into_iter()
            .chain([
                format!("false shadow {:.3}%", 100.0 * m.false_shadow_rate),
                format!("false lit {:.3}%", 100.0 * m.false_lit_rate),
                format!("all surfaces: mismatch {:.3}%", 100.0 * m.surface_mismatch_rate),
            ])
            .collect();
        tiles.push(vec![
            Tile { image: rgba(w, h, frame.color.clone()), caption, downscale: Downscale::Smooth },
            Tile {
                image: rgba(w, h, error),
                caption: error_caption,
                downscale: Downscale::Salient(if soft { soft_priority } else { hard_priority }),
            },
        ]);
        rows.push(Row {
            technique: name.to_owned(),
            drawn,
            metrics: m,
            shadow_ms: timing.map(|t| t.shadow_ms),
            filter_ms: timing.and_then(|t| t.filter_ms),
            lighting_ms: timing.map(|t| t.lighting_ms),
            moment_format: frame.moment_format.map(|f| format!("{f:?}").to_lowercase()),
            flicker,
        });
    }
    let grid = grid::compose(&page_of(tiles), 480, &legend(soft));
    staged.png_rgba(&out.join("grid.png"), grid.width(), grid.height(), grid.as_raw())?;
    Ok(rows)
}

/// Stages motion.png and motion-error.png in `out`: the last frame of `compare
/// --motion` and its error against its own `reference`.
pub(crate) fn stage_motion(
    staged: &mut output::Staged,
    out: &Path,
    frame: &gnomon_render::Frame,
    reference: &ReferenceImage,
) -> anyhow::Result<()> {
    let raster =
        RasterView { visibility: &frame.visibility, object_id: &frame.object_id, depth: &frame.depth };
    let classes = metrics::classify(raster, reference);
    let error = if reference.samples > 1 {
        heatmap::soft(&frame.visibility, reference, &classes)
    } else {
        heatmap::hard(&frame.visibility, reference, &classes)
    };
    let (w, h) = (reference.width, reference.height);
    staged.png_rgba(&out.join("motion.png"), w, h, &frame.color)?;
    staged.png_rgba(&out.join("motion-error.png"), w, h, &error)
}

/// The heat-maps' legend: the error ramp under an area light, the classes otherwise.
fn legend(soft: bool) -> Vec<(String, [u8; 3])> {
    if soft {
        [0.0f32, 0.25, 0.5, 0.75, 1.0].iter().map(|&e| (format!("|V-R| {e}"), heatmap::ramp(e))).collect()
    } else {
        heatmap::HARD_LEGEND.iter().map(|(l, c)| (l.to_string(), *c)).collect()
    }
}

/// Many techniques go two to a row, so the grid stays a page, not a scroll.
fn page_of(mut tiles: Vec<Vec<Tile>>) -> Vec<Vec<Tile>> {
    if tiles.len() > 5 {
        let mut techniques = tiles.split_off(1);
        while !techniques.is_empty() {
            let n = techniques.len().min(2);
            tiles.push(techniques.drain(..n).flatten().collect());
        }
    }
    tiles
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

fn caption_reference(r: &ReferenceImage) -> Vec<String> {
    let kind = if r.samples > 1 { format!("{} samples/pixel", r.samples) } else { "exact".to_string() };
    vec!["reference (ray traced)".into(), kind]
}

//! Labelled image grids for `gnomon compare`: tiles in rows, a caption over each, and
//! a legend, drawn with an 8×8 bitmap font (font8x8, public domain).

use font8x8::UnicodeFonts;
use image::{Rgba, RgbaImage, imageops};

const BACKGROUND: Rgba<u8> = Rgba([18, 18, 22, 255]);
const TEXT: Rgba<u8> = Rgba([235, 235, 235, 255]);
const SCALE: u32 = 2;
const LINE: u32 = 8 * SCALE + 6;
const PAD: u32 = 8;

/// How a tile is shrunk to the grid's width.
pub enum Downscale {
    /// Smooth (triangle filter): for pictures.
    Smooth,
    /// Each output pixel takes the source pixel of highest priority in its footprint,
    /// so that single wrong pixels in a heat-map survive the shrink.
    Salient(fn([u8; 4]) -> u32),
}

/// One tile: an image and its caption lines.
pub struct Tile {
    pub image: RgbaImage,
    pub caption: Vec<String>,
    pub downscale: Downscale,
}

/// Shrinks (or keeps) `image` to `width`, keeping the most salient pixel of each footprint.
fn downscale_salient(image: &RgbaImage, width: u32, priority: fn([u8; 4]) -> u32) -> RgbaImage {
    let height = ((image.height() as u64 * width as u64) / image.width().max(1) as u64).max(1) as u32;
    let (sx, sy) = (image.width() as f64 / width as f64, image.height() as f64 / height as f64);
    RgbaImage::from_fn(width, height, |x, y| {
        let (x0, x1) = ((x as f64 * sx) as u32, (((x + 1) as f64 * sx).ceil() as u32).min(image.width()));
        let (y0, y1) = ((y as f64 * sy) as u32, (((y + 1) as f64 * sy).ceil() as u32).min(image.height()));
        let centre =
            *image.get_pixel(((x0 + x1) / 2).min(image.width() - 1), ((y0 + y1) / 2).min(image.height() - 1));
        let mut best = (priority(centre.0), centre);
        for yy in y0..y1.max(y0 + 1) {
            for xx in x0..x1.max(x0 + 1) {
                let p = *image.get_pixel(xx.min(image.width() - 1), yy.min(image.height() - 1));
                let k = priority(p.0);
                if k > best.0 {
                    best = (k, p);
                }
            }
        }
        best.1
    })
}

/// Draws `text` at (x, y) with the 8×8 font scaled by [`SCALE`], clipped at `max_x`.
pub fn draw_text(canvas: &mut RgbaImage, x: u32, y: u32, text: &str, color: Rgba<u8>, max_x: u32) {
    for (k, ch) in text.chars().enumerate() {
        let glyph = font8x8::BASIC_FONTS.get(ch).or_else(|| font8x8::BASIC_FONTS.get('?')).unwrap_or([0; 8]);
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                for dy in 0..SCALE {
                    for dx in 0..SCALE {
                        let px = x + (k as u32 * 8 + col) * SCALE + dx;
                        let py = y + row as u32 * SCALE + dy;
                        if px < canvas.width().min(max_x) && py < canvas.height() {
                            canvas.put_pixel(px, py, color);
                        }
                    }
                }
            }
        }
    }
}

/// Composes `rows` of tiles, each scaled to `tile_width`, with captions, and a legend
/// of colour swatches at the bottom.
pub fn compose(rows: &[Vec<Tile>], tile_width: u32, legend: &[(String, [u8; 3])]) -> RgbaImage {
    let columns = rows.iter().map(Vec::len).max().unwrap_or(1) as u32;
    let scaled: Vec<Vec<(RgbaImage, &Vec<String>)>> = rows
        .iter()
        .map(|row| {
            row.iter()
                .map(|t| {
                    let h =
                        (t.image.height() as u64 * tile_width as u64 / t.image.width().max(1) as u64) as u32;
                    let image = match t.downscale {
                        Downscale::Smooth => {
                            imageops::resize(&t.image, tile_width, h.max(1), imageops::FilterType::Triangle)
                        }
                        Downscale::Salient(priority) => downscale_salient(&t.image, tile_width, priority),
                    };
                    (image, &t.caption)
                })
                .collect()
        })
        .collect();
    let row_heights: Vec<u32> = scaled
        .iter()
        .map(|row| {
            let lines = row.iter().map(|(_, c)| c.len()).max().unwrap_or(0) as u32;
            lines * LINE + row.iter().map(|(i, _)| i.height()).max().unwrap_or(0) + PAD
        })
        .collect();
    let width = PAD + columns * (tile_width + PAD);
    // The legend wraps onto as many lines as it needs.
    let entry_width = |label: &str| 8 * SCALE + 6 + label.chars().count() as u32 * 8 * SCALE + 3 * PAD;
    let mut legend_lines = u32::from(!legend.is_empty());
    let mut x = PAD;
    for (label, _) in legend {
        if x + entry_width(label) > width && x > PAD {
            legend_lines += 1;
            x = PAD;
        }
        x += entry_width(label);
    }
    let legend_height = legend_lines * LINE + PAD;
    let height = PAD + row_heights.iter().sum::<u32>() + legend_height;
    let mut canvas = RgbaImage::from_pixel(width, height, BACKGROUND);
    let mut y = PAD;
    for (row, row_height) in scaled.iter().zip(&row_heights) {
        let lines = row.iter().map(|(_, c)| c.len()).max().unwrap_or(0) as u32;
        for (k, (image, caption)) in row.iter().enumerate() {
            let x = PAD + k as u32 * (tile_width + PAD);
            for (l, text) in caption.iter().enumerate() {
                draw_text(&mut canvas, x, y + l as u32 * LINE, text, TEXT, x + tile_width);
            }
            imageops::overlay(&mut canvas, image, x as i64, (y + lines * LINE) as i64);
        }
        y += row_height;
    }
    let mut x = PAD;
    for (label, color) in legend {
        if x + entry_width(label) > width && x > PAD {
            x = PAD;
            y += LINE;
        }
        let swatch = Rgba([color[0], color[1], color[2], 255]);
        for dy in 0..8 * SCALE {
            for dx in 0..8 * SCALE {
                if x + dx < width {
                    canvas.put_pixel(x + dx, y + dy, swatch);
                }
            }
        }
        draw_text(&mut canvas, x + 8 * SCALE + 6, y, label, TEXT, width);
        x += entry_width(label);
    }
    canvas
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compose_lays_out_tiles_captions_and_legend() {
        let red = RgbaImage::from_pixel(100, 50, Rgba([255, 0, 0, 255]));
        let rows = vec![vec![
            Tile { image: red.clone(), caption: vec!["a".into()], downscale: Downscale::Smooth },
            Tile { image: red, caption: vec![], downscale: Downscale::Smooth },
        ]];
        let legend = vec![("x".to_string(), [0, 255, 0])];
        let grid = compose(&rows, 200, &legend);
        assert_eq!(grid.width(), PAD + 2 * (200 + PAD));
        assert_eq!(grid.height(), PAD + LINE + 100 + PAD + LINE + PAD);
        // The first tile starts under its caption line; the legend swatch is green.
        assert_eq!(*grid.get_pixel(PAD + 5, PAD + LINE + 5), Rgba([255, 0, 0, 255]));
        assert_eq!(*grid.get_pixel(PAD + 2, PAD + LINE + 100 + PAD + 2), Rgba([0, 255, 0, 255]));
        // The caption drew some text pixels.
        let text = (0..LINE)
            .flat_map(|y| (PAD..PAD + 16).map(move |x| (x, y + PAD)))
            .filter(|&(x, y)| *grid.get_pixel(x, y) == TEXT)
            .count();
        assert!(text > 10);
    }
}

#[cfg(test)]
mod salient_tests {
    use super::*;

    #[test]
    fn a_single_error_pixel_survives_a_4x_shrink() {
        let mut image = RgbaImage::from_pixel(400, 200, Rgba([100, 100, 100, 255]));
        image.put_pixel(201, 103, Rgba([255, 0, 0, 255]));
        let priority = |p: [u8; 4]| u32::from(p[0] == 255);
        let small = downscale_salient(&image, 100, priority);
        assert_eq!((small.width(), small.height()), (100, 50));
        let red = small.pixels().filter(|p| p.0 == [255, 0, 0, 255]).count();
        assert_eq!(red, 1, "the error pixel is kept, once");
        let smooth = imageops::resize(&image, 100, 50, imageops::FilterType::Triangle);
        assert!(smooth.pixels().all(|p| p.0[0] < 200), "a smooth shrink loses it");
    }
}

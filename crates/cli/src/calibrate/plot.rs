//! The calibration plot: every swept setting as a point of false shadow against
//! false lit, the Pareto front through them, the chosen setting and the defaults,
//! drawn with plotters into an RGB buffer. The font is the Ubuntu Light that egui
//! bundles (`epaint_default_fonts`), so that no system font is needed.

use plotters::prelude::*;

use super::sweep::Measured;

/// What the plot shows, in percent of light-facing pixels.
pub struct PlotInput<'a, S> {
    pub title: &'a str,
    pub points: &'a [Measured<S>],
    /// Indices into `points`, along the front.
    pub front: &'a [usize],
    pub chosen: usize,
    /// The default settings' figures on the same views.
    pub defaults: (f64, f64),
}

/// The plot's size in pixels.
pub const PLOT_SIZE: (u32, u32) = (960, 720);

/// Registers the bundled font once per process under plotters' "sans-serif".
fn register_font() -> anyhow::Result<()> {
    static REGISTERED: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            plotters::style::register_font(
                "sans-serif",
                FontStyle::Normal,
                epaint_default_fonts::UBUNTU_LIGHT,
            )
            .map_err(|_| "the bundled font could not be read".to_string())
        })
        .clone()
        .map_err(anyhow::Error::msg)
}

/// Draws the plot; returns RGB8 pixels, `PLOT_SIZE` large, top row first.
pub fn draw<S>(input: &PlotInput<S>) -> anyhow::Result<Vec<u8>> {
    register_font()?;
    let (w, h) = PLOT_SIZE;
    let mut pixels = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        // Log axes: acne in one corner runs to tens of percent while the front lies
        // near a tenth of one. A zero is drawn at the axis' floor.
        let xs = input.points.iter().map(|p| p.false_shadow).chain([input.defaults.0]);
        let ys = input.points.iter().map(|p| p.false_lit).chain([input.defaults.1]);
        let (x_lo, x_hi) = log_range(xs);
        let (y_lo, y_hi) = log_range(ys);
        let percent = move |v: f64| (100.0 * v).max(x_lo);
        let percent_y = move |v: f64| (100.0 * v).max(y_lo);
        let mut chart = ChartBuilder::on(&root)
            .caption(input.title, ("sans-serif", 26))
            .margin(24)
            .x_label_area_size(56)
            .y_label_area_size(72)
            .build_cartesian_2d((x_lo..x_hi).log_scale(), (y_lo..y_hi).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("false shadow, % of light-facing pixels (log)")
            .y_desc("false lit, % of light-facing pixels (log)")
            .x_labels(10)
            .y_labels(10)
            .x_label_formatter(&|v| format!("{}", (v * 1e4).round() / 1e4))
            .y_label_formatter(&|v| format!("{}", (v * 1e4).round() / 1e4))
            .axis_desc_style(("sans-serif", 20))
            .label_style(("sans-serif", 16))
            .draw()?;
        let grey = RGBColor(150, 150, 150);
        chart
            .draw_series(
                input.points.iter().map(|p| {
                    Circle::new((percent(p.false_shadow), percent_y(p.false_lit)), 3, grey.filled())
                }),
            )?
            .label("settings swept")
            .legend(move |(x, y)| Circle::new((x + 10, y), 3, grey.filled()));
        let blue = RGBColor(40, 110, 220);
        let front = input
            .front
            .iter()
            .map(|&i| (percent(input.points[i].false_shadow), percent_y(input.points[i].false_lit)));
        chart
            .draw_series(LineSeries::new(front, blue.stroke_width(2)))?
            .label("Pareto front")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue.stroke_width(2)));
        let c = &input.points[input.chosen];
        let red = RGBColor(220, 50, 40);
        chart
            .draw_series(std::iter::once(Circle::new(
                (percent(c.false_shadow), percent_y(c.false_lit)),
                7,
                red.filled(),
            )))?
            .label("chosen: least total mismatch")
            .legend(move |(x, y)| Circle::new((x + 10, y), 5, red.filled()));
        chart
            .draw_series(std::iter::once(Cross::new(
                (percent(input.defaults.0), percent_y(input.defaults.1)),
                8,
                BLACK.stroke_width(2),
            )))?
            .label("defaults")
            .legend(|(x, y)| Cross::new((x + 10, y), 5, BLACK.stroke_width(2)));
        chart
            .configure_series_labels()
            .label_font(("sans-serif", 18))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
        root.present()?;
    }
    Ok(pixels)
}

/// A log axis' range in percent over `rates` (fractions): from half the smallest
/// positive value (or 0.001 %) to a little above the largest.
fn log_range(rates: impl Iterator<Item = f64> + Clone) -> (f64, f64) {
    let positive = rates.clone().filter(|&r| r > 0.0).map(|r| 100.0 * r);
    let lo = positive.clone().fold(f64::INFINITY, f64::min);
    let lo = if lo.is_finite() { 0.5 * lo } else { 1e-3 };
    let hi = rates.map(|r| 100.0 * r).fold(lo * 4.0, f64::max) * 1.3;
    (lo, hi)
}

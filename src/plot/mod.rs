//! PNG plots: smoothed series, persistence diagrams, grid heat maps (`grid`), fields on
//! meshes and plane triangulations.
//!
//! Drawing uses plotters' bitmap backend into an in-memory RGB buffer, written as PNG by the
//! `image` crate.

use chrono::{Datelike, NaiveDate, TimeDelta};
use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::error::Error;
use std::sync::OnceLock;

mod grid;
mod mesh;
mod triangulation;
mod volume;
pub use grid::{plot_grid_fields, GridMarker, GridPanel, GridPlotOptions};
pub use mesh::{plot_mesh_colours, plot_mesh_fields, MeshView};
pub use triangulation::plot_triangulation;
pub use volume::{plot_volume_slices, VolumePlot};

/// Error of a plot: carries a message.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct PlotError(pub String);

/// How the x axis of a series is labelled.
#[derive(Clone, Debug, PartialEq)]
pub enum XAxis {
    /// x is a plain number with this axis label (e.g. "sample" or "x").
    Numeric(String),
    /// x counts days since this date: tick labels are drawn as dates (YYYY-MM or YYYY-MM-DD, picked by span).
    DaysSince(NaiveDate),
}

/// A kept extremum marker: index into the arrays, and whether it is a maximum (red) or minimum (blue).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Marker {
    /// Index into the `x` / `output` arrays.
    pub index: usize,
    /// True for a maximum, false for a minimum.
    pub is_max: bool,
}

/// One point of a persistence diagram.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiagramPoint {
    /// Value at which the feature is born.
    pub birth: f64,
    /// Value at which it dies (infinite for an essential feature).
    pub death: f64,
    /// True for a pair of a maximum, false for a pair of a minimum.
    pub is_max: bool,
    /// True if the extremum is kept by the smoothing, false if it is cancelled.
    pub kept: bool,
}

const FONT: &str = "sans-serif";
const GREY: RGBColor = RGBColor(90, 90, 90);
const ORANGE: RGBColor = RGBColor(255, 140, 0);
const MIN_C: RGBColor = RGBColor(20, 70, 220);
const MAX_C: RGBColor = RGBColor(210, 20, 20);
/// Cancelled pairs in a persistence diagram: a light grey, so that a dense band of them stays
/// background.
const CANCELLED_C: RGBColor = RGBColor(175, 175, 175);

/// Registers DejaVu Sans as "sans-serif" once; plotters' `ab_glyph` text needs it.
fn ensure_font() -> Result<(), PlotError> {
    static OK: OnceLock<bool> = OnceLock::new();
    let ok =
        OK.get_or_init(|| plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular()).is_ok());
    ok.then_some(()).ok_or_else(|| PlotError("cannot register the DejaVu Sans font".into()))
}

/// Validates the size, draws with `draw` on a white RGB canvas and writes it as PNG to `out`.
fn render<F>(out: &mut dyn std::io::Write, (w, h): (u32, u32), draw: F) -> Result<(), PlotError>
where
    F: FnOnce(&Area<'_>, f64) -> Result<(), Box<dyn Error>>,
{
    let fail = |e: &dyn std::fmt::Display| PlotError(format!("plot: {e}"));
    if !(100..=16384).contains(&w) || !(100..=16384).contains(&h) {
        return Err(fail(&format!("image size {w}x{h} outside 100..=16384")));
    }
    ensure_font()?;
    let mut buf = vec![255u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        // Font scale: 1 on a 1200×600 image.
        let scale = ((w as f64 * h as f64).sqrt() / 848.5).clamp(0.6, 4.0);
        draw(&root, scale).map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    use image::ImageEncoder;
    image::codecs::png::PngEncoder::new(out)
        .write_image(&buf, w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| fail(&e))
}

/// A non-degenerate range around `lo..hi` (NaN or infinite bounds give 0..1), widened by `pad` each side.
fn nice_range(lo: f64, hi: f64, pad: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return (0.0, 1.0);
    }
    let (mid, half) = (lo / 2.0 + hi / 2.0, hi / 2.0 - lo / 2.0);
    let half = if half > mid.abs() * 1e-9 { half * (1.0 + 2.0 * pad) } else { mid.abs().max(1.0) * 0.05 };
    (mid - half, mid + half)
}

/// Whether `v` is plotted: finite and within ±1e300 (so that spans of values stay finite).
fn ok(v: f64) -> bool {
    v.abs() <= 1e300
}

fn min_max(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.filter(|&a| ok(a)).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)))
}

/// Finite `(x, y)` pairs; with more than 4 points per column, keeps each column bucket's min and max.
fn decimate(x: &[f64], y: &[f64], (lo, hi): (f64, f64), cols: usize) -> Vec<(f64, f64)> {
    let pts: Vec<(f64, f64)> = x.iter().zip(y).map(|(&a, &b)| (a, b)).filter(|&(a, b)| ok(a) && ok(b)).collect();
    if pts.len() <= 4 * cols {
        return pts;
    }
    let col = |a: f64| ((a - lo) / (hi - lo) * cols as f64) as i64;
    let mut out = Vec::with_capacity(4 * cols);
    let flush = |out: &mut Vec<_>, (_, a, b): (i64, usize, usize)| {
        out.push(pts[a.min(b)]);
        if a != b {
            out.push(pts[a.max(b)]);
        }
    };
    let mut cur: Option<(i64, usize, usize)> = None; // (column, index of min, index of max)
    for (i, &(a, b)) in pts.iter().enumerate() {
        match cur.as_mut() {
            Some((c, mn, mx)) if *c == col(a) => {
                if b < pts[*mn].1 {
                    *mn = i;
                }
                if b > pts[*mx].1 {
                    *mx = i;
                }
            }
            _ => {
                cur.into_iter().for_each(|g| flush(&mut out, g));
                cur = Some((col(a), i, i));
            }
        }
    }
    cur.into_iter().for_each(|g| flush(&mut out, g));
    out
}

/// An f64 axis whose bold ticks are given (date ticks) or, for `None`, plotters' default ones.
struct TickAxis(RangedCoordf64, Option<Vec<f64>>);

impl Ranged for TickAxis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;
    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        self.0.map(v, limit)
    }
    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        match &self.1 {
            Some(t) if !hint.weight().allow_light_points() => t.clone(),
            Some(_) => vec![],
            None => self.0.key_points(hint),
        }
    }
    fn range(&self) -> std::ops::Range<f64> {
        self.0.range()
    }
}

impl ValueFormatter<f64> for TickAxis {
    fn format(v: &f64) -> String {
        RangedCoordf64::format(v)
    }
}

/// Formats `days` after `origin` as YYYY-MM-DD (`with_day`) or YYYY-MM; out of range as a number.
fn date_label(origin: NaiveDate, days: f64, with_day: bool) -> String {
    match TimeDelta::try_days(days.round() as i64).and_then(|d| origin.checked_add_signed(d)) {
        Some(d) if with_day => d.format("%Y-%m-%d").to_string(),
        Some(d) => d.format("%Y-%m").to_string(),
        None => format!("{days:e}"),
    }
}

/// Tick positions (days after `origin`) on day, month or year boundaries, at most about `max`
/// of them, and whether labels need the day. `None` if the range is outside chrono's dates.
fn date_ticks(origin: NaiveDate, lo: f64, hi: f64, max: usize) -> Option<(Vec<f64>, bool)> {
    let day = |d: f64| origin.checked_add_signed(TimeDelta::try_days(d.floor() as i64)?);
    let (a, b, max) = (day(lo)?, day(hi)?, max.max(2) as f64);
    if let Some(&s) = [1.0, 2.0, 7.0, 14.0].iter().find(|&&s| (hi - lo) / s <= max) {
        let ticks = ((lo / s).ceil() as i64..=(hi / s).floor() as i64).map(|k| k as f64 * s);
        return Some((ticks.collect(), true));
    }
    let month = |d: NaiveDate| d.year() as i64 * 12 + d.month0() as i64;
    let (ma, mb) = (month(a), month(b) + 1);
    let mut steps = [1, 2, 3, 6].into_iter().chain((0..8).flat_map(|e| [12, 24, 60].map(|s| s * 10i64.pow(e))));
    let step = steps.find(|&s| ((mb - ma) / s) as f64 <= max)?;
    let ticks = (ma.div_euclid(step)..=mb.div_euclid(step)).filter_map(|k| {
        let m = k * step;
        let d = NaiveDate::from_ymd_opt(i32::try_from(m.div_euclid(12)).ok()?, m.rem_euclid(12) as u32 + 1, 1)?;
        Some((d - origin).num_days() as f64).filter(|t| (lo..=hi).contains(t))
    });
    Some((ticks.collect(), false))
}

/// Plots `input` (grey, thin) and `output` (orange, thicker) against `x`, with the kept minima
/// (blue) and maxima (red) drawn as dots at `(x, output)`, a legend, `title` and axis labels,
/// into a PNG of `size` pixels written to `out`. Non-finite points are skipped, markers whose index is
/// out of range are ignored, and long series are decimated to the min/max of each pixel column.
/// Errors on empty or mismatched arrays, no finite point, a size outside 100..=16384 or a
/// drawing/writing failure.
#[allow(clippy::too_many_arguments)]
pub fn plot_series(
    out: &mut dyn std::io::Write,
    x: &[f64],
    axis: &XAxis,
    y_label: &str,
    input: &[f64],
    output: &[f64],
    markers: &[Marker],
    title: &str,
    size: (u32, u32),
) -> Result<(), PlotError> {
    let fail = |m: &str| PlotError(format!("plot: {m}"));
    if x.len() != input.len() || x.len() != output.len() {
        let (a, b, c) = (x.len(), input.len(), output.len());
        return Err(fail(&format!("mismatched lengths: x {a}, input {b}, output {c}")));
    }
    let xs = min_max(x.iter().zip(input.iter().zip(output)).filter(|(_, (&a, &b))| ok(a) || ok(b)).map(|(x, _)| *x));
    let ys = min_max(x.iter().zip(input).chain(x.iter().zip(output)).filter(|(&x, _)| ok(x)).map(|(_, y)| *y));
    if !(xs.0 <= xs.1 && ys.0 <= ys.1) {
        return Err(fail("no finite point to plot"));
    }
    let (xr, yr) = (nice_range(xs.0, xs.1, 0.0), nice_range(ys.0, ys.1, 0.05));
    let cols = size.0 as usize;
    let (inp, smoothed) = (decimate(x, input, xr, cols), decimate(x, output, xr, cols));
    let dots: Vec<_> = markers
        .iter()
        .filter(|m| m.index < x.len() && ok(x[m.index]) && ok(output[m.index]))
        .map(|m| ((x[m.index], output[m.index]), m.is_max))
        .collect();
    render(out, size, |root, s| {
        let px = |v: f64| (v * s).round() as u32;
        let (ticks, with_day) = match axis {
            XAxis::DaysSince(o) => date_ticks(*o, xr.0, xr.1, (size.0 as usize / 130).clamp(2, 12)).unzip(),
            XAxis::Numeric(_) => (None, None),
        };
        let xfmt: Box<dyn Fn(&f64) -> String> = match (axis, with_day) {
            (XAxis::DaysSince(o), Some(wd)) => Box::new(move |v| date_label(*o, *v, wd)),
            _ => Box::new(move |v| tick_label(*v, xr.1 - xr.0)),
        };
        let root = root.margin(px(8.0), 0, 0, 0).titled(title, (FONT, 24.0 * s))?;
        let (top, root) = root.split_vertically(px(30.0));
        let x_desc = match axis {
            XAxis::Numeric(l) => l.as_str(),
            XAxis::DaysSince(_) => "date",
        };
        let ax = TickAxis((xr.0..xr.1).into(), ticks);
        let mut chart = make_chart(&root, s, ax, yr, (x_desc, y_label), &*xfmt)?;
        let (thin, thick) = (GREY.stroke_width(px(1.0).max(1)), ORANGE.stroke_width(px(2.5)));
        // one path per segment: a thick polyline gets miter spikes at sharp turns
        chart.draw_series(smoothed.windows(2).map(|w| PathElement::new(vec![w[0], w[1]], thick)))?;
        // the input on top, thin, so that its noise shows over the smooth band
        chart.draw_series(LineSeries::new(inp, thin))?;
        let mut legend = vec![(Mark::Line(thin), "input"), (Mark::Line(thick), "smoothed")];
        for (is_max, colour, name) in [(false, MIN_C, "kept minimum"), (true, MAX_C, "kept maximum")] {
            if dots.iter().any(|d| d.1 == is_max) {
                let pts = dots.iter().filter(|d| d.1 == is_max);
                let r = if dots.len() > 100 { px(3.5) } else { px(5.0) };
                chart.draw_series(pts.map(|d| Circle::new(d.0, r, colour.filled())))?;
                legend.push((Mark::Dot(colour.filled(), px(5.0)), name));
            }
        }
        draw_legend(&top, &legend, s, Some(px(95.0) as i32))
    })
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;
type Chart<'a, 'b> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<TickAxis, RangedCoordf64>>;

/// A chart on `area` with its mesh, axis descriptions `desc` and x tick labels from `xfmt`.
fn make_chart<'a, 'b>(
    area: &'a Area<'b>,
    s: f64,
    x: TickAxis,
    (y0, y1): (f64, f64),
    desc: (&str, &str),
    xfmt: &dyn Fn(&f64) -> String,
) -> Result<Chart<'a, 'b>, Box<dyn Error>> {
    let px = |v: f64| (v * s).round() as u32;
    let mut chart = ChartBuilder::on(area)
        .margin(px(10.0))
        .margin_right(px(40.0))
        .x_label_area_size(px(55.0))
        .y_label_area_size(px(85.0))
        .build_cartesian_2d(x, y0..y1)?;
    chart
        .configure_mesh()
        .x_desc(desc.0)
        .y_desc(desc.1)
        .x_label_formatter(xfmt)
        .y_label_formatter(&|v| tick_label(*v, y1 - y0))
        .axis_desc_style((FONT, 20.0 * s))
        .label_style((FONT, 17.0 * s))
        .bold_line_style(RGBColor(210, 210, 210))
        .light_line_style(RGBColor(242, 242, 242))
        .max_light_lines(4)
        .draw()?;
    Ok(chart)
}

/// Formats a plain tick value, printing values within 1e-9 of the axis span from 0 as 0.
/// Large or tiny magnitudes use scientific notation.
fn tick_label(v: f64, span: f64) -> String {
    match v.abs() {
        a if a < span * 1e-9 => RangedCoordf64::format(&0.0),
        a if !(1e-4..1e7).contains(&a) => format!("{v:e}"),
        _ => RangedCoordf64::format(&v),
    }
}

/// A legend symbol.
enum Mark {
    Line(ShapeStyle),
    Dot(ShapeStyle, u32),
    Tri(ShapeStyle, u32),
    Dash(ShapeStyle),
    /// An × of this half-size.
    Cross(ShapeStyle, u32),
}

/// Draws legend entries in a row starting at x = `row` (centred vertically), or in a column.
fn draw_legend<S: AsRef<str>>(
    area: &Area<'_>,
    entries: &[(Mark, S)],
    s: f64,
    row: Option<i32>,
) -> Result<(), Box<dyn Error>> {
    let px = |v: f64| (v * s).round() as i32;
    let text = TextStyle::from((FONT, 17.0 * s).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    let (mut x, mut y) = match row {
        Some(x) => (x, area.dim_in_pixel().1 as i32 / 2),
        None => (px(5.0), px(40.0)),
    };
    for (mark, label) in entries {
        let (w, c) = (px(25.0), x + px(12.0));
        match mark {
            Mark::Line(st) => area.draw(&PathElement::new([(x, y), (x + w, y)], *st))?,
            Mark::Dot(st, r) => area.draw(&Circle::new((c, y), *r, *st))?,
            Mark::Tri(st, r) => area.draw(&TriangleMarker::new((c, y), *r, *st))?,
            Mark::Dash(st) => area.draw(&DashedPathElement::new([(x, y), (x + w, y)], px(6.0), px(4.0), *st))?,
            Mark::Cross(st, r) => area.draw(&Cross::new((c, y), *r, *st))?,
        }
        area.draw(&Text::new(label.as_ref(), (x + px(35.0), y), text.clone()))?;
        match row {
            Some(_) => x += px(65.0) + area.estimate_text_size(label.as_ref(), &text)?.0 as i32,
            None => y += px(30.0),
        }
    }
    Ok(())
}

/// How a persistence pair is drawn: kept pairs as large filled dots (minima blue, maxima red)
/// outlined in black, cancelled ones as small thin light-grey crosses whatever their kind, so
/// that a dense band of cancelled pairs cannot pass for kept ones.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PairLook {
    colour: RGBColor,
    /// Radius of a dot, half-size of a cross, in pixels.
    size: u32,
    /// A filled dot (kept) rather than a cross (cancelled).
    dot: bool,
    /// Line width of a cross.
    stroke: u32,
}

/// The look of a kept or cancelled pair of a maximum (`is_max`) or minimum, at font scale `s`.
fn pair_look(kept: bool, is_max: bool, s: f64) -> PairLook {
    let px = |v: f64| ((v * s).round() as u32).max(1);
    match (kept, is_max) {
        (true, true) => PairLook { colour: MAX_C, size: px(6.0), dot: true, stroke: px(1.0) },
        (true, false) => PairLook { colour: MIN_C, size: px(6.0), dot: true, stroke: px(1.0) },
        (false, _) => PairLook { colour: CANCELLED_C, size: px(3.0), dot: false, stroke: 1 },
    }
}

/// `n` with commas between groups of three digits: 1128 → "1,128".
fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, ch) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(ch);
    }
    out
}

/// The legend's counts of the pairs drawn: kept minima and kept maxima (each when the diagram
/// has pairs of that kind), then cancelled pairs (when there are any).
fn diagram_counts(points: &[&DiagramPoint]) -> Vec<(PairLook, String)> {
    let count = |f: &dyn Fn(&DiagramPoint) -> bool| points.iter().filter(|p| f(p)).count();
    let mut out = Vec::new();
    for (is_max, name) in [(false, "minima"), (true, "maxima")] {
        if count(&|p| p.is_max == is_max) > 0 {
            let kept = count(&|p| p.is_max == is_max && p.kept);
            out.push((pair_look(true, is_max, 1.0), format!("kept: {} {name}", thousands(kept))));
        }
    }
    let cancelled = count(&|p| !p.kept);
    if cancelled > 0 {
        out.push((pair_look(false, false, 1.0), format!("cancelled: {}", thousands(cancelled))));
    }
    out
}

/// Plots a persistence diagram: kept pairs as large filled dots (minima blue, maxima red) drawn
/// over the cancelled ones, which are small thin light-grey crosses (see [`PairLook`]); the
/// diagonal in grey and, for `Some(t)`, dashed lines at |death − birth| = t. Essential points
/// (infinite death) are drawn as triangles at the top edge (bottom edge for −∞), 5% of the range
/// beyond the finite values. The legend on the right gives the counts ("kept: 6 minima",
/// "kept: 6 maxima", "cancelled: 1,128"). Points with a non-finite birth or NaN death are
/// skipped; an empty diagram is still drawn.
pub fn plot_persistence_diagram(
    out: &mut dyn std::io::Write,
    points: &[DiagramPoint],
    threshold: Option<f64>,
    title: &str,
    size: (u32, u32),
) -> Result<(), PlotError> {
    let pts: Vec<_> = points.iter().filter(|p| ok(p.birth) && (ok(p.death) || p.death.is_infinite())).collect();
    let (lo, hi) = min_max(pts.iter().flat_map(|p| [p.birth, p.death]));
    let (lo, hi) = nice_range(lo, hi, 0.0);
    let r = hi - lo;
    let (a, b) = (lo - 0.08 * r, hi + 0.08 * r);
    let level = |d: f64| {
        if ok(d) {
            d
        } else if d > 0.0 {
            hi + 0.05 * r
        } else {
            lo - 0.05 * r
        }
    };
    render(out, size, |root, s| {
        let px = |v: f64| (v * s).round() as u32;
        let root = root.margin(px(8.0), 0, 0, 0).titled(title, (FONT, 24.0 * s))?;
        let (plot, panel) = root.split_horizontally(size.0 - px(250.0).min(size.0 / 2));
        let fmt = |v: &f64| tick_label(*v, b - a);
        let ax = TickAxis((a..b).into(), None);
        let mut chart = make_chart(&plot, s, ax, (a, b), ("birth", "death"), &fmt)?;
        chart.draw_series(LineSeries::new([(a, a), (b, b)], GREY.stroke_width(px(1.5))))?;
        let mut legend = Vec::new();
        let dash = RGBColor(110, 110, 110).stroke_width(px(1.5));
        if let Some(t) = threshold.filter(|&t| ok(t) && t > 0.0) {
            for c in [t, -t] {
                let (x0, x1) = (a.max(a - c), b.min(b - c));
                if x0 < x1 {
                    chart.draw_series(DashedLineSeries::new([(x0, x0 + c), (x1, x1 + c)], px(8.0), px(6.0), dash))?;
                }
            }
            // four significant digits: the legend's width holds the label
            let digits = (4.0 - t.log10().ceil()).clamp(0.0, 12.0) as usize;
            legend.push((Mark::Dash(dash), format!("persistence = {t:.digits$}")));
        }
        if pts.iter().any(|p| !ok(p.death)) {
            let y = level(f64::INFINITY);
            chart.draw_series(DashedLineSeries::new([(a, y), (b, y)], px(2.0), px(5.0), GREY.stroke_width(1)))?;
            legend.push((Mark::Tri(BLACK.stroke_width(px(1.5)), px(7.0)), "essential (death = ∞)".into()));
        }
        // cancelled pairs first, so that every kept pair is drawn over them
        for (kept, is_max) in [(false, false), (false, true), (true, false), (true, true)] {
            let look = pair_look(kept, is_max, s);
            let sel = pts.iter().filter(|p| p.is_max == is_max && p.kept == kept);
            let (fin, ess): (Vec<&&DiagramPoint>, Vec<_>) = sel.partition(|p| ok(p.death));
            let at = |p: &DiagramPoint| (p.birth, level(p.death));
            if look.dot {
                let (fill, edge) = (look.colour.filled(), BLACK.filled());
                chart.draw_series(fin.iter().map(|p| Circle::new(at(p), look.size + px(1.0).max(1), edge)))?;
                chart.draw_series(fin.iter().map(|p| Circle::new(at(p), look.size, fill)))?;
                let tri = look.size + px(2.0);
                chart.draw_series(ess.iter().map(|p| TriangleMarker::new(at(p), tri + px(1.0).max(1), edge)))?;
                chart.draw_series(ess.iter().map(|p| TriangleMarker::new(at(p), tri, fill)))?;
            } else {
                let line = look.colour.stroke_width(look.stroke);
                chart.draw_series(fin.iter().chain(&ess).map(|p| Cross::new(at(p), look.size, line)))?;
            }
        }
        for (look, label) in diagram_counts(&pts) {
            let size = ((look.size as f64 * s).round() as u32).max(1);
            let mark = if look.dot {
                Mark::Dot(look.colour.filled(), size)
            } else {
                Mark::Cross(look.colour.stroke_width(look.stroke), size)
            };
            legend.push((mark, label));
        }
        draw_legend(&panel, &legend, s, None)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("toposmooth_plot_{}_{name}.png", std::process::id()))
    }

    /// Asserts that `path` holds a PNG (signature and IHDR of the given size), then removes it.
    fn check_png(path: &std::path::Path, (w, h): (u32, u32)) {
        let bytes = std::fs::read(path).expect("PNG written");
        std::fs::remove_file(path).ok();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(&bytes[12..16], b"IHDR");
        assert_eq!(bytes[16..24], [w.to_be_bytes(), h.to_be_bytes()].concat()[..]);
    }

    fn series(
        name: &str,
        x: &[f64],
        axis: &XAxis,
        y: &[f64],
        markers: &[Marker],
        size: (u32, u32),
    ) -> Result<(), PlotError> {
        let path = tmp(name);
        plot_series(&mut std::fs::File::create(&path).unwrap(), x, axis, "y", y, y, markers, name, size)?;
        check_png(&path, size);
        Ok(())
    }

    #[test]
    fn series_plots() {
        let x: Vec<f64> = (0..20_000).map(|i| i as f64 * 0.01).collect();
        let y: Vec<f64> = x.iter().map(|t| t.sin()).collect();
        let m = [
            Marker { index: 157, is_max: true },
            Marker { index: 471, is_max: false },
            Marker { index: 10_000_000, is_max: true },
        ];
        series("numeric", &x, &XAxis::Numeric("x".into()), &y, &m, (1200, 600)).unwrap();
        let d = XAxis::DaysSince(NaiveDate::from_ymd_opt(2000, 1, 1).unwrap());
        series("dates", &x, &d, &y, &m, (800, 400)).unwrap();
        series("constant", &[1.0, 2.0, 3.0], &d, &[5.0; 3], &[], (1200, 600)).unwrap();
        series("single", &[4.0], &XAxis::Numeric("x".into()), &[-0.0], &[], (100, 100)).unwrap();
        series("nan", &[0.0, f64::NAN, 2.0, 3.0], &d, &[1.0, 2.0, f64::INFINITY, f64::NAN], &[], (300, 200)).unwrap();
        series("huge", &[-1e300, 1e300, 0.0, 1e308], &d, &[1e300, -1e300, 0.0, 1.0], &[], (300, 200)).unwrap();
        series("unsorted", &[3.0, 1.0, 2.0, -5.0], &d, &[1.0, 2.0, 3.0, 4.0], &[], (300, 200)).unwrap();
    }

    #[test]
    fn series_errors() {
        let a = XAxis::Numeric("x".into());
        let mut out = Vec::new();
        assert!(plot_series(&mut out, &[], &a, "y", &[], &[], &[], "t", (600, 300)).is_err());
        assert!(plot_series(&mut out, &[1.0, 2.0], &a, "y", &[1.0], &[1.0, 2.0], &[], "t", (600, 300)).is_err());
        assert!(plot_series(&mut out, &[f64::NAN], &a, "y", &[1.0], &[1.0], &[], "t", (600, 300)).is_err());
        assert!(plot_series(&mut out, &[1.0], &a, "y", &[1.0], &[1.0], &[], "t", (0, 300)).is_err());
        assert!(out.is_empty(), "nothing is written before the checks pass");
    }

    #[test]
    fn diagrams() {
        let pt = |birth, death, is_max, kept| DiagramPoint { birth, death, is_max, kept };
        let pts = [
            pt(0.0, 1.0, false, true),
            pt(2.0, 0.5, true, false),
            pt(-1.0, f64::INFINITY, false, true),
            pt(f64::NAN, 1.0, true, true),
        ];
        for (name, pts, t) in [
            ("diag", &pts[..], Some(0.6)),
            ("diag_empty", &[], None),
            ("diag_essential_only", &pts[2..3], Some(f64::NAN)),
            (
                "diag_huge",
                &[pt(-1e300, 1e300, false, true), pt(1e300, f64::NEG_INFINITY, true, true), pt(1e308, 1.0, true, true)],
                Some(1e300),
            ),
        ] {
            let path = tmp(name);
            plot_persistence_diagram(&mut std::fs::File::create(&path).unwrap(), pts, t, name, (700, 600)).unwrap();
            check_png(&path, (700, 600));
        }
    }

    /// A band of `n` cancelled minima pairs just above the diagonal, 3 kept minima well above it
    /// and 2 kept maxima below it.
    fn banded(n: usize) -> Vec<DiagramPoint> {
        let pt = |birth, death, is_max, kept| DiagramPoint { birth, death, is_max, kept };
        let mut pts: Vec<DiagramPoint> = (0..n)
            .map(|i| {
                let t = i as f64 / n as f64;
                pt(t, t + 0.01 + 0.01 * (i as f64 * 7.3).sin().abs(), false, false)
            })
            .collect();
        pts.extend([pt(0.1, 0.9, false, true), pt(0.2, 0.7, false, true), pt(0.0, 0.5, false, true)]);
        pts.extend([pt(0.9, 0.1, true, true), pt(0.8, 0.3, true, true)]);
        pts
    }

    #[test]
    fn cancelled_pairs_are_small_grey_crosses_and_kept_ones_large_dots() {
        let (kept, cancelled) = (pair_look(true, false, 1.0), pair_look(false, false, 1.0));
        assert_eq!(pair_look(false, true, 1.0), cancelled, "cancelled pairs look alike whatever their kind");
        assert!(kept.dot && kept.colour == MIN_C && pair_look(true, true, 1.0).colour == MAX_C);
        assert!(!cancelled.dot && cancelled.stroke == 1 && 2 * cancelled.size <= kept.size);
        let RGBColor(r, g, b) = cancelled.colour;
        assert!(r == g && g == b && r > 150, "light grey: {:?}", cancelled.colour);

        // drawn: the band of 1,000 cancelled pairs adds light grey, not blue
        let mut png = Vec::new();
        plot_persistence_diagram(&mut png, &banded(1000), Some(0.3), "band", (900, 800)).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        let blue = img.pixels().filter(|p| p[2] > 150 && p[0] < 90 && p[1] < 120).count();
        let red = img.pixels().filter(|p| p[0] > 150 && p[1] < 90 && p[2] < 90).count();
        let light = img.pixels().filter(|p| p[0] == p[1] && p[1] == p[2] && (160..=190).contains(&p[0])).count();
        // 3 kept dots and the legend's of radius 6: about 4 · 113 px
        assert!(blue > 300 && blue < 700, "blue pixels: {blue}");
        assert!(red > 200 && red < 500, "red pixels: {red}");
        assert!(light > 1000, "light grey pixels: {light}");
    }

    #[test]
    fn the_legend_counts_kept_and_cancelled_pairs() {
        let pts = banded(1128);
        let refs: Vec<&DiagramPoint> = pts.iter().collect();
        let labels: Vec<String> = diagram_counts(&refs).into_iter().map(|(_, l)| l).collect();
        assert_eq!(labels, ["kept: 3 minima", "kept: 2 maxima", "cancelled: 1,128"]);
        let only_kept_minima: Vec<String> = diagram_counts(&refs[1128..1131]).into_iter().map(|(_, l)| l).collect();
        assert_eq!(only_kept_minima, ["kept: 3 minima"], "no maxima, none cancelled");
        assert!(diagram_counts(&[]).is_empty());
        assert_eq!(
            [thousands(0), thousands(999), thousands(1000), thousands(1234567)],
            ["0", "999", "1,000", "1,234,567"]
        );
    }

    #[test]
    fn dates() {
        let o = NaiveDate::from_ymd_opt(2000, 1, 1).unwrap();
        assert_eq!(date_label(o, 0.0, true), "2000-01-01");
        assert_eq!(date_label(o, 31.2, true), "2000-02-01");
        assert_eq!(date_label(o, -1.0, false), "1999-12");
        assert_eq!(date_label(o, 1e300, false), "1e300");
        assert_eq!(
            (tick_label(1e-20, 1.0), tick_label(2e7, 1e8), tick_label(0.5, 1.0)),
            ("0.0".into(), "2e7".into(), "0.5".into())
        );
        let (t, with_day) = date_ticks(o, 0.0, 10.0, 6).unwrap();
        assert!(with_day && t == [0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        let (t, with_day) = date_ticks(o, 0.0, 3653.0, 6).unwrap(); // 2000-01-01 .. 2010-01-01
        assert!(!with_day && t.len() == 6 && t[0] == 0.0);
        assert_eq!(date_label(o, t[1], false), "2002-01");
        assert!(date_ticks(o, 0.0, 1e12, 6).is_none());
    }

    #[test]
    fn decimation_keeps_spikes() {
        let x: Vec<f64> = (0..100_000).map(|i| i as f64).collect();
        let mut y = vec![0.0; x.len()];
        y[54_321] = 9.0;
        let d = decimate(&x, &y, (0.0, 99_999.0), 100);
        assert!(d.len() <= 200 && d.iter().any(|p| p.1 == 9.0));
    }
}

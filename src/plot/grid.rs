//! Heat maps of fields on regular 2-D grids: one or more panels (e.g. input, smoothed and
//! representative) side by side, or stacked for wide grids, sharing one colour scale that a colour
//! bar on the right shows, with optional isolines and the kept minima (blue) and maxima (red) as dots.
//!
//! Cells are drawn as nearest-neighbour blocks: small grids are scaled up by an integer factor where
//! the width budget allows it, large grids are sampled down so that the image stays under about
//! 2000 × 2000 pixels.
//!
//! Each panel has axes in the file's coordinates (vertex (r, c) at origin + (c·dx, r·dy), spacing
//! signs kept) and is oriented as ParaView shows the grid: larger x to the right and larger y at
//! the top, whatever the signs of the spacing, so a grid with dy < 0 and the same grid stored
//! with its rows reversed and dy > 0 give the same picture (a raster, read with its top row at the
//! largest y, looks as the image does).

use super::{min_max, nice_range, render, tick_label, Area, PlotError, FONT, MAX_C, MIN_C};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::error::Error;

/// One panel of a grid plot.
#[derive(Clone, Debug, PartialEq)]
pub struct GridPanel<'a> {
    /// Title drawn above the panel.
    pub title: String,
    /// `nx * ny` values in row-major order (index `r * nx + c`), placed as
    /// [`GridPlotOptions`] says; NaN is drawn as a neutral grey "missing" colour.
    pub values: &'a [f64],
}

/// A kept extremum drawn as a dot on every panel: blue for a minimum, red for a maximum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GridMarker {
    /// Grid index `r * nx + c` of the extremum; out-of-range indices are ignored.
    pub index: usize,
    /// True for a maximum, false for a minimum.
    pub is_max: bool,
}

/// Options of [`plot_grid_fields`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridPlotOptions {
    /// Number of evenly spaced contour levels drawn as thin dark lines (0: none). The levels split
    /// the colour range into `isolines + 1` equal parts.
    pub isolines: usize,
    /// True: a diverging blue–white–red colour map symmetric about 0 (e.g. for vorticity);
    /// false: the sequential, perceptually uniform viridis map over the values' range.
    pub diverging: bool,
    /// Coordinates (x, y) of vertex (row 0, column 0).
    pub origin: [f64; 2],
    /// Spacing (dx, dy), signs kept: vertex (r, c) lies at `origin + (c·dx, r·dy)`. The cells
    /// are drawn |dy| / |dx| as tall as wide, so that the picture is not distorted.
    pub spacing: [f64; 2],
    /// The colour scale's range instead of the panels' own (figures of several plots that
    /// share one scale, such as a volume's slices); a diverging map takes its largest |value|.
    pub range: Option<[f64; 2]>,
    /// The names of the horizontal and vertical axes (a volume's slices: `x`/`z`, `y`/`z`).
    pub axes: [&'static str; 2],
}

impl Default for GridPlotOptions {
    fn default() -> Self {
        GridPlotOptions {
            isolines: 0,
            diverging: false,
            origin: [0.0, 0.0],
            spacing: [1.0, 1.0],
            range: None,
            axes: ["x", "y"],
        }
    }
}

/// How grid vertices map to the picture: which grid column and row each drawn column and row
/// shows, and the coordinates along the two axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct View {
    nx: usize,
    ny: usize,
    /// Drawn column 0 (left) is grid column `nx − 1` rather than 0.
    flip_cols: bool,
    /// Drawn row 0 (top) is grid row `ny − 1` rather than 0.
    flip_rows: bool,
    /// x of the left drawn column and y of the top drawn row.
    first: [f64; 2],
    /// Change of x per drawn column (rightward) and of y per drawn row (downward).
    step: [f64; 2],
}

impl View {
    /// The view of an `nx × ny` grid with the options' origin, spacing and y direction.
    pub(super) fn new(nx: usize, ny: usize, o: &GridPlotOptions) -> View {
        let ([ox, oy], [dx, dy]) = (o.origin, o.spacing);
        let flip_cols = dx < 0.0;
        // the top row holds the largest y
        let flip_rows = dy > 0.0;
        let end = |o: f64, d: f64, n: usize, flip: bool| if flip { o + (n - 1) as f64 * d } else { o };
        let first = [end(ox, dx, nx, flip_cols), end(oy, dy, ny, flip_rows)];
        let step = [dx.abs(), -dy.abs()];
        View { nx, ny, flip_cols, flip_rows, first, step }
    }

    /// Grid column shown in drawn column `d` (0 at the left).
    fn col(&self, d: usize) -> usize {
        if self.flip_cols {
            self.nx - 1 - d
        } else {
            d
        }
    }

    /// Grid row shown in drawn row `d` (0 at the top).
    fn row(&self, d: usize) -> usize {
        if self.flip_rows {
            self.ny - 1 - d
        } else {
            d
        }
    }

    /// Pixel position (within a panel of `size` pixels) of the centre of grid vertex `index`'s cell.
    pub(super) fn centre(&self, (pw, ph): (u32, u32), index: usize) -> (f64, f64) {
        // `col` and `row` are their own inverses
        let (c, r) = (self.col(index % self.nx), self.row(index / self.nx));
        ((c as f64 + 0.5) * pw as f64 / self.nx as f64, (r as f64 + 0.5) * ph as f64 / self.ny as f64)
    }

    /// The ranges `(lo, hi)` of x and of y over the vertices, in the file's coordinates.
    pub(super) fn ranges(&self) -> [(f64, f64); 2] {
        let range = |k: usize, n: usize| {
            let last = self.first[k] + (n - 1) as f64 * self.step[k];
            (self.first[k].min(last), self.first[k].max(last))
        };
        [range(0, self.nx), range(1, self.ny)]
    }

    /// Pixel offset, along axis `k` (0: x rightward, 1: y downward) of a panel `size` pixels
    /// long, of the coordinate `v`: vertex centres land on their cells' centres.
    pub(super) fn pixel(&self, k: usize, v: f64, size: u32) -> f64 {
        let n = [self.nx, self.ny][k] as f64;
        let d = if n > 1.0 { (v - self.first[k]) / self.step[k] } else { 0.0 };
        (d + 0.5) * size as f64 / n
    }
}

/// Colour of NaN ("missing") cells.
const MISSING: RGBColor = RGBColor(150, 150, 150);
const ISOLINE: RGBColor = RGBColor(30, 30, 30);

// Layout, in pixels.
const MARGIN: u32 = 12;
const TITLE_H: u32 = 44;
const PANEL_TITLE_H: u32 = 30;
/// Room left of each panel for the y axis's tick labels and name.
const AXIS_W: u32 = 84;
/// Room below each panel for the x axis's tick labels and name.
const AXIS_H: u32 = 46;
const GAP: u32 = 16;
const BAR_GAP: u32 = 20;
const BAR_W: u32 = 22;
const BAR_LABELS: u32 = 100;
/// Room below the colour bar for the "missing" swatch.
const SWATCH_H: u32 = 30;
const MAX_W: u32 = 2000;
const MAX_H: u32 = 2000;
/// Preferred least panel width and height.
const WANT_W: f64 = 400.0;
const WANT_H: f64 = 150.0;
/// Least panel side (distorting extremely thin grids rather than drawing a sliver).
const MIN_SIDE: u32 = 60;
const MAX_PANELS: usize = 64;

/// Where the panels and the colour bar go.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Layout {
    /// Image size.
    size: (u32, u32),
    /// Size of one panel's heat map.
    panel: (u32, u32),
    /// Panels one above the other (wide grids) instead of side by side.
    stacked: bool,
    n: usize,
}

impl Layout {
    /// Layout of `n` panels of an `nx × ny` grid with cells of height/width `aspect`: side by side
    /// or stacked, whichever gives an overall shape closer to 0.6 tall per wide. Each panel has
    /// room for its axes on its left and below it.
    fn new(nx: usize, ny: usize, n: usize, aspect: f64) -> Layout {
        let a = (ny as f64 * aspect / nx as f64).clamp(1e-6, 1e6); // panel height / width
        let shape = |r: f64| (r / 0.6).ln().abs();
        let stacked = n > 1 && shape(a * n as f64) < shape(a / n as f64);
        let (cols, rows) = if stacked { (1, n as u32) } else { (n as u32, 1) };
        let w_budget =
            (MAX_W - 2 * MARGIN - BAR_GAP - BAR_W - BAR_LABELS).saturating_sub((cols - 1) * GAP + cols * AXIS_W) / cols;
        let h_budget =
            (MAX_H - TITLE_H - MARGIN).saturating_sub(rows * (PANEL_TITLE_H + AXIS_H) + (rows - 1) * GAP) / rows;
        let (wb, hb) = (w_budget.max(MIN_SIDE) as f64, h_budget.max(MIN_SIDE) as f64);
        let (nxf, want) = (nx as f64, WANT_W.max(WANT_H / a));
        let mut pw = if nxf >= wb {
            wb
        } else if nxf >= want {
            nxf
        } else {
            // scale up by whole blocks, within the budget
            (want / nxf).ceil().min((wb / nxf).floor()) * nxf
        };
        let mut ph = a * pw;
        if ph > hb {
            (pw, ph) = (hb / a, hb);
        }
        let side = |v: f64, max: f64| v.round().clamp(MIN_SIDE as f64, max.max(MIN_SIDE as f64)) as u32;
        let panel = (side(pw, wb), side(ph, hb));
        let w = 2 * MARGIN + cols * (AXIS_W + panel.0) + (cols - 1) * GAP + BAR_GAP + BAR_W + BAR_LABELS;
        let h = TITLE_H + rows * (PANEL_TITLE_H + panel.1 + AXIS_H) + (rows - 1) * GAP + MARGIN;
        Layout { size: (w, h), panel, stacked, n }
    }

    /// Top-left pixel of panel `k`'s heat map.
    fn origin(&self, k: usize) -> (i32, i32) {
        let (pw, ph, k) = (self.panel.0 as i32, self.panel.1 as i32, k as i32);
        let (left, top) = ((MARGIN + AXIS_W) as i32, (TITLE_H + PANEL_TITLE_H) as i32);
        if self.stacked {
            (left, top + k * (ph + (AXIS_H + PANEL_TITLE_H + GAP) as i32))
        } else {
            (left + k * (pw + (GAP + AXIS_W) as i32), top)
        }
    }

    /// The colour bar's top-left pixel and size, level with the panels; shorter if room for the
    /// "missing" swatch is needed.
    fn bar(&self, missing: bool) -> ((i32, i32), (u32, u32)) {
        let cols = if self.stacked { 1 } else { self.n as u32 };
        let x = MARGIN + cols * (AXIS_W + self.panel.0) + (cols - 1) * GAP + BAR_GAP;
        let y = TITLE_H + PANEL_TITLE_H;
        let h = self.size.1 - MARGIN - AXIS_H - y - if missing { SWATCH_H } else { 0 };
        ((x as i32, y as i32), (BAR_W, h.max(2)))
    }
}

/// Viridis at 0, 1/8, …, 1.
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// ColorBrewer RdBu, reversed: blue (negative) through near-white to red (positive).
const DIVERGING: [[u8; 3]; 9] = [
    [33, 102, 172],
    [67, 147, 195],
    [146, 197, 222],
    [209, 229, 240],
    [247, 247, 247],
    [253, 219, 199],
    [244, 165, 130],
    [214, 96, 77],
    [178, 24, 43],
];

/// The shared colour scale: values `lo..=hi` map linearly onto a colour ramp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Scale {
    pub(super) lo: f64,
    pub(super) hi: f64,
    ramp: &'static [[u8; 3]; 9],
}

impl Scale {
    /// The scale over all panels' finite values: symmetric about 0 if `diverging`, widened around
    /// a constant, 0..1 if there is no finite value.
    pub(super) fn new(panels: &[GridPanel], diverging: bool, range: Option<[f64; 2]>) -> Scale {
        let (lo, hi) = match range {
            Some([lo, hi]) => (lo, hi),
            None => min_max(panels.iter().flat_map(|p| p.values.iter().copied())),
        };
        if diverging {
            let m = lo.abs().max(hi.abs());
            let m = if m > 0.0 && m.is_finite() { m } else { 1.0 };
            Scale { lo: -m, hi: m, ramp: &DIVERGING }
        } else {
            let (lo, hi) = nice_range(lo, hi, 0.0);
            Scale { lo, hi, ramp: &VIRIDIS }
        }
    }

    /// Colour at fraction `t` (clamped to 0..=1) of the ramp.
    fn at(&self, t: f64) -> RGBColor {
        let t = if t.is_nan() { 0.5 } else { t.clamp(0.0, 1.0) } * (self.ramp.len() - 1) as f64;
        let i = (t.floor() as usize).min(self.ramp.len() - 2);
        let (f, a, b) = (t - i as f64, self.ramp[i], self.ramp[i + 1]);
        let mix = |k: usize| (a[k] as f64 + (b[k] as f64 - a[k] as f64) * f).round() as u8;
        RGBColor(mix(0), mix(1), mix(2))
    }

    /// Colour of value `v`: NaN is [`MISSING`], values beyond the range (±∞ included) are clamped.
    pub(super) fn colour(&self, v: f64) -> RGBColor {
        if v.is_nan() {
            MISSING
        } else {
            self.at((v - self.lo) / (self.hi - self.lo))
        }
    }
}

/// The heat map of `values` as an RGB buffer of `pw × ph` pixels, cells as nearest-neighbour
/// blocks, oriented by `view`.
fn heat_map(values: &[f64], view: &View, (pw, ph): (u32, u32), scale: &Scale) -> Vec<u8> {
    let pick = |n: usize, size: u32| -> Vec<usize> {
        (0..size).map(|p| (((p as f64 + 0.5) * n as f64 / size as f64) as usize).min(n - 1)).collect()
    };
    let nx = view.nx;
    let cols: Vec<usize> = pick(nx, pw).into_iter().map(|d| view.col(d)).collect();
    let rows: Vec<usize> = pick(view.ny, ph).into_iter().map(|d| view.row(d)).collect();
    let mut buf = Vec::with_capacity(pw as usize * ph as usize * 3);
    for &r in &rows {
        for &c in &cols {
            let RGBColor(a, b, d) = scale.colour(values[r * nx + c]);
            buf.extend_from_slice(&[a, b, d]);
        }
    }
    buf
}

/// Contour segments, in panel pixels, of `values` at the sorted `levels`, by marching triangles
/// over the cell centres (each square split along its diagonal). Triangles with a NaN or infinite
/// corner are skipped. Grids larger than the panel are sampled with a stride of about one pixel.
/// The segments are placed by `view`, so they lie over the heat map drawn with it.
fn contour_segments(values: &[f64], view: &View, size: (u32, u32), levels: &[f64]) -> Vec<((f64, f64), (f64, f64))> {
    let (nx, ny) = (view.nx, view.ny);
    let mut segs = Vec::new();
    if levels.is_empty() || nx < 2 || ny < 2 {
        return segs;
    }
    let stride = (nx as f64 / size.0 as f64).max(ny as f64 / size.1 as f64).ceil().max(1.0) as usize;
    let (cs, rs): (Vec<usize>, Vec<usize>) = ((0..nx).step_by(stride).collect(), (0..ny).step_by(stride).collect());
    let point = |r: usize, c: usize| {
        let (x, y) = view.centre(size, r * nx + c);
        (x, y, values[r * nx + c])
    };
    for rw in rs.windows(2) {
        for cw in cs.windows(2) {
            let (p00, p01) = (point(rw[0], cw[0]), point(rw[0], cw[1]));
            let (p10, p11) = (point(rw[1], cw[0]), point(rw[1], cw[1]));
            for tri in [[p00, p01, p11], [p00, p11, p10]] {
                if tri.iter().any(|p| !p.2.is_finite()) {
                    continue;
                }
                let lo = tri.iter().map(|p| p.2).fold(f64::INFINITY, f64::min);
                let hi = tri.iter().map(|p| p.2).fold(f64::NEG_INFINITY, f64::max);
                let first = levels.partition_point(|&l| l <= lo);
                for &level in levels[first..].iter().take_while(|&&l| l <= hi) {
                    let mut cut = [(0.0, 0.0); 2];
                    let mut k = 0;
                    for (a, b) in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
                        if (a.2 >= level) != (b.2 >= level) && k < 2 {
                            let t = (level - a.2) / (b.2 - a.2);
                            cut[k] = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
                            k += 1;
                        }
                    }
                    if k == 2 {
                        segs.push((cut[0], cut[1]));
                    }
                }
            }
        }
    }
    segs
}

/// Plots `panels` of an `nx × ny` grid as heat maps into a PNG written to `out`: side by side (stacked
/// for wide grids), each with its title and its x and y axes in the grid's coordinates, under the
/// overall `title`, with one colour scale shared by all panels' finite values and shown by a colour
/// bar with tick labels on the right (plus a "missing" swatch if some value is NaN). NaN cells are
/// grey; `markers` are drawn on every panel as dots (minima blue, maxima red, outlined in black
/// and white); see [`GridPlotOptions`] for isolines, the colour map, the geometry and the
/// orientation (by default larger y at the top, as ParaView draws it).
///
/// Each panel is about 400 px wide or more (small grids scaled up by whole blocks), and the image
/// stays within about 2000 × 2000 px (large grids sampled down). Constant fields, all-NaN panels
/// and single finite values are drawn without error. Errors on an empty grid, no or too many (over
/// 64) panels, a panel with other than `nx * ny` values, a zero or non-finite spacing, a
/// non-finite origin or extent, or a drawing/writing failure.
pub fn plot_grid_fields(
    out: &mut dyn std::io::Write,
    nx: usize,
    ny: usize,
    panels: &[GridPanel],
    markers: &[GridMarker],
    title: &str,
    options: &GridPlotOptions,
) -> Result<(), PlotError> {
    let fail = |m: &str| PlotError(format!("plot: {m}"));
    let len = nx.checked_mul(ny).filter(|&l| l > 0).ok_or_else(|| fail(&format!("bad grid size {nx}x{ny}")))?;
    if panels.is_empty() || panels.len() > MAX_PANELS {
        return Err(fail(&format!("{} panels, expected 1..={MAX_PANELS}", panels.len())));
    }
    if let Some(p) = panels.iter().find(|p| p.values.len() != len) {
        return Err(fail(&format!("panel '{}' has {} values, expected {nx}x{ny}", p.title, p.values.len())));
    }
    let view = View::new(nx, ny, options);
    let aspect = (options.spacing[1] / options.spacing[0]).abs();
    let finite = |v: &f64| v.is_finite();
    let extent_ok =
        options.origin.iter().all(finite) && view.ranges().iter().all(|(lo, hi)| [lo, hi].iter().all(|v| finite(v)));
    if !(aspect.is_finite() && aspect > 0.0 && extent_ok) {
        let (o, d) = (options.origin, options.spacing);
        return Err(fail(&format!("grid origin {o:?} and spacing {d:?} do not give finite, non-degenerate cells")));
    }
    let layout = Layout::new(nx, ny, panels.len(), aspect);
    let scale = Scale::new(panels, options.diverging, options.range);
    let n_lev = options.isolines;
    let levels: Vec<f64> =
        (1..=n_lev).map(|k| scale.lo + (scale.hi - scale.lo) * k as f64 / (n_lev + 1) as f64).collect();
    let missing = panels.iter().any(|p| p.values.iter().any(|v| v.is_nan()));
    let dots: Vec<GridMarker> = markers.iter().copied().filter(|m| m.index < len).collect();
    render(out, layout.size, |root, _| {
        let centred = |size: f64| TextStyle::from((FONT, size).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
        root.draw(&Text::new(title, (layout.size.0 as i32 / 2, TITLE_H as i32 / 2 + 2), centred(24.0)))?;
        let (pw, ph) = layout.panel;
        for (k, panel) in panels.iter().enumerate() {
            let (x0, y0) = layout.origin(k);
            let head = (x0 + pw as i32 / 2, y0 - PANEL_TITLE_H as i32 / 2);
            root.draw(&Text::new(panel.title.as_str(), head, centred(18.0)))?;
            let buf = heat_map(panel.values, &view, layout.panel, &scale);
            root.draw(&BitMapElement::with_owned_buffer((x0, y0), layout.panel, buf).ok_or("heat map buffer")?)?;
            root.draw(&Rectangle::new([(x0 - 1, y0 - 1), (x0 + pw as i32, y0 + ph as i32)], BLACK))?;
            draw_axes(root, &view, (x0, y0), layout.panel, options.axes)?;
            let at = |(x, y): (f64, f64)| (x0 + x.round() as i32, y0 + y.round() as i32);
            let line = ISOLINE.stroke_width(1);
            for (a, b) in contour_segments(panel.values, &view, layout.panel, &levels) {
                // left end first: the bitmap backend's fast path draws nothing for a horizontal
                // 1-px line given right to left
                let (a, b) = (at(a), at(b));
                root.draw(&PathElement::new(vec![a.min(b), a.max(b)], line))?;
            }
            let r = if dots.len() > 200 { 3 } else { 5 };
            for m in &dots {
                let c = at(view.centre(layout.panel, m.index));
                let colour = if m.is_max { MAX_C } else { MIN_C };
                root.draw(&Circle::new(c, r + 2, BLACK.filled()))?;
                root.draw(&Circle::new(c, r + 1, WHITE.filled()))?;
                root.draw(&Circle::new(c, r, colour.filled()))?;
            }
        }
        draw_colour_bar(root, &layout, &scale, missing)
    })
}

/// Tick values for an axis over `lo..=hi`: about `max` round values, or the single value of a
/// degenerate range.
fn axis_ticks(lo: f64, hi: f64, max: usize) -> Vec<f64> {
    if hi > lo {
        let axis: RangedCoordf64 = (lo..hi).into();
        axis.key_points(max.max(2))
    } else {
        vec![lo]
    }
}

/// The ticks of axis `k` (0: x along the panel's width, 1: y along its height) of a panel of
/// `size` pixels: each tick's pixel offset from the panel's left or top edge and its label, a
/// coordinate of the grid placed by `view`.
fn axis_marks(view: &View, k: usize, size: (u32, u32)) -> Vec<(i32, String)> {
    let (lo, hi) = view.ranges()[k];
    let (len, per_tick) = if k == 0 { (size.0, 90) } else { (size.1, 60) };
    axis_ticks(lo, hi, (len as usize / per_tick).clamp(2, 10))
        .into_iter()
        .map(|v| (view.pixel(k, v, len).round() as i32, tick_label(v, hi - lo)))
        .collect()
}

/// Draws the x axis below and the y axis left of the panel whose heat map's top-left pixel is
/// `(x0, y0)` and size `(pw, ph)`: ticks and labels from [`axis_marks`], and the axis names.
fn draw_axes(
    root: &Area<'_>,
    view: &View,
    (x0, y0): (i32, i32),
    (pw, ph): (u32, u32),
    [across, up]: [&str; 2],
) -> Result<(), Box<dyn Error>> {
    let style = |h: HPos, v: VPos| TextStyle::from((FONT, 14.0).into_font()).pos(Pos::new(h, v));
    let (bottom, left) = (y0 + ph as i32, x0 - 1);
    for (x, label) in axis_marks(view, 0, (pw, ph)) {
        root.draw(&PathElement::new(vec![(x0 + x, bottom), (x0 + x, bottom + 5)], BLACK))?;
        root.draw(&Text::new(label, (x0 + x, bottom + 7), style(HPos::Center, VPos::Top)))?;
    }
    let name = (x0 + pw as i32 / 2, bottom + AXIS_H as i32 - 4);
    root.draw(&Text::new(across, name, style(HPos::Center, VPos::Bottom)))?;
    for (y, label) in axis_marks(view, 1, (pw, ph)) {
        root.draw(&PathElement::new(vec![(left - 5, y0 + y), (left, y0 + y)], BLACK))?;
        root.draw(&Text::new(label, (left - 7, y0 + y), style(HPos::Right, VPos::Center)))?;
    }
    let name = (x0 - AXIS_W as i32 + 2, y0 + ph as i32 / 2);
    root.draw(&Text::new(up, name, style(HPos::Left, VPos::Center)))?;
    Ok(())
}

/// Draws the colour bar (high values at the top) with ticks and labels, and the "missing" swatch.
fn draw_colour_bar(root: &Area<'_>, layout: &Layout, scale: &Scale, missing: bool) -> Result<(), Box<dyn Error>> {
    draw_colour_bar_at(root, layout.bar(missing), scale, missing)
}

/// Draws a colour bar at `((x, y), (w, h))` with ticks and labels to its right, and the
/// "missing" swatch below it when `missing`.
pub(super) fn draw_colour_bar_at(
    root: &Area<'_>,
    ((bx, by), (bw, bh)): ((i32, i32), (u32, u32)),
    scale: &Scale,
    missing: bool,
) -> Result<(), Box<dyn Error>> {
    let mut buf = Vec::with_capacity(bw as usize * bh as usize * 3);
    for y in 0..bh {
        let RGBColor(a, b, c) = scale.at(1.0 - (y as f64 + 0.5) / bh as f64);
        (0..bw).for_each(|_| buf.extend_from_slice(&[a, b, c]));
    }
    root.draw(&BitMapElement::with_owned_buffer((bx, by), (bw, bh), buf).ok_or("colour bar buffer")?)?;
    let (right, bottom) = (bx + bw as i32, by + bh as i32);
    root.draw(&Rectangle::new([(bx - 1, by - 1), (right, bottom)], BLACK))?;
    let text = TextStyle::from((FONT, 15.0).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    let (lo, hi) = (scale.lo, scale.hi);
    let axis: RangedCoordf64 = (lo..hi).into();
    for v in axis.key_points((bh as usize / 60).clamp(2, 10)) {
        let y = by + ((hi - v) / (hi - lo) * (bh - 1) as f64).round() as i32;
        root.draw(&PathElement::new(vec![(right, y), (right + 5, y)], BLACK))?;
        root.draw(&Text::new(tick_label(v, hi - lo), (right + 8, y), text.clone()))?;
    }
    if missing {
        let y = bottom + SWATCH_H as i32 / 2 - 7;
        root.draw(&Rectangle::new([(bx, y), (right, y + 14)], MISSING.filled()))?;
        root.draw(&Rectangle::new([(bx - 1, y - 1), (right, y + 14)], BLACK))?;
        root.draw(&Text::new("missing", (right + 8, y + 7), text))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests;

//! Heat maps of fields on regular 2-D grids: one or more panels (e.g. input, smoothed and
//! representative) side by side, or stacked for wide grids, sharing one colour scale that a colour
//! bar on the right shows, with optional isolines and the kept minima (blue) and maxima (red) as dots.
//!
//! Cells are drawn as nearest-neighbour blocks: small grids are scaled up by an integer factor where
//! the width budget allows it, large grids are sampled down so that the image stays under about
//! 2000 × 2000 pixels.

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
    /// `nx * ny` values in row-major order (index `r * nx + c`); row 0 is drawn at the top, NaN
    /// as a neutral grey "missing" colour.
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
    /// Physical cell height over width, |dy| / |dx|, so that the picture is not distorted.
    pub aspect: f64,
}

impl Default for GridPlotOptions {
    fn default() -> Self {
        GridPlotOptions { isolines: 0, diverging: false, aspect: 1.0 }
    }
}

/// Colour of NaN ("missing") cells.
const MISSING: RGBColor = RGBColor(150, 150, 150);
const ISOLINE: RGBColor = RGBColor(30, 30, 30);

// Layout, in pixels.
const MARGIN: u32 = 12;
const TITLE_H: u32 = 44;
const PANEL_TITLE_H: u32 = 30;
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
    /// or stacked, whichever gives an overall shape closer to 0.6 tall per wide.
    fn new(nx: usize, ny: usize, n: usize, aspect: f64) -> Layout {
        let a = (ny as f64 * aspect / nx as f64).clamp(1e-6, 1e6); // panel height / width
        let shape = |r: f64| (r / 0.6).ln().abs();
        let stacked = n > 1 && shape(a * n as f64) < shape(a / n as f64);
        let (cols, rows) = if stacked { (1, n as u32) } else { (n as u32, 1) };
        let w_budget = (MAX_W - 2 * MARGIN - BAR_GAP - BAR_W - BAR_LABELS).saturating_sub((cols - 1) * GAP) / cols;
        let h_budget = (MAX_H - TITLE_H - MARGIN).saturating_sub(rows * PANEL_TITLE_H + (rows - 1) * GAP) / rows;
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
        let w = 2 * MARGIN + cols * panel.0 + (cols - 1) * GAP + BAR_GAP + BAR_W + BAR_LABELS;
        let h = TITLE_H + rows * (PANEL_TITLE_H + panel.1) + (rows - 1) * GAP + MARGIN;
        Layout { size: (w, h), panel, stacked, n }
    }

    /// Top-left pixel of panel `k`'s heat map.
    fn origin(&self, k: usize) -> (i32, i32) {
        let (pw, ph, k) = (self.panel.0 as i32, self.panel.1 as i32, k as i32);
        let top = (TITLE_H + PANEL_TITLE_H) as i32;
        if self.stacked {
            (MARGIN as i32, top + k * (ph + (PANEL_TITLE_H + GAP) as i32))
        } else {
            (MARGIN as i32 + k * (pw + GAP as i32), top)
        }
    }

    /// The colour bar's top-left pixel and size; shorter if room for the "missing" swatch is needed.
    fn bar(&self, missing: bool) -> ((i32, i32), (u32, u32)) {
        let cols = if self.stacked { 1 } else { self.n as u32 };
        let x = MARGIN + cols * self.panel.0 + (cols - 1) * GAP + BAR_GAP;
        let y = TITLE_H + PANEL_TITLE_H;
        let h = self.size.1 - MARGIN - y - if missing { SWATCH_H } else { 0 };
        ((x as i32, y as i32), (BAR_W, h.max(2)))
    }
}

/// Pixel position (within a panel of `size` pixels) of the centre of grid cell `index`.
fn cell_centre(nx: usize, ny: usize, (pw, ph): (u32, u32), index: usize) -> (f64, f64) {
    let (r, c) = (index / nx, index % nx);
    ((c as f64 + 0.5) * pw as f64 / nx as f64, (r as f64 + 0.5) * ph as f64 / ny as f64)
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
    pub(super) fn new(panels: &[GridPanel], diverging: bool) -> Scale {
        let (lo, hi) = min_max(panels.iter().flat_map(|p| p.values.iter().copied()));
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

/// The heat map of `values` as an RGB buffer of `pw × ph` pixels, cells as nearest-neighbour blocks.
fn heat_map(values: &[f64], nx: usize, ny: usize, (pw, ph): (u32, u32), scale: &Scale) -> Vec<u8> {
    let pick = |n: usize, size: u32| -> Vec<usize> {
        (0..size).map(|p| (((p as f64 + 0.5) * n as f64 / size as f64) as usize).min(n - 1)).collect()
    };
    let (cols, rows) = (pick(nx, pw), pick(ny, ph));
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
fn contour_segments(
    values: &[f64],
    nx: usize,
    ny: usize,
    size: (u32, u32),
    levels: &[f64],
) -> Vec<((f64, f64), (f64, f64))> {
    let mut segs = Vec::new();
    if levels.is_empty() || nx < 2 || ny < 2 {
        return segs;
    }
    let stride = (nx as f64 / size.0 as f64).max(ny as f64 / size.1 as f64).ceil().max(1.0) as usize;
    let (cs, rs): (Vec<usize>, Vec<usize>) = ((0..nx).step_by(stride).collect(), (0..ny).step_by(stride).collect());
    let point = |r: usize, c: usize| {
        let (x, y) = cell_centre(nx, ny, size, r * nx + c);
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
/// for wide grids), each with its title, under the overall `title`, with one colour scale shared by
/// all panels' finite values and shown by a colour bar with tick labels on the right (plus a
/// "missing" swatch if some value is NaN). NaN cells are grey; `markers` are drawn on every panel
/// as dots (minima blue, maxima red, outlined in black and white); see [`GridPlotOptions`] for
/// isolines, the colour map and the cell aspect.
///
/// Each panel is about 400 px wide or more (small grids scaled up by whole blocks), and the image
/// stays within about 2000 × 2000 px (large grids sampled down). Constant fields, all-NaN panels
/// and single finite values are drawn without error. Errors on an empty grid, no or too many (over
/// 64) panels, a panel with other than `nx * ny` values, a non-positive or non-finite aspect, or a
/// drawing/writing failure.
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
    if !(options.aspect.is_finite() && options.aspect > 0.0) {
        return Err(fail(&format!("cell aspect {} is not positive", options.aspect)));
    }
    let layout = Layout::new(nx, ny, panels.len(), options.aspect);
    let scale = Scale::new(panels, options.diverging);
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
            let buf = heat_map(panel.values, nx, ny, layout.panel, &scale);
            root.draw(&BitMapElement::with_owned_buffer((x0, y0), layout.panel, buf).ok_or("heat map buffer")?)?;
            root.draw(&Rectangle::new([(x0 - 1, y0 - 1), (x0 + pw as i32, y0 + ph as i32)], BLACK))?;
            let at = |(x, y): (f64, f64)| (x0 + x.round() as i32, y0 + y.round() as i32);
            let line = ISOLINE.stroke_width(1);
            for (a, b) in contour_segments(panel.values, nx, ny, layout.panel, &levels) {
                // left end first: the bitmap backend's fast path draws nothing for a horizontal
                // 1-px line given right to left
                let (a, b) = (at(a), at(b));
                root.draw(&PathElement::new(vec![a.min(b), a.max(b)], line))?;
            }
            let r = if dots.len() > 200 { 3 } else { 5 };
            for m in &dots {
                let c = at(cell_centre(nx, ny, layout.panel, m.index));
                let colour = if m.is_max { MAX_C } else { MIN_C };
                root.draw(&Circle::new(c, r + 2, BLACK.filled()))?;
                root.draw(&Circle::new(c, r + 1, WHITE.filled()))?;
                root.draw(&Circle::new(c, r, colour.filled()))?;
            }
        }
        draw_colour_bar(root, &layout, &scale, missing)
    })
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

//! Volumes as three orthogonal slices through the centre voxel: z (x across, y up), y (x
//! across, z up) and x (y across, z up), one row each, every row the panels (input and
//! smoothed) side by side on one colour scale shared by all rows, axes in the file's
//! coordinates. Each kept extremum is marked in the one slice whose plane is nearest to it
//! (by distance in the file's units), at its projection.

use super::grid::{plot_grid_fields, GridMarker, GridPanel, GridPlotOptions};
use super::{min_max, PlotError};

/// A volume to draw: geometry, panels of `nx·ny·nz` values (x fastest) and kept extrema.
#[derive(Clone, Copy, Debug)]
pub struct VolumePlot<'a> {
    /// Voxels along x, y, z.
    pub dims: [usize; 3],
    /// Spacing (signs kept).
    pub spacing: [f64; 3],
    /// Coordinates of voxel (0, 0, 0).
    pub origin: [f64; 3],
    /// The panels of each row (e.g. input and smoothed).
    pub panels: &'a [GridPanel<'a>],
    /// Kept extrema by volume index.
    pub markers: &'a [GridMarker],
    /// The figure's title (drawn over the first row).
    pub title: &'a str,
    /// Isolines per slice.
    pub isolines: usize,
    /// A diverging colour map about 0.
    pub diverging: bool,
}

/// One slice: its size, the volume index of each of its vertices, and its axes.
struct Slice {
    nx: usize,
    ny: usize,
    index: Vec<usize>,
    origin: [f64; 2],
    spacing: [f64; 2],
    label: String,
    axes: [&'static str; 2],
}

/// The three slices through voxel `c`.
fn slices(p: &VolumePlot, c: [usize; 3]) -> [Slice; 3] {
    let [nx, ny, nz] = p.dims;
    let (s, o) = (p.spacing, p.origin);
    let at = |i: usize, j: usize, k: usize| i + nx * (j + ny * k);
    let coord = |a: usize| o[a] + c[a] as f64 * s[a];
    let label = |a: usize| {
        format!(
            "{} = {} ({} {})",
            ["x", "y", "z"][a],
            super::tick_label(coord(a), s[a].abs()),
            ["i", "j", "k"][a],
            c[a]
        )
    };
    let mut z = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            z.push(at(i, j, c[2]));
        }
    }
    let mut y = Vec::with_capacity(nx * nz);
    for k in 0..nz {
        for i in 0..nx {
            y.push(at(i, c[1], k));
        }
    }
    let mut x = Vec::with_capacity(ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            x.push(at(c[0], j, k));
        }
    }
    [
        Slice { nx, ny, index: z, origin: [o[0], o[1]], spacing: [s[0], s[1]], label: label(2), axes: ["x", "y"] },
        Slice { nx, ny: nz, index: y, origin: [o[0], o[2]], spacing: [s[0], s[2]], label: label(1), axes: ["x", "z"] },
        Slice {
            nx: ny,
            ny: nz,
            index: x,
            origin: [o[1], o[2]],
            spacing: [s[1], s[2]],
            label: label(0),
            axes: ["y", "z"],
        },
    ]
}

/// Draws the volume's three slices as one PNG.
///
/// # Errors
/// A panel of the wrong length, an empty volume, non-finite geometry, a drawing failure.
pub fn plot_volume_slices(out: &mut dyn std::io::Write, p: &VolumePlot) -> Result<(), PlotError> {
    let fail = |m: String| PlotError(format!("plot: {m}"));
    let [nx, ny, nz] = p.dims;
    let n = nx * ny * nz;
    if n == 0 {
        return Err(fail(format!("empty volume {nx}×{ny}×{nz}")));
    }
    if let Some(q) = p.panels.iter().find(|q| q.values.len() != n) {
        return Err(fail(format!("panel '{}' has {} values for {n} voxels", q.title, q.values.len())));
    }
    let centre = [nx / 2, ny / 2, nz / 2];
    let (lo, hi) = min_max(p.panels.iter().flat_map(|q| q.values.iter().copied()));
    let cuts = slices(p, centre);
    // each extremum in the slice nearest to it: 0 (z), 1 (y) or 2 (x)
    let mut marks: [Vec<GridMarker>; 3] = Default::default();
    for m in p.markers.iter().filter(|m| m.index < n) {
        let ijk = [m.index % nx, (m.index / nx) % ny, m.index / (nx * ny)];
        let far = |a: usize| ijk[a].abs_diff(centre[a]) as f64 * p.spacing[a].abs();
        let best = [2, 1, 0].into_iter().enumerate().min_by(|x, y| far(x.1).total_cmp(&far(y.1))).map_or(0, |b| b.0);
        let index = match best {
            0 => ijk[0] + nx * ijk[1],
            1 => ijk[0] + nx * ijk[2],
            _ => ijk[1] + ny * ijk[2],
        };
        marks[best].push(GridMarker { index, is_max: m.is_max });
    }
    let mut rows = Vec::with_capacity(3);
    for (r, cut) in cuts.iter().enumerate() {
        let values: Vec<Vec<f64>> = p.panels.iter().map(|q| cut.index.iter().map(|&v| q.values[v]).collect()).collect();
        let panels: Vec<GridPanel> = p
            .panels
            .iter()
            .zip(&values)
            .map(|(q, v)| GridPanel { title: format!("{}: {}", cut.label, q.title), values: v })
            .collect();
        let options = GridPlotOptions {
            isolines: p.isolines,
            diverging: p.diverging,
            origin: cut.origin,
            spacing: cut.spacing,
            range: Some([lo, hi]),
            axes: cut.axes,
        };
        let shown = marks[r].len();
        let title = if r == 0 {
            p.title.to_string()
        } else {
            format!("slice {} ({shown} kept extrema nearest to it marked)", cut.label)
        };
        let mut png = Vec::new();
        plot_grid_fields(&mut png, cut.nx, cut.ny, &panels, &marks[r], &title, &options)?;
        rows.push(image::load_from_memory(&png).map_err(|e| fail(e.to_string()))?.to_rgb8());
    }
    let w = rows.iter().map(|r| r.width()).max().unwrap_or(1);
    let h: u32 = rows.iter().map(|r| r.height()).sum();
    let mut canvas = image::RgbImage::from_pixel(w, h, image::Rgb([255, 255, 255]));
    let mut y = 0;
    for row in &rows {
        image::imageops::replace(&mut canvas, row, i64::from((w - row.width()) / 2), i64::from(y));
        y += row.height();
    }
    use image::ImageEncoder;
    image::codecs::png::PngEncoder::new(out)
        .write_image(canvas.as_raw(), w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| fail(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_slices_share_one_figure_and_each_extremum_is_marked_once() {
        let dims = [6, 5, 4];
        let n = 120;
        let h: Vec<f64> = (0..n).map(|v| (v as f64 * 0.37).sin()).collect();
        let panels = [GridPanel { title: "input".into(), values: &h }, GridPanel { title: "out".into(), values: &h }];
        // (1, 2, 2) lies in the z slice (k = 2), (3, 0, 0) in the x slice (i = 3)
        let markers = [GridMarker { index: 1 + 6 * (2 + 5 * 2), is_max: true }, GridMarker { index: 3, is_max: false }];
        let p = VolumePlot {
            dims,
            spacing: [1.0, 1.0, 1.0],
            origin: [0.0; 3],
            panels: &panels,
            markers: &markers,
            title: "t",
            isolines: 0,
            diverging: true,
        };
        let cuts = slices(&p, [3, 2, 2]);
        assert_eq!(cuts.each_ref().map(|c| (c.nx, c.ny, c.index.len())), [(6, 5, 30), (6, 4, 24), (5, 4, 20)]);
        assert_eq!(cuts[1].index[6 * 3 + 4], 4 + 6 * (2 + 5 * 3));
        let mut png = Vec::new();
        plot_volume_slices(&mut png, &p).unwrap();
        let img = image::load_from_memory(&png).unwrap();
        assert!(img.height() > img.width() / 2, "{}×{}", img.width(), img.height());
        let short = [GridPanel { title: "x".into(), values: &h[..10] }];
        assert!(plot_volume_slices(&mut Vec::new(), &VolumePlot { panels: &short, ..p }).is_err());
    }
}

//! Pictures of plane triangulations (the `mesh` command): triangles filled, edges drawn over
//! them, the boundary in black; x and y at the same scale.

use super::{render, PlotError, FONT};
use plotters::prelude::*;
use std::collections::HashMap;

const FILL: RGBColor = RGBColor(198, 219, 239);
const EDGE: RGBColor = RGBColor(49, 99, 160);
/// Longest side of the plotting area, in pixels.
const SIDE: f64 = 900.0;

/// Draws the triangles of a planar mesh (x, y of `positions`; z ignored) with `title` above.
///
/// # Errors
/// No triangle, a vertex index out of range, non-finite coordinates, or a drawing or writing
/// failure.
pub fn plot_triangulation(
    out: &mut dyn std::io::Write,
    positions: &[[f64; 3]],
    triangles: &[[usize; 3]],
    title: &str,
) -> Result<(), PlotError> {
    let fail = |m: &str| PlotError(format!("plot: {m}"));
    if triangles.is_empty() {
        return Err(fail("no triangle to draw"));
    }
    if triangles.iter().flatten().any(|&v| v >= positions.len()) {
        return Err(fail("a triangle refers to a vertex beyond the positions"));
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in positions {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if !(lo.iter().chain(&hi).all(|v| v.is_finite())) {
        return Err(fail("non-finite coordinates"));
    }
    // equal scales: the shorter side gets the room it needs, at least a fifth of the longer
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
    let pad = 0.03 * span;
    let size = [0, 1].map(|k| ((hi[k] - lo[k]).max(0.2 * span) + 2.0 * pad) / (span + 2.0 * pad) * SIDE);
    let mid = [0, 1].map(|k| (lo[k] + hi[k]) / 2.0);
    let half = [0, 1].map(|k| size[k] / SIDE * (span + 2.0 * pad) / 2.0);
    let (label_w, label_h, caption) = (80u32, 50u32, 50u32);
    let canvas = (size[0].round() as u32 + label_w + 40, size[1].round() as u32 + label_h + caption + 20);
    let mut edges: HashMap<(usize, usize), u8> = HashMap::with_capacity(3 * triangles.len() / 2 + 3);
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let xy = |v: usize| (positions[v][0], positions[v][1]);
    let thin = if triangles.len() > 20_000 { 0.5 } else { 1.0 };
    render(out, canvas, |root, s| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FONT, 22.0 * s))
            .margin(15)
            .x_label_area_size(label_h)
            .y_label_area_size(label_w)
            .build_cartesian_2d(mid[0] - half[0]..mid[0] + half[0], mid[1] - half[1]..mid[1] + half[1])?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x")
            .y_desc("y")
            .label_style((FONT, 15.0 * s))
            .axis_desc_style((FONT, 17.0 * s))
            .draw()?;
        chart.draw_series(triangles.iter().map(|t| Polygon::new(t.map(xy).to_vec(), FILL.filled())))?;
        let style = |boundary: bool| {
            if boundary {
                BLACK.stroke_width(2)
            } else {
                EDGE.mix(thin).stroke_width(1)
            }
        };
        for boundary in [false, true] {
            chart.draw_series(
                edges
                    .iter()
                    .filter(|(_, &c)| (c == 1) == boundary)
                    .map(|(&(a, b), _)| PathElement::new(vec![xy(a), xy(b)], style(boundary))),
            )?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_is_drawn_filled_with_a_black_boundary() {
        let dir = std::env::temp_dir().join(format!("toposmooth-triplot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("square.png");
        let p = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        plot_triangulation(&mut std::fs::File::create(&path).unwrap(), &p, &[[0, 1, 2], [0, 2, 3]], "a rectangle")
            .unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        // twice as wide as high, give or take the labels
        assert!(img.width() > img.height(), "{}x{}", img.width(), img.height());
        let filled = img.pixels().filter(|q| q.0 == [FILL.0, FILL.1, FILL.2]).count();
        assert!(filled > 100_000, "{filled}");
        assert!(plot_triangulation(&mut std::fs::File::create(&path).unwrap(), &p, &[[0, 1, 7]], "t").is_err());
    }
}

//! Pictures of fields on triangle meshes: a small software rasteriser (orthographic camera,
//! z-buffer, per-pixel interpolated colour, two-sided Lambert shading) draws each panel —
//! input and output side by side — with one shared colour scale, a colour bar, and the kept
//! minima (blue) and maxima (red) that face the camera as dots.
//!
//! The camera looks at the mesh's centre from `azimuth` degrees around the up axis and
//! `elevation` degrees above the horizon; y is up (the OBJ convention), and a planar mesh
//! (z = 0 everywhere) is seen from above with x to the right and y up.

use super::grid::{draw_colour_bar_at, Scale};
use super::{render, PlotError, FONT, MAX_C, MIN_C};
use crate::domain::vec3::{cross, dot, sub, unit};
use crate::plot::{GridMarker, GridPanel};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Camera of [`plot_mesh_fields`], in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshView {
    /// Rotation around the up axis (0: looking along −z).
    pub azimuth: f64,
    /// Angle above the horizon.
    pub elevation: f64,
}

impl Default for MeshView {
    fn default() -> Self {
        MeshView { azimuth: 30.0, elevation: 20.0 }
    }
}

const PANEL: u32 = 640;
const MARGIN: u32 = 12;
const TITLE_H: u32 = 44;
const PANEL_TITLE_H: u32 = 30;
const GAP: u32 = 16;
const BAR_W: u32 = 22;
const BAR_ROOM: u32 = 130;

/// Screen coordinates (pixels, y down) and depth (larger: nearer) of every vertex, and the
/// view direction towards the camera.
fn project(positions: &[[f64; 3]], view: MeshView) -> (Vec<[f64; 3]>, [f64; 3]) {
    let n = positions.len().max(1) as f64;
    let mut c = [0.0; 3];
    for p in positions {
        for k in 0..3 {
            c[k] += p[k] / n;
        }
    }
    let planar = positions.iter().all(|p| p[2] == 0.0);
    let (u, v, w) = if planar {
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0])
    } else {
        let (az, el) = (view.azimuth.to_radians(), view.elevation.to_radians());
        let w = [el.cos() * az.sin(), el.sin(), el.cos() * az.cos()];
        let u = unit(cross([0.0, 1.0, 0.0], w));
        let u = if dot(u, u) == 0.0 { [1.0, 0.0, 0.0] } else { u };
        (u, cross(w, u), w)
    };
    let raw: Vec<[f64; 3]> = positions
        .iter()
        .map(|p| {
            let d = sub(*p, c);
            [dot(d, u), dot(d, v), dot(d, w)]
        })
        .collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for r in &raw {
        for k in 0..2 {
            lo[k] = lo[k].min(r[k]);
            hi[k] = hi[k].max(r[k]);
        }
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-300);
    let s = 0.94 * PANEL as f64 / span;
    let (cx, cy) = ((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0);
    let half = PANEL as f64 / 2.0;
    let screen = raw.iter().map(|r| [half + s * (r[0] - cx), half - s * (r[1] - cy), s * r[2]]).collect();
    (screen, w)
}

/// The colour of a pixel from its triangle and barycentric weights.
type ColourAt<'a> = dyn Fn(&[usize; 3], [f64; 3]) -> [u8; 3] + 'a;

/// Rasterises one panel: RGB pixels and the depth buffer.
fn raster(
    positions: &[[f64; 3]],
    screen: &[[f64; 3]],
    towards: [f64; 3],
    triangles: &[[usize; 3]],
    colour_at: &ColourAt,
) -> (Vec<u8>, Vec<f64>) {
    let size = PANEL as usize;
    let mut rgb = vec![255u8; size * size * 3];
    let mut depth = vec![f64::NEG_INFINITY; size * size];
    for t in triangles {
        let [a, b, c] = t.map(|v| screen[v]);
        let normal = unit(cross(sub(positions[t[1]], positions[t[0]]), sub(positions[t[2]], positions[t[0]])));
        let shade = 0.35 + 0.65 * dot(normal, towards).abs();
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area.abs() < 1e-12 {
            continue;
        }
        let x0 = a[0].min(b[0]).min(c[0]).floor().max(0.0) as usize;
        let x1 = (a[0].max(b[0]).max(c[0]).ceil() as usize).min(size - 1);
        let y0 = a[1].min(b[1]).min(c[1]).floor().max(0.0) as usize;
        let y1 = (a[1].max(b[1]).max(c[1]).ceil() as usize).min(size - 1);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let w0 = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) / area;
                let w1 = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) / area;
                let w2 = 1.0 - w0 - w1;
                if w0 < -1e-9 || w1 < -1e-9 || w2 < -1e-9 {
                    continue;
                }
                let z = w0 * a[2] + w1 * b[2] + w2 * c[2];
                let k = y * size + x;
                if z <= depth[k] {
                    continue;
                }
                depth[k] = z;
                let colour = colour_at(t, [w0, w1, w2]);
                rgb[3 * k..3 * k + 3].copy_from_slice(&colour.map(|ch| (ch as f64 * shade).round() as u8));
            }
        }
    }
    (rgb, depth)
}

/// Draws `panels` (values per vertex of the mesh) side by side with a shared colour scale;
/// `markers` (vertex indices) are drawn where they face the camera. Returns how many markers
/// were hidden behind the surface.
///
/// # Errors
/// A panel of the wrong length, no panel, or a drawing or writing failure.
#[allow(clippy::too_many_arguments)]
pub fn plot_mesh_fields(
    out: &mut dyn std::io::Write,
    positions: &[[f64; 3]],
    triangles: &[[usize; 3]],
    panels: &[GridPanel],
    markers: &[GridMarker],
    title: &str,
    view: MeshView,
    diverging: bool,
) -> Result<usize, PlotError> {
    let fail = |m: &str| PlotError(format!("plot: {m}"));
    let n = positions.len();
    if panels.is_empty() || panels.len() > 4 {
        return Err(fail(&format!("{} panels, expected 1..=4", panels.len())));
    }
    if let Some(p) = panels.iter().find(|p| p.values.len() != n) {
        return Err(fail(&format!("panel '{}' has {} values for {n} vertices", p.title, p.values.len())));
    }
    if !(view.azimuth.is_finite() && view.elevation.is_finite()) {
        return Err(fail("the view angles must be finite"));
    }
    let scale = Scale::new(panels, diverging, None);
    let (screen, towards) = project(positions, view);
    let k = panels.len() as u32;
    let size = (2 * MARGIN + k * PANEL + (k - 1) * GAP + BAR_ROOM, TITLE_H + PANEL_TITLE_H + PANEL + MARGIN);
    let mut hidden = 0;
    render(out, size, |root, _| {
        let centred = |s: f64| TextStyle::from((FONT, s).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
        root.draw(&Text::new(title, (size.0 as i32 / 2, TITLE_H as i32 / 2 + 2), centred(22.0)))?;
        let tolerance = 0.01 * PANEL as f64;
        for (i, panel) in panels.iter().enumerate() {
            let x0 = (MARGIN + i as u32 * (PANEL + GAP)) as i32;
            let y0 = (TITLE_H + PANEL_TITLE_H) as i32;
            root.draw(&Text::new(
                panel.title.as_str(),
                (x0 + PANEL as i32 / 2, y0 - PANEL_TITLE_H as i32 / 2),
                centred(17.0),
            ))?;
            let values = panel.values;
            let colour_at = |t: &[usize; 3], w: [f64; 3]| {
                let RGBColor(r, g, b) = scale.colour(w[0] * values[t[0]] + w[1] * values[t[1]] + w[2] * values[t[2]]);
                [r, g, b]
            };
            let (rgb, depth) = raster(positions, &screen, towards, triangles, &colour_at);
            root.draw(&BitMapElement::with_owned_buffer((x0, y0), (PANEL, PANEL), rgb).ok_or("panel buffer")?)?;
            let r = if markers.len() > 100 { 3 } else { 5 };
            for m in markers.iter().filter(|m| m.index < n) {
                let [sx, sy, sz] = screen[m.index];
                let (px, py) = (sx.floor() as i64, sy.floor() as i64);
                let inside = (0..PANEL as i64).contains(&px) && (0..PANEL as i64).contains(&py);
                // visible: not behind the surface drawn at its pixel (or its neighbours)
                let visible = inside && {
                    let mut best = f64::NEG_INFINITY;
                    for dy in -1..=1i64 {
                        for dx in -1..=1i64 {
                            let (qx, qy) = (px + dx, py + dy);
                            if (0..PANEL as i64).contains(&qx) && (0..PANEL as i64).contains(&qy) {
                                best = best.max(depth[(qy as usize) * PANEL as usize + qx as usize]);
                            }
                        }
                    }
                    sz >= best - tolerance
                };
                if !visible {
                    if i == 0 {
                        hidden += 1;
                    }
                    continue;
                }
                let c = (x0 + sx.round() as i32, y0 + sy.round() as i32);
                root.draw(&Circle::new(c, r + 2, BLACK.filled()))?;
                root.draw(&Circle::new(c, r + 1, WHITE.filled()))?;
                root.draw(&Circle::new(c, r, if m.is_max { MAX_C } else { MIN_C }.filled()))?;
            }
        }
        let bx = (MARGIN + k * PANEL + (k - 1) * GAP + 20) as i32;
        draw_colour_bar_at(root, ((bx, (TITLE_H + PANEL_TITLE_H) as i32), (BAR_W, PANEL)), &scale, false)
    })?;
    Ok(hidden)
}

/// Draws a mesh with per-vertex 8-bit colours (interpolated inside triangles; a view, not a
/// certified array): the picture of a colour diffusion on a mesh.
///
/// # Errors
/// A colour array of the wrong length, or a drawing or writing failure.
pub fn plot_mesh_colours(
    out: &mut dyn std::io::Write,
    positions: &[[f64; 3]],
    triangles: &[[usize; 3]],
    colours: &[[u8; 3]],
    title: &str,
    view: MeshView,
) -> Result<(), PlotError> {
    if colours.len() != positions.len() {
        return Err(PlotError(format!("plot: {} colours for {} vertices", colours.len(), positions.len())));
    }
    let (screen, towards) = project(positions, view);
    let size = (2 * MARGIN + PANEL, TITLE_H + PANEL + MARGIN);
    render(out, size, |root, _| {
        let centred = TextStyle::from((FONT, 20.0).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
        root.draw(&Text::new(title, (size.0 as i32 / 2, TITLE_H as i32 / 2 + 2), centred))?;
        let colour_at = |t: &[usize; 3], w: [f64; 3]| {
            std::array::from_fn(|ch| {
                (0..3).map(|k| w[k] * f64::from(colours[t[k]][ch])).sum::<f64>().round().clamp(0.0, 255.0) as u8
            })
        };
        let (rgb, _) = raster(positions, &screen, towards, triangles, &colour_at);
        root.draw(
            &BitMapElement::with_owned_buffer((MARGIN as i32, TITLE_H as i32), (PANEL, PANEL), rgb)
                .ok_or("panel buffer")?,
        )?;
        Ok(())
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::shapes;

    #[test]
    fn a_sphere_is_drawn_with_its_colours_and_visible_dots() {
        let m = shapes::sphere(1.0, 30, 60);
        let p = m.positions();
        // value = height: the top of the picture is high (yellow), the bottom low (purple)
        let values: Vec<f64> = p.iter().map(|q| q[1]).collect();
        // markers facing the camera (+z): upper front and lower front; one at the back
        let top = (0..p.len()).max_by(|&a, &b| (p[a][1] + p[a][2]).total_cmp(&(p[b][1] + p[b][2]))).unwrap();
        let bottom = (0..p.len()).max_by(|&a, &b| (p[a][2] - p[a][1]).total_cmp(&(p[b][2] - p[b][1]))).unwrap();
        let back = (0..p.len()).min_by(|&a, &b| p[a][2].total_cmp(&p[b][2])).unwrap();
        let dir = std::env::temp_dir().join(format!("toposmooth-meshplot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("sphere.png");
        let panels = [GridPanel { title: "y".into(), values: &values }];
        let markers = [
            GridMarker { index: top, is_max: true },
            GridMarker { index: bottom, is_max: false },
            GridMarker { index: back, is_max: true },
        ];
        let view = MeshView { azimuth: 0.0, elevation: 0.0 };
        let hidden = plot_mesh_fields(
            &mut std::fs::File::create(&path).unwrap(),
            p,
            m.faces(),
            &panels,
            &markers,
            "sphere",
            view,
            false,
        )
        .unwrap();
        assert_eq!(hidden, 1, "the vertex at the back is hidden");
        let img = image::open(&path).unwrap().to_rgb8();
        let (x0, y0) = (MARGIN, TITLE_H + PANEL_TITLE_H);
        let at = |x: u32, y: u32| img.get_pixel(x0 + x, y0 + y).0;
        // near the top of the disc: yellowish (high red and green); near the bottom: purple
        let hi = at(PANEL / 2, PANEL / 2 - PANEL * 2 / 5);
        let lo = at(PANEL / 2, PANEL / 2 + PANEL * 2 / 5);
        assert!(hi[0] > 120 && hi[1] > 120 && hi[2] < 100, "{hi:?}");
        assert!(lo[2] > lo[1], "{lo:?}");
        // the corner is background
        assert_eq!(at(2, 2), [255, 255, 255]);
        let bad = plot_mesh_fields(
            &mut std::fs::File::create(&path).unwrap(),
            p,
            m.faces(),
            &[GridPanel { title: "x".into(), values: &[1.0] }],
            &[],
            "t",
            view,
            false,
        );
        assert!(bad.is_err());
    }
}

//! Colour diffusion (paper figures 4 and 11): colours given at points spread over an image's
//! shape or a mesh as a convex blend with monotone weights, so that no pixel leaves the
//! per-channel range of the given colours. Blending happens in linear RGB.
//!
//! ```
//! use toposmooth::apps::diffuse::{linear_to_srgb8, srgb8_to_linear};
//! for c in 0..=255u8 {
//!     assert_eq!(linear_to_srgb8(srgb8_to_linear(c)), c);
//! }
//! ```

use crate::domain::TriMesh;
use crate::error::{Error, Result};

/// Where a colour is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColorAt {
    /// Image pixel `[column, row]` (row 0 at the top).
    Pixel([usize; 2]),
    /// Mesh vertex index.
    Vertex(usize),
    /// A position on a mesh (nearest vertex).
    Point([f64; 3]),
}

/// One coloured point.
#[derive(Clone, Debug, PartialEq)]
pub struct ColorPoint {
    /// Name (`c<k>` unless given).
    pub name: String,
    /// Where.
    pub at: ColorAt,
    /// 8-bit sRGB colour.
    pub rgb: [u8; 3],
}

/// Parses `colors.json` (SPEC.md formats): `{"points": [{"pixel": [col, row], "rgb": [r, g, b]}]}`;
/// on meshes `"vertex": i` or `"point": [x, y, z]` instead of `"pixel"`; `"name"` optional.
///
/// # Errors
/// Malformed JSON, fewer than two points, colour components outside 0–255, bad positions.
pub fn parse_colors(text: &str) -> Result<Vec<ColorPoint>> {
    let v: serde_json::Value = serde_json::from_str(text).map_err(|e| Error::input(format!("not valid JSON: {e}")))?;
    let list = v
        .get("points")
        .and_then(|p| p.as_array())
        .ok_or_else(|| Error::input("expected {\"points\": [{\"pixel\": [col, row], \"rgb\": [r, g, b]}, ...]}"))?;
    let mut out: Vec<ColorPoint> = Vec::new();
    for (k, p) in list.iter().enumerate() {
        let name = match p.get("name") {
            Some(n) => {
                n.as_str().ok_or_else(|| Error::input(format!("point {k}: \"name\" must be a string")))?.to_string()
            }
            None => format!("c{k}"),
        };
        crate::apps::handles::check_name(&name).map_err(|e| Error::input(format!("point {k}: {e}")))?;
        if out.iter().any(|o| o.name == name) {
            return Err(Error::input(format!("two colour points are named `{name}`")));
        }
        let nums = |key: &str| -> Option<Vec<f64>> {
            p.get(key)?.as_array()?.iter().map(|x| x.as_f64().filter(|v| v.is_finite())).collect()
        };
        let rgb = nums("rgb")
            .filter(|c| c.len() == 3 && c.iter().all(|&x| (0.0..=255.0).contains(&x) && x.fract() == 0.0))
            .ok_or_else(|| Error::input(format!("point {k}: \"rgb\" must be three integers 0–255")))?;
        let at = if let Some(px) = nums("pixel") {
            if px.len() != 2 || px.iter().any(|&x| x < 0.0 || x.fract() != 0.0) {
                return Err(Error::input(format!("point {k}: \"pixel\" must be [column, row], non-negative integers")));
            }
            ColorAt::Pixel([px[0] as usize, px[1] as usize])
        } else if let Some(v) = p.get("vertex") {
            ColorAt::Vertex(
                v.as_u64().ok_or_else(|| Error::input(format!("point {k}: \"vertex\" must be an index")))? as usize
            )
        } else if let Some(q) = nums("point") {
            if !(q.len() == 2 || q.len() == 3) {
                return Err(Error::input(format!("point {k}: \"point\" must be [x, y] or [x, y, z]")));
            }
            ColorAt::Point([q[0], q[1], q.get(2).copied().unwrap_or(0.0)])
        } else {
            return Err(Error::input(format!("point {k} has none of \"pixel\", \"vertex\", \"point\"")));
        };
        out.push(ColorPoint { name, at, rgb: [rgb[0] as u8, rgb[1] as u8, rgb[2] as u8] });
    }
    if out.len() < 2 {
        return Err(Error::input(format!("at least two colour points are needed, got {}", out.len())));
    }
    Ok(out)
}

/// sRGB (8 bit) to linear RGB in [0, 1].
pub fn srgb8_to_linear(c: u8) -> f64 {
    let s = f64::from(c) / 255.0;
    if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear RGB to 8-bit sRGB (clamped to [0, 1] first, rounded to nearest).
pub fn linear_to_srgb8(l: f64) -> u8 {
    let l = if l.is_nan() { 0.0 } else { l.clamp(0.0, 1.0) };
    let s = if l <= 0.0031308 { 12.92 * l } else { 1.055 * l.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0).round().clamp(0.0, 255.0) as u8
}

/// Blends the colours with per-vertex weights (`weights[h][v]`) in linear RGB. Values outside
/// [0, 1] (unconstrained weights overshoot) are clamped when converted to 8 bit: the box
/// count of [`outside_box`] sees the clamped colours only where they leave the box.
pub fn blend(weights: &[Vec<f64>], colors: &[[u8; 3]]) -> Vec<[f64; 3]> {
    let n = weights.first().map_or(0, |w| w.len());
    let lin: Vec<[f64; 3]> = colors.iter().map(|c| c.map(srgb8_to_linear)).collect();
    (0..n)
        .map(|v| {
            let mut out = [0.0; 3];
            for (h, w) in weights.iter().enumerate() {
                for ch in 0..3 {
                    out[ch] += w[v] * lin[h][ch];
                }
            }
            out
        })
        .collect()
}

/// Number of pixels whose 8-bit colour leaves the per-channel [min, max] box of `colors`.
pub fn outside_box(colors: &[[u8; 3]], pixels: &[[u8; 3]]) -> usize {
    let lo: [u8; 3] = std::array::from_fn(|ch| colors.iter().map(|c| c[ch]).min().unwrap_or(0));
    let hi: [u8; 3] = std::array::from_fn(|ch| colors.iter().map(|c| c[ch]).max().unwrap_or(255));
    pixels.iter().filter(|p| (0..3).any(|ch| p[ch] < lo[ch] || p[ch] > hi[ch])).count()
}

/// An image's shape as a planar triangle mesh: one vertex per pixel inside (alpha ≥ 128),
/// two triangles per 2 × 2 block of inside pixels split along SPEC's grid diagonal; blocks
/// that would touch others at a single corner only are dropped (a mesh must be manifold).
/// Positions are `(column, height − 1 − row)`, y up.
#[derive(Clone, Debug)]
pub struct PixelMesh {
    /// The mesh.
    pub mesh: TriMesh,
    /// Pixel index `row · width + column` of each vertex.
    pub pixel_of_vertex: Vec<usize>,
    /// Vertex of each pixel, if it is in the mesh.
    pub vertex_of_pixel: Vec<Option<usize>>,
    /// Image width.
    pub width: usize,
    /// Image height.
    pub height: usize,
    /// Inside pixels left out (not in any full 2 × 2 block).
    pub dropped: usize,
}

/// Builds the [`PixelMesh`] of an inside mask (`inside[row · width + column]`).
///
/// # Errors
/// A mask with no 2 × 2 block of inside pixels.
pub fn pixel_mesh(width: usize, height: usize, inside: &[bool]) -> Result<PixelMesh> {
    assert_eq!(inside.len(), width * height);
    if width < 2 || height < 2 {
        return Err(Error::input(format!("a {width} × {height} image has no 2 × 2 block of pixels")));
    }
    let (cw, ch) = (width - 1, height - 1);
    let mut cell: Vec<bool> = (0..cw * ch)
        .map(|k| {
            let (r, c) = (k / cw, k % cw);
            [(r, c), (r, c + 1), (r + 1, c), (r + 1, c + 1)].iter().all(|&(r, c)| inside[r * width + c])
        })
        .collect();
    // a pixel corner shared by two diagonal cells only is non-manifold: drop the later cell
    loop {
        let mut changed = false;
        for r in 0..ch.saturating_sub(1) {
            for c in 0..cw.saturating_sub(1) {
                let (a, b, d, e) =
                    (cell[r * cw + c], cell[r * cw + c + 1], cell[(r + 1) * cw + c], cell[(r + 1) * cw + c + 1]);
                if a && e && !b && !d {
                    cell[(r + 1) * cw + c + 1] = false;
                    changed = true;
                } else if b && d && !a && !e {
                    cell[(r + 1) * cw + c] = false;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    let mut vertex_of_pixel: Vec<Option<usize>> = vec![None; width * height];
    let mut pixel_of_vertex = Vec::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut vid = |p: usize, vertex_of_pixel: &mut Vec<Option<usize>>| -> usize {
        *vertex_of_pixel[p].get_or_insert_with(|| {
            pixel_of_vertex.push(p);
            positions.push([(p % width) as f64, (height - 1 - p / width) as f64, 0.0]);
            pixel_of_vertex.len() - 1
        })
    };
    for r in 0..ch {
        for c in 0..cw {
            if !cell[r * cw + c] {
                continue;
            }
            let a = vid(r * width + c, &mut vertex_of_pixel);
            let b = vid(r * width + c + 1, &mut vertex_of_pixel);
            let d = vid((r + 1) * width + c, &mut vertex_of_pixel);
            let e = vid((r + 1) * width + c + 1, &mut vertex_of_pixel);
            // SPEC's diagonal a–e; counter-clockwise with y up
            triangles.push([a, e, b]);
            triangles.push([a, d, e]);
        }
    }
    if triangles.is_empty() {
        return Err(Error::input("the image's shape (alpha ≥ 128) has no 2 × 2 block of pixels"));
    }
    let dropped = inside.iter().filter(|&&b| b).count() - pixel_of_vertex.len();
    let mesh = TriMesh::new(positions, triangles)?;
    Ok(PixelMesh { mesh, pixel_of_vertex, vertex_of_pixel, width, height, dropped })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Domain;

    #[test]
    fn parses_colours_and_refuses_bad_ones() {
        let c = parse_colors(
            r#"{"points": [{"pixel": [1, 2], "rgb": [255, 0, 0]}, {"name": "sky", "vertex": 7, "rgb": [0, 0, 255]}]}"#,
        )
        .unwrap();
        assert_eq!(c[0].at, ColorAt::Pixel([1, 2]));
        assert_eq!((c[1].name.as_str(), c[1].at), ("sky", ColorAt::Vertex(7)));
        for bad in [
            r#"{"points": [{"pixel": [1, 2], "rgb": [255, 0, 0]}]}"#,
            r#"{"points": [{"pixel": [1, 2], "rgb": [256, 0, 0]}, {"pixel": [3, 2], "rgb": [0, 0, 0]}]}"#,
            r#"{"points": [{"pixel": [1.5, 2], "rgb": [25, 0, 0]}, {"pixel": [3, 2], "rgb": [0, 0, 0]}]}"#,
            r#"{"points": [{"rgb": [25, 0, 0]}, {"pixel": [3, 2], "rgb": [0, 0, 0]}]}"#,
            "[]",
        ] {
            assert!(parse_colors(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_convex_blend_stays_in_the_box_and_an_overshoot_leaves_it() {
        let colors = [[200, 30, 30], [20, 120, 220]];
        let w = vec![vec![1.0, 0.0, 0.3], vec![0.0, 1.0, 0.7]];
        let px: Vec<[u8; 3]> = blend(&w, &colors).iter().map(|c| c.map(linear_to_srgb8)).collect();
        assert_eq!(px[0], colors[0]);
        assert_eq!(px[1], colors[1]);
        assert_eq!(outside_box(&colors, &px), 0);
        let over = vec![vec![1.2], vec![-0.2]];
        let px: Vec<[u8; 3]> = blend(&over, &colors).iter().map(|c| c.map(linear_to_srgb8)).collect();
        assert_eq!(outside_box(&colors, &px), 1);
    }

    #[test]
    fn pixel_meshes_drop_corner_contacts() {
        // two 2 × 2 blocks touching at one pixel corner, plus a lone pixel
        #[rustfmt::skip]
        let mask = [
            1, 1, 0, 0, 0,
            1, 1, 0, 0, 1,
            0, 0, 1, 1, 0,
            0, 0, 1, 1, 0,
        ].map(|b| b == 1);
        // the blocks are diagonal neighbours without a shared pixel: two components
        let pm = pixel_mesh(5, 4, &mask).unwrap();
        assert_eq!(pm.mesh.faces().len(), 4);
        assert_eq!(pm.dropped, 1);
        assert_eq!(pm.mesh.n_components(), 2);
        // a 3 × 3 checker of cells meeting at a corner pixel: one cell dropped
        #[rustfmt::skip]
        let mask = [
            1, 1, 0,
            1, 1, 1,
            0, 1, 1,
        ].map(|b| b == 1);
        let pm = pixel_mesh(3, 3, &mask).unwrap();
        assert_eq!(pm.mesh.faces().len(), 2);
        assert_eq!(pm.dropped, 3);
        assert!(pm.mesh.n_vertices() == 4 && pm.vertex_of_pixel[4].is_some());
        let full = pixel_mesh(4, 3, &[true; 12]).unwrap();
        assert_eq!((full.mesh.n_vertices(), full.mesh.faces().len(), full.dropped), (12, 12, 0));
        assert!(full.mesh.repairs().is_empty()); // already consistently oriented
        assert!(pixel_mesh(3, 3, &[false; 9]).is_err());
    }
}

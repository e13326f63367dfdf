//! Outlines from PNG masks: the boundary of the largest 4-connected inside region, traced along
//! pixel edges and simplified (see [`super::read_outline`] for the conventions).

use super::shape::{signed_area2, Outline, TRACE_TOLERANCE};
use crate::error::{Error, Result};

type Loops = Vec<Vec<[f64; 2]>>;

/// Directions of boundary edges on the corner lattice (y up): +x, +y, −x, −y.
const STEP: [[i64; 2]; 4] = [[1, 0], [0, 1], [-1, 0], [0, -1]];

/// The mask, traced and simplified: the outer boundary first, then the holes.
pub(super) fn read_png(bytes: &[u8]) -> Result<Loops> {
    let img = image::load_from_memory_with_format(bytes, image::ImageFormat::Png)
        .map_err(|e| Error::input(format!("cannot read the PNG image: {e}")))?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    let mut mask: Vec<bool> = Vec::new();
    if img.color().has_alpha() {
        let rgba = img.to_rgba8();
        // rows stored top first; the mask is indexed with y up
        mask = (0..w * h).map(|k| rgba.get_pixel((k % w) as u32, (h - 1 - k / w) as u32).0[3] >= 128).collect();
        if mask.iter().all(|&m| m) {
            mask.clear(); // every pixel opaque: the alpha channel carries no shape
        }
    }
    if mask.is_empty() {
        let luma = img.to_luma8();
        mask = (0..w * h).map(|k| luma.get_pixel((k % w) as u32, (h - 1 - k / w) as u32).0[0] < 128).collect();
    }
    let region = largest_region(&mask, w, h).ok_or_else(|| {
        Error::input("no pixel is inside the shape (inside: alpha ≥ 50 %, or without transparency a grey level < 50 %)")
    })?;
    let loops = trace(&region, w, h);
    Ok(simplify_valid(loops))
}

/// The largest 4-connected region of `mask` (ties: the first in storage order), or `None`.
fn largest_region(mask: &[bool], w: usize, h: usize) -> Option<Vec<bool>> {
    let mut label = vec![u32::MAX; w * h];
    let (mut best, mut best_size, mut next) = (u32::MAX, 0usize, 0u32);
    let mut queue = Vec::new();
    for seed in 0..w * h {
        if !mask[seed] || label[seed] != u32::MAX {
            continue;
        }
        label[seed] = next;
        queue.clear();
        queue.push(seed);
        let mut size = 0;
        while let Some(k) = queue.pop() {
            size += 1;
            let (x, y) = (k % w, k / w);
            let mut visit = |j: usize| {
                if mask[j] && label[j] == u32::MAX {
                    label[j] = next;
                    queue.push(j);
                }
            };
            if x > 0 {
                visit(k - 1);
            }
            if x + 1 < w {
                visit(k + 1);
            }
            if y > 0 {
                visit(k - w);
            }
            if y + 1 < h {
                visit(k + w);
            }
        }
        if size > best_size {
            (best, best_size) = (next, size);
        }
        next += 1;
    }
    (best_size > 0).then(|| label.iter().map(|&l| l == best).collect())
}

/// Boundary loops of a 4-connected region along pixel edges, inside on the left: the outer
/// boundary counter-clockwise (first), holes clockwise. Corners only (straight runs merged);
/// at a corner where two inside pixels touch diagonally the loop turns left (keeping the
/// region 4-connected) and its corner moves a quarter pixel into the pixel it goes around.
fn trace(region: &[bool], w: usize, h: usize) -> Loops {
    let inside = |x: i64, y: i64| {
        x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h && region[y as usize * w + x as usize]
    };
    let cw = w + 1;
    // outgoing boundary edges of each corner, one bit per direction
    let mut out = vec![0u8; cw * (h + 1)];
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            if !inside(x, y) {
                continue;
            }
            let c = |x: i64, y: i64| y as usize * cw + x as usize;
            if !inside(x, y - 1) {
                out[c(x, y)] |= 1; // bottom edge, going +x
            }
            if !inside(x + 1, y) {
                out[c(x + 1, y)] |= 2; // right edge, going +y
            }
            if !inside(x, y + 1) {
                out[c(x + 1, y + 1)] |= 4; // top edge, going −x
            }
            if !inside(x - 1, y) {
                out[c(x, y + 1)] |= 8; // left edge, going −y
            }
        }
    }
    // the successor of an edge arriving at `corner` in direction d: left turn, straight, right
    let turn = |bits: u8, d: usize| -> usize {
        [(d + 1) % 4, d, (d + 3) % 4].into_iter().find(|&o| bits & (1 << o) != 0).unwrap_or(d)
    };
    let mut used = vec![0u8; out.len()];
    let mut loops: Loops = Vec::new();
    for c0 in 0..out.len() {
        for d0 in 0..4 {
            if out[c0] & (1 << d0) == 0 || used[c0] & (1 << d0) != 0 {
                continue;
            }
            let mut lp: Vec<[f64; 2]> = Vec::new();
            let (mut c, mut d) = (c0, d0);
            loop {
                used[c] |= 1 << d;
                let (x, y) = ((c % cw) as i64 + STEP[d][0], (c / cw) as i64 + STEP[d][1]);
                let next = y as usize * cw + x as usize;
                let o = turn(out[next], d);
                if o != d {
                    let mut p = [x as f64, y as f64];
                    if out[next].count_ones() == 2 {
                        // a saddle: move into the pixel behind and to the left of the arrival
                        let n = STEP[(d + 1) % 4];
                        p[0] += 0.25 * (n[0] - STEP[d][0]) as f64;
                        p[1] += 0.25 * (n[1] - STEP[d][1]) as f64;
                    }
                    lp.push(p);
                }
                (c, d) = (next, o);
                if (c, d) == (c0, d0) {
                    break;
                }
            }
            loops.push(lp);
        }
    }
    // the outer boundary is the one counter-clockwise loop
    if let Some(k) = loops.iter().position(|l| signed_area2(l) > 0.0) {
        let outer = loops.remove(k);
        loops.insert(0, outer);
    }
    loops
}

/// Douglas–Peucker simplification with [`TRACE_TOLERANCE`]; where that makes loops cross,
/// the tolerance is halved (down to the unsimplified corners, which never cross).
fn simplify_valid(loops: Loops) -> Loops {
    let mut tolerance = TRACE_TOLERANCE;
    for _ in 0..5 {
        let simple: Loops = loops.iter().map(|l| simplify_loop(l, tolerance)).collect();
        if (Outline { loops: simple.clone() }).validate().is_ok() {
            return simple;
        }
        tolerance /= 2.0;
    }
    loops
}

/// Distance from `p` to the segment `ab`.
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0) } else { 0.0 };
    ((p[0] - a[0] - t * dx).powi(2) + (p[1] - a[1] - t * dy).powi(2)).sqrt()
}

/// Douglas–Peucker on a closed loop, anchored at its lowest-leftmost corner and the corner
/// farthest from it. A loop that would keep fewer than 3 corners is returned unchanged.
fn simplify_loop(l: &[[f64; 2]], tolerance: f64) -> Vec<[f64; 2]> {
    let n = l.len();
    if n <= 3 {
        return l.to_vec();
    }
    let a = (0..n).min_by(|&i, &j| l[i][0].total_cmp(&l[j][0]).then(l[i][1].total_cmp(&l[j][1]))).unwrap_or(0);
    let dist2 = |i: usize| (l[i][0] - l[a][0]).powi(2) + (l[i][1] - l[a][1]).powi(2);
    let b = (0..n).max_by(|&i, &j| dist2(i).total_cmp(&dist2(j))).unwrap_or(0);
    // positions along the loop from a: 0..n, with b at offset m
    let at = |k: usize| l[(a + k) % n];
    let m = (b + n - a) % n;
    let mut keep = vec![false; n + 1];
    keep[0] = true;
    keep[m] = true;
    keep[n] = true;
    let mut stack = vec![(0usize, m), (m, n)];
    while let Some((i, j)) = stack.pop() {
        if j <= i + 1 {
            continue;
        }
        let (mut far, mut far_d) = (i, -1.0);
        for k in i + 1..j {
            let d = segment_distance(at(k), at(i), at(j));
            if d > far_d {
                (far, far_d) = (k, d);
            }
        }
        if far_d > tolerance {
            keep[far] = true;
            stack.push((i, far));
            stack.push((far, j));
        }
    }
    let out: Vec<[f64; 2]> = (0..n).filter(|&k| keep[k]).map(at).collect();
    if out.len() < 3 {
        l.to_vec()
    } else {
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A mask from rows of text, top row first (`#` inside).
    fn mask(rows: &[&str]) -> (Vec<bool>, usize, usize) {
        let (w, h) = (rows[0].len(), rows.len());
        let m = (0..w * h).map(|k| rows[h - 1 - k / w].as_bytes()[k % w] == b'#').collect();
        (m, w, h)
    }

    #[test]
    fn a_ring_is_traced_with_its_hole() {
        let (m, w, h) = mask(&["....", ".###", ".#.#", ".###"]);
        let loops = trace(&largest_region(&m, w, h).unwrap(), w, h);
        assert_eq!(loops.len(), 2);
        // outer boundary: the 3 × 3 block at x 1..4, y 0..3, counter-clockwise from (1, 0)
        assert_eq!(loops[0], vec![[4.0, 0.0], [4.0, 3.0], [1.0, 3.0], [1.0, 0.0]]);
        assert!(signed_area(&loops[0]) == 9.0 && signed_area(&loops[1]) == -1.0);
        // the hole's square is kept although Douglas–Peucker would collapse it
        let simple = simplify_valid(loops);
        assert_eq!(simple[1].len(), 4);
    }

    fn signed_area(l: &[[f64; 2]]) -> f64 {
        super::super::shape::signed_area2(l) / 2.0
    }

    #[test]
    fn diagonal_contacts_are_separated_and_islands_dropped() {
        // pixels (1, 0) and (2, 1) (y up) touch only at the corner (2, 1), which the outer
        // boundary passes twice: each pass moves a quarter pixel into its own pixel
        let (m, w, h) = mask(&["###", "#.#", "##."]);
        let region = largest_region(&m, w, h).unwrap();
        let loops = trace(&region, w, h);
        assert_eq!(loops.len(), 1);
        assert!(loops[0].contains(&[1.75, 0.75]) && loops[0].contains(&[2.25, 1.25]), "{:?}", loops[0]);
        let o = Outline { loops };
        o.validate().unwrap();
        assert!((o.area() - 7.0).abs() < 0.6, "{}", o.area());
        // an island apart from the largest region is dropped
        let (m, w, h) = mask(&["##..", "##.#", "...."]);
        let r = largest_region(&m, w, h).unwrap();
        assert_eq!(r.iter().filter(|&&b| b).count(), 4);
    }

    #[test]
    fn douglas_peucker_keeps_the_shape_within_tolerance() {
        // a staircase diagonal: 20 steps of one pixel
        let mut l = vec![[0.0, 0.0], [20.0, 0.0]];
        for k in (0..20).rev() {
            l.push([k as f64 + 1.0, k as f64 + 1.0]);
            l.push([k as f64, k as f64 + 1.0]);
        }
        l.pop();
        let s = simplify_loop(&l, TRACE_TOLERANCE);
        assert!(s.len() < 6, "{s:?}");
        for p in &l {
            let d =
                (0..s.len()).map(|i| segment_distance(*p, s[i], s[(i + 1) % s.len()])).fold(f64::INFINITY, f64::min);
            assert!(d <= TRACE_TOLERANCE, "{p:?} at {d}");
        }
    }
}

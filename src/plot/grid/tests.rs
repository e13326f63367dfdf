//! Tests of `grid`.

use super::*;
use std::path::PathBuf;

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("toposmooth_grid_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(format!("{name}.png"))
}

/// Plots, reads the PNG back (removing it), checks its size against the layout and returns both.
fn plot(
    name: &str,
    nx: usize,
    ny: usize,
    panels: &[GridPanel],
    markers: &[GridMarker],
    options: &GridPlotOptions,
) -> (image::RgbImage, Layout) {
    let path = tmp(name);
    plot_grid_fields(&mut std::fs::File::create(&path).unwrap(), nx, ny, panels, markers, name, options).unwrap();
    let img = image::open(&path).unwrap().to_rgb8();
    std::fs::remove_file(&path).ok();
    let layout = Layout::new(nx, ny, panels.len(), options.aspect);
    assert_eq!(img.dimensions(), layout.size);
    (img, layout)
}

/// Colour of the image at the centre of cell `index` in panel `k`.
fn at_cell(img: &image::RgbImage, l: &Layout, k: usize, nx: usize, ny: usize, index: usize) -> [u8; 3] {
    let (x0, y0) = l.origin(k);
    let (x, y) = cell_centre(nx, ny, l.panel, index);
    img.get_pixel((x0 + x.round() as i32) as u32, (y0 + y.round() as i32) as u32).0
}

/// Colours at the top and bottom of the colour bar.
fn bar_ends(img: &image::RgbImage, l: &Layout, missing: bool) -> ([u8; 3], [u8; 3]) {
    let ((x, y), (w, h)) = l.bar(missing);
    let px = |y: i32| img.get_pixel((x + w as i32 / 2) as u32, y as u32).0;
    (px(y + 1), px(y + h as i32 - 2))
}

fn panel<'a>(title: &str, values: &'a [f64]) -> GridPanel<'a> {
    GridPanel { title: title.into(), values }
}

fn reddish(p: [u8; 3]) -> bool {
    p[0] > 150 && p[1] < 90 && p[2] < 90
}

fn bluish(p: [u8; 3]) -> bool {
    p[2] > 150 && p[0] < 90 && p[1] < 120
}

const GREY: [u8; 3] = [MISSING.0, MISSING.1, MISSING.2];

#[test]
fn grid_two_bumps_with_holes() {
    let (nx, ny) = (63, 63);
    let bumps = |r: usize, c: usize| {
        let (x, y) = (c as f64 / 62.0, r as f64 / 62.0);
        let g = |x0: f64, y0: f64, s: f64| (-((x - x0).powi(2) + (y - y0).powi(2)) / s).exp();
        g(0.3, 0.3, 0.02) - 0.8 * g(0.7, 0.65, 0.03)
    };
    let holes = |r: usize, c: usize| ((50..53).contains(&r) && (8..11).contains(&c)) || (r, c) == (5, 55);
    let field = |noise: f64| -> Vec<f64> {
        (0..nx * ny)
            .map(|i| (i / nx, i % nx))
            .map(|(r, c)| {
                if holes(r, c) {
                    f64::NAN
                } else {
                    bumps(r, c) + noise * (7.0 * r as f64).sin() * (5.0 * c as f64).cos()
                }
            })
            .collect()
    };
    let (input, smooth) = (field(0.05), field(0.0));
    let (max, min) = (19 * nx + 19, 40 * nx + 43);
    let markers = [
        GridMarker { index: max, is_max: true },
        GridMarker { index: min, is_max: false },
        GridMarker { index: 10 * nx + 50, is_max: true },
        GridMarker { index: 55 * nx + 30, is_max: false },
        GridMarker { index: nx * ny, is_max: true }, // out of range: ignored
    ];
    let panels = [panel("input", &input), panel("smoothed", &smooth)];
    let opts = GridPlotOptions { isolines: 8, diverging: false, aspect: 1.0 };
    let (img, l) = plot("bumps", nx, ny, &panels, &markers, &opts);
    assert_eq!((l.size, l.panel, l.stacked), ((1064, 527), (441, 441), false));
    for k in 0..2 {
        assert!(reddish(at_cell(&img, &l, k, nx, ny, max)), "{:?}", at_cell(&img, &l, k, nx, ny, max));
        assert!(bluish(at_cell(&img, &l, k, nx, ny, min)), "{:?}", at_cell(&img, &l, k, nx, ny, min));
        assert_eq!(at_cell(&img, &l, k, nx, ny, 51 * nx + 9), GREY);
        assert_eq!(at_cell(&img, &l, k, nx, ny, 5 * nx + 55), GREY);
    }
    let (top, bottom) = bar_ends(&img, &l, true);
    assert_ne!(top, bottom);
    assert!(top[0] > 200 && top[1] > 200 && top[2] < 100, "viridis top is yellow: {top:?}");
    assert!(bottom[2] > bottom[1], "viridis bottom is purple: {bottom:?}");

    // three panels, diverging, five isolines
    let rep: Vec<f64> = smooth.iter().map(|v| v * 0.5).collect();
    let panels = [panel("input", &input), panel("smoothed", &smooth), panel("representative", &rep)];
    let opts = GridPlotOptions { isolines: 5, diverging: true, aspect: 1.0 };
    let (img, l) = plot("bumps_div", nx, ny, &panels, &markers, &opts);
    assert_eq!((l.size, l.panel, l.stacked), ((1521, 527), (441, 441), false));
    assert!(reddish(at_cell(&img, &l, 2, nx, ny, max)));
    assert_eq!(at_cell(&img, &l, 2, nx, ny, 51 * nx + 9), GREY);
    let ((x, y), (w, h)) = l.bar(true);
    let mid = img.get_pixel((x + w as i32 / 2) as u32, (y + h as i32 / 2) as u32).0;
    assert!(mid.iter().all(|&v| v > 225), "diverging middle is near white: {mid:?}");
    let (top, bottom) = bar_ends(&img, &l, true);
    assert!(reddish(top) && bottom[2] > 150 && bottom[0] < 60, "{top:?} {bottom:?}");
}

#[test]
fn grid_wide_stacks_panels() {
    let (nx, ny) = (513, 65);
    // value = row: low (purple) at the top, high (yellow) at the bottom
    let rows: Vec<f64> = (0..nx * ny).map(|i| (i / nx) as f64).collect();
    let wave: Vec<f64> = (0..nx * ny).map(|i| ((i % nx) as f64 / 40.0).sin() * 64.0).collect();
    let markers = [GridMarker { index: 5, is_max: true }, GridMarker { index: 64 * nx + 500, is_max: false }];
    let panels = [panel("rows", &rows), panel("wave", &wave)];
    let (img, l) = plot("wide", nx, ny, &panels, &markers, &GridPlotOptions::default());
    assert_eq!((l.size, l.panel, l.stacked), ((1705, 522), (1539, 195), true));
    assert!(l.origin(1).1 > l.origin(0).1 + 195 && l.origin(1).0 == l.origin(0).0);
    let scale = Scale::new(&panels, false);
    let (x0, y0) = l.origin(0);
    let top = img.get_pixel((x0 + 700) as u32, (y0 + 1) as u32).0;
    let bottom = img.get_pixel((x0 + 700) as u32, (y0 + 193) as u32).0;
    assert_eq!(top, [scale.colour(0.0).0, scale.colour(0.0).1, scale.colour(0.0).2]);
    assert_eq!(bottom, [scale.colour(64.0).0, scale.colour(64.0).1, scale.colour(64.0).2]);
    let i = 32 * nx + 100;
    let c = scale.colour(wave[i]);
    assert_eq!(at_cell(&img, &l, 1, nx, ny, i), [c.0, c.1, c.2]);
    for k in 0..2 {
        assert!(reddish(at_cell(&img, &l, k, nx, ny, 5)));
        assert!(bluish(at_cell(&img, &l, k, nx, ny, 64 * nx + 500)));
    }
    let (top, bottom) = bar_ends(&img, &l, false);
    assert_ne!(top, bottom);

    // with isolines as well
    let opts = GridPlotOptions { isolines: 6, ..Default::default() };
    let (img, l) = plot("wide_iso", nx, ny, &panels, &markers, &opts);
    // level -64 + 128 * 5/7 = 27.43 crosses the rows field at y = (27.5 + 0.43) * 3 = 83.8 px: a solid line
    let (x0, y0) = l.origin(0);
    let dark = (5..1535).filter(|&x| img.get_pixel((x0 + x) as u32, (y0 + 84) as u32).0 == [30, 30, 30]).count();
    assert_eq!(dark, 1530);
}

#[test]
fn grid_constant_and_degenerate() {
    let (nx, ny) = (20, 20);
    let constant = vec![5.0; nx * ny];
    let m = [GridMarker { index: 210, is_max: true }, GridMarker { index: 0, is_max: false }];
    for diverging in [false, true] {
        let opts = GridPlotOptions { isolines: 4, diverging, aspect: 1.0 };
        let (img, l) = plot("constant", nx, ny, &[panel("c", &constant)], &m, &opts);
        assert_eq!((l.panel, l.stacked), ((400, 400), false));
        assert!(reddish(at_cell(&img, &l, 0, nx, ny, 210)));
        let c = Scale::new(&[panel("c", &constant)], diverging).colour(5.0);
        assert_eq!(at_cell(&img, &l, 0, nx, ny, 5 * nx + 5), [c.0, c.1, c.2]);
        let (top, bottom) = bar_ends(&img, &l, false);
        assert_ne!(top, bottom);
    }
    // all NaN: grey, no error
    let nan = vec![f64::NAN; nx * ny];
    let (img, l) = plot("all_nan", nx, ny, &[panel("a", &nan), panel("b", &nan)], &m, &Default::default());
    assert_eq!(at_cell(&img, &l, 1, nx, ny, 5 * nx + 5), GREY);
    assert_ne!(bar_ends(&img, &l, true).0, bar_ends(&img, &l, true).1);
    // a single finite value, next to an all-NaN panel, with infinities and isolines
    let mut one = nan.clone();
    one[7] = -3.0;
    one[8] = f64::INFINITY;
    let opts = GridPlotOptions { isolines: 3, diverging: true, aspect: 1.0 };
    let (img, l) = plot("single", nx, ny, &[panel("one", &one), panel("nan", &nan)], &[], &opts);
    assert!(bluish(at_cell(&img, &l, 0, nx, ny, 7)));
    assert!(reddish(at_cell(&img, &l, 0, nx, ny, 8)), "∞ clamps to the top colour");
    // 1×1 grid, 1×n and n×1 grids, a non-unit aspect
    plot("one_cell", 1, 1, &[panel("p", &[2.0])], &[GridMarker { index: 0, is_max: true }], &Default::default());
    let line: Vec<f64> = (0..300).map(|i| i as f64).collect();
    plot("row", 300, 1, &[panel("p", &line), panel("q", &line)], &[], &Default::default());
    plot("column", 1, 300, &[panel("p", &line), panel("q", &line)], &[], &Default::default());
    let opts = GridPlotOptions { aspect: 2.0, ..Default::default() };
    let v: Vec<f64> = (0..800).map(|i| i as f64).collect();
    let (_, l) = plot("aspect", 40, 20, &[panel("p", &v)], &[], &opts);
    assert_eq!(l.panel, (400, 400));
}

#[test]
fn grid_large_is_sampled_down() {
    let n = 1000;
    let v: Vec<f64> = (0..n * n).map(|i| ((i / n) as f64 / 50.0).sin() + ((i % n) as f64 / 70.0).cos()).collect();
    let m = [GridMarker { index: 500 * n + 500, is_max: true }];
    let opts = GridPlotOptions { isolines: 10, ..Default::default() };
    let (img, l) = plot("large", n, n, &[panel("a", &v), panel("b", &v)], &m, &opts);
    assert_eq!((l.size, l.panel, l.stacked), ((2000, 995), (909, 909), false));
    assert!(reddish(at_cell(&img, &l, 1, n, n, 500 * n + 500)));
    for k in 1..=8 {
        let l = Layout::new(n, n, k, 1.0);
        assert!(l.size.0 <= MAX_W && l.size.1 <= MAX_H, "{k} panels: {l:?}");
    }
    let l = Layout::new(63, 63, 4, 1.0);
    assert!(l.panel.0 >= 400 && l.size.0 <= MAX_W, "{l:?}");
}

#[test]
fn grid_errors() {
    let mut p = Vec::new();
    let v = [1.0; 6];
    let ok = [panel("p", &v[..])];
    let o = GridPlotOptions::default();
    assert!(plot_grid_fields(&mut p, 0, 6, &ok, &[], "t", &o).is_err());
    assert!(plot_grid_fields(&mut p, usize::MAX, 2, &ok, &[], "t", &o).is_err());
    assert!(plot_grid_fields(&mut p, 2, 3, &[], &[], "t", &o).is_err());
    let e = plot_grid_fields(&mut p, 2, 2, &ok, &[], "t", &o).unwrap_err();
    assert!(e.0.contains("panel 'p' has 6 values"), "{e}");
    for aspect in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(plot_grid_fields(&mut p, 2, 3, &ok, &[], "t", &GridPlotOptions { aspect, ..o }).is_err());
    }
    let many = vec![panel("p", &v[..]); 65];
    assert!(plot_grid_fields(&mut p, 2, 3, &many, &[], "t", &o).is_err());
    assert!(p.is_empty(), "nothing is written before the checks pass");
}

#[test]
fn contours_cross_where_expected() {
    // a ramp in x: the level 1.5 lies halfway between columns 1 and 2, on every row
    let (nx, ny) = (4, 3);
    let v: Vec<f64> = (0..nx * ny).map(|i| (i % nx) as f64).collect();
    let segs = contour_segments(&v, nx, ny, (40, 30), &[1.5]);
    assert!(!segs.is_empty());
    for (a, b) in &segs {
        assert!((a.0 - 20.0).abs() < 1e-9 && (b.0 - 20.0).abs() < 1e-9, "{a:?} {b:?}");
    }
    let mut holed = v.clone();
    holed[5] = f64::NAN;
    assert!(contour_segments(&holed, nx, ny, (40, 30), &[1.5]).len() < segs.len());
    assert!(contour_segments(&v, nx, ny, (40, 30), &[]).is_empty());
    assert!(contour_segments(&v, nx, 1, (40, 30), &[1.5]).is_empty());
}

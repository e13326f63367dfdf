//! Tests of `grid`.

use super::*;
use std::path::PathBuf;

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("toposmooth_grid_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(format!("{name}.png"))
}

/// What a plot drew: the image, its layout and the grid's view.
struct Drawn {
    img: image::RgbImage,
    l: Layout,
    view: View,
}

/// Plots, reads the PNG back (removing it), checks its size against the layout and returns them.
fn plot(
    name: &str,
    nx: usize,
    ny: usize,
    panels: &[GridPanel],
    markers: &[GridMarker],
    options: &GridPlotOptions,
) -> Drawn {
    let path = tmp(name);
    plot_grid_fields(&mut std::fs::File::create(&path).unwrap(), nx, ny, panels, markers, name, options).unwrap();
    let img = image::open(&path).unwrap().to_rgb8();
    std::fs::remove_file(&path).ok();
    let layout = Layout::new(nx, ny, panels.len(), (options.spacing[1] / options.spacing[0]).abs());
    assert_eq!(img.dimensions(), layout.size);
    Drawn { img, l: layout, view: View::new(nx, ny, options) }
}

impl Drawn {
    /// Colour of the image at the centre of cell `index` in panel `k`.
    fn at_cell(&self, k: usize, index: usize) -> [u8; 3] {
        let (x0, y0) = self.l.origin(k);
        let (x, y) = self.view.centre(self.l.panel, index);
        self.img.get_pixel((x0 + x.round() as i32) as u32, (y0 + y.round() as i32) as u32).0
    }
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
const ISO: [u8; 3] = [ISOLINE.0, ISOLINE.1, ISOLINE.2];

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
    let opts = GridPlotOptions { isolines: 8, diverging: false, ..Default::default() };
    let d = plot("bumps", nx, ny, &panels, &markers, &opts);
    assert_eq!((d.l.size, d.l.panel, d.l.stacked), ((1232, 573), (441, 441), false));
    for k in 0..2 {
        assert!(reddish(d.at_cell(k, max)), "{:?}", d.at_cell(k, max));
        assert!(bluish(d.at_cell(k, min)), "{:?}", d.at_cell(k, min));
        assert_eq!(d.at_cell(k, 51 * nx + 9), GREY);
        assert_eq!(d.at_cell(k, 5 * nx + 55), GREY);
    }
    let (top, bottom) = bar_ends(&d.img, &d.l, true);
    assert_ne!(top, bottom);
    assert!(top[0] > 200 && top[1] > 200 && top[2] < 100, "viridis top is yellow: {top:?}");
    assert!(bottom[2] > bottom[1], "viridis bottom is purple: {bottom:?}");

    // three panels, diverging, five isolines
    let rep: Vec<f64> = smooth.iter().map(|v| v * 0.5).collect();
    let panels = [panel("input", &input), panel("smoothed", &smooth), panel("representative", &rep)];
    let opts = GridPlotOptions { isolines: 5, diverging: true, ..Default::default() };
    let d = plot("bumps_div", nx, ny, &panels, &markers, &opts);
    assert_eq!((d.l.size, d.l.panel, d.l.stacked), ((1773, 573), (441, 441), false));
    assert!(reddish(d.at_cell(2, max)));
    assert_eq!(d.at_cell(2, 51 * nx + 9), GREY);
    let ((x, y), (w, h)) = d.l.bar(true);
    let mid = d.img.get_pixel((x + w as i32 / 2) as u32, (y + h as i32 / 2) as u32).0;
    assert!(mid.iter().all(|&v| v > 225), "diverging middle is near white: {mid:?}");
    let (top, bottom) = bar_ends(&d.img, &d.l, true);
    assert!(reddish(top) && bottom[2] > 150 && bottom[0] < 60, "{top:?} {bottom:?}");
}

#[test]
fn grid_wide_stacks_panels() {
    let (nx, ny) = (513, 65);
    // value = row = y (origin 0, spacing 1): high (yellow) at the top as in ParaView, low
    // (purple) at the bottom
    let rows: Vec<f64> = (0..nx * ny).map(|i| (i / nx) as f64).collect();
    let wave: Vec<f64> = (0..nx * ny).map(|i| ((i % nx) as f64 / 40.0).sin() * 64.0).collect();
    let markers = [GridMarker { index: 5, is_max: true }, GridMarker { index: 64 * nx + 500, is_max: false }];
    let panels = [panel("rows", &rows), panel("wave", &wave)];
    let d = plot("wide", nx, ny, &panels, &markers, &GridPlotOptions::default());
    assert_eq!((d.l.size, d.l.panel, d.l.stacked), ((1789, 614), (1539, 195), true));
    assert!(d.l.origin(1).1 > d.l.origin(0).1 + 195 && d.l.origin(1).0 == d.l.origin(0).0);
    let scale = Scale::new(&panels, false, None);
    let (x0, y0) = d.l.origin(0);
    let rgb = |v: f64| {
        let c = scale.colour(v);
        [c.0, c.1, c.2]
    };
    let top = d.img.get_pixel((x0 + 700) as u32, (y0 + 1) as u32).0;
    let bottom = d.img.get_pixel((x0 + 700) as u32, (y0 + 193) as u32).0;
    assert_eq!((top, bottom), (rgb(64.0), rgb(0.0)));
    let i = 32 * nx + 100;
    let c = scale.colour(wave[i]);
    assert_eq!(d.at_cell(1, i), [c.0, c.1, c.2]);
    for k in 0..2 {
        assert!(reddish(d.at_cell(k, 5)));
        assert!(bluish(d.at_cell(k, 64 * nx + 500)));
    }
    let (top, bottom) = bar_ends(&d.img, &d.l, false);
    assert_ne!(top, bottom);
    // the markers moved with the rows: index 5 (row 0) is drawn at the bottom
    assert!(d.view.centre(d.l.panel, 5).1 > 190.0 && d.view.centre(d.l.panel, 64 * nx + 500).1 < 5.0);

    // with isolines as well; level -64 + 128 * 5/7 = 27.43 crosses the rows field 0.43 of the way
    // from row 27 (drawn row 37, centred at 112.5 px) to row 28: at 112.5 - 0.43 * 3 = 111.2 px
    let opts = GridPlotOptions { isolines: 6, ..Default::default() };
    let d = plot("wide_iso", nx, ny, &panels, &markers, &opts);
    let (x0, y0) = d.l.origin(0);
    let dark = |y: i32| (5..1535).filter(|&x| d.img.get_pixel((x0 + x) as u32, (y0 + y) as u32).0 == ISO).count();
    assert_eq!(dark(111), 1530);

    // placed as a raster (row 0 at y = ny − 1, dy = −1): row 0 at the top, the isoline at
    // (27.5 + 0.43) * 3 = 83.8 px
    let raster = crate::io::grid::raster_grid(nx, ny, [1.0, 1.0]).unwrap();
    let opts =
        GridPlotOptions { isolines: 6, origin: raster.origin(), spacing: raster.spacing(), ..Default::default() };
    let d = plot("wide_down", nx, ny, &panels, &markers, &opts);
    let (x0, y0) = d.l.origin(0);
    let top = d.img.get_pixel((x0 + 700) as u32, (y0 + 1) as u32).0;
    let bottom = d.img.get_pixel((x0 + 700) as u32, (y0 + 193) as u32).0;
    assert_eq!((top, bottom), (rgb(0.0), rgb(64.0)));
    let dark = |y: i32| (5..1535).filter(|&x| d.img.get_pixel((x0 + x) as u32, (y0 + y) as u32).0 == ISO).count();
    assert_eq!(dark(84), 1530);
    assert!(reddish(d.at_cell(0, 5)) && d.view.centre(d.l.panel, 5).1 < 5.0);
}

#[test]
fn grid_constant_and_degenerate() {
    let (nx, ny) = (20, 20);
    let constant = vec![5.0; nx * ny];
    let m = [GridMarker { index: 210, is_max: true }, GridMarker { index: 0, is_max: false }];
    for diverging in [false, true] {
        let opts = GridPlotOptions { isolines: 4, diverging, ..Default::default() };
        let d = plot("constant", nx, ny, &[panel("c", &constant)], &m, &opts);
        assert_eq!((d.l.panel, d.l.stacked), ((400, 400), false));
        assert!(reddish(d.at_cell(0, 210)));
        let c = Scale::new(&[panel("c", &constant)], diverging, None).colour(5.0);
        assert_eq!(d.at_cell(0, 5 * nx + 5), [c.0, c.1, c.2]);
        let (top, bottom) = bar_ends(&d.img, &d.l, false);
        assert_ne!(top, bottom);
    }
    // all NaN: grey, no error
    let nan = vec![f64::NAN; nx * ny];
    let d = plot("all_nan", nx, ny, &[panel("a", &nan), panel("b", &nan)], &m, &Default::default());
    assert_eq!(d.at_cell(1, 5 * nx + 5), GREY);
    assert_ne!(bar_ends(&d.img, &d.l, true).0, bar_ends(&d.img, &d.l, true).1);
    // a single finite value, next to an all-NaN panel, with infinities and isolines
    let mut one = nan.clone();
    one[7] = -3.0;
    one[8] = f64::INFINITY;
    let opts = GridPlotOptions { isolines: 3, diverging: true, ..Default::default() };
    let d = plot("single", nx, ny, &[panel("one", &one), panel("nan", &nan)], &[], &opts);
    assert!(bluish(d.at_cell(0, 7)));
    assert!(reddish(d.at_cell(0, 8)), "∞ clamps to the top colour");
    // 1×1 grid, 1×n and n×1 grids, a non-unit aspect
    plot("one_cell", 1, 1, &[panel("p", &[2.0])], &[GridMarker { index: 0, is_max: true }], &Default::default());
    let line: Vec<f64> = (0..300).map(|i| i as f64).collect();
    plot("row", 300, 1, &[panel("p", &line), panel("q", &line)], &[], &Default::default());
    plot("column", 1, 300, &[panel("p", &line), panel("q", &line)], &[], &Default::default());
    let opts = GridPlotOptions { spacing: [0.5, -1.0], ..Default::default() };
    let v: Vec<f64> = (0..800).map(|i| i as f64).collect();
    let d = plot("aspect", 40, 20, &[panel("p", &v)], &[], &opts);
    assert_eq!(d.l.panel, (400, 400));
}

#[test]
fn grid_large_is_sampled_down() {
    let n = 1000;
    let v: Vec<f64> = (0..n * n).map(|i| ((i / n) as f64 / 50.0).sin() + ((i % n) as f64 / 70.0).cos()).collect();
    let m = [GridMarker { index: 500 * n + 500, is_max: true }];
    let opts = GridPlotOptions { isolines: 10, ..Default::default() };
    let d = plot("large", n, n, &[panel("a", &v), panel("b", &v)], &m, &opts);
    assert_eq!((d.l.size, d.l.panel, d.l.stacked), ((2000, 957), (825, 825), false));
    assert!(reddish(d.at_cell(1, 500 * n + 500)));
    for k in 1..=8 {
        let l = Layout::new(n, n, k, 1.0);
        assert!(d.l.size.0 <= MAX_W && d.l.size.1 <= MAX_H, "{k} panels: {l:?}");
    }
    let l = Layout::new(63, 63, 4, 1.0);
    assert!(d.l.panel.0 >= 400 && d.l.size.0 <= MAX_W, "{l:?}");
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
    for bad in [0.0, f64::NAN, f64::INFINITY] {
        for spacing in [[bad, 1.0], [1.0, bad]] {
            assert!(plot_grid_fields(&mut p, 2, 3, &ok, &[], "t", &GridPlotOptions { spacing, ..o }).is_err());
        }
    }
    for bad in [f64::NAN, f64::NEG_INFINITY] {
        assert!(plot_grid_fields(&mut p, 2, 3, &ok, &[], "t", &GridPlotOptions { origin: [0.0, bad], ..o }).is_err());
    }
    let far = GridPlotOptions { origin: [1.7e308, 0.0], spacing: [1e308, 1.0], ..o };
    assert!(plot_grid_fields(&mut p, 2, 3, &ok, &[], "t", &far).is_err(), "the extent overflows");
    let many = vec![panel("p", &v[..]); 65];
    assert!(plot_grid_fields(&mut p, 2, 3, &many, &[], "t", &o).is_err());
    assert!(p.is_empty(), "nothing is written before the checks pass");
}

#[test]
fn contours_cross_where_expected() {
    // a ramp in x: the level 1.5 lies halfway between columns 1 and 2, on every row
    let (nx, ny) = (4, 3);
    let v: Vec<f64> = (0..nx * ny).map(|i| (i % nx) as f64).collect();
    let view = View::new(nx, ny, &GridPlotOptions::default());
    let segs = contour_segments(&v, &view, (40, 30), &[1.5]);
    assert!(!segs.is_empty());
    for (a, b) in &segs {
        assert!((a.0 - 20.0).abs() < 1e-9 && (b.0 - 20.0).abs() < 1e-9, "{a:?} {b:?}");
    }
    let mut holed = v.clone();
    holed[5] = f64::NAN;
    assert!(contour_segments(&holed, &view, (40, 30), &[1.5]).len() < segs.len());
    assert!(contour_segments(&v, &view, (40, 30), &[]).is_empty());
    assert!(contour_segments(&v, &View::new(nx, 1, &GridPlotOptions::default()), (40, 30), &[1.5]).is_empty());
}

#[test]
fn view_follows_the_coordinates() {
    // 3 × 4 grid, origin (1, 4), spacing (0.5, −2): x 1..2, y −2..4, row 0 (y = 4) on top
    let o = GridPlotOptions { origin: [1.0, 4.0], spacing: [0.5, -2.0], ..Default::default() };
    let v = View::new(3, 4, &o);
    assert_eq!(v.ranges(), [(1.0, 2.0), (-2.0, 4.0)]);
    assert_eq!((v.centre((30, 40), 0), v.centre((30, 40), 11)), ((5.0, 5.0), (25.0, 35.0)));
    assert_eq!((v.pixel(0, 2.0, 30), v.pixel(1, 4.0, 40), v.pixel(1, -2.0, 40)), (25.0, 5.0, 35.0));
    // the same points stored with rows and columns reversed: the same view of every point
    let r = View::new(3, 4, &GridPlotOptions { origin: [2.0, -2.0], spacing: [-0.5, 2.0], ..Default::default() });
    assert_eq!(r.ranges(), v.ranges());
    for i in 0..12 {
        let (row, col) = (i / 3, i % 3);
        assert_eq!(r.centre((30, 40), (3 - row) * 3 + (2 - col)), v.centre((30, 40), i));
    }
}

#[test]
fn axes_are_labelled_in_the_file_coordinates() {
    let o = GridPlotOptions { origin: [100.0, 4.0], spacing: [0.5, -2.0], ..Default::default() };
    let v = View::new(21, 11, &o); // x 100..110, y −16..4
    let (xs, ys) = (axis_marks(&v, 0, (420, 220)), axis_marks(&v, 1, (420, 220)));
    let labels = |m: &[(i32, String)]| m.iter().map(|t| t.1.clone()).collect::<Vec<_>>();
    assert_eq!(labels(&xs), ["100.0", "105.0", "110.0"]);
    assert_eq!((xs[0].0, xs[2].0), (10, 410), "the end ticks sit on the end columns' centres");
    // y = −10 is drawn row (4 + 10) / 2 = 7, centred at 7.5 · 20 px; y = 0 is row 2: higher up
    assert_eq!(ys, [(150, "-10.0".to_string()), (50, "0.0".to_string())]);
    assert_eq!(axis_ticks(3.0, 3.0, 5), [3.0]);

    // drawn: dark label pixels left of the panel and below it
    let values: Vec<f64> = (0..21 * 11).map(|i| i as f64).collect();
    let d = plot("axes", 21, 11, &[panel("p", &values)], &[], &o);
    let ((x0, y0), (pw, ph)) = (d.l.origin(0), d.l.panel);
    let dark = |xs: std::ops::Range<i32>, ys: std::ops::Range<i32>| {
        let img = &d.img;
        ys.flat_map(|y| xs.clone().map(move |x| img.get_pixel(x as u32, y as u32).0)).filter(|p| p[0] < 100).count()
    };
    assert!(dark(x0 - AXIS_W as i32..x0 - 8, y0..y0 + ph as i32) > 100, "y tick labels");
    assert!(dark(x0..x0 + pw as i32, y0 + ph as i32 + 6..y0 + ph as i32 + AXIS_H as i32) > 100, "x tick labels");
}

#[test]
fn larger_y_is_drawn_on_top_whatever_the_spacing_sign() {
    // h = y + x/10 on 30 × 20 points x = 0..29, y = 0..19, stored with dy = +1 (row r at y = r)
    // and with dy = −1 (row r at y = 19 − r), and with dx = −1 as well
    let (nx, ny) = (30, 20);
    let h = |x: f64, y: f64| y + x / 10.0;
    let sample = |o: &GridPlotOptions| -> Vec<f64> {
        (0..nx * ny)
            .map(|i| {
                let (r, c) = ((i / nx) as f64, (i % nx) as f64);
                h(o.origin[0] + c * o.spacing[0], o.origin[1] + r * o.spacing[1])
            })
            .collect()
    };
    let up = GridPlotOptions { diverging: false, ..Default::default() };
    let down = GridPlotOptions { origin: [0.0, 19.0], spacing: [1.0, -1.0], ..up };
    let both = GridPlotOptions { origin: [29.0, 19.0], spacing: [-1.0, -1.0], ..up };
    // the maximum (29, 19) and the minimum (0, 0) as markers, at their indices in each storage
    let marks = |v: &[f64]| {
        let arg = |best: fn(f64, f64) -> bool| (0..v.len()).reduce(|a, b| if best(v[b], v[a]) { b } else { a });
        let (max, min) = (arg(|a, b| a > b).unwrap_or(0), arg(|a, b| a < b).unwrap_or(0));
        [GridMarker { index: max, is_max: true }, GridMarker { index: min, is_max: false }]
    };
    let mut pictures = Vec::new();
    for (name, o) in [("up", up), ("down", down), ("both", both)] {
        let v = sample(&o);
        let m = marks(&v);
        let d = plot(name, nx, ny, &[panel("h", &v)], &m, &o);
        let scale = Scale::new(&[panel("h", &v)], false, None);
        let (x0, y0) = d.l.origin(0);
        let (pw, ph) = d.l.panel;
        // the top of the middle column is the point (15, 19), its bottom (15, 0)
        let c = |v: f64| {
            let c = scale.colour(v);
            [c.0, c.1, c.2]
        };
        let px = |x: i32, y: i32| d.img.get_pixel((x0 + x) as u32, (y0 + y) as u32).0;
        let mid = pw as i32 / 2 + 1;
        assert_eq!((px(mid, 2), px(mid, ph as i32 - 3)), (c(h(15.0, 19.0)), c(h(15.0, 0.0))), "{name}");
        // the maximum's marker at the top right, the minimum's at the bottom left
        assert!(reddish(px(pw as i32 - pw as i32 / 60, ph as i32 / 40)), "{name}");
        assert!(bluish(px(pw as i32 / 60, ph as i32 - ph as i32 / 40)), "{name}");
        pictures.push(d.img);
    }
    for p in &pictures[1..] {
        // below the title (which names the plot)
        let below = p.enumerate_pixels().filter(|(_, y, _)| *y >= TITLE_H);
        let differ: Vec<_> = below.filter(|(x, y, q)| pictures[0].get_pixel(*x, *y) != *q).take(5).collect();
        assert!(differ.is_empty(), "the same field gives the same picture: {differ:?}");
    }
}

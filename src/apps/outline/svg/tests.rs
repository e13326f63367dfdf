use super::*;

fn close(a: &[[f64; 2]], b: &[[f64; 2]]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(p, q)| (p[0] - q[0]).abs() < 1e-5 && (p[1] - q[1]).abs() < 1e-5)
}

fn read(svg: &str) -> Loops {
    read_svg(svg.as_bytes()).unwrap_or_else(|e| panic!("{e}"))
}

fn err(svg: &str) -> String {
    read_svg(svg.as_bytes()).unwrap_err().to_string()
}

#[test]
fn relative_and_absolute_path_commands() {
    // a 10 × 10 square with a 2 × 2 square hole, relative commands; implicit linetos
    let loops = read(r#"<svg><path d="m 0,0 h 10 v 10 h -10 z M2 2l2 0 0 2-2 0Z"/></svg>"#);
    assert_eq!(loops.len(), 2);
    let clean = |l: &[[f64; 2]]| super::super::shape::clean_loop(l);
    assert!(close(&clean(&loops[0]), &[[0.0, 0.0], [10.0, 0.0], [10.0, -10.0], [0.0, -10.0]]), "{:?}", loops[0]);
    assert!(close(&clean(&loops[1]), &[[2.0, -2.0], [4.0, -2.0], [4.0, -4.0], [2.0, -4.0]]), "{:?}", loops[1]);
}

#[test]
fn curves_are_flattened_within_the_tolerance() {
    // a disk of radius 10 (usvg: four cubics), alone: the drawing's diagonal is 20 √2
    let loops = read(r#"<svg><circle cx="50" cy="50" r="10"/></svg>"#);
    let tol = CURVE_TOLERANCE * 20.0 * 2f64.sqrt();
    let l = &loops[0];
    for p in l {
        let d = (p[0] - 50.0).hypot(p[1] + 50.0);
        // corners on the cubics: within 0.03 % of the radius of the circle
        assert!((d - 10.0).abs() < 3e-3, "{d}");
    }
    for (p, q) in l.iter().zip(l.iter().skip(1)) {
        // each chord's middle within the tolerance of the circle
        let m = [(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0];
        let d = (m[0] - 50.0).hypot(m[1] + 50.0);
        assert!(10.0 - d < tol + 3e-3, "{}", 10.0 - d);
    }
    // not finer than twice what the tolerance asks: a chord of sagitta tol spans 2 acos(1 − tol/r)
    let needed = (2.0 * std::f64::consts::PI / (2.0 * (1.0 - tol / 10.0).acos())).ceil() as usize;
    assert!(l.len() >= needed && l.len() <= 2 * needed + 4, "{} corners, {needed} needed", l.len());
    // a quadratic and a cubic end where they should
    let loops = read(r#"<svg><path d="M0 0 Q5 10 10 0 C10 -5 0 -5 0 0z"/></svg>"#);
    assert!(loops[0].iter().any(|p| close(&[*p], &[[10.0, 0.0]])));
    // the quadratic's top is at y = 5 (y negated), within the tolerance of a drawing whose
    // points and control points span 10 × 15
    let top = loops[0].iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
    assert!((top + 5.0).abs() <= CURVE_TOLERANCE * 10f64.hypot(15.0), "{top}");
}

#[test]
fn documents_with_transforms_and_hidden_shapes() {
    let svg = r#"<?xml version="1.0"?>
<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">
  <defs><rect x="0" y="0" width="1" height="1"/></defs>
  <g transform="translate(10, 20) scale(2)">
    <polygon points="0,0 10,0 10,10 0,10"/>
    <path transform="rotate(90 5 5)" d="M4 4 h2 v2 h-2 z"/>
  </g>
  <circle cx="0" cy="0" r="1" transform="matrix(1 0 0 1 25 35)"/>
</svg>"#;
    let loops = read(svg);
    assert_eq!(loops.len(), 3);
    // y negated
    assert!(close(&loops[0], &[[10.0, -20.0], [30.0, -20.0], [30.0, -40.0], [10.0, -40.0]]), "{:?}", loops[0]);
    // rotating the small square by 90° about its centre (5, 5) maps (4, 4) to (6, 4)
    assert!(close(&loops[1][..1], &[[22.0, -28.0]]), "{:?}", loops[1]);
    // usvg draws a circle from (cx + r, cy)
    assert!(close(&loops[2][..1], &[[26.0, -35.0]]), "{:?}", loops[2]);
    for (text, needle) in [
        (r#"<svg><path transform="perspective(1)" d="M0 0 L1 0 L0 1z"/></svg>"#, "`transform=\"perspective(1)\"`"),
        (r#"<svg><polygon points="0 0 1"/></svg>"#, "odd number"),
        (r#"<svg><g/></svg>"#, "no shape"),
        (r#"<svg><rect width="4" height="4" fill="none" stroke="black"/></svg>"#, "1 visible shape is without fill"),
        (r#"<html/>"#, "not an SVG"),
        (r#"<svg><rect width="1" height="1e999"/></svg>"#, "not a finite number"),
        (r#"<svg><rect width="1" height="1e39"/></svg>"#, "not a finite number"),
        (r#"<svg><path d="M0 0 L1"/></svg>"#, "`d` cannot be read after command 1"),
        (r#"<svg><ellipse rx="-1" ry="2"/></svg>"#, "`rx=\"-1\"` is negative: a radius"),
        (r#"<svg><rect width="2" height="-2"/></svg>"#, "`height=\"-2\"` is negative: a size"),
        (r#"<svg><circle r="two"/></svg>"#, "not a length"),
        ("<svg><rect", "malformed XML"),
    ] {
        let e = err(text);
        assert!(e.contains(needle), "{text}: {e}");
    }
    let e = err("<svg>\n  <path d=\"M0 0 Lx\"/></svg>");
    assert!(e.starts_with("<path> at line 2, column 3: "), "{e}");
    let e = err("<svg>\n<circle id=\"c\" r=\"-3\"/></svg>");
    assert!(e.starts_with("<circle id=\"c\"> at line 2, column 1: `r=\"-3\"` is negative"), "{e}");
}

#[test]
fn loops_are_named_after_their_elements() {
    // the second subpath of the path crosses the rectangle
    let svg = "<svg>\n<rect width=\"10\" height=\"10\"/>\n<path id=\"p\" d=\"M1 1h1v1h-1z M5 5 L12 6 L5 7z\"/></svg>";
    let e = err(svg);
    assert!(e.contains("hole 2 (<path id=\"p\"> at line 3, column 1, subpath 2)"), "{e}");
    assert!(e.contains("the outer boundary (<rect> at line 2, column 1)"), "{e}");
}

#[test]
fn the_view_box_is_undone() {
    // 100 user units drawn on 50 mm, centred in a wider viewport (xMidYMid meet)
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="50mm" viewBox="-10 0 100 100">
  <rect x="-10" y="0" width="100" height="100"/>
</svg>"#;
    let loops = read(svg);
    assert!(close(&loops[0], &[[-10.0, 0.0], [90.0, 0.0], [90.0, -100.0], [-10.0, -100.0]]), "{:?}", loops[0]);
    // slice and the other alignments
    for aspect in ["xMinYMin slice", "xMaxYMax meet", "none"] {
        let svg = format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="30" height="70" viewBox="5 5 10 20" preserveAspectRatio="{aspect}"><rect x="6" y="7" width="2" height="3"/></svg>"#
        );
        let loops = read(&svg);
        assert!(close(&loops[0], &[[6.0, -7.0], [8.0, -7.0], [8.0, -10.0], [6.0, -10.0]]), "{aspect}: {:?}", loops[0]);
    }
}

#[test]
fn clones_are_named_after_their_use() {
    let svg = "<svg>\n<defs><circle id=\"dot\" r=\"1\"/></defs>\n<rect width=\"10\" height=\"10\"/>\n<use href=\"#dot\" x=\"20\" y=\"5\"/></svg>";
    let e = err(svg);
    assert!(e.contains("hole 1 (a clone by <use> at line 4, column 1) is not inside"), "{e}");
    // a <line> and a two-point polyline enclose nothing: left out
    let loops = read(r#"<svg><rect width="10" height="10"/><line x2="5" y2="5"/><polyline points="1 1 2 2"/></svg>"#);
    assert_eq!(loops.len(), 1);
}

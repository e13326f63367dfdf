//! `toposmooth extrema`: list the extrema with persistence and strictness; draw the diagram.

use super::{check_distinct, check_png_name, sig6, stage_plot};
use crate::domain::{AnyDomain, Domain};
use crate::error::{Error, Result};
use crate::io::import::{read_field, Field, ReadOptions};
use crate::io::series_csv::XSource;
use crate::plot::{plot_persistence_diagram, DiagramPoint};
use crate::topology::{extrema_table, select, ExtremumKind, KeptSet, Role, Selection};
use std::path::{Path, PathBuf};

/// Options of `extrema`.
#[derive(Clone, Debug)]
pub struct ExtremaArgs {
    /// Input file (none when a grid comes from `--u`/`--v`).
    pub input: Option<PathBuf>,
    /// How to read it.
    pub read: ReadOptions,
    /// Print JSON instead of a table.
    pub json: bool,
    /// Persistence diagram PNG.
    pub plot: Option<PathBuf>,
    /// Persistence diagram in TTK's layout (`.vtu`).
    pub diagram: Option<PathBuf>,
    /// Selection whose kept extrema are marked (default: SPEC's 5 %).
    pub selection: Selection,
}

#[derive(serde::Serialize)]
struct Listing<'a> {
    file: String,
    column: &'a str,
    /// `[columns, rows]` for a grid.
    grid: Option<[usize; 2]>,
    samples: usize,
    sos_minima: usize,
    sos_maxima: usize,
    ends: usize,
    strict_minima: usize,
    strict_maxima: usize,
    threshold: Option<f64>,
    extrema: Vec<Row<'a>>,
}

#[derive(serde::Serialize)]
struct Row<'a> {
    #[serde(flatten)]
    info: &'a crate::topology::ExtremumInfo,
    #[serde(flatten)]
    place: serde_json::Map<String, serde_json::Value>,
    kept: bool,
    /// The table's text for the place.
    #[serde(skip)]
    label: String,
}

/// Where a vertex is, as JSON: on a series `x` (the domain's coordinate: days since 1970-01-01
/// for dates, which also get `x_text`, the file's text), on a grid `row`, `col` and `position`
/// [x, y] in the file's coordinates, on a mesh `position` [x, y, z].
fn place(field: &Field, i: usize) -> serde_json::Map<String, serde_json::Value> {
    use serde_json::{json, Map};
    let mut m = Map::new();
    match &field.domain {
        AnyDomain::Series(s) => {
            m.insert("x".into(), json!(s.x()[i]));
            if let Some(axis) = field.axis.as_ref().filter(|a| matches!(a.source, XSource::Dates(..))) {
                m.insert("x_text".into(), json!(axis.x_text.get(i)));
            }
        }
        AnyDomain::Grid(g) => {
            let (r, c) = g.row_col(i);
            let ([dx, dy], [ox, oy]) = (g.spacing(), g.origin());
            m.insert("row".into(), json!(r));
            m.insert("col".into(), json!(c));
            m.insert("position".into(), json!([ox + c as f64 * dx, oy + r as f64 * dy]));
        }
        AnyDomain::Mesh(mesh) => {
            m.insert("position".into(), json!(mesh.positions()[i]));
        }
        AnyDomain::Tets(mesh) => {
            m.insert("position".into(), json!(mesh.positions()[i]));
        }
        AnyDomain::Volume(g) => {
            let ijk = g.ijk(i);
            m.insert("ijk".into(), json!(ijk));
            m.insert("position".into(), json!(g.world(i)));
        }
    }
    m
}

/// Runs `extrema`; returns the text printed on standard output.
pub fn extrema(args: &ExtremaArgs) -> Result<String> {
    check_png_name(args.plot.as_deref())?;
    let inputs: Vec<&Path> = args.input.iter().map(PathBuf::as_path).collect();
    check_distinct(&inputs, &[("--plot", args.plot.as_deref()), ("--diagram", args.diagram.as_deref())])?;
    if let Some(d) = &args.diagram {
        crate::io::ttk::check_diagram_output(d)?;
    }
    let path = args.input.clone().unwrap_or_default();
    let field = read_field(args.input.as_deref(), &args.read)?.into_field(&path)?;
    let text = crate::with_domain!(&field.domain, d => list(args, &field, d)?);
    if args.json {
        return Ok(text);
    }
    Ok(field.notes.iter().map(|n| format!("note: {n}\n")).collect::<String>() + &text)
}

/// Where a vertex is, as the table prints it: the x text, `(row,col)` or `(x,y,z)`.
fn label(field: &Field, i: usize) -> String {
    match &field.domain {
        AnyDomain::Series(_) => {
            field.axis.as_ref().map(|a| a.x_text.get(i).into_owned()).unwrap_or_else(|| i.to_string())
        }
        AnyDomain::Grid(g) => {
            let (r, c) = g.row_col(i);
            format!("({r},{c})")
        }
        AnyDomain::Mesh(_) | AnyDomain::Tets(_) => {
            let p = crate::with_domain!(&field.domain, d => d.point(i));
            format!("({},{},{})", sig6(p[0]), sig6(p[1]), sig6(p[2]))
        }
        AnyDomain::Volume(g) => {
            let [a, b, c] = g.ijk(i);
            format!("({a},{b},{c})")
        }
    }
}

fn list<D: Domain>(args: &ExtremaArgs, field: &Field, domain: &D) -> Result<String> {
    let (path, h, column) = (&field.path, &field.values, field.description.as_str());
    let grid = match &field.domain {
        AnyDomain::Grid(g) => Some([g.nx(), g.ny()]),
        _ => None,
    };
    let mesh = match &field.domain {
        AnyDomain::Mesh(m) => Some(format!("mesh of {}", m.describe())),
        AnyDomain::Volume(_) | AnyDomain::Tets(_) => Some(field.domain.describe()),
        _ => None,
    };
    let label = |i: usize| label(field, i);
    let surface = grid.is_some() || mesh.is_some();
    let table = extrema_table(domain, h);
    let kept = select(domain, h, &args.selection).map_err(|e| e.in_file(path))?;
    let count = |k: ExtremumKind, strict: bool| table.iter().filter(|r| r.kind == k && (!strict || r.strict)).count();
    let listing = Listing {
        file: path.display().to_string(),
        column,
        grid,
        samples: h.len(),
        sos_minima: count(ExtremumKind::Min, false),
        sos_maxima: count(ExtremumKind::Max, false) + count(ExtremumKind::End, false),
        ends: count(ExtremumKind::End, false),
        strict_minima: count(ExtremumKind::Min, true),
        strict_maxima: count(ExtremumKind::Max, true) + count(ExtremumKind::End, true),
        threshold: kept.threshold,
        extrema: table
            .iter()
            .map(|r| Row {
                info: r,
                place: place(field, r.index),
                kept: matches!(kept.roles[r.index], Role::Min | Role::Max),
                label: label(r.index),
            })
            .collect(),
    };
    if let Some(plot_path) = &args.plot {
        stage_diagram(plot_path, path, column, &table, h, &kept, surface)?.commit()?;
    }
    if let Some(d) = &args.diagram {
        let pairs = crate::io::ttk::diagram_pairs(domain, h, &table, field.domain.dimension());
        crate::io::ttk::stage_diagram(d, &field.domain, &pairs, &kept.roles)?.commit()?;
    }
    if args.json {
        return serde_json::to_string_pretty(&listing).map_err(|e| Error::input(e.to_string()));
    }
    Ok(table_text(&listing, grid, mesh, surface, &kept))
}

/// The persistence diagram: one point per minimum (birth, death), and on surfaces one per
/// maximum below the diagonal; kept points filled.
fn stage_diagram(
    plot_path: &Path,
    path: &Path,
    column: &str,
    table: &[crate::topology::ExtremumInfo],
    h: &[f64],
    kept: &KeptSet,
    surface: bool,
) -> Result<crate::io::Staged> {
    let mut points = Vec::new();
    // a series pairs each maximum with a minimum (one point per pair); on a grid the
    // maxima have their own superlevel-set pairs, drawn below the diagonal
    for r in table {
        match r.kind {
            ExtremumKind::Min => {
                let death = r.partner.map(|p| h[p]).unwrap_or(f64::INFINITY);
                let kept = kept.roles[r.index] == Role::Min;
                points.push(DiagramPoint { birth: r.value, death, is_max: false, kept });
            }
            ExtremumKind::Max if surface => {
                let death = r.partner.map(|p| h[p]).unwrap_or(f64::NEG_INFINITY);
                let kept = kept.roles[r.index] == Role::Max;
                points.push(DiagramPoint { birth: r.value, death, is_max: true, kept });
            }
            _ => {}
        }
    }
    let title =
        format!("{} — {} ({} points)", path.file_name().unwrap_or_default().to_string_lossy(), column, points.len());
    stage_plot(plot_path, |p| plot_persistence_diagram(p, &points, kept.threshold, &title, (900, 800)))
}

/// The table of extrema and its summary lines.
fn table_text(
    listing: &Listing,
    grid: Option<[usize; 2]>,
    mesh: Option<String>,
    surface: bool,
    kept: &KeptSet,
) -> String {
    let mut out = String::new();
    out += &format!(
        "{:>8} {:>12} {:>9} {:>14} {:>14} {:>6} {:>4}\n",
        "index",
        match (grid, &mesh) {
            (Some(_), _) => "(row,col)",
            (_, Some(_)) => "(x,y,z)",
            _ => "x",
        },
        "type",
        "value",
        "persistence",
        "strict",
        "kept"
    );
    for row in &listing.extrema {
        let r = row.info;
        let kind = match r.kind {
            ExtremumKind::Min if r.endpoint => "min (end)",
            ExtremumKind::Min => "min",
            ExtremumKind::Max => "max",
            ExtremumKind::End => "end",
        };
        let pers = match r.persistence {
            None => "-".to_string(),
            Some(p) if p.is_infinite() => "inf".to_string(),
            Some(p) => sig6(p),
        };
        out += &format!(
            "{:>8} {:>12} {:>9} {:>14} {:>14} {:>6} {:>4}\n",
            r.index,
            row.label,
            kind,
            sig6(r.value),
            pers,
            if r.strict { "yes" } else { "no" },
            if row.kept { "yes" } else { "" }
        );
    }
    let what = match (grid, mesh) {
        (Some([nx, ny]), _) => format!("{nx} × {ny} grid"),
        (None, Some(m)) => m,
        (None, None) => format!("{} samples", listing.samples),
    };
    out += &format!(
        "{}: {what} of `{}`; SoS extrema: {} minima, {} maxima{}; strict in the raw values: {} minima, {} maxima\n",
        listing.file,
        listing.column,
        listing.sos_minima,
        listing.sos_maxima,
        if surface { " (boundary included)".to_string() } else { format!(" (incl. {} ends)", listing.ends) },
        listing.strict_minima,
        listing.strict_maxima
    );
    if let Some(t) = kept.threshold {
        out += &format!(
            "kept at persistence ≥ {}: {} minima, {} maxima\n",
            sig6(t),
            kept.minima().len(),
            kept.maxima().len()
        );
    }
    out
}

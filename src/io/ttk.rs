//! The Topology ToolKit's layouts, so that TTK's filters and a TTK user's ParaView state read
//! our critical points and persistence diagrams as their own (codes from TTK's
//! `core/base/common/DataTypes.h` and `ttkPersistenceDiagramUtils.cpp`).
//!
//! * `CriticalType` (Int32): 0 minimum, 1 1-saddle, 2 2-saddle, 3 maximum, 4 degenerate,
//!   5 regular. On surfaces every saddle is a 1-saddle; in volumes the saddle a minimum dies
//!   at is a 1-saddle and the saddle a maximum dies at a 2-saddle.
//! * `PairType` (Int32): 0 minimum–saddle, 1 saddle–maximum on surfaces (in volumes: 0
//!   minimum–1-saddle, 2 2-saddle–maximum; TTK's 1 1-saddle–2-saddle pairs are not
//!   computed); −1 the diagonal.
//! * `SeparatrixType` (Int32): 0 descending (saddle to minimum), 1 ascending on surfaces
//!   (volumes: 0 descending, 1 saddle connector, 2 ascending).
//!
//! The diagram is TTK's: one line cell per pair from (birth, birth, 0) to (birth, death, 0),
//! point data `ttkVertexScalarField` (the vertex), `CriticalType` and `Coordinates` (Float32,
//! the vertex's position), cell data `PairIdentifier`, `PairType`, `Persistence`, `Birth`,
//! `IsFinite` (UInt8), then the diagonal from the first point to the pair born highest, with
//! `PairIdentifier` = `PairType` = −1 and `Persistence` twice the first pair's. The essential
//! pair of each connected part (its global minimum with its global maximum) comes first, once,
//! with `IsFinite` 0 and `PairType` 0, as TTK writes it. We add a cell array `Kept` (UInt8):
//! whether the pair's extremum is kept. Vertex ids are the domain's vertices; TTK's
//! separatrix `SourceId`/`DestinationId` are cell ids of its discrete gradient, ours the
//! saddle's and the extremum's vertex ids.

use super::vtk::{stage_vtu_cells, Cells, OutArray, Scalar};
use super::Staged;
use crate::domain::{AnyDomain, Domain};
use crate::error::Result;
use crate::topology::{ExtremumInfo, ExtremumKind, Role};
use std::path::Path;

/// TTK's `CriticalType` codes.
pub mod critical {
    /// A local minimum.
    pub const MINIMUM: i32 = 0;
    /// A 1-saddle (every saddle of a surface).
    pub const SADDLE1: i32 = 1;
    /// A 2-saddle (volumes).
    pub const SADDLE2: i32 = 2;
    /// A local maximum.
    pub const MAXIMUM: i32 = 3;
    /// A vertex of more than one kind (in a volume: a 1-saddle and a 2-saddle).
    pub const DEGENERATE: i32 = 4;
    /// A regular vertex.
    pub const REGULAR: i32 = 5;
}

/// One pair of the diagram.
#[derive(Clone, Debug, PartialEq)]
pub struct DiagramPair {
    /// The vertex where it is born (the lower one) and where it dies.
    pub vertices: [usize; 2],
    /// Their `CriticalType`.
    pub types: [i32; 2],
    /// `PairType`.
    pub pair_type: i32,
    /// Birth and death values.
    pub values: [f64; 2],
    /// False for the essential pair of a connected part.
    pub finite: bool,
    /// The vertex of the pair that is the extremum the selection keeps or cancels (the
    /// maximum of a saddle–maximum pair, the minimum otherwise).
    pub extremum: usize,
}

impl DiagramPair {
    /// `death − birth`.
    pub fn persistence(&self) -> f64 {
        self.values[1] - self.values[0]
    }
}

/// The connected part of each vertex.
fn components<D: Domain + ?Sized>(domain: &D) -> Vec<usize> {
    let n = domain.n_vertices();
    let mut part = vec![usize::MAX; n];
    let mut next = 0;
    let mut stack = Vec::new();
    for s in 0..n {
        if part[s] != usize::MAX {
            continue;
        }
        part[s] = next;
        stack.push(s);
        while let Some(v) = stack.pop() {
            for w in domain.neighbors(v) {
                if part[w] == usize::MAX {
                    part[w] = next;
                    stack.push(w);
                }
            }
        }
        next += 1;
    }
    part
}

/// The persistence pairs of `h` in TTK's terms, the essential pairs first: on a series
/// (`dimension` 1) each minimum with the maximum it dies at; on a surface (2) each minimum with
/// its saddle and each maximum with its saddle; in a volume (3) each minimum with its 1-saddle
/// (`PairType` 0) and each maximum with its 2-saddle (`PairType` 2; the 1-saddle–2-saddle
/// pairs of TTK's diagram are not computed); each connected part's global minimum with its
/// global maximum.
pub fn diagram_pairs<D: Domain + ?Sized>(
    domain: &D,
    h: &[f64],
    table: &[ExtremumInfo],
    dimension: usize,
) -> Vec<DiagramPair> {
    use critical::{MAXIMUM, MINIMUM, SADDLE1, SADDLE2};
    let surface = dimension >= 2;
    let (max_saddle, max_pair) = if dimension >= 3 { (SADDLE2, 2) } else { (SADDLE1, 1) };
    let part = components(domain);
    let parts = part.iter().max().map_or(0, |m| m + 1);
    let mut top: Vec<Option<usize>> = vec![None; parts];
    for v in 0..h.len() {
        let t = &mut top[part[v]];
        if t.is_none_or(|u| crate::domain::sos_less(h, u, v)) {
            *t = Some(v);
        }
    }
    let (mut essential, mut finite) = (Vec::new(), Vec::new());
    for r in table {
        match (r.kind, r.partner) {
            (ExtremumKind::Min, None) => {
                let max = top[part[r.index]].unwrap_or(r.index);
                essential.push(DiagramPair {
                    vertices: [r.index, max],
                    types: [MINIMUM, MAXIMUM],
                    pair_type: 0,
                    values: [h[r.index], h[max]],
                    finite: false,
                    extremum: r.index,
                });
            }
            (ExtremumKind::Min, Some(p)) => finite.push(DiagramPair {
                vertices: [r.index, p],
                types: [MINIMUM, if surface { SADDLE1 } else { MAXIMUM }],
                pair_type: 0,
                values: [h[r.index], h[p]],
                finite: true,
                extremum: r.index,
            }),
            (ExtremumKind::Max, Some(p)) if surface => finite.push(DiagramPair {
                vertices: [p, r.index],
                types: [max_saddle, MAXIMUM],
                pair_type: max_pair,
                values: [h[p], h[r.index]],
                finite: true,
                extremum: r.index,
            }),
            _ => {}
        }
    }
    essential.extend(finite);
    essential
}

/// Checks that a persistence diagram can be written at `path` (`.vtu`).
///
/// # Errors
/// [`crate::Error::Usage`] for another extension.
pub fn check_diagram_output(path: &Path) -> Result<()> {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("vtu") => Ok(()),
        _ => Err(crate::Error::Usage(format!(
            "{}: the persistence diagram is written as .vtu (TTK's layout)",
            path.display()
        ))),
    }
}

/// [`diagram_pairs`] of `h` on a domain chosen at run time.
pub fn diagram_of(domain: &AnyDomain, h: &[f64]) -> Vec<DiagramPair> {
    let table = crate::with_domain!(domain, d => crate::topology::extrema_table(d, h));
    diagram_from_table(domain, h, &table)
}

/// [`diagram_pairs`] on a domain chosen at run time, from its extremum table.
pub fn diagram_from_table(domain: &AnyDomain, h: &[f64], table: &[ExtremumInfo]) -> Vec<DiagramPair> {
    crate::with_domain!(domain, d => diagram_pairs(d, h, table, domain.dimension()))
}

/// The position of vertex `v` (a grid's and a volume's in the file's coordinates, as VTK
/// places the image's points).
pub(crate) fn point_of(domain: &AnyDomain, v: usize) -> [f64; 3] {
    match domain {
        AnyDomain::Grid(g) => g.world(v),
        AnyDomain::Volume(g) => g.world(v),
        _ => crate::with_domain!(domain, d => d.point(v)),
    }
}

/// Stages the diagram of `pairs` at `path` (`.vtu`) in TTK's layout; `roles` marks the kept
/// extrema (cell array `Kept`).
///
/// # Errors
/// A usage error for another extension; I/O errors naming the file.
pub fn stage_diagram(path: &Path, domain: &AnyDomain, pairs: &[DiagramPair], roles: &[Role]) -> Result<Staged> {
    check_diagram_output(path)?;
    let n = pairs.len();
    let mut points = Vec::with_capacity(2 * n);
    let (mut ids, mut types, mut coords) = (Vec::new(), Vec::new(), Vec::new());
    let (mut pair_id, mut pair_type, mut persistence, mut birth, mut finite, mut kept) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (i, p) in pairs.iter().enumerate() {
        points.push([p.values[0], p.values[0], 0.0]);
        points.push([p.values[0], p.values[1], 0.0]);
        for k in 0..2 {
            ids.push(p.vertices[k] as f64);
            types.push(f64::from(p.types[k]));
            coords.extend(point_of(domain, p.vertices[k]).map(|c| f64::from(c as f32)));
        }
        pair_id.push(i as f64);
        pair_type.push(f64::from(p.pair_type));
        persistence.push(p.persistence());
        birth.push(p.values[0]);
        finite.push(f64::from(u8::from(p.finite)));
        kept.push(f64::from(u8::from(roles.get(p.extremum).is_some_and(|r| r.is_fixed()))));
    }
    let mut cells = Cells {
        types: vec![super::vtk::cell::LINE; n],
        offsets: (0..=n).map(|k| 2 * k).collect(),
        connectivity: (0..2 * n).collect(),
    };
    if let Some(last) = (0..n).max_by(|&a, &b| pairs[a].values[0].total_cmp(&pairs[b].values[0])) {
        // the diagonal, as TTK draws it: from the first point to the highest birth
        cells.types.push(super::vtk::cell::LINE);
        cells.connectivity.extend([0, 2 * last]);
        cells.offsets.push(cells.connectivity.len());
        pair_id.push(-1.0);
        pair_type.push(-1.0);
        persistence.push(2.0 * pairs[0].persistence());
        birth.push(0.0);
        finite.push(0.0);
        kept.push(0.0);
    }
    let id_type = if domain.n_vertices() > i32::MAX as usize { Scalar::I64 } else { Scalar::I32 };
    let typed = |name, ty, components, values| OutArray { name, ty, components, values };
    let point = [
        typed("ttkVertexScalarField", id_type, 1, &ids[..]),
        typed("CriticalType", Scalar::I32, 1, &types),
        typed("Coordinates", Scalar::F32, 3, &coords),
    ];
    let cell = [
        typed("PairIdentifier", id_type, 1, &pair_id[..]),
        typed("PairType", Scalar::I32, 1, &pair_type),
        typed("Persistence", Scalar::F64, 1, &persistence),
        typed("Birth", Scalar::F64, 1, &birth),
        typed("IsFinite", Scalar::U8, 1, &finite),
        typed("Kept", Scalar::U8, 1, &kept),
    ];
    stage_vtu_cells(path, &points, &cells, (&point, &cell), None)
}

//! The kept critical points and the simplified complex as outputs: role codes, plot markers,
//! and the complex as VTK PolyData.

use crate::io::vtk::PolyData;
use crate::plot::GridMarker;
use crate::topology::morse_smale::MorseSmale;
use crate::topology::Role;

/// The kept extrema of a surface result as plot markers.
pub fn kept_markers(roles: &[Role]) -> Vec<GridMarker> {
    roles
        .iter()
        .enumerate()
        .filter_map(|(i, r)| match r {
            Role::Min => Some(GridMarker { index: i, is_max: false }),
            Role::Max => Some(GridMarker { index: i, is_max: true }),
            _ => None,
        })
        .collect()
}

/// Role codes as Float64 (SPEC.md: −1 kept min, +1 kept max, 2 fixed, 3 end, 0 other).
pub fn role_codes(roles: &[Role]) -> Vec<f64> {
    roles.iter().map(|r| f64::from(r.code())).collect()
}

/// The kept extrema, surviving saddles and separatrices as PolyData: vertex cells first
/// (cell array `type`: −1 minimum, +1 maximum, 0 saddle), then one polyline per separatrix
/// (`type` −1 descending to a minimum, +1 ascending to a maximum).
/// `place` gives each vertex's position.
pub fn complex_polydata(place: &dyn Fn(usize) -> [f64; 3], h: &[f64], roles: &[Role], ms: &MorseSmale) -> PolyData {
    let mut slot = std::collections::HashMap::new();
    let mut points = Vec::new();
    let mut values = Vec::new();
    let mut id = |v: usize, points: &mut Vec<[f64; 3]>, values: &mut Vec<f64>| -> usize {
        *slot.entry(v).or_insert_with(|| {
            points.push(place(v));
            values.push(h[v]);
            points.len() - 1
        })
    };
    let mut verts = Vec::new();
    let mut types = Vec::new();
    for (v, r) in roles.iter().enumerate() {
        if matches!(r, Role::Min | Role::Max) {
            verts.push(id(v, &mut points, &mut values));
            types.push(f64::from(r.code()));
        }
    }
    for &s in &ms.saddles {
        verts.push(id(s, &mut points, &mut values));
        types.push(0.0);
    }
    let mut lines = Vec::new();
    for (list, t) in [(&ms.descending, -1.0), (&ms.ascending, 1.0)] {
        for sep in list {
            lines.push(sep.path.iter().map(|&v| id(v, &mut points, &mut values)).collect::<Vec<usize>>());
            types.push(t);
        }
    }
    PolyData {
        points,
        verts,
        lines,
        point_arrays: vec![("input".into(), values)],
        cell_arrays: vec![("type".into(), types)],
        ..Default::default()
    }
}

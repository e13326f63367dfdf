use super::*;
use crate::error::Location;

/// The unit corner tetrahedron and a second one across its slanted face `1–2–3`.
fn two_tets() -> (Vec<[f64; 3]>, Vec<[usize; 4]>) {
    (
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]],
        vec![[0, 1, 2, 3], [1, 2, 3, 4]],
    )
}

fn err(p: Vec<[f64; 3]>, t: Vec<[usize; 4]>) -> (String, Option<Location>) {
    let e = TetMesh::new(p, t).unwrap_err();
    assert_eq!(e.kind(), crate::ErrorKind::Input);
    (e.to_string(), e.location())
}

fn centroid(p: &[[f64; 3]], vs: &[usize]) -> [f64; 3] {
    let mut c = [0.0; 3];
    for &v in vs {
        for a in 0..3 {
            c[a] += p[v][a] / vs.len() as f64;
        }
    }
    c
}

#[test]
fn an_empty_mesh_is_refused() {
    let (m, at) = err(Vec::new(), Vec::new());
    assert!(m.contains("at least one tetrahedron"), "{m}");
    assert_eq!(at, None);
    let (m, _) = err(two_tets().0, Vec::new());
    assert!(m.contains("5 vertices and 0 tetrahedra"), "{m}");
}

#[test]
fn a_non_finite_coordinate_is_refused() {
    let (mut p, t) = two_tets();
    p[3][2] = f64::NAN;
    p[4][0] = f64::INFINITY;
    let (m, at) = err(p, t);
    assert!(m.contains("non-finite coordinates at vertices 3, 4"), "{m}");
    assert_eq!(at, Some(Location::Vertex(3)));
}

#[test]
fn an_index_out_of_range_is_refused() {
    let (p, _) = two_tets();
    let (m, at) = err(p, vec![[0, 1, 2, 3], [1, 2, 3, 5]]);
    assert!(m.contains("tetrahedra 1 use a vertex index beyond the 5 vertices"), "{m}");
    assert!(m.contains("[1, 2, 3, 5]"), "{m}");
    assert_eq!(at, Some(Location::Tetrahedron(1)));
}

#[test]
fn a_repeated_corner_is_refused() {
    let (p, _) = two_tets();
    let (m, at) = err(p, vec![[0, 1, 2, 3], [1, 2, 4, 4]]);
    assert!(m.contains("tetrahedra 1 repeat a corner"), "{m}");
    assert_eq!(at, Some(Location::Tetrahedron(1)));
}

#[test]
fn a_zero_volume_tetrahedron_is_refused() {
    // vertex 4 moved into the plane x + y + z = 1 of the shared face
    let (mut p, t) = two_tets();
    p[4] = [1.0, 1.0, -1.0];
    let (m, at) = err(p.clone(), t.clone());
    assert!(m.contains("tetrahedra 1 have zero volume"), "{m}");
    assert_eq!(at, Some(Location::Tetrahedron(1)));
    // the test is relative to the tetrahedron's size: a tiny but well-shaped mesh passes,
    // a sliver 10¹³ times flatter than it is long does not
    let tiny: Vec<[f64; 3]> = two_tets().0.iter().map(|q| q.map(|x| x * 1e-9)).collect();
    assert!(TetMesh::new(tiny, t.clone()).is_ok());
    p[4] = [1.0, 1.0, -1.0 + 1e-13];
    assert!(err(p.clone(), t.clone()).0.contains("zero volume"));
    p[4] = [1.0, 1.0, -1.0 + 1e-9];
    assert!(TetMesh::new(p, t).is_ok());
}

#[test]
fn a_duplicate_tetrahedron_is_refused() {
    let (p, mut t) = two_tets();
    t.push([3, 2, 1, 0]);
    t.push([0, 3, 1, 2]);
    let (m, at) = err(p, t);
    assert!(m.contains("duplicate tetrahedra 2 (= 0), 3 (= 0)"), "{m}");
    assert_eq!(at, Some(Location::Tetrahedron(2)));
}

#[test]
fn an_unused_vertex_is_refused() {
    let (mut p, t) = two_tets();
    p.insert(2, [5.0, 5.0, 5.0]);
    let t = t.into_iter().map(|tet| tet.map(|v| if v >= 2 { v + 1 } else { v })).collect();
    let (m, at) = err(p, t);
    assert!(m.contains("vertices 2 are used by no tetrahedron"), "{m}");
    assert_eq!(at, Some(Location::Vertex(2)));
}

#[test]
fn two_vertices_at_one_position_are_refused() {
    // a third tetrahedron on a copy of vertex 1
    let (mut p, mut t) = two_tets();
    p.push([1.0, 0.0, 0.0]);
    p.push([1.0, -1.0, 0.0]);
    t.push([5, 6, 0, 3]);
    let (m, at) = err(p, t);
    assert!(m.contains("vertices at the same position: 1 and 5"), "{m}");
    assert_eq!(at, Some(Location::Vertex(1)));
}

#[test]
fn a_triangle_on_three_tetrahedra_is_refused() {
    let (mut p, mut t) = two_tets();
    p.push([2.0, 2.0, 2.0]);
    t.push([1, 2, 3, 5]);
    let (m, at) = err(p, t);
    assert!(m.contains("triangles on more than two tetrahedra: 1–2–3 (tetrahedra 0, 1, 2)"), "{m}");
    assert_eq!(at, Some(Location::Vertex(1)));
}

#[test]
fn a_non_manifold_edge_is_refused() {
    // two tetrahedra sharing only the edge 0–1
    let p =
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]];
    let (m, at) = err(p, vec![[0, 1, 2, 3], [0, 1, 4, 5]]);
    assert!(m.contains("non-manifold edges"), "{m}");
    assert!(m.contains("0–1 (2 fans of 2 tetrahedra)"), "{m}");
    assert_eq!(at, Some(Location::Vertex(0)));
}

#[test]
fn a_non_manifold_vertex_is_refused() {
    // two tetrahedra touching at vertex 0 only
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, -1.0],
    ];
    let (m, at) = err(p, vec![[0, 1, 2, 3], [0, 4, 5, 6]]);
    assert!(m.contains("non-manifold vertices 0 (their tetrahedra are not connected"), "{m}");
    assert_eq!(at, Some(Location::Vertex(0)));
}

#[test]
fn a_vertex_whose_tetrahedra_are_connected_but_no_ball_is_refused() {
    // a cone from vertex 0 over a triangulated annulus (a triangle with a triangular hole):
    // every edge is manifold and the tetrahedra at vertex 0 are connected, but its link is
    // an annulus (Euler characteristic 0), not a disk
    let mut p = vec![[0.0, 0.0, 1.0]];
    for (r, turn) in [(1.0, 0.0), (3.0, 0.5)] {
        for k in 0..3 {
            let a = (k as f64 + turn) * 2.0 * std::f64::consts::PI / 3.0;
            p.push([r * a.cos(), r * a.sin(), 0.0]);
        }
    }
    let (inner, outer) = (|k: usize| 1 + k % 3, |k: usize| 4 + k % 3);
    let mut t = Vec::new();
    for k in 0..3 {
        t.push([0, inner(k), outer(k), inner(k + 1)]);
        t.push([0, inner(k + 1), outer(k), outer(k + 1)]);
    }
    let (m, at) = err(p, t);
    assert!(m.contains("non-manifold vertices 0 (boundary vertex, link Euler characteristic 0)"), "{m}");
    assert!(m.contains("do not form a ball"), "{m}");
    assert_eq!(at, Some(Location::Vertex(0)));
}

#[test]
fn inverted_tetrahedra_are_reoriented_and_reported() {
    let (p, mut t) = two_tets();
    t[1] = [2, 1, 3, 4];
    let m = TetMesh::new(p.clone(), t.clone()).unwrap();
    assert_eq!(m.repairs().len(), 1, "{:?}", m.repairs());
    assert!(m.repairs()[0].starts_with("1 inverted tetrahedron reoriented (the first: 1)"), "{:?}", m.repairs());
    assert_eq!(m.tets()[1], [2, 1, 4, 3]);
    t[0] = [0, 2, 1, 3];
    let m = TetMesh::new(p.clone(), t).unwrap();
    assert!(m.repairs()[0].starts_with("2 inverted tetrahedra reoriented (the first: 0)"), "{:?}", m.repairs());
    for tet in m.tets() {
        let [a, b, c, d] = tet.map(|v| p[v]);
        assert!(signed_volume6(a, b, c, d) > 0.0);
    }
    assert!((m.volume() - (1.0 / 6.0 + 2.0 / 6.0)).abs() < 1e-15);
    assert!(TetMesh::new(p, two_tets().1).unwrap().repairs().is_empty());
}

#[test]
fn two_tetrahedra_have_their_neighbours_and_an_outward_boundary() {
    let (p, t) = two_tets();
    let m = TetMesh::new(p.clone(), t).unwrap();
    let nb = |v: usize| m.neighbors(v).collect::<Vec<_>>();
    assert_eq!(nb(0), vec![1, 2, 3]);
    assert_eq!(nb(1), vec![0, 2, 3, 4]);
    assert_eq!(nb(4), vec![1, 2, 3]);
    assert_eq!((m.n_edges(), m.n_faces(), m.euler_characteristic()), (9, 7, 1));
    assert_eq!(m.edges().len(), 9);
    assert_eq!((m.n_components(), m.components()), (1, &[0, 0, 0, 0, 0][..]));
    assert_eq!(m.boundary_faces().len(), 6);
    assert!(!m.boundary_faces().iter().any(|f| {
        let mut s = *f;
        s.sort_unstable();
        s == [1, 2, 3]
    }));
    // every boundary face has its own tetrahedron's fourth corner (and the mesh's centroid)
    // on its negative side
    let inside = centroid(&p, &[0, 1, 2, 3, 4]);
    for f in m.boundary_faces() {
        let tet = m.tets().iter().find(|tet| f.iter().all(|v| tet.contains(v))).unwrap();
        let other = *tet.iter().find(|v| !f.contains(v)).unwrap();
        let [a, b, c] = f.map(|v| p[v]);
        assert!(signed_volume6(a, b, c, p[other]) < 0.0, "{f:?}");
        assert!(signed_volume6(a, b, c, inside) < 0.0, "{f:?}");
    }
    assert_eq!(m.pairing_rule(), PairingRule::Surface);
    assert!(m.triangles().is_empty(), "no 2D triangles for the discrete gradient");
    assert_eq!(m.point(4), [1.0, 1.0, 1.0]);
    assert!((m.diameter() - 3f64.sqrt()).abs() < 1e-15);
    assert_eq!(m.describe(), "5 vertices, 2 tetrahedra, 1 component, 6 boundary triangles, Euler characteristic 1");
}

#[test]
fn components_are_counted() {
    let (mut p, mut t) = two_tets();
    p.extend([[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, 1.0, 0.0], [5.0, 0.0, 1.0]]);
    t.insert(0, [5, 6, 7, 8]);
    let m = TetMesh::new(p, t).unwrap();
    assert_eq!(m.n_components(), 2);
    assert_eq!(m.components(), &[1, 1, 1, 1, 1, 0, 0, 0, 0]);
    assert_eq!(m.euler_characteristic(), 2);
    assert!(m.describe().contains("2 components"), "{}", m.describe());
}

#[test]
fn the_box_grid_is_the_kuhn_split() {
    let m = TetMesh::box_grid(3, 3, 3, [1.0, 1.0, 1.0]);
    assert!(m.repairs().is_empty());
    assert_eq!(m.tets().len(), 48);
    let centre = 1 + 3 * (1 + 3);
    let expected: Vec<usize> = {
        let mut v = Vec::new();
        for d in [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [0, 1, 1], [1, 0, 1], [1, 1, 1]] {
            for s in [-1i64, 1] {
                let c = d.map(|x| (1 + s * x) as usize);
                v.push(c[0] + 3 * (c[1] + 3 * c[2]));
            }
        }
        v.sort_unstable();
        v
    };
    assert_eq!(m.neighbors(centre).collect::<Vec<_>>(), expected);
    assert_eq!(expected.len(), 14);
    assert_eq!(m.boundary_faces().len(), 2 * (2 * 2) * 6);
    assert_eq!(m.n_edges(), 98);
    assert_eq!(m.euler_characteristic(), 1);
    assert!((m.volume() - 8.0).abs() < 1e-12);
    // outward: the box's centre is behind every boundary face, which lies on the box's surface
    let p = m.positions();
    for f in m.boundary_faces() {
        let [a, b, c] = f.map(|v| p[v]);
        assert!(signed_volume6(a, b, c, [1.0, 1.0, 1.0]) < 0.0, "{f:?}");
        assert!((0..3).any(|axis| f.iter().all(|&v| p[v][axis] == 0.0) || f.iter().all(|&v| p[v][axis] == 2.0)));
    }
    // every face split along its +,+ diagonal: on the face z = 0, the edge (0,0)–(1,1), not (1,0)–(0,1)
    assert!(m.neighbors(0).any(|v| v == 4));
    assert!(!m.neighbors(1).any(|v| v == 3));
    // vertex order and positions
    let s = TetMesh::box_grid(4, 3, 2, [0.5, -2.0, 3.0]);
    assert_eq!(s.point(1 + 4 * (2 + 3)), [0.5, -4.0, 3.0]);
    assert!(s.repairs().is_empty());
    assert!((s.volume() - 1.5 * 4.0 * 3.0).abs() < 1e-12);
}

#[test]
fn the_jittered_box_keeps_the_box_topology() {
    let b = TetMesh::box_grid(5, 4, 4, [1.0, 0.5, 2.0]);
    let j = TetMesh::jittered_box(5, 4, 4, [1.0, 0.5, 2.0], 0.05, 7);
    assert_eq!(j.tets(), b.tets());
    assert_eq!((j.n_edges(), j.euler_characteristic()), (b.n_edges(), 1));
    assert!((j.volume() - b.volume()).abs() < 1e-12, "the boundary stays put");
    let moved = (0..b.n_vertices()).filter(|&v| j.point(v) != b.point(v)).count();
    assert_eq!(moved, 3 * 2 * 2, "every interior vertex moves");
    assert_ne!(j.positions(), TetMesh::jittered_box(5, 4, 4, [1.0, 0.5, 2.0], 0.05, 8).positions());
}

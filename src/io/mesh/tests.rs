//! Tests of the mesh readers and writers.

use super::*;

fn tmp(name: &str, content: &[u8]) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("toposmooth-mesh-io-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    std::fs::write(&p, content).unwrap();
    p
}

const SQUARE_OBJ: &str = "# a square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.5\nf 1 2 3 4\n";

#[test]
fn obj_off_and_ply_give_the_same_mesh() {
    let obj = read_mesh(&tmp("sq.obj", SQUARE_OBJ.as_bytes())).unwrap();
    assert_eq!(obj.positions.len(), 4);
    assert_eq!(obj.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(obj.notes.len(), 1);
    let off = read_mesh(&tmp("sq.off", b"OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0.5\n4 0 1 2 3\n")).unwrap();
    assert_eq!((off.positions.clone(), off.triangles.clone()), (obj.positions.clone(), obj.triangles.clone()));
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
               property double temp\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
               0 0 0 1.5\n1 0 0 2.5\n1 1 0 3.5\n0 1 0.5 4.5\n4 0 1 2 3\n";
    let p = read_mesh(&tmp("sq.ply", ply.as_bytes())).unwrap();
    assert_eq!((p.positions.clone(), p.triangles.clone()), (obj.positions.clone(), obj.triangles.clone()));
    assert_eq!(p.array("temp").unwrap().values, vec![1.5, 2.5, 3.5, 4.5]);
    assert_eq!(p.array("z").unwrap().values, vec![0.0, 0.0, 0.0, 0.5]);
    assert!(p.array("pressure").unwrap_err().to_string().contains("temp, x, y, z"));
}

#[test]
fn vertex_order_follows_the_file_and_extras_are_ignored() {
    // the first vertex is used last; negative indices; v/vt/vn forms; an unused vertex
    let obj = "v 5 5 1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 2/1 3/1 4/1\nf -4 -3 -1\nv 9 9 9\n";
    let m = read_mesh(&tmp("order.obj", obj.as_bytes())).unwrap();
    assert_eq!(m.positions[0], [5.0, 5.0, 1.0]);
    assert_eq!(m.positions.len(), 5);
    assert_eq!(m.triangles, vec![[1, 2, 3], [0, 1, 3]]);
    let e = crate::domain::TriMesh::new(m.positions, m.triangles).unwrap_err().to_string();
    assert!(e.contains("vertices 4 are used by no triangle"), "{e}");
    // OFF with per-vertex and per-face colours and comments
    let off = "OFF # a square\n4 2 0\n0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 9 9 9\n\
               3 0 1 2 255 0 0\n3 0 2 3 0 255 0 # second\n";
    let m = read_mesh(&tmp("colour.off", off.as_bytes())).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.positions[3], [0.0, 1.0, 0.0]);
}

#[test]
fn obj_groups_share_their_vertices() {
    let two = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\ng a\nf 1 2 3\ng b\nf 1 3 4\n";
    let m = read_mesh(&tmp("groups.obj", two.as_bytes())).unwrap();
    assert_eq!(m.positions.len(), 4, "{:?}", m.positions);
    assert_eq!(m.triangles.len(), 2);
    let mesh = crate::domain::TriMesh::new(m.positions, m.triangles).unwrap();
    assert_eq!(mesh.n_components(), 1);
}

#[test]
fn written_ply_reads_back_bit_for_bit() {
    let d = std::env::temp_dir().join(format!("toposmooth-mesh-io-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let path = d.join("out.ply");
    let pos = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.1], [0.0, 1.0, -0.2]];
    let vals = [0.1, 1.0 / 3.0, -2e-300];
    stage_ply(&path, &pos, &[[0, 1, 2]], &[("smoothed", &vals)]).unwrap().commit().unwrap();
    let m = read_mesh(&path).unwrap();
    assert_eq!(m.positions, pos.to_vec());
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
    let got = m.array("smoothed").unwrap().values;
    assert!(got.iter().zip(&vals).all(|(a, b)| a.to_bits() == b.to_bits()));
}

#[test]
fn written_obj_and_off_read_back_bit_for_bit() {
    let d = std::env::temp_dir().join(format!("toposmooth-mesh-io-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let pos = [[0.1, 1.0 / 3.0, 0.0], [1e-300, -2.5e17, 0.0], [-0.0, 1.0, 7.0]];
    for name in ["out.obj", "out.off"] {
        let path = d.join(name);
        let staged = if name.ends_with("obj") {
            stage_obj(&path, &pos, &[[0, 1, 2]])
        } else {
            stage_off(&path, &pos, &[[0, 1, 2]])
        };
        assert!(!path.exists(), "staged, not yet committed");
        staged.unwrap().commit().unwrap();
        let m = read_mesh(&path).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        assert!(m.positions.iter().flatten().zip(pos.iter().flatten()).all(|(a, b)| a.to_bits() == b.to_bits()));
    }
    assert!(stage_obj(&d.join("bad.obj"), &pos, &[[0, 1, 3]]).is_err());
}

#[test]
fn legacy_vtk_polydata_and_unstructured_grids_are_read() {
    let poly = "# vtk DataFile Version 3.0\nsquare\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n\
                0 0 0 1 0 0 1 1 0 0 1 0.5\nPOLYGONS 1 5\n4 0 1 2 3\nPOINT_DATA 4\nSCALARS t double 1\n\
                LOOKUP_TABLE default\n1.5 2.5 3.5 4.5\n";
    let m = read_mesh(&tmp("sq.vtk", poly.as_bytes())).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.array("t").unwrap().values, vec![1.5, 2.5, 3.5, 4.5]);
    let ug = "# vtk DataFile Version 3.0\nsquare\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n\
              0 0 0 1 0 0 1 1 0 0 1 0.5\nCELLS 3 10\n3 0 1 2\n3 0 2 3\n1 3\nCELL_TYPES 3\n5\n5\n1\n";
    let m = read_mesh(&tmp("ug.vtk", ug.as_bytes())).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.notes, vec!["1 vertex and line cells ignored".to_string()]);
    let tet = ug.replace("CELL_TYPES 3\n5\n5\n1", "CELL_TYPES 3\n5\n5\n10");
    let e = read_mesh(&tmp("tet.vtk", tet.as_bytes())).unwrap_err().to_string();
    assert!(e.contains("tet.vtk") && e.contains("cell 2"), "{e}");
}

#[test]
fn broken_files_are_input_errors() {
    for (name, content, needle) in [
        ("empty.obj", &b""[..], "empty"),
        ("bad.off", &b"OFF\n3 1 0\n0 0 0\n1 0 0\n"[..], "ends before all vertices"),
        ("range.off", &b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n"[..], "vertex 5"),
        ("text.off", &b"OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n"[..], "line 4"),
        ("range.obj", &b"v 0 0 0\nv 1 0 0\nf 1 2 3\n"[..], "line 3: vertex reference 3 is out of range"),
        ("short.off", &b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n"[..], "lists 2 of its 3 corners"),
        (
            "noface.ply",
            &b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n"[..],
            "face",
        ),
        ("junk.vtu", &b"<VTKFile type=\"UnstructuredGrid\"><broken"[..], "malformed XML near byte"),
        ("x.stl", &b"solid"[..], "not a mesh format"),
    ] {
        let e = read_mesh(&tmp(name, content)).unwrap_err();
        let msg = e.to_string();
        assert_eq!(e.exit_code(), 3, "{name}: {msg}");
        assert!(msg.contains(name) && msg.contains(needle), "{name}: {msg}");
    }
}

//! Meshes our .vtu and .vtp writers write read back bit for bit.

use super::*;

#[test]
fn vtu_and_vtp_written_here_read_back_bit_for_bit() {
    let d = std::env::temp_dir().join(format!("toposmooth-mesh-vtk-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let pos = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.1], [0.0, 1.0, -0.2], [1.0, 1.0, 0.3]];
    let tris = vec![[0, 1, 2], [1, 3, 2]];
    let vals = [0.1, 1.0 / 3.0, -2e-300, 7.0];
    let vtu = d.join("m.vtu");
    super::super::vtk::stage_vtu(&vtu, &pos, &tris, &[("smoothed", &vals)]).unwrap().commit().unwrap();
    let vtp = d.join("m.vtp");
    let poly = super::super::vtk::PolyData {
        points: pos.clone(),
        polys: tris.clone(),
        point_arrays: vec![("smoothed".into(), vals.to_vec())],
        ..Default::default()
    };
    super::super::vtk::stage_vtp(&vtp, &poly).unwrap().commit().unwrap();
    for p in [vtu, vtp] {
        let m = read_mesh(&p).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.positions, pos);
        assert_eq!(m.triangles, tris);
        let got = m.array("smoothed").unwrap().values;
        assert!(got.iter().zip(&vals).all(|(a, b)| a.to_bits() == b.to_bits()));
    }
}

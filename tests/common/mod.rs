//! Helpers shared by the integration tests. The extremum counter here is written from the
//! definition (SPEC.md "Extrema") and shares no code with the crate's certificate.
#![allow(dead_code)]

pub mod reference;

/// Strict minima, strict maxima and non-regular, non-extremal vertices of a series.
pub struct Counted {
    pub minima: Vec<usize>,
    pub maxima: Vec<usize>,
    pub flat: Vec<usize>,
}

pub fn count_series_extrema(f: &[f64]) -> Counted {
    let n = f.len();
    let mut c = Counted { minima: vec![], maxima: vec![], flat: vec![] };
    for i in 0..n {
        let nb: Vec<f64> =
            [i.checked_sub(1), (i + 1 < n).then_some(i + 1)].into_iter().flatten().map(|j| f[j]).collect();
        let lower = nb.iter().filter(|&&v| v < f[i]).count();
        let higher = nb.iter().filter(|&&v| v > f[i]).count();
        if higher == nb.len() {
            c.minima.push(i);
        } else if lower == nb.len() {
            c.maxima.push(i);
        } else if lower == 0 || higher == 0 {
            c.flat.push(i);
        }
    }
    c
}

/// A deterministic pseudo-random sequence in [0, 1) (splitmix64).
pub fn uniform(seed: u64, n: usize) -> Vec<f64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}

/// A unique scratch directory for one test.
pub fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("toposmooth-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Strict extrema and flat vertices of a grid field, from SPEC's 6-neighbour rule written out
/// here independently of the crate.
pub fn grid_extrema(nx: usize, ny: usize, f: &[f64]) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let (mut mins, mut maxs, mut flat) = (vec![], vec![], vec![]);
    for r in 0..ny as isize {
        for c in 0..nx as isize {
            let v = (r as usize) * nx + c as usize;
            let nb: Vec<f64> = [(0, -1), (0, 1), (-1, 0), (1, 0), (-1, -1), (1, 1)]
                .iter()
                .map(|(dr, dc)| (r + dr, c + dc))
                .filter(|&(rr, cc)| rr >= 0 && rr < ny as isize && cc >= 0 && cc < nx as isize)
                .map(|(rr, cc)| f[rr as usize * nx + cc as usize])
                .collect();
            let lower = nb.iter().filter(|&&w| w < f[v]).count();
            let higher = nb.iter().filter(|&&w| w > f[v]).count();
            if higher == nb.len() {
                mins.push(v);
            } else if lower == nb.len() {
                maxs.push(v);
            } else if lower == 0 || higher == 0 {
                flat.push(v);
            }
        }
    }
    (mins, maxs, flat)
}

/// Strict extrema and flat vertices of a field on a triangle mesh (neighbours: vertices
/// sharing an edge), from the triangles alone, independently of the crate's adjacency.
pub fn mesh_extrema(n: usize, triangles: &[[usize; 3]], f: &[f64]) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let mut nb: Vec<std::collections::BTreeSet<usize>> = vec![Default::default(); n];
    for t in triangles {
        for k in 0..3 {
            nb[t[k]].insert(t[(k + 1) % 3]);
            nb[t[(k + 1) % 3]].insert(t[k]);
        }
    }
    let (mut mins, mut maxs, mut flat) = (vec![], vec![], vec![]);
    for v in 0..n {
        let lower = nb[v].iter().filter(|&&w| f[w] < f[v]).count();
        let higher = nb[v].iter().filter(|&&w| f[w] > f[v]).count();
        if higher == nb[v].len() {
            mins.push(v);
        } else if lower == nb[v].len() {
            maxs.push(v);
        } else if lower == 0 || higher == 0 {
            flat.push(v);
        }
    }
    (mins, maxs, flat)
}

/// Runs the built binary with `args`.
pub fn toposmooth(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_toposmooth")).args(args).output().expect("runs")
}

/// A bundled dataset's path.
/// A JSON file the tool wrote (a run's report, the colours of `colors --json`) as a value.
pub fn json(path: impl AsRef<std::path::Path>) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

pub fn dataset(name: &str) -> String {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets").join(name).display().to_string()
}

/// Standard output and standard error of a run, for messages.
pub fn text(o: &std::process::Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// Runs the built binary with `args` and asserts that it exits 0 (the message otherwise).
pub fn succeeds(args: &[&str]) -> std::process::Output {
    let o = toposmooth(args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", text(&o));
    o
}

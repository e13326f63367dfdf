//! Helpers shared by the integration tests. The extremum counter here is written from the
//! definition (SPEC.md "Extrema") and shares no code with the crate's certificate.
#![allow(dead_code)]

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

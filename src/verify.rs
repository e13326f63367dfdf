//! The certificate (SPEC.md): the output has exactly the kept extrema, at their input values.
//!
//! Written from the definitions alone (exact comparisons, no tolerance), independently of the
//! solver and the constraint set.
//!
//! ```
//! use toposmooth::{domain::Series, topology::Role, verify::certify};
//! let roles = [Role::Min, Role::Other, Role::Max];
//! assert!(certify(&Series::uniform(3), &[0.0, 0.5, 1.0], &roles, Some(&[0.0, 7.0, 1.0])).passed);
//! assert!(!certify(&Series::uniform(3), &[0.0, 1.0, 1.0], &roles, None).passed); // tie
//! ```

use crate::domain::Domain;
use crate::topology::Role;

/// One violated item of the certificate.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Failure {
    /// Certificate item (1–4, SPEC.md).
    pub item: u8,
    /// Offending vertex.
    pub vertex: usize,
    /// What is wrong.
    pub reason: String,
}

/// Result of checking a field against roles.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Certificate {
    /// All items hold.
    pub passed: bool,
    /// Strict local minima of the checked field.
    pub strict_minima: usize,
    /// Strict local maxima of the checked field.
    pub strict_maxima: usize,
    /// Vertices that are neither regular nor strict extrema (flat spots).
    pub flat: usize,
    /// Free ends among the strict extrema (series).
    pub free_ends: usize,
    /// Whether kept values were compared with the input (item 3).
    pub kept_values_checked: bool,
    /// Number of failures found.
    pub failure_count: usize,
    /// The first failures (at most 20).
    pub failures: Vec<Failure>,
}

impl Certificate {
    /// One line naming the failed items and the first offending vertices.
    pub fn summary(&self) -> String {
        if self.passed {
            let ends = match self.free_ends {
                0 => String::new(),
                k => format!(" ({k} free end{} included)", if k == 1 { "" } else { "s" }),
            };
            return format!(
                "certified: {} strict minima and {} strict maxima{ends}, exactly the kept ones; no other extremum, no flat spot",
                self.strict_minima, self.strict_maxima
            );
        }
        let list: Vec<String> = self
            .failures
            .iter()
            .take(5)
            .map(|f| format!("item {}: vertex {} {}", f.item, f.vertex, f.reason))
            .collect();
        format!("{} failure(s); first: {}", self.failure_count, list.join("; "))
    }
}

/// Checks items 1, 2 and 4 of the certificate on `f` for the given roles, and item 3 when
/// `input` is given (kept values equal the input bit for bit).
///
/// * `Min`/`Max`: strict local minimum/maximum (item 1);
/// * `Other`: regular, i.e. a strictly lower and a strictly higher neighbour (item 2);
/// * `End` (a series' free end): a strict extremum (item 2);
/// * `Fixed`: exempt.
///
/// Item 5 (the values as written and read back) is this function applied to the file's values.
pub fn certify<D: Domain>(domain: &D, f: &[f64], roles: &[Role], input: Option<&[f64]>) -> Certificate {
    let n = domain.n_vertices();
    assert_eq!(f.len(), n);
    assert_eq!(roles.len(), n);
    let mut failures = Vec::new();
    let (mut strict_minima, mut strict_maxima, mut flat) = (0, 0, 0);
    let mut fail = |item: u8, vertex: usize, reason: String| failures.push(Failure { item, vertex, reason });
    for v in 0..n {
        if !f[v].is_finite() {
            fail(4, v, format!("is not finite ({})", f[v]));
            continue;
        }
        let (mut lower, mut higher, mut equal) = (0usize, 0usize, 0usize);
        for w in domain.neighbors(v) {
            if f[w] < f[v] {
                lower += 1;
            } else if f[w] > f[v] {
                higher += 1;
            } else {
                equal += 1;
            }
        }
        let is_min = lower == 0 && equal == 0 && higher > 0;
        let is_max = higher == 0 && equal == 0 && lower > 0;
        let regular = lower > 0 && higher > 0;
        strict_minima += is_min as usize;
        strict_maxima += is_max as usize;
        flat += (!is_min && !is_max && !regular) as usize;
        match roles[v] {
            Role::Min if !is_min => {
                fail(1, v, format!("should be a strict minimum ({lower} lower, {equal} equal neighbours)"))
            }
            Role::Max if !is_max => {
                fail(1, v, format!("should be a strict maximum ({higher} higher, {equal} equal neighbours)"))
            }
            Role::Other if !regular => fail(
                2,
                v,
                if is_min {
                    "is a spurious minimum".to_string()
                } else if is_max {
                    "is a spurious maximum".to_string()
                } else {
                    format!("is a flat spot ({equal} equal neighbours)")
                },
            ),
            Role::End if !(is_min || is_max) => fail(2, v, "free end is not a strict extremum".into()),
            _ => {}
        }
        if let Some(h) = input {
            if matches!(roles[v], Role::Min | Role::Max | Role::Fixed) && f[v].to_bits() != h[v].to_bits() {
                fail(3, v, format!("kept value {} differs from the input {}", f[v], h[v]));
            }
        }
    }
    let failure_count = failures.len();
    failures.truncate(20);
    Certificate {
        passed: failure_count == 0,
        strict_minima,
        strict_maxima,
        flat,
        free_ends: roles.iter().filter(|&&r| r == Role::End).count(),
        kept_values_checked: input.is_some(),
        failure_count,
        failures,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Series;

    #[test]
    fn finds_each_kind_of_defect() {
        let s = Series::uniform(6);
        let roles = [Role::End, Role::Other, Role::Min, Role::Other, Role::Max, Role::End];
        let good = [1.0, 0.5, 0.0, 1.0, 2.0, 1.5];
        let c = certify(&s, &good, &roles, Some(&good));
        assert!(c.passed, "{}", c.summary());
        assert_eq!((c.strict_minima, c.strict_maxima), (2, 2)); // ends count as extrema
        let spurious = [1.0, 0.5, 0.0, 1.0, 0.9, 1.5];
        let c = certify(&s, &spurious, &roles, None);
        assert!(!c.passed);
        assert!(c.failures.iter().any(|f| f.item == 1 && f.vertex == 4));
        let flat = [1.0, 0.5, 0.0, 1.0, 2.0, 2.0];
        let c = certify(&s, &flat, &roles, None);
        assert!(c.failures.iter().any(|f| f.vertex == 5 && f.item == 2));
        let mut moved = good;
        moved[2] = 1e-300;
        let c = certify(&s, &moved, &roles, Some(&good));
        assert!(c.failures.iter().any(|f| f.item == 3 && f.vertex == 2));
        let mut nan = good;
        nan[1] = f64::NAN;
        assert!(certify(&s, &nan, &roles, None).failures.iter().any(|f| f.item == 4));
    }
}

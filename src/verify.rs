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
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Failure {
    /// Certificate item (1–4, SPEC.md; 0 when the arrays do not fit the domain).
    pub item: u8,
    /// Offending vertex.
    pub vertex: usize,
    /// What is wrong.
    pub reason: String,
}

/// Result of checking a field against roles.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
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
/// * `End` (a series' free end): a strict extremum, inside `[min, max]` of `input` when it is
///   given (item 2);
/// * `Fixed`: exempt.
///
/// Item 5 (the values as written and read back) is this function applied to the file's values.
pub fn certify<D: Domain>(domain: &D, f: &[f64], roles: &[Role], input: Option<&[f64]>) -> Certificate {
    let n = domain.n_vertices();
    if f.len() != n || roles.len() != n || input.is_some_and(|h| h.len() != n) {
        // sizes that disagree certify nothing (item 0: the arrays themselves)
        let sizes = format!(
            "{} values, {} roles{} for {n} vertices",
            f.len(),
            roles.len(),
            input.map(|h| format!(", {} input values", h.len())).unwrap_or_default()
        );
        return Certificate {
            failure_count: 1,
            failures: vec![Failure {
                item: 0,
                vertex: 0,
                reason: format!("the arrays do not fit the domain: {sizes}"),
            }],
            ..Default::default()
        };
    }
    let mut failures = Vec::new();
    let (mut strict_minima, mut strict_maxima, mut flat) = (0, 0, 0);
    // a series' free end must lie inside the input's range (item 2)
    let range = input.map(crate::domain::value_range);
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
            Role::End => {
                if let Some((lo, hi)) = range.filter(|&(lo, hi)| !(lo <= f[v] && f[v] <= hi)) {
                    fail(2, v, format!("free end value {} lies outside the input's range [{lo}, {hi}]", f[v]));
                }
            }
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

/// [`certify`] on a domain chosen at run time.
pub fn certify_any(domain: &crate::domain::AnyDomain, f: &[f64], roles: &[Role], input: Option<&[f64]>) -> Certificate {
    crate::with_domain!(domain, d => certify(d, f, roles, input))
}

/// What a connected set of fixed vertices with one prescribed value must be (no-data mode).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum RegionKind {
    /// Every vertex adjacent to the region from outside is strictly higher.
    Min,
    /// Every vertex adjacent to the region from outside is strictly lower.
    Max,
    /// Exempt (a cage boundary with values varying along it).
    Exempt,
}

/// Connected sets of fixed vertices with equal prescribed values (SPEC.md, "Fixed regions"),
/// each sorted, in order of their smallest vertex.
pub fn fixed_regions<D: Domain>(domain: &D, prescribed: &[Option<f64>]) -> Vec<Vec<usize>> {
    let n = domain.n_vertices();
    let mut seen = vec![false; n];
    let mut out = Vec::new();
    for s in 0..n {
        let Some(value) = prescribed[s] else { continue };
        if seen[s] {
            continue;
        }
        seen[s] = true;
        let mut region = vec![s];
        let mut k = 0;
        while k < region.len() {
            let v = region[k];
            k += 1;
            for w in domain.neighbors(v) {
                if !seen[w] && prescribed[w].is_some_and(|x| x.to_bits() == value.to_bits()) {
                    seen[w] = true;
                    region.push(w);
                }
            }
        }
        region.sort_unstable();
        out.push(region);
    }
    out
}

/// The no-data certificate (SPEC.md, "Fixed regions"): fixed vertices carry their prescribed
/// values bit for bit (item 3), every free vertex is regular (item 2), every value is finite
/// (item 4), and every region that `kind` declares a minimum or maximum is one: each vertex
/// adjacent to it from outside is strictly higher or lower (item 1). `strict_minima` and
/// `strict_maxima` count the regions so verified.
pub fn certify_no_data<D: Domain>(
    domain: &D,
    f: &[f64],
    prescribed: &[Option<f64>],
    kind: impl Fn(f64) -> RegionKind,
) -> Certificate {
    let roles: Vec<Role> = prescribed.iter().map(|p| if p.is_some() { Role::Fixed } else { Role::Other }).collect();
    let values: Vec<f64> = prescribed.iter().map(|p| p.unwrap_or(f64::NAN)).collect();
    let mut c = certify(domain, f, &roles, Some(&values));
    let mut failures = std::mem::take(&mut c.failures);
    let (mut minima, mut maxima) = (0, 0);
    let mut in_region = vec![usize::MAX; f.len()];
    for (r, region) in fixed_regions(domain, prescribed).into_iter().enumerate() {
        let value = prescribed[region[0]].expect("a region is fixed");
        let k = kind(value);
        if k == RegionKind::Exempt {
            continue;
        }
        for &v in &region {
            in_region[v] = r;
        }
        let mut ok = true;
        for &v in &region {
            for w in domain.neighbors(v) {
                let bad = in_region[w] != r
                    && match k {
                        RegionKind::Max => f[w].partial_cmp(&value) != Some(std::cmp::Ordering::Less),
                        _ => f[w].partial_cmp(&value) != Some(std::cmp::Ordering::Greater),
                    };
                if bad {
                    ok = false;
                    c.failure_count += 1;
                    failures.push(Failure {
                        item: 1,
                        vertex: w,
                        reason: format!(
                            "borders the {} region at {value} (vertex {v}) but is not strictly {} ({})",
                            if k == RegionKind::Max { "maximum" } else { "minimum" },
                            if k == RegionKind::Max { "lower" } else { "higher" },
                            f[w]
                        ),
                    });
                }
            }
        }
        if ok {
            match k {
                RegionKind::Max => maxima += 1,
                _ => minima += 1,
            }
        }
    }
    failures.truncate(20);
    c.failures = failures;
    c.passed = c.failure_count == 0;
    c.strict_minima = minima;
    c.strict_maxima = maxima;
    c
}

/// Connected components of the free vertices (`prescribed` is `None`) that are not regular in
/// `f`: no neighbour below `f_v − tolerance` or none above `f_v + tolerance` (tolerance 0:
/// exact comparisons). Spurious extrema and flat spots, counted once per connected patch.
pub fn spurious_components<D: Domain>(domain: &D, f: &[f64], prescribed: &[Option<f64>], tolerance: f64) -> usize {
    let n = domain.n_vertices();
    let bad: Vec<bool> = (0..n)
        .map(|v| {
            if prescribed[v].is_some() {
                return false;
            }
            let (mut lower, mut higher) = (false, false);
            for w in domain.neighbors(v) {
                lower |= f[w] < f[v] - tolerance;
                higher |= f[w] > f[v] + tolerance;
            }
            !(lower && higher)
        })
        .collect();
    let mut seen = vec![false; n];
    let mut count = 0;
    for s in 0..n {
        if !bad[s] || seen[s] {
            continue;
        }
        count += 1;
        seen[s] = true;
        let mut stack = vec![s];
        while let Some(v) = stack.pop() {
            for w in domain.neighbors(v) {
                if bad[w] && !seen[w] {
                    seen[w] = true;
                    stack.push(w);
                }
            }
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_that_do_not_fit_the_domain_fail_instead_of_panicking() {
        let s = crate::domain::Series::uniform(4);
        let c = certify(&s, &[0.0, 1.0, 0.0], &[Role::Min, Role::Max, Role::Min, Role::Max], None);
        assert!(!c.passed && c.failures[0].item == 0, "{c:?}");
        assert!(c.summary().contains("3 values, 4 roles for 4 vertices"), "{}", c.summary());
    }
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
        let mut beyond = good;
        beyond[0] = 2.5; // the free end above the input's maximum (2.0)
        let c = certify(&s, &beyond, &roles, Some(&good));
        assert!(
            c.failures.iter().any(|f| f.item == 2 && f.vertex == 0 && f.reason.contains("outside")),
            "{}",
            c.summary()
        );
        assert!(certify(&s, &beyond, &roles, None).passed, "without the input no range is known");
        let mut nan = good;
        nan[1] = f64::NAN;
        assert!(certify(&s, &nan, &roles, None).failures.iter().any(|f| f.item == 4));
    }

    #[test]
    fn regions_are_checked_as_one_extremum() {
        // 0 1 2 3 4 5 6: a maximum region {2, 3} at 1, minimum regions at both ends
        let s = Series::uniform(7);
        let p = [Some(0.0), None, Some(1.0), Some(1.0), None, None, Some(0.0)];
        let kind = |v: f64| if v == 1.0 { RegionKind::Max } else { RegionKind::Min };
        assert_eq!(fixed_regions(&s, &p), vec![vec![0], vec![2, 3], vec![6]]);
        let good = [0.0, 0.5, 1.0, 1.0, 0.7, 0.3, 0.0];
        let c = certify_no_data(&s, &good, &p, kind);
        assert!(c.passed, "{}", c.summary());
        assert_eq!((c.strict_minima, c.strict_maxima), (2, 1));
        let mut above = good;
        above[4] = 1.0; // ties the maximum region
        let c = certify_no_data(&s, &above, &p, kind);
        assert!(c.failures.iter().any(|f| f.item == 1 && f.vertex == 4), "{}", c.summary());
        let mut dip = good;
        dip[5] = 0.8; // 4 becomes a spurious minimum, 5 a spurious maximum
        let c = certify_no_data(&s, &dip, &p, kind);
        assert!(c.failures.iter().any(|f| f.item == 2 && f.vertex == 4));
        assert_eq!(spurious_components(&s, &dip, &p, 0.0), 1); // 4 (min) and 5 (max), adjacent: one patch
        let mut moved = good;
        moved[3] = 0.999;
        assert!(certify_no_data(&s, &moved, &p, kind).failures.iter().any(|f| f.item == 3 && f.vertex == 3));
        assert_eq!(spurious_components(&s, &good, &p, 0.0), 0);
        assert_eq!(spurious_components(&s, &good, &p, 0.35), 1); // 4 and 5 look flat at that tolerance
    }
}

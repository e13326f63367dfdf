//! Which extrema survive: selection by persistence threshold, by count, or by explicit list,
//! and the role of every vertex in the output (SPEC.md, "Persistence" and "Formats").

mod rules;

pub use rules::{parse_indices, parse_threshold, DEFAULT_SELECTION, SELECTION_SETTINGS};

use super::persistence::{sublevel_pairs, superlevel_pairs, Pair};
use crate::domain::{sos_greater, sos_less, Domain, PairingRule};
use crate::error::{Error, Result};

/// How the user chooses the kept extrema.
#[derive(Clone, Debug, PartialEq)]
pub enum Selection {
    /// Keep persistence ≥ T (T > 0, in the field's units).
    Absolute(f64),
    /// Keep persistence ≥ T·(max − min), 0 < T.
    Relative(f64),
    /// Surfaces: the N most persistent minima and M most persistent maxima.
    Count {
        /// N
        minima: usize,
        /// M
        maxima: usize,
    },
    /// Series: the N most persistent (minimum, maximum) pairs besides the essential minimum.
    Pairs(usize),
    /// Surfaces: every maximum of persistence > 0 and only the essential (global) minimum of
    /// each component (`--keep-all-maxima`: geodesic distance keeps its maxima).
    AllMaxima,
    /// Surfaces: every minimum of persistence > 0 and only the global maximum of each component.
    AllMinima,
    /// Explicit vertex indices.
    Explicit {
        /// Kept minima.
        minima: Vec<usize>,
        /// Kept maxima.
        maxima: Vec<usize>,
    },
}

/// In a JSON report: `{"rule": "relative", "fraction_of_range": 0.05}`,
/// `{"rule": "absolute", "persistence": 0.3}`, `{"rule": "count", "minima": 7, "maxima": 6}`,
/// `{"rule": "pairs", "pairs": 4}`, `{"rule": "all_maxima"}`, `{"rule": "all_minima"}`,
/// `{"rule": "explicit", "minima": [..], "maxima": [..]}`.
#[cfg(feature = "serde")]
impl serde::Serialize for Selection {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> std::result::Result<S::Ok, S::Error> {
        #[derive(serde::Serialize)]
        #[serde(tag = "rule", rename_all = "snake_case")]
        enum Record<'a> {
            Absolute { persistence: f64 },
            Relative { fraction_of_range: f64 },
            Count { minima: usize, maxima: usize },
            Pairs { pairs: usize },
            AllMaxima,
            AllMinima,
            Explicit { minima: &'a [usize], maxima: &'a [usize] },
        }
        let record = match self {
            Selection::Absolute(t) => Record::Absolute { persistence: *t },
            Selection::Relative(t) => Record::Relative { fraction_of_range: *t },
            Selection::Count { minima, maxima } => Record::Count { minima: *minima, maxima: *maxima },
            Selection::Pairs(n) => Record::Pairs { pairs: *n },
            Selection::AllMaxima => Record::AllMaxima,
            Selection::AllMinima => Record::AllMinima,
            Selection::Explicit { minima, maxima } => Record::Explicit { minima, maxima },
        };
        record.serialize(serializer)
    }
}

/// Reads what [`Selection`]'s `Serialize` writes.
#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for Selection {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> std::result::Result<Self, D::Error> {
        #[derive(serde::Deserialize)]
        #[serde(tag = "rule", rename_all = "snake_case", deny_unknown_fields)]
        enum Record {
            Absolute { persistence: f64 },
            Relative { fraction_of_range: f64 },
            Count { minima: usize, maxima: usize },
            Pairs { pairs: usize },
            AllMaxima,
            AllMinima,
            Explicit { minima: Vec<usize>, maxima: Vec<usize> },
        }
        Ok(match Record::deserialize(deserializer)? {
            Record::Absolute { persistence } => Selection::Absolute(persistence),
            Record::Relative { fraction_of_range } => Selection::Relative(fraction_of_range),
            Record::Count { minima, maxima } => Selection::Count { minima, maxima },
            Record::Pairs { pairs } => Selection::Pairs(pairs),
            Record::AllMaxima => Selection::AllMaxima,
            Record::AllMinima => Selection::AllMinima,
            Record::Explicit { minima, maxima } => Selection::Explicit { minima, maxima },
        })
    }
}

impl Selection {
    /// Whether the kept set is chosen by persistence (then it is always realizable and any
    /// failure to certify it is our bug, exit 1).
    pub fn by_persistence(&self) -> bool {
        !matches!(self, Selection::Explicit { .. })
    }
}

/// Role of a vertex in the output (SPEC.md codes: −1, +1, 2, 3, 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Role {
    /// Kept minimum, fixed to its input value.
    Min,
    /// Kept maximum, fixed to its input value.
    Max,
    /// Member of a fixed region (no-data mode), exempt from regularity.
    Fixed,
    /// Free end of a series: a strict extremum whose value is free.
    End,
    /// Any other vertex: must be regular in the output.
    Other,
}

impl Role {
    /// Integer code used in arrays.
    pub fn code(self) -> i32 {
        match self {
            Role::Min => -1,
            Role::Max => 1,
            Role::Fixed => 2,
            Role::End => 3,
            Role::Other => 0,
        }
    }

    /// The role of an array code; `None` for any other number.
    pub fn from_code(c: f64) -> Option<Role> {
        [Role::Min, Role::Max, Role::Fixed, Role::End, Role::Other].into_iter().find(|r| f64::from(r.code()) == c)
    }

    /// Text used in series CSV files.
    pub fn label(self) -> &'static str {
        match self {
            Role::Min => "min",
            Role::Max => "max",
            Role::Fixed => "fixed",
            Role::End => "end",
            Role::Other => "",
        }
    }

    /// Parses a CSV label; `None` if unknown.
    pub fn from_label(s: &str) -> Option<Role> {
        match s.trim() {
            "min" => Some(Role::Min),
            "max" => Some(Role::Max),
            "fixed" => Some(Role::Fixed),
            "end" => Some(Role::End),
            "" => Some(Role::Other),
            _ => None,
        }
    }

    /// Whether the vertex keeps its input value.
    pub fn is_fixed(self) -> bool {
        matches!(self, Role::Min | Role::Max | Role::Fixed)
    }
}

/// One kept extremum, as the report lists it.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct KeptExtremum {
    /// Vertex index.
    pub index: usize,
    /// `min` or `max`.
    #[cfg_attr(feature = "serde", serde(rename = "type"))]
    pub role: Role,
    /// Input value (kept bit for bit).
    pub value: f64,
    /// Persistence of its pair; `None` (JSON null) for essential or explicitly listed ones
    /// that have none.
    pub persistence: Option<f64>,
    /// Its position in the domain's coordinates (a series' x, a grid's x and y, a mesh's
    /// x, y, z; unused coordinates 0).
    pub point: [f64; 3],
}

/// The kept extrema and the role of every vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct KeptSet {
    /// One role per vertex.
    pub roles: Vec<Role>,
    /// Kept extrema sorted by index.
    pub kept: Vec<KeptExtremum>,
    /// The absolute persistence threshold that was applied, if any.
    pub threshold: Option<f64>,
    /// Non-fatal remarks (a count larger than what exists, …).
    pub warnings: Vec<String>,
}

impl KeptSet {
    /// Indices of kept minima.
    pub fn minima(&self) -> Vec<usize> {
        self.kept.iter().filter(|k| k.role == Role::Min).map(|k| k.index).collect()
    }
    /// Indices of kept maxima.
    pub fn maxima(&self) -> Vec<usize> {
        self.kept.iter().filter(|k| k.role == Role::Max).map(|k| k.index).collect()
    }
}

/// Chooses the kept extrema of `values` on `domain`.
///
/// # Errors
/// * input error: a constant field (nothing to keep), a non-finite value;
/// * usage error: a threshold ≤ 0 or not finite;
/// * infeasible (exit 3): an explicit list that no strict function realizes (an index out
///   of range, a vertex that is not an extremum of the listed type, kept minima and maxima
///   that do not alternate along a series, a minimum not strictly below a neighbouring kept
///   maximum, no minimum or no maximum).
pub fn select<D: Domain>(domain: &D, values: &[f64], selection: &Selection) -> Result<KeptSet> {
    let n = domain.n_vertices();
    let (lo, hi) = check_field(domain, values)?;
    let mut warnings = Vec::new();
    let mut threshold = None;
    let minima_pairs = sublevel_pairs(domain, values);
    let (kept_min, kept_max): (Kept, Kept) = match selection {
        Selection::Explicit { minima, maxima } => {
            check_explicit(domain, values, minima, maxima)?;
            let pers_min = |v: usize| minima_pairs.iter().find(|p| p.extremum == v).map(|p| p.persistence);
            (minima.iter().map(|&v| (v, pers_min(v))).collect(), maxima.iter().map(|&v| (v, None)).collect())
        }
        Selection::Absolute(t) | Selection::Relative(t) => {
            if !(t.is_finite() && *t > 0.0) {
                return Err(Error::Usage(format!("the persistence threshold must be > 0, got {t}")));
            }
            let t = if matches!(selection, Selection::Relative(_)) { t * (hi - lo) } else { *t };
            if !(t > 0.0 && t.is_finite()) {
                return Err(Error::Usage(format!("the persistence threshold scales to {t:e}: choose a larger one")));
            }
            threshold = Some(t);
            match domain.pairing_rule() {
                PairingRule::Path => {
                    path_by_rank(values, &minima_pairs, |p| p.persistence >= t && p.persistence > 0.0, usize::MAX)
                }
                PairingRule::Surface => {
                    let maxima_pairs = superlevel_pairs(domain, values);
                    (by_threshold(&minima_pairs, t), by_threshold(&maxima_pairs, t))
                }
            }
        }
        Selection::Pairs(count) => {
            if domain.pairing_rule() != PairingRule::Path {
                return Err(Error::setting(
                    "pairs",
                    "applies to series; on a surface keep a count of minima and maxima",
                ));
            }
            let available = minima_pairs.iter().filter(|p| p.partner.is_some() && p.persistence > 0.0).count();
            if *count > available {
                warnings.push(format!("asked for {count} pairs, the series has {available}: keeping all"));
            }
            path_by_rank(values, &minima_pairs, |p| p.persistence > 0.0, *count)
        }
        Selection::AllMaxima | Selection::AllMinima => {
            if domain.pairing_rule() == PairingRule::Path {
                return Err(Error::setting("all_extrema", "apply to surfaces"));
            }
            let maxima_pairs = superlevel_pairs(domain, values);
            let all = |pairs: &[Pair]| -> Kept {
                pairs.iter().filter(|p| p.persistence > 0.0).map(|p| (p.extremum, Some(p.persistence))).collect()
            };
            let essential = |pairs: &[Pair]| -> Kept {
                pairs.iter().filter(|p| p.partner.is_none()).map(|p| (p.extremum, Some(p.persistence))).collect()
            };
            if *selection == Selection::AllMaxima {
                (essential(&minima_pairs), all(&maxima_pairs))
            } else {
                (all(&minima_pairs), essential(&maxima_pairs))
            }
        }
        Selection::Count { minima, maxima } => {
            if domain.pairing_rule() == PairingRule::Path {
                return Err(Error::setting(
                    "count",
                    "on a series a count of minima and maxima is a count of pairs: keep pairs",
                ));
            }
            let maxima_pairs = superlevel_pairs(domain, values);
            let (a, w1) = by_count(values, &minima_pairs, *minima, true);
            let (b, w2) = by_count(values, &maxima_pairs, *maxima, false);
            warnings.extend(w1.into_iter().chain(w2));
            (a, b)
        }
    };

    let (mut roles, mut kept) = roles_of(domain, values, &kept_min, &kept_max);
    kept.sort_by_key(|k| k.index);
    if domain.pairing_rule() == PairingRule::Path {
        for end in [0, n - 1] {
            if roles[end] == Role::Other {
                roles[end] = Role::End;
            }
        }
        if selection.by_persistence() {
            // kept sets chosen by persistence are realizable by construction; a failure here is our bug
            check_alternation(values, &kept)
                .map_err(|e| Error::internal(format!("persistence selection is not realizable: {e}")))?;
        }
    }
    Ok(KeptSet { roles, kept, threshold, warnings })
}

/// Checks that `values` can have extrema to keep: one finite value per vertex, and no
/// connected component (nor the whole field) constant. Returns the value range.
fn check_field<D: Domain>(domain: &D, values: &[f64]) -> Result<(f64, f64)> {
    let n = domain.n_vertices();
    if values.len() != n {
        return Err(Error::input(format!("the field has {} values, the domain {n} vertices", values.len())));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(Error::input(format!("value at vertex {i} is not finite ({})", values[i]))
            .at(crate::error::Location::Vertex(i)));
    }
    let (lo, hi) = crate::domain::value_range(values);
    if lo == hi {
        return Err(Error::input(format!("the field is constant ({lo}): it has no extrema to keep")));
    }
    if !(hi - lo).is_finite() {
        return Err(Error::input(format!(
            "the values run from {lo:e} to {hi:e}: their range (max − min) overflows Float64 arithmetic, \
             which the smoothing works in; rescale the field first (divide it by 1e10, say)"
        )));
    }
    if let Some((v, size)) = constant_component(domain, values) {
        return Err(Error::input(format!(
            "the connected component of vertex {v} ({size} vertices) is constant ({}): it has no extrema to keep",
            values[v]
        )));
    }
    Ok((lo, hi))
}

/// The roles and the kept extrema (minima first, then maxima, with their finite persistence).
fn roles_of<D: Domain>(domain: &D, values: &[f64], kept_min: &Kept, kept_max: &Kept) -> (Vec<Role>, Vec<KeptExtremum>) {
    let mut roles = vec![Role::Other; domain.n_vertices()];
    let mut kept = Vec::new();
    for &(v, p) in kept_min {
        roles[v] = Role::Min;
        kept.push(KeptExtremum {
            index: v,
            role: Role::Min,
            value: values[v],
            persistence: p.filter(|x| x.is_finite()),
            point: domain.point(v),
        });
    }
    for &(v, p) in kept_max {
        roles[v] = Role::Max;
        kept.push(KeptExtremum {
            index: v,
            role: Role::Max,
            value: values[v],
            persistence: p.filter(|x| x.is_finite()),
            point: domain.point(v),
        });
    }
    (roles, kept)
}

/// A connected component on which the field is constant: its first vertex and its size.
fn constant_component<D: Domain>(domain: &D, values: &[f64]) -> Option<(usize, usize)> {
    let n = domain.n_vertices();
    let mut seen = vec![false; n];
    let mut stack = Vec::new();
    for start in 0..n {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let (mut size, mut constant) = (0usize, true);
        while let Some(v) = stack.pop() {
            size += 1;
            constant &= values[v] == values[start];
            for w in domain.neighbors(v) {
                if !seen[w] {
                    seen[w] = true;
                    stack.push(w);
                }
            }
        }
        if constant {
            return Some((start, size));
        }
    }
    None
}

/// Series rule: rank (minimum, maximum) pairs by persistence (ties: lower (value, index) of
/// the minimum first), keep the first `count` that pass `keep`; the essential minimum and
/// the global maximum are always kept (when the global maximum's pair is dropped, only its
/// minimum goes).
type Kept = Vec<(usize, Option<f64>)>;
fn path_by_rank(values: &[f64], pairs: &[Pair], keep: impl Fn(&Pair) -> bool, count: usize) -> (Kept, Kept) {
    // a finite count includes the global maximum's own pair (SPEC: it "counts among them")
    let counted = count != usize::MAX;
    let n = values.len();
    let gmax = (0..n).fold(0, |b, v| if sos_greater(values, v, b) { v } else { b });
    let mut ranked: Vec<&Pair> = pairs.iter().filter(|p| p.partner.is_some()).collect();
    ranked.sort_by(|a, b| {
        b.persistence
            .total_cmp(&a.persistence)
            .then(values[a.extremum].total_cmp(&values[b.extremum]))
            .then(a.extremum.cmp(&b.extremum))
    });
    let mut mins = Vec::new();
    let mut maxs = Vec::new();
    for p in pairs.iter().filter(|p| p.partner.is_none()) {
        mins.push((p.extremum, Some(p.persistence)));
    }
    let gmax_pair = pairs.iter().position(|p| p.partner == Some(gmax) && keep(p));
    let mut budget = count;
    if counted && budget > 0 {
        if let Some(k) = gmax_pair {
            let p = &pairs[k];
            mins.push((p.extremum, Some(p.persistence)));
            maxs.push((gmax, Some(p.persistence)));
            budget -= 1;
        }
    }
    for p in ranked.into_iter().filter(|p| keep(p) && !(counted && p.partner == Some(gmax))).take(budget) {
        mins.push((p.extremum, Some(p.persistence)));
        maxs.push((p.partner.expect("ranked pairs have partners"), Some(p.persistence)));
    }
    if !maxs.iter().any(|&(v, _)| v == gmax) {
        let p = pairs.iter().find(|p| p.partner == Some(gmax)).map(|p| p.persistence);
        maxs.push((gmax, p));
    }
    (mins, maxs)
}

fn by_threshold(pairs: &[Pair], t: f64) -> Kept {
    pairs.iter().filter(|p| p.persistence >= t).map(|p| (p.extremum, Some(p.persistence))).collect()
}

fn by_count(values: &[f64], pairs: &[Pair], count: usize, minima: bool) -> (Kept, Option<String>) {
    let mut ranked: Vec<&Pair> = pairs.iter().filter(|p| p.persistence > 0.0).collect();
    ranked.sort_by(|a, b| {
        let sos =
            if minima { sos_less(values, b.extremum, a.extremum) } else { sos_greater(values, b.extremum, a.extremum) };
        b.persistence.total_cmp(&a.persistence).then(if sos {
            std::cmp::Ordering::Greater
        } else {
            std::cmp::Ordering::Less
        })
    });
    let essential = pairs.iter().filter(|p| p.partner.is_none()).count();
    let count = count.max(essential);
    let warning = (count > ranked.len()).then(|| {
        format!(
            "asked for {count} {}, the field has {}: keeping all",
            if minima { "minima" } else { "maxima" },
            ranked.len()
        )
    });
    (ranked.into_iter().take(count).map(|p| (p.extremum, Some(p.persistence))).collect(), warning)
}

fn check_explicit<D: Domain>(domain: &D, values: &[f64], minima: &[usize], maxima: &[usize]) -> Result<()> {
    let n = domain.n_vertices();
    if minima.is_empty() || maxima.is_empty() {
        return Err(Error::infeasible(format!(
            "an explicit list must keep at least one minimum and one maximum (got {} minima, {} maxima)",
            minima.len(),
            maxima.len()
        )));
    }
    let mut seen = vec![false; n];
    for (&v, is_min) in minima.iter().map(|v| (v, true)).chain(maxima.iter().map(|v| (v, false))) {
        if v >= n {
            return Err(Error::infeasible(format!("vertex {v} is out of range (the input has {n} vertices)"))
                .at(crate::error::Location::Vertex(v)));
        }
        if seen[v] {
            return Err(Error::infeasible(format!("vertex {v} is listed twice")).at(crate::error::Location::Vertex(v)));
        }
        seen[v] = true;
        let ok = if is_min {
            domain.neighbors(v).all(|w| sos_greater(values, w, v))
        } else {
            domain.neighbors(v).all(|w| sos_less(values, w, v))
        };
        if !ok {
            return Err(Error::infeasible(format!(
                "vertex {v} (value {}) is not a local {} of the input",
                values[v],
                if is_min { "minimum" } else { "maximum" }
            )));
        }
    }
    if domain.pairing_rule() == PairingRule::Path {
        let mut kept: Vec<KeptExtremum> = minima
            .iter()
            .map(|&v| KeptExtremum {
                index: v,
                role: Role::Min,
                value: values[v],
                persistence: None,
                point: domain.point(v),
            })
            .chain(maxima.iter().map(|&v| KeptExtremum {
                index: v,
                role: Role::Max,
                value: values[v],
                persistence: None,
                point: domain.point(v),
            }))
            .collect();
        kept.sort_by_key(|k| k.index);
        check_alternation(values, &kept)?;
    }
    Ok(())
}

/// Along a series, kept minima and maxima must alternate and each minimum must lie strictly
/// below its neighbouring kept maxima.
fn check_alternation(values: &[f64], kept: &[KeptExtremum]) -> Result<()> {
    for w in kept.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if a.role == b.role {
            return Err(Error::infeasible(format!(
                "kept {}s {} and {} are consecutive: minima and maxima must alternate along a series",
                a.role.label(),
                a.index,
                b.index
            )));
        }
        let (mn, mx) = if a.role == Role::Min { (a, b) } else { (b, a) };
        if values[mn.index] >= values[mx.index] {
            return Err(Error::infeasible(format!(
                "kept minimum {} (value {}) is not strictly below the neighbouring kept maximum {} (value {})",
                mn.index, values[mn.index], mx.index, values[mx.index]
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_field_of_the_wrong_length_is_an_input_error_not_a_panic() {
        let e = select(&crate::domain::Series::uniform(5), &[0.0, 1.0, 0.0], &Selection::Relative(0.1)).unwrap_err();
        assert_eq!(e.kind(), crate::error::ErrorKind::Input);
        assert!(e.to_string().contains("3 values, the domain 5 vertices"), "{e}");
    }
    use crate::domain::Series;

    fn kept(values: &[f64], sel: Selection) -> (Vec<usize>, Vec<usize>) {
        let k = select(&Series::uniform(values.len()), values, &sel).unwrap();
        (k.minima(), k.maxima())
    }

    #[test]
    fn two_bumps_keep_the_large_one() {
        // bump of height 5 at 2, bump of height 1 at 6, between valleys
        let h = [0.0, 2.0, 5.0, 2.0, 0.5, 1.0, 1.5, 1.0, 0.2];
        // pairs: (min 4, max 6) persistence 1.0; (min 8, max 2) persistence 4.8; min 0 essential
        let (mn, mx) = kept(&h, Selection::Absolute(1.2));
        assert_eq!(mx, vec![2]);
        assert_eq!(mn, vec![0, 8]);
        let (mn, mx) = kept(&h, Selection::Absolute(1.0));
        assert_eq!(mx, vec![2, 6]);
        assert_eq!(mn, vec![0, 4, 8]);
    }

    #[test]
    fn global_maximum_survives_a_low_pair() {
        // global max at 1 with a shallow left side: its pair (0? no, endpoint) …
        let h = [9.0, 10.0, 0.0, 3.0, 1.0];
        // pairs: min 4 (1.0) dies at 3 (3.0) p=2; min 0 (9.0) dies at 1 (10.0) p=1; min 2 essential
        let (mn, mx) = kept(&h, Selection::Absolute(1.5));
        assert_eq!(mn, vec![2, 4]);
        assert_eq!(mx, vec![1, 3]);
        let (mn, mx) = kept(&h, Selection::Absolute(2.5));
        assert_eq!(mn, vec![2]);
        assert_eq!(mx, vec![1]);
        // a count includes the global maximum's pair, however small: one pair = (0, 1)
        assert_eq!(kept(&h, Selection::Pairs(1)), (vec![0, 2], vec![1]));
        assert_eq!(kept(&h, Selection::Pairs(0)), (vec![2], vec![1]));
        assert_eq!(kept(&h, Selection::Pairs(2)), (vec![0, 2, 4], vec![1, 3]));
    }

    #[test]
    fn pairs_count_and_warning() {
        let h = [0.0, 2.0, 5.0, 2.0, 0.5, 1.0, 1.5, 1.0, 0.2];
        let s = Series::uniform(h.len());
        let k = select(&s, &h, &Selection::Pairs(1)).unwrap();
        assert_eq!((k.minima(), k.maxima()), (vec![0, 8], vec![2]));
        assert!(k.warnings.is_empty());
        let k = select(&s, &h, &Selection::Pairs(10)).unwrap();
        assert_eq!(k.warnings.len(), 1);
        assert_eq!((k.minima(), k.maxima()), (vec![0, 4, 8], vec![2, 6]));
        // a free end: keep only the global pair of a series that ends high
        let g = [3.0, 0.0, 5.0, 4.0];
        let k = select(&Series::uniform(4), &g, &Selection::Pairs(0)).unwrap();
        assert_eq!((k.minima(), k.maxima()), (vec![1], vec![2]));
        assert_eq!((k.roles[0], k.roles[3]), (Role::End, Role::End));
    }

    #[test]
    fn explicit_lists_are_checked() {
        let h = [0.0, 2.0, 5.0, 2.0, 0.5, 1.0, 1.5, 1.0, 0.2];
        let s = Series::uniform(h.len());
        let sel = |mn: Vec<usize>, mx: Vec<usize>| Selection::Explicit { minima: mn, maxima: mx };
        assert!(select(&s, &h, &sel(vec![4], vec![2, 6])).is_ok());
        let e = select(&s, &h, &sel(vec![4], vec![3])).unwrap_err();
        assert!(e.to_string().contains("vertex 3"), "{e}");
        assert_eq!(e.exit_code(), 3);
        let e = select(&s, &h, &sel(vec![0, 4], vec![6])).unwrap_err();
        assert!(e.to_string().contains("alternate"), "{e}");
        let e = select(&s, &h, &sel(vec![], vec![6])).unwrap_err();
        assert_eq!(e.exit_code(), 3);
        let e = select(&s, &h, &sel(vec![99], vec![6])).unwrap_err();
        assert!(e.to_string().contains("out of range"), "{e}");
    }

    #[test]
    fn constant_field_is_an_input_error() {
        let e = select(&Series::uniform(3), &[1.0; 3], &Selection::Relative(0.05)).unwrap_err();
        assert_eq!(e.exit_code(), 3);
    }
}

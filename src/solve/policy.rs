//! Which route solves the monotone QP, and what a hand-over from one route to another says.
//!
//! The route follows from the problem alone (its size and whether its domain is solid:
//! volumes and tetrahedral meshes), never from the machine's load or memory, so a run's route
//! and output are the same on every machine; a route predicted past the memory budget is
//! refused ([`crate::memory`]), not swapped for a slower one. Every hand-over says why: in the
//! report's `solver_fallback` and, as it happens, to the progress observer as a stage
//! `hand-over` whose summary is the reason (the command line prints it).

use super::settings::{Method, ACTIVE_SET_FROM};

/// The fit's target (Ĝ ≤ 10⁻⁶ × the data term, SPEC.md) that an active-set output must meet
/// as written, after the margin repair; else the structured solver runs instead.
pub const ACTIVE_SET_FIT: f64 = 1e-6;

/// The route for `requested` on a problem of `n` variables: [`Method::Auto`] is the active-set
/// iteration on solid domains (volumes, masked volumes, tetrahedral meshes) of at least
/// [`ACTIVE_SET_FROM`] vertices, whose direct factorisation fills in as 3D nested dissection
/// does, and the structured interior-point solver elsewhere; any other request stands.
#[must_use]
pub fn route(requested: Method, n: usize, solid: bool) -> Method {
    match requested {
        Method::Auto if solid && n >= ACTIVE_SET_FROM => Method::ActiveSet,
        Method::Auto => Method::Structured,
        other => other,
    }
}

/// Tells the progress observer (if any) that `to` takes over, and why.
pub fn announce_hand_over(why: &str, to: Method) {
    let to = match to {
        Method::Clarabel | Method::ClarabelAuxiliary => "Clarabel",
        Method::ActiveSet => "the active-set iteration",
        Method::Structured | Method::Auto => "the interior-point method",
    };
    crate::progress::Stage::begin("hand-over").end(|| format!("{why}; {to} takes over"));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_route_depends_on_the_request_the_size_and_the_domain_only() {
        assert_eq!(route(Method::Auto, ACTIVE_SET_FROM, true), Method::ActiveSet);
        assert_eq!(route(Method::Auto, ACTIVE_SET_FROM - 1, true), Method::Structured);
        assert_eq!(route(Method::Auto, 10 * ACTIVE_SET_FROM, false), Method::Structured);
        for m in [Method::Structured, Method::Clarabel, Method::ClarabelAuxiliary, Method::ActiveSet] {
            assert_eq!(route(m, 10, false), m);
            assert_eq!(route(m, 10 * ACTIVE_SET_FROM, true), m);
        }
    }
}

//! What a domain supplies to the pipeline: its operators and its representative function
//! (the series' linear one, the surfaces' separatrix, harmonic and flooded constructions).

use crate::domain::{Domain, Grid2d, Grid3d, Series, TetMesh, TriMesh};
use crate::error::{Error, Result};
use crate::linalg::Analyses;
use crate::operators::{
    cotan_stiffness, dirichlet_solve, edge_factor, gradient_factor, grid_mass, grid_stiffness, lumped_mass,
    polyharmonic, polyharmonic_products, positive_cotan_stiffness, positive_tet_stiffness, series_mass,
    series_stiffness, tet_gradient_factor, tet_lumped_mass, tet_stiffness, volume_edge_pattern, volume_mass,
    volume_stiffness, with_pattern_of, Energy, Factor, Sparse,
};
use crate::representative::{flooded_representative, separatrix_representative, series_representative, Repairs};
use crate::topology::morse_smale::MorseSmale;
use crate::topology::{KeptSet, Role};
use crate::verify::{certify, Certificate};

/// Which representative function to build on surfaces (series always use the linear one).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum RepresentativeChoice {
    /// Separatrices interpolated, harmonic elsewhere (paper section 3.3).
    #[default]
    Separatrix,
    /// Harmonic: kept minima at the data's minimum, kept maxima at its maximum.
    Harmonic,
    /// The data itself with every cancelled basin flooded to its spill value (Tierny &
    /// Pascucci 2012; NOTES.md 9), plateaus made strict in flood order.
    Flooded,
}

named_enum!(
    RepresentativeChoice,
    "representative",
    [
        (RepresentativeChoice::Separatrix, "separatrix"),
        (RepresentativeChoice::Harmonic, "harmonic"),
        (RepresentativeChoice::Flooded, "flooded"),
    ]
);

/// The construction a representative function came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RepresentativeKind {
    /// Series: linear between consecutive kept extrema.
    Linear,
    /// Separatrices interpolated, harmonic elsewhere.
    Separatrix,
    /// Harmonic between the kept extrema.
    Harmonic,
    /// The data with the cancelled basins flooded.
    Flooded,
}

impl RepresentativeKind {
    /// The construction in one word, as reports name it.
    pub fn name(self) -> &'static str {
        match self {
            RepresentativeKind::Linear => "linear",
            RepresentativeKind::Separatrix => "separatrix",
            RepresentativeKind::Harmonic => "harmonic",
            RepresentativeKind::Flooded => "flooded",
        }
    }
}

impl std::fmt::Display for RepresentativeKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl From<RepresentativeChoice> for RepresentativeKind {
    fn from(c: RepresentativeChoice) -> Self {
        match c {
            RepresentativeChoice::Separatrix => RepresentativeKind::Separatrix,
            RepresentativeChoice::Harmonic => RepresentativeKind::Harmonic,
            RepresentativeChoice::Flooded => RepresentativeKind::Flooded,
        }
    }
}

/// A representative function, the construction that produced it and the complex it used.
#[derive(Clone, Debug)]
pub struct Representative {
    /// Values per vertex.
    pub u: Vec<f64>,
    /// Construction used.
    pub kind: RepresentativeKind,
    /// Construction used, with its variant (one-sided saddles, released vertices).
    pub name: String,
    /// Why each construction tried before it was not used (automatic choice only).
    pub fallbacks: Vec<String>,
    /// The simplified Morse–Smale complex (surfaces).
    pub complex: Option<MorseSmale>,
    /// The certificate of `u` its construction made to accept it (`None` where it made none:
    /// the caller certifies then; at 128³ a certificate takes about 0.25 s).
    pub certificate: Option<Certificate>,
    /// The vertices in u's order ([`crate::domain::sos_sort`]) where the construction made
    /// them in that order (the flooded one), else `None`.
    pub order: Option<Vec<usize>>,
}

/// A domain the pipeline can smooth on: it supplies its operators and its representative.
pub trait Smoothable: Domain {
    /// Stiffness `K = −L`.
    fn stiffness(&self) -> Sparse;
    /// Lumped mass (diagonal, > 0).
    fn mass(&self) -> Vec<f64>;
    /// The Laplacian of harmonic fills where it differs from [`Smoothable::stiffness`], else
    /// `None`: non-negative weights on the domain's own edges, so that the maximum principle
    /// holds (the stiffness is that Laplacian where it already holds).
    fn own_fill_stiffness(&self) -> Option<Sparse> {
        None
    }
    /// The domain's edges (and each vertex itself) as a pattern of zeros where its stiffness
    /// does not store every edge, else `None`: the interior-point routes analyse the energy's
    /// pattern as their normal matrix's, which must hold every constrained pair.
    fn edge_pattern(&self) -> Option<Sparse> {
        None
    }
    /// A volume (tetrahedra): direct factorisations of its energies fill in as a 3D nested
    /// dissection does, which sets [`Method::Auto`](crate::solve::Method::Auto)'s choice.
    fn solid(&self) -> bool {
        false
    }
    /// Whether the representative costs next to nothing (a series: a pass along the samples),
    /// so that the pipeline builds the operators after it on every thread instead of beside
    /// it on half of them.
    fn light_representative(&self) -> bool {
        false
    }
    /// `F₁` with `F₁ᵀF₁ = k` (the stiffness): one row per edge of positive weight, or `None`
    /// when a weight is negative and the domain has no other square root.
    fn stiffness_factor(&self, k: &Sparse) -> Option<Factor> {
        edge_factor(k)
    }
    /// A function with exactly the kept extrema (checked by the pipeline), built by the
    /// first construction in the order `choice` prefers that is not `excluded` (kind and
    /// why: the pipeline excludes one whose order makes the constraints infeasible); `fill`
    /// is the harmonic fills' Laplacian ([`Smoothable::own_fill_stiffness`] or the stiffness), the
    /// factorisations' analyses are in `analyses`. By default the surface constructions
    /// (separatrix, harmonic, flooded) on the domain's Morse–Smale complex, on solid domains
    /// the flooded and harmonic ones; series override it.
    fn representative(
        &self,
        h: &[f64],
        kept: &KeptSet,
        choice: Option<RepresentativeChoice>,
        fill: &Sparse,
        excluded: &[(RepresentativeKind, String)],
        analyses: &mut Analyses,
    ) -> Result<Representative>
    where
        Self: Sized,
    {
        let cells = if self.solid() { Cells::Tetrahedra } else { Cells::Triangles };
        surface_representative(self, h, kept, choice, fill, excluded, analyses, cells)
    }
}

/// The polyharmonic energy with every edge of the domain in its pattern, where the
/// interior-point routes need the constrained pairs (a volume's stiffness does not store its
/// diagonal edges: [`Smoothable::edge_pattern`]).
pub(crate) fn energy_on_edges<D: Smoothable>(
    domain: &D,
    k: &Sparse,
    m: &[f64],
    energy: &Energy,
    scale: &[f64],
) -> Sparse {
    match domain.edge_pattern() {
        Some(edges) => with_pattern_of(polyharmonic_products(k, m, energy, scale), &edges),
        None => polyharmonic(k, m, energy, scale),
    }
}

impl Smoothable for Series {
    fn stiffness(&self) -> Sparse {
        series_stiffness(self)
    }
    fn light_representative(&self) -> bool {
        true
    }
    fn mass(&self) -> Vec<f64> {
        series_mass(self)
    }
    fn representative(
        &self,
        h: &[f64],
        kept: &KeptSet,
        _: Option<RepresentativeChoice>,
        _: &Sparse,
        _: &[(RepresentativeKind, String)],
        _: &mut Analyses,
    ) -> Result<Representative> {
        let u = series_representative(self, h, kept)?;
        Ok(Representative {
            u,
            kind: RepresentativeKind::Linear,
            name: "linear".into(),
            fallbacks: Vec::new(),
            complex: None,
            certificate: None,
            order: None,
        })
    }
}

/// The harmonic representative: kept minima at the data's minimum, kept maxima at its
/// maximum, harmonic elsewhere with `k` (non-negative weights: the maximum principle holds).
fn harmonic_representative(
    h: &[f64],
    kept: &KeptSet,
    k: &Sparse,
) -> std::result::Result<Vec<f64>, crate::error::NumericalError> {
    let (lo, hi) = crate::domain::value_range(h);
    let fixed: Vec<Option<f64>> = kept
        .roles
        .iter()
        .map(|r| match r {
            Role::Min => Some(lo),
            Role::Max => Some(hi),
            _ => None,
        })
        .collect();
    dirichlet_solve(k, &fixed)
}

/// The separatrix representative's name with its variant: the one-sided saddles it used and
/// what its repairs changed.
fn separatrix_name(one_sided_saddles: usize, r: Repairs) -> String {
    let mut name = "separatrix".to_string();
    if one_sided_saddles > 0 {
        name = format!("separatrix with {one_sided_saddles} one-sided saddles");
    }
    let mut changes = Vec::new();
    if r.released > 0 {
        changes.push(format!("{} contradicting separatrix vertices released to the harmonic fill", r.released));
    }
    let plural = |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
    if r.moved > 0 {
        changes.push(format!("{} moved outward", plural(r.moved, "kept value", "kept values")));
    }
    if r.pinned > 0 {
        changes.push(format!("{} pinned beside them", plural(r.pinned, "free vertex", "free vertices")));
    }
    if !changes.is_empty() {
        name = format!("{name} ({})", changes.join(", "));
    }
    name
}

/// The cells a domain's representative is built on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Cells {
    /// Triangles: the Morse–Smale complex and the separatrix construction exist.
    Triangles,
    /// Tetrahedra: the flooded and harmonic constructions only (docs/volumes.md says why).
    Tetrahedra,
}

/// The representative on a triangulated surface or a volume. A construction the user chose is
/// built or refused (its check failing is an error naming the vertices); the automatic choice
/// tries the flooded one first (NOTES.md 9: closer to the data on every bundled grid,
/// docs/grids.md section 5), then on surfaces the separatrix one, then the harmonic one, and
/// records why each one before was not used. The Morse-Smale complex is built only for the
/// separatrix one (`--complex` builds it for the others). `k` is the Laplacian of the
/// harmonic fills (non-negative weights).
#[allow(clippy::too_many_arguments)]
fn surface_representative<D: Domain>(
    domain: &D,
    h: &[f64],
    kept: &KeptSet,
    choice: Option<RepresentativeChoice>,
    k: &Sparse,
    excluded: &[(RepresentativeKind, String)],
    analyses: &mut Analyses,
    cells: Cells,
) -> Result<Representative> {
    if cells == Cells::Tetrahedra && choice == Some(RepresentativeChoice::Separatrix) {
        return Err(Error::Usage(
            "--representative separatrix is for series, grids and triangle meshes: on volumes use flooded or harmonic \
             (docs/volumes.md)"
                .into(),
        ));
    }
    let analyses = std::cell::RefCell::new(analyses);
    let mut why: Vec<String> = excluded.iter().map(|(kind, e)| format!("{kind} representative: {e}")).collect();
    let skip = |kind: RepresentativeKind| excluded.iter().any(|(x, _)| *x == kind);
    // the complex, built when the separatrix representative is tried (surfaces only)
    let built: std::cell::OnceCell<Option<MorseSmale>> = std::cell::OnceCell::new();
    let complex_for = |why: &mut Vec<String>| -> Option<&MorseSmale> {
        built
            .get_or_init(|| {
                let stage = crate::progress::Stage::begin("complex");
                match MorseSmale::new(domain, h, kept) {
                    Ok(ms) => {
                        stage.end(|| {
                            format!(
                                "{} saddles, {} descending and {} ascending separatrices",
                                ms.saddles.len(),
                                ms.descending.len(),
                                ms.ascending.len()
                            )
                        });
                        Some(ms)
                    }
                    Err(e) => {
                        stage.end(|| format!("not built ({e})"));
                        why.push(format!("Morse-Smale complex: {e}"));
                        None
                    }
                }
            })
            .as_ref()
    };
    let repairs = std::cell::Cell::new(Repairs::default());
    let one_sided_saddles = std::cell::Cell::new(0);
    let merged_used: std::cell::RefCell<Option<MorseSmale>> = std::cell::RefCell::new(None);
    // the matched saddles first; if u fails its check, once more with the one-sided saddles
    // (a kept boundary extremum's partner is often one: without its separatrices the cells
    // beside it reach along the boundary to values beyond it); then both again with failing
    // kept extrema moved outward instead of released around (few-valued data: a kept minimum
    // beside free vertices the fill holds below it). u is built from the values with their
    // ties broken as the complex broke them (SoS): a saddle and an extremum of equal input
    // value no longer give a flat separatrix.
    let separatrix = |why: &mut Vec<String>| -> Option<(Vec<f64>, Certificate, Option<Vec<usize>>)> {
        let matched = complex_for(why)?;
        let merged = matched.with_one_sided();
        let untied = crate::domain::sos_untied(h);
        let complexes: Vec<&MorseSmale> = std::iter::once(matched).chain(merged.as_ref()).collect();
        let attempts = [false, true].into_iter().flat_map(|moving| complexes.iter().map(move |&ms| (ms, moving)));
        // the failure of the last attempt (the most mended one) is the one reported
        let mut last_failure = None;
        for (ms, move_kept) in attempts {
            if crate::progress::cancelled() {
                return None;
            }
            match separatrix_representative(domain, &untied, kept, ms, k, move_kept, &mut analyses.borrow_mut()) {
                Ok((u, r)) => {
                    let c = certify(domain, &u, &kept.roles, None);
                    if c.passed {
                        repairs.set(r);
                        if !std::ptr::eq(ms, matched) {
                            // the one-sided saddles are never matched ones
                            one_sided_saddles.set(ms.saddles.len() - matched.saddles.len());
                            *merged_used.borrow_mut() = Some(ms.clone());
                        }
                        return Some((u, c, None));
                    }
                    last_failure = Some(format!("separatrix representative: {}", c.summary()));
                }
                Err(e) => last_failure = Some(format!("separatrix representative: {e}")),
            }
        }
        why.extend(last_failure);
        None
    };
    let harmonic = |why: &mut Vec<String>| -> Option<(Vec<f64>, Certificate, Option<Vec<usize>>)> {
        crate::progress::update("representative", || "harmonic fill".into());
        match harmonic_representative(h, kept, k) {
            Ok(u) => {
                let c = certify(domain, &u, &kept.roles, None);
                if c.passed {
                    return Some((u, c, None));
                }
                why.push(format!("harmonic representative: {}", c.summary()));
            }
            Err(e) => why.push(format!("harmonic representative: {e}")),
        }
        None
    };
    let flooded = |why: &mut Vec<String>| -> Option<(Vec<f64>, Certificate, Option<Vec<usize>>)> {
        crate::progress::update("representative", || "flooded".into());
        let u = flooded_representative(domain, h, kept);
        if u.is_none() {
            why.push(if u32::try_from(h.len()).is_err() {
                "flooded representative: more than 2³² vertices".into()
            } else {
                "flooded representative: the floods did not settle".into()
            });
        }
        u
    };
    use RepresentativeKind::{Flooded, Harmonic, Separatrix};
    let automatic = match cells {
        Cells::Triangles => vec![Flooded, Separatrix, Harmonic],
        Cells::Tetrahedra => vec![Flooded, Harmonic],
    };
    let order: Vec<RepresentativeKind> = match choice {
        None => automatic,
        Some(c) => vec![c.into()],
    };
    if choice.is_some() {
        why.clear();
    }
    let build = |kind: RepresentativeKind, why: &mut Vec<String>| match kind {
        Separatrix => separatrix(why),
        Harmonic => harmonic(why),
        _ => flooded(why),
    };
    let named = |kind: RepresentativeKind| match kind {
        Separatrix => separatrix_name(one_sided_saddles.get(), repairs.get()),
        _ => kind.name().to_string(),
    };
    let mut found = None;
    for kind in order {
        crate::progress::checkpoint()?;
        if skip(kind) {
            continue;
        }
        if let Some(made) = build(kind, &mut why) {
            found = Some((kind, made));
            break;
        }
    }
    // the constructions' borrows of the complex end here: it moves into the result
    if let Some((kind, (u, certificate, order))) = found {
        // --complex writes the separatrices u was built from
        let complex = built.into_inner().flatten();
        let complex = if kind == Separatrix { merged_used.take().or(complex) } else { complex };
        return Ok(Representative {
            u,
            kind,
            name: named(kind),
            fallbacks: why,
            complex,
            certificate: Some(certificate),
            order,
        });
    }
    let message = match choice {
        Some(_) => format!("{} (requested explicitly: not replaced by another construction)", why.join("; ")),
        None => why.join("; "),
    };
    Err(Error::Representative { path: None, message })
}

impl Smoothable for TriMesh {
    fn stiffness(&self) -> Sparse {
        cotan_stiffness(self.positions(), self.faces())
    }
    fn mass(&self) -> Vec<f64> {
        lumped_mass(self.positions(), self.faces())
    }
    /// The harmonic fills use [`positive_cotan_stiffness`]: cotangent weights of obtuse
    /// triangles can be negative and break the maximum principle the representative relies on
    /// (paper section 5).
    fn own_fill_stiffness(&self) -> Option<Sparse> {
        Some(positive_cotan_stiffness(self.positions(), self.faces()))
    }
    /// One row per edge when every cotangent weight is ≥ 0, else the area-weighted triangle
    /// gradients (three rows per triangle).
    fn stiffness_factor(&self, k: &Sparse) -> Option<Factor> {
        edge_factor(k).or_else(|| Some(gradient_factor(self.positions(), self.faces())))
    }
}

impl Smoothable for Grid2d {
    fn stiffness(&self) -> Sparse {
        grid_stiffness(self)
    }
    fn mass(&self) -> Vec<f64> {
        grid_mass(self)
    }
}

/// The volume grid: the 7-point stencil (its weights are ≥ 0, so it is also the fills'
/// Laplacian and has an edge factor) and the flooded or harmonic representative.
impl Smoothable for Grid3d {
    fn solid(&self) -> bool {
        true
    }
    fn stiffness(&self) -> Sparse {
        volume_stiffness(self)
    }
    fn edge_pattern(&self) -> Option<Sparse> {
        Some(volume_edge_pattern(self))
    }
    fn mass(&self) -> Vec<f64> {
        volume_mass(self)
    }
}

/// Tetrahedral meshes: P1 elements (stiffness from the dihedral cotangents, lumped mass),
/// the clamped positive-weight stiffness for harmonic fills, and the flooded or harmonic
/// representative, as on the volume grid.
impl Smoothable for TetMesh {
    fn solid(&self) -> bool {
        true
    }
    fn stiffness(&self) -> Sparse {
        tet_stiffness(self.positions(), self.tets())
    }
    fn mass(&self) -> Vec<f64> {
        tet_lumped_mass(self.positions(), self.tets())
    }
    /// Obtuse dihedral angles give negative edge weights, which break the maximum principle
    /// of harmonic fills: [`positive_tet_stiffness`] clamps them.
    fn own_fill_stiffness(&self) -> Option<Sparse> {
        Some(positive_tet_stiffness(self.positions(), self.tets()))
    }
    /// One row per edge when every weight is ≥ 0, else the volume-weighted tetrahedron
    /// gradients (three rows per tetrahedron).
    fn stiffness_factor(&self, k: &Sparse) -> Option<Factor> {
        edge_factor(k).or_else(|| Some(tet_gradient_factor(self.positions(), self.tets())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A volume's stiffness stores its 7-point stencil only; the energy the interior-point
    /// routes get holds every edge (each of SPEC's 14 neighbours), the active set's only the
    /// products' 25-point stencil.
    #[test]
    fn a_volume_s_energy_holds_every_edge_for_the_interior_point_routes() {
        let g = Grid3d::with_geometry([5, 4, 6], [1.0, 1.5, 0.7], [0.0; 3]).unwrap();
        let (k, m) = (g.stiffness(), g.mass());
        let energy = Energy::order(2);
        let holds = |p: &Sparse, v: usize, w: usize| {
            let (cp, ri) = (p.symbolic().col_ptr(), p.symbolic().row_idx());
            ri[cp[w]..cp[w + 1]].binary_search(&v).is_ok()
        };
        let on_edges = energy_on_edges(&g, &k, &m, &energy, &[1.0]);
        let products = polyharmonic_products(&k, &m, &energy, &[1.0]);
        let mut diagonal_missing = 0;
        for v in 0..g.n_vertices() {
            for w in g.neighbors(v) {
                assert!(holds(&on_edges, v, w), "edge ({v}, {w})");
                diagonal_missing += usize::from(!holds(&products, v, w));
            }
        }
        assert!(diagonal_missing > 0, "the cube diagonals lie outside the 25-point stencil");
        // the same values where both hold an entry
        let x: Vec<f64> = (0..g.n_vertices()).map(|i| (i as f64 * 0.37).sin()).collect();
        let (a, b) = (crate::operators::quadratic_form(&on_edges, &x), crate::operators::quadratic_form(&products, &x));
        assert!((a - b).abs() <= 1e-12 * a.abs(), "{a} against {b}");
    }
}

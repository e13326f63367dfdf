//! Many fields on one domain: [`Smoother`], generic over the domain, and [`AnySmoother`], the
//! same over a domain chosen at run time (for bindings that cannot be generic).

pub use crate::domain::AnyDomain;
use crate::domain::{Domain, Grid2d, Grid3d, Series, TetMesh, TriMesh};
use crate::error::Result;
use crate::linalg::Analyses;
#[cfg(doc)]
use crate::pipeline::smooth;
use crate::pipeline::{smooth_on, DomainOperators, SmoothSettings, Smoothable, Smoothed};

/// The library's entry point for many fields on one domain (time steps, ensemble members,
/// colour channels): built once per domain and settings, it owns the domain's operators
/// ([`DomainOperators`]) and the analyses of its factorisations ([`Analyses`]), and
/// [`Smoother::smooth`] reuses them. What a second field skips: building the stiffness, the
/// mass and the fills' Laplacian, and the symbolic analysis of the fills' Laplacian (the
/// harmonic fills of the representative). The solver's normal matrix depends on the fixed
/// vertices: its analysis is made again for every field, on the other core beside the
/// representative, with the factor storage it is used with. The energy depends on the
/// smoothing length, which on series follows the kept extrema, and is rebuilt. Memory for
/// speed: the analyses stay between fields (the one-off [`smooth`] drops the fills' before the
/// solve). A smoother is `Send`: one per thread works.
///
/// ```
/// use toposmooth::domain::Grid2d;
/// use toposmooth::pipeline::SmoothSettings;
/// use toposmooth::smoother::Smoother;
/// use toposmooth::topology::Selection;
///
/// let grid = Grid2d::new(24, 16).unwrap();
/// // cancel the pairs below 20 % of the range
/// let settings = SmoothSettings { selection: Selection::Relative(0.2), ..Default::default() };
/// let mut smoother = Smoother::new(grid, settings).unwrap();
/// for step in 0..2 {
///     let h: Vec<f64> = (0..24 * 16)
///         .map(|i| ((i % 24) as f64 * 0.4 + step as f64).sin() + ((i / 24) as f64 * 0.5).cos() + 0.05 * ((i * 7919) % 13) as f64)
///         .collect();
///     let out = smoother.smooth(&h).unwrap();
///     assert!(out.report.certificate.passed);
/// }
/// ```
pub struct Smoother<D: Smoothable + Sync> {
    domain: D,
    settings: SmoothSettings,
    operators: DomainOperators,
    analyses: Analyses,
}

impl<D: Smoothable + Sync> Smoother<D> {
    /// Checks the settings and builds the domain's operators.
    ///
    /// # Errors
    /// A usage error for contradictory settings.
    pub fn new(domain: D, settings: SmoothSettings) -> Result<Self> {
        settings.validate()?;
        let operators = DomainOperators::new(&domain);
        Ok(Smoother { domain, settings, operators, analyses: Analyses::default() })
    }

    /// Smooths one field (one value per vertex of the domain), as [`smooth`] does.
    ///
    /// # Errors
    /// As [`smooth`].
    pub fn smooth(&mut self, h: &[f64]) -> Result<Smoothed> {
        smooth_on(&self.domain, &mut self.operators, h, &self.settings, &mut self.analyses, true)
    }

    /// The domain.
    pub fn domain(&self) -> &D {
        &self.domain
    }

    /// The settings.
    pub fn settings(&self) -> &SmoothSettings {
        &self.settings
    }
}

/// [`Smoother`] over an [`AnyDomain`].
pub enum AnySmoother {
    /// On a series.
    Series(Smoother<Series>),
    /// On a grid.
    Grid(Smoother<Grid2d>),
    /// On a mesh.
    Mesh(Smoother<TriMesh>),
    /// On a volume grid.
    Volume(Smoother<Grid3d>),
    /// On a tetrahedral mesh.
    Tets(Smoother<TetMesh>),
}

/// Runs `$body` with `$s` bound to the [`Smoother`] inside an [`AnySmoother`].
macro_rules! with_smoother {
    ($any:expr, $s:ident => $body:expr) => {
        match $any {
            AnySmoother::Series($s) => $body,
            AnySmoother::Grid($s) => $body,
            AnySmoother::Mesh($s) => $body,
            AnySmoother::Volume($s) => $body,
            AnySmoother::Tets($s) => $body,
        }
    };
}

impl AnySmoother {
    /// As [`Smoother::new`].
    ///
    /// # Errors
    /// As [`Smoother::new`].
    pub fn new(domain: AnyDomain, settings: SmoothSettings) -> Result<Self> {
        Ok(match domain {
            AnyDomain::Series(d) => AnySmoother::Series(Smoother::new(d, settings)?),
            AnyDomain::Grid(d) => AnySmoother::Grid(Smoother::new(d, settings)?),
            AnyDomain::Mesh(d) => AnySmoother::Mesh(Smoother::new(d, settings)?),
            AnyDomain::Volume(d) => AnySmoother::Volume(Smoother::new(d, settings)?),
            AnyDomain::Tets(d) => AnySmoother::Tets(Smoother::new(d, settings)?),
        })
    }

    /// As [`Smoother::smooth`].
    ///
    /// # Errors
    /// As [`Smoother::smooth`].
    pub fn smooth(&mut self, h: &[f64]) -> Result<Smoothed> {
        with_smoother!(self, s => s.smooth(h))
    }

    /// Vertices of the domain (the length a field must have).
    pub fn n_vertices(&self) -> usize {
        with_smoother!(self, s => s.domain().n_vertices())
    }

    /// The settings.
    pub fn settings(&self) -> &SmoothSettings {
        with_smoother!(self, s => s.settings())
    }
}

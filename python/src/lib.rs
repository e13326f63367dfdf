//! `toposmooth._toposmooth`: the library's public API on numpy arrays. The Python package
//! (`python/toposmooth/`) wraps it with keyword arguments, pandas and docstrings; this module
//! takes plain values: a [`Domain`], a settings dict, contiguous float64 arrays.
//!
//! Every computation runs with the GIL released ([`Python::detach`]): other Python threads go
//! on while a field is smoothed. Errors are raised as the package's exception classes
//! (`toposmooth.errors`), one per [`ErrorKind`], with the library's message, the kind, the
//! CLI's exit status and the file when one is known.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};
use toposmooth::apps::weights::{WeightMethod, WeightSettings};
use toposmooth::domain::{AnyDomain, Domain as _, Grid2d, Grid3d, Series, TetMesh, TriMesh};
use toposmooth::topology::{extrema_table, select, ExtremumKind, Role, Selection};
use toposmooth::{
    AnySmoother, EdgeSet, Energy, Error, ErrorKind, Formulation, Method, QpSettings, RepresentativeChoice,
    SmoothSettings,
};

/// The package's exception for a library error: `toposmooth.errors.<Class>(message)` with the
/// attributes `kind`, `exit_code` and `path`.
fn to_py(py: Python<'_>, e: Error) -> PyErr {
    let class = match e.kind() {
        ErrorKind::Usage => "UsageError",
        ErrorKind::Io => "IoError",
        ErrorKind::Input => "InputError",
        ErrorKind::Infeasible => "InfeasibleError",
        ErrorKind::Uncertified => "CertificateError",
        ErrorKind::Internal => "InternalError",
        ErrorKind::NoSolution => "SolverError",
    };
    let raised = (|| -> PyResult<PyErr> {
        let ty = py.import("toposmooth.errors")?.getattr(class)?.cast_into::<PyType>()?;
        let err = PyErr::from_type(ty, (e.to_string(),));
        let value = err.value(py);
        value.setattr("kind", format!("{:?}", e.kind()).to_lowercase())?;
        value.setattr("exit_code", e.exit_code())?;
        value.setattr("path", e.path().map(|p| p.display().to_string()))?;
        Ok(err)
    })();
    raised.unwrap_or_else(|import_failure| import_failure)
}

fn usage(py: Python<'_>, message: String) -> PyErr {
    to_py(py, Error::Usage(message))
}

/// A contiguous float64 array's values (no copy), or a usage error naming the argument.
fn values<'a>(py: Python<'_>, name: &str, a: &'a PyReadonlyArray1<'_, f64>) -> PyResult<&'a [f64]> {
    a.as_slice().map_err(|_| usage(py, format!("{name} must be a contiguous float64 array")))
}

/// [`values`] of a field on `domain`: one per vertex, or an input error.
fn field<'a>(py: Python<'_>, domain: &AnyDomain, name: &str, a: &'a PyReadonlyArray1<'_, f64>) -> PyResult<&'a [f64]> {
    let h = values(py, name, a)?;
    if h.len() != domain.n_vertices() {
        let msg = format!("{name} has {} entries, the domain {} vertices", h.len(), domain.n_vertices());
        return Err(to_py(py, Error::input(msg)));
    }
    Ok(h)
}

/// The extremum table of `h` and the kept set of `sel`, on a domain chosen at run time.
fn table_and_kept(
    d: &AnyDomain,
    h: &[f64],
    sel: &Selection,
) -> toposmooth::Result<(Vec<toposmooth::topology::ExtremumInfo>, toposmooth::topology::KeptSet)> {
    Ok(toposmooth::with_domain!(d, g => (extrema_table(g, h), select(g, h, sel)?)))
}

/// A domain: a series, a regular grid or a triangle mesh (validated).
#[pyclass(module = "toposmooth._toposmooth", frozen)]
struct Domain {
    inner: AnyDomain,
}

#[pymethods]
impl Domain {
    /// A series on `x` (strictly increasing, finite), or on 0, 1, …, n−1 when `x` is None.
    #[staticmethod]
    #[pyo3(signature = (n, x=None))]
    fn series(py: Python<'_>, n: usize, x: Option<PyReadonlyArray1<'_, f64>>) -> PyResult<Self> {
        let series = match x {
            None => Series::uniform(n),
            Some(x) => {
                let x = values(py, "x", &x)?;
                if x.len() != n {
                    return Err(to_py(py, Error::input(format!("x has {} values, the series {n}", x.len()))));
                }
                Series::with_coordinates(x.to_vec()).map_err(|e| to_py(py, e))?
            }
        };
        Ok(Domain { inner: AnyDomain::Series(series) })
    }

    /// An `nx × ny` grid, vertex (r, c) at `origin + (c·dx, r·dy)`.
    #[staticmethod]
    fn grid(py: Python<'_>, nx: usize, ny: usize, spacing: [f64; 2], origin: [f64; 2]) -> PyResult<Self> {
        let grid = Grid2d::with_geometry(nx, ny, spacing, origin).map_err(|e| to_py(py, e))?;
        Ok(Domain { inner: AnyDomain::Grid(grid) })
    }

    /// An `nx × ny × nz` volume grid, vertex (i, j, k) at `origin + (i·dx, j·dy, k·dz)` with
    /// flat index `i + nx·(j + ny·k)` (a C-order array of shape (nz, ny, nx), flattened).
    #[staticmethod]
    fn volume(py: Python<'_>, nx: usize, ny: usize, nz: usize, spacing: [f64; 3], origin: [f64; 3]) -> PyResult<Self> {
        let grid = Grid3d::with_geometry([nx, ny, nz], spacing, origin).map_err(|e| to_py(py, e))?;
        Ok(Domain { inner: AnyDomain::Volume(grid) })
    }

    /// A triangle mesh from `vertices` (n, 2|3) float64 and `faces` (m, 3) int64.
    #[staticmethod]
    fn mesh(py: Python<'_>, vertices: PyReadonlyArray2<'_, f64>, faces: PyReadonlyArray2<'_, i64>) -> PyResult<Self> {
        let (v, f) = (vertices.as_array(), faces.as_array());
        let dim = v.ncols();
        if dim != 2 && dim != 3 {
            return Err(to_py(py, Error::input(format!("vertices must have 2 or 3 columns, got {dim}"))));
        }
        if f.ncols() != 3 {
            return Err(to_py(py, Error::input(format!("faces must have 3 columns, got {}", f.ncols()))));
        }
        let positions: Vec<[f64; 3]> =
            v.rows().into_iter().map(|r| [r[0], r[1], if dim == 3 { r[2] } else { 0.0 }]).collect();
        let n = positions.len() as i64;
        let mut triangles = Vec::with_capacity(f.nrows());
        for (k, r) in f.rows().into_iter().enumerate() {
            if let Some(&bad) = r.iter().find(|&&i| !(0..n).contains(&i)) {
                return Err(to_py(py, Error::input(format!("face {k} has vertex {bad}; the mesh has {n} vertices"))));
            }
            triangles.push([r[0] as usize, r[1] as usize, r[2] as usize]);
        }
        let mesh = py.detach(|| TriMesh::new(positions, triangles)).map_err(|e| to_py(py, e))?;
        Ok(Domain { inner: AnyDomain::Mesh(mesh) })
    }

    /// A tetrahedral mesh from `vertices` (n, 3) float64 and `tets` (m, 4) int64.
    #[staticmethod]
    fn tetrahedra(
        py: Python<'_>,
        vertices: PyReadonlyArray2<'_, f64>,
        tets: PyReadonlyArray2<'_, i64>,
    ) -> PyResult<Self> {
        let (v, t) = (vertices.as_array(), tets.as_array());
        if v.ncols() != 3 {
            return Err(to_py(
                py,
                Error::input(format!("vertices of tetrahedra must have 3 columns, got {}", v.ncols())),
            ));
        }
        if t.ncols() != 4 {
            return Err(to_py(py, Error::input(format!("tetrahedra must have 4 columns, got {}", t.ncols()))));
        }
        let positions: Vec<[f64; 3]> = v.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect();
        let n = positions.len() as i64;
        let mut cells = Vec::with_capacity(t.nrows());
        for (k, r) in t.rows().into_iter().enumerate() {
            if let Some(&bad) = r.iter().find(|&&i| !(0..n).contains(&i)) {
                return Err(to_py(
                    py,
                    Error::input(format!("tetrahedron {k} has vertex {bad}; the mesh has {n} vertices")),
                ));
            }
            cells.push([r[0] as usize, r[1] as usize, r[2] as usize, r[3] as usize]);
        }
        let mesh = py.detach(|| TetMesh::new(positions, cells)).map_err(|e| to_py(py, e))?;
        Ok(Domain { inner: AnyDomain::Tets(mesh) })
    }

    /// Number of vertices (the length of a field on this domain).
    #[getter]
    fn n_vertices(&self) -> usize {
        self.inner.n_vertices()
    }

    /// "series", "grid", "mesh", "volume" or "tetrahedra".
    #[getter]
    fn kind(&self) -> &'static str {
        match self.inner {
            AnyDomain::Series(_) => "series",
            AnyDomain::Grid(_) => "grid",
            AnyDomain::Mesh(_) => "mesh",
            AnyDomain::Volume(_) => "volume",
            AnyDomain::Tets(_) => "tetrahedra",
        }
    }

    fn __repr__(&self) -> String {
        match &self.inner {
            AnyDomain::Series(s) => format!("Domain.series({} samples)", s.n_vertices()),
            AnyDomain::Grid(g) => {
                format!("Domain.grid({} × {}, spacing {:?}, origin {:?})", g.nx(), g.ny(), g.spacing(), g.origin())
            }
            AnyDomain::Mesh(m) => format!("Domain.mesh({} vertices, {} triangles)", m.n_vertices(), m.faces().len()),
            AnyDomain::Volume(g) => format!(
                "Domain.volume({} × {} × {}, spacing {:?}, origin {:?})",
                g.nx(),
                g.ny(),
                g.nz(),
                g.spacing(),
                g.origin()
            ),
            AnyDomain::Tets(m) => {
                format!("Domain.tetrahedra({} vertices, {} tetrahedra)", m.n_vertices(), m.tets().len())
            }
        }
    }
}

/// `persistence` as the CLI takes it: a number is absolute, `"5%"` relative to the range.
fn persistence(py: Python<'_>, p: &Bound<'_, PyAny>) -> PyResult<Selection> {
    let (v, relative) = if let Ok(text) = p.extract::<String>() {
        let t = text.trim();
        match t.strip_suffix('%') {
            Some(num) => (num.trim().parse::<f64>().ok(), true),
            None => (t.parse::<f64>().ok(), false),
        }
    } else {
        (p.extract::<f64>().ok(), false)
    };
    match v {
        Some(v) if v.is_finite() && v > 0.0 => {
            Ok(if relative { Selection::Relative(v / 100.0) } else { Selection::Absolute(v) })
        }
        _ => Err(usage(py, format!("persistence must be a number > 0 or a percentage such as \"5%\", got {p}"))),
    }
}

fn get<'py, T: FromPyObjectOwned<'py>>(py: Python<'py>, d: &Bound<'py, PyDict>, key: &str) -> PyResult<Option<T>> {
    match d.get_item(key)? {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(v) => v.extract::<T>().map(Some).map_err(|e| usage(py, format!("{key}: {}", Into::<PyErr>::into(e)))),
    }
}

/// The selection from `persistence`, `minima`/`maxima`, `pairs`, `keep_min`/`keep_max`,
/// `keep_all_maxima`/`keep_all_minima` (exactly one rule; 5 % of the range when none is given).
fn selection(py: Python<'_>, d: &Bound<'_, PyDict>) -> PyResult<Selection> {
    let p = d.get_item("persistence")?.filter(|v| !v.is_none());
    let (minima, maxima) = (get::<usize>(py, d, "minima")?, get::<usize>(py, d, "maxima")?);
    let pairs = get::<usize>(py, d, "pairs")?;
    let (keep_min, keep_max) = (get::<Vec<usize>>(py, d, "keep_min")?, get::<Vec<usize>>(py, d, "keep_max")?);
    let all_max = get::<bool>(py, d, "keep_all_maxima")?.unwrap_or(false);
    let all_min = get::<bool>(py, d, "keep_all_minima")?.unwrap_or(false);
    let rules = [
        ("persistence", p.is_some()),
        ("minima/maxima", minima.is_some() || maxima.is_some()),
        ("pairs", pairs.is_some()),
        ("keep_min/keep_max", keep_min.is_some() || keep_max.is_some()),
        ("keep_all_maxima", all_max),
        ("keep_all_minima", all_min),
    ];
    let given: Vec<&str> = rules.iter().filter(|r| r.1).map(|r| r.0).collect();
    if given.len() > 1 {
        return Err(usage(py, format!("choose one selection rule, got {}", given.join(" and "))));
    }
    Ok(match given.first().copied() {
        None => Selection::Relative(0.05),
        Some("persistence") => persistence(py, &p.expect("given"))?,
        Some("minima/maxima") => Selection::Count { minima: minima.unwrap_or(1), maxima: maxima.unwrap_or(1) },
        Some("pairs") => Selection::Pairs(pairs.expect("given")),
        Some("keep_min/keep_max") => {
            Selection::Explicit { minima: keep_min.unwrap_or_default(), maxima: keep_max.unwrap_or_default() }
        }
        Some("keep_all_maxima") => Selection::AllMaxima,
        _ => Selection::AllMinima,
    })
}

fn choice<T: Copy>(py: Python<'_>, key: &str, text: Option<String>, options: &[(&str, T)], default: T) -> PyResult<T> {
    let Some(text) = text else { return Ok(default) };
    options.iter().find(|o| o.0 == text).map(|o| o.1).ok_or_else(|| {
        let names: Vec<String> = options.iter().map(|o| format!("\"{}\"", o.0)).collect();
        usage(py, format!("{key} must be one of {}, got \"{text}\"", names.join(", ")))
    })
}

fn qp_settings(py: Python<'_>, d: &Bound<'_, PyDict>) -> PyResult<QpSettings> {
    let solver = choice(
        py,
        "solver",
        get(py, d, "solver")?,
        &[
            ("auto", Method::Auto),
            ("structured", Method::Structured),
            ("clarabel", Method::Clarabel),
            ("clarabel-auxiliary", Method::ClarabelAuxiliary),
            ("active-set", Method::ActiveSet),
        ],
        Method::Auto,
    )?;
    let formulation = choice(
        py,
        "formulation",
        get(py, d, "formulation")?,
        &[("auto", Formulation::Auto), ("assembled", Formulation::Assembled), ("factored", Formulation::Factored)],
        Formulation::Auto,
    )?;
    let max_iter = get::<u32>(py, d, "max_iter")?.unwrap_or(200);
    if max_iter == 0 {
        return Err(usage(py, "max_iter must be at least 1".into()));
    }
    Ok(QpSettings { max_iter, method: solver, formulation, ..Default::default() })
}

fn edges(py: Python<'_>, d: &Bound<'_, PyDict>) -> PyResult<EdgeSet> {
    choice(py, "edges", get(py, d, "edges")?, &[("minimal", EdgeSet::Minimal), ("all", EdgeSet::All)], EdgeSet::Minimal)
}

/// The library's settings from the package's keyword arguments (unknown keys are refused).
fn smooth_settings(py: Python<'_>, d: &Bound<'_, PyDict>) -> PyResult<SmoothSettings> {
    const KEYS: &[&str] = &[
        "persistence",
        "minima",
        "maxima",
        "pairs",
        "keep_min",
        "keep_max",
        "keep_all_maxima",
        "keep_all_minima",
        "order",
        "sharp",
        "data_weight",
        "smooth_weight",
        "smooth_length",
        "edges",
        "representative",
        "max_iter",
        "solver",
        "formulation",
        "threads",
    ];
    for key in d.keys() {
        let key: String = key.extract()?;
        if !KEYS.contains(&key.as_str()) {
            return Err(usage(py, format!("unknown setting `{key}`")));
        }
    }
    let order = match d.get_item("order")?.filter(|v| !v.is_none()) {
        None => "2".to_string(),
        Some(o) => o.str()?.to_string(),
    };
    let mut energy = Energy::parse(&order).map_err(|e| to_py(py, e))?;
    if let Some(sharp) = get::<Vec<usize>>(py, d, "sharp")? {
        energy.sharp = sharp;
    }
    let representative = choice(
        py,
        "representative",
        get::<String>(py, d, "representative")?.map(Some).unwrap_or(None),
        &[
            ("separatrix", Some(RepresentativeChoice::Separatrix)),
            ("harmonic", Some(RepresentativeChoice::Harmonic)),
            ("flooded", Some(RepresentativeChoice::Flooded)),
        ],
        None,
    )?;
    let settings = SmoothSettings {
        selection: selection(py, d)?,
        energy,
        data_weight: get(py, d, "data_weight")?.unwrap_or(1.0),
        smooth_weight: get(py, d, "smooth_weight")?,
        smooth_length: get(py, d, "smooth_length")?,
        edges: edges(py, d)?,
        qp: qp_settings(py, d)?,
        representative,
    };
    settings.validate().map_err(|e| to_py(py, e))?;
    Ok(settings)
}

fn role_codes(roles: &[Role]) -> Vec<i8> {
    roles.iter().map(|r| r.code() as i8).collect()
}

/// Smooths many fields on one domain with one set of settings, reusing the domain's operators
/// and analyses (`toposmooth.Smoother`).
#[pyclass(module = "toposmooth._toposmooth")]
struct Smoother {
    inner: AnySmoother,
    /// The thread cap of each call ([`toposmooth::parallel::with_threads`]).
    threads: usize,
}

/// The `threads` setting: at most this many threads per call (default the library's 2).
fn threads(py: Python<'_>, d: &Bound<'_, PyDict>) -> PyResult<usize> {
    match get::<usize>(py, d, "threads")? {
        None => Ok(toposmooth::parallel::DEFAULT_THREADS),
        Some(0) => Err(usage(py, "threads must be at least 1".into())),
        Some(n) => Ok(n),
    }
}

#[pymethods]
impl Smoother {
    #[new]
    fn new(py: Python<'_>, domain: &Domain, settings: &Bound<'_, PyDict>) -> PyResult<Self> {
        let threads = threads(py, settings)?;
        let settings = smooth_settings(py, settings)?;
        let domain = domain.inner.clone();
        let inner = py.detach(|| AnySmoother::new(domain, settings)).map_err(|e| to_py(py, e))?;
        Ok(Smoother { inner, threads })
    }

    /// Smooths one field: a dict with `smoothed`, `representative` (float64), `roles` (int8
    /// codes: −1 kept minimum, 1 kept maximum, 0 other, 2 fixed, 3 free end), `report` (the
    /// JSON report as text) and `certified`.
    fn smooth<'py>(&mut self, py: Python<'py>, h: PyReadonlyArray1<'py, f64>) -> PyResult<Bound<'py, PyDict>> {
        let h = values(py, "values", &h)?;
        let n = self.inner.n_vertices();
        if h.len() != n {
            let msg = format!("values has {} entries, the domain {n} vertices", h.len());
            return Err(to_py(py, Error::input(msg)));
        }
        let (inner, threads) = (&mut self.inner, self.threads);
        let out =
            py.detach(|| toposmooth::parallel::with_threads(threads, || inner.smooth(h))).map_err(|e| to_py(py, e))?;
        result_dict(py, out)
    }

    /// Number of vertices of the domain.
    #[getter]
    fn n_vertices(&self) -> usize {
        self.inner.n_vertices()
    }
}

/// The result dict of a smoothing run (see [`Smoother::smooth`]).
fn result_dict(py: Python<'_>, out: toposmooth::pipeline::Smoothed) -> PyResult<Bound<'_, PyDict>> {
    let report = serde_json::to_string(&out.report).map_err(|e| to_py(py, Error::internal(e.to_string())))?;
    let d = PyDict::new(py);
    d.set_item("certified", out.report.certificate.passed)?;
    d.set_item("roles", PyArray1::from_vec(py, role_codes(&out.roles)))?;
    d.set_item("smoothed", PyArray1::from_vec(py, out.output))?;
    d.set_item("representative", PyArray1::from_vec(py, out.u))?;
    d.set_item("report", report)?;
    Ok(d)
}

/// Smooths `h` on a grid or volume restricted to `mask` (true inside), as the CLI's `--mask`:
/// the domain is the triangles (tetrahedra) with every corner inside; the outside comes back
/// unchanged with role 0. The same dict as [`Smoother::smooth`].
#[pyfunction]
fn smooth_masked<'py>(
    py: Python<'py>,
    domain: &Domain,
    settings: &Bound<'py, PyDict>,
    h: PyReadonlyArray1<'py, f64>,
    mask: PyReadonlyArray1<'py, bool>,
) -> PyResult<Bound<'py, PyDict>> {
    let threads = threads(py, settings)?;
    let settings = smooth_settings(py, settings)?;
    // NaN outside the mask is background, as in the CLI: the pipeline checks the inside
    let h = values(py, "values", &h)?;
    if h.len() != domain.inner.n_vertices() {
        let msg = format!("values has {} entries, the domain {} vertices", h.len(), domain.inner.n_vertices());
        return Err(to_py(py, Error::input(msg)));
    }
    let inside = mask.as_slice().map_err(|_| usage(py, "mask must be a contiguous bool array".into()))?;
    if inside.len() != h.len() {
        return Err(to_py(py, Error::input(format!("mask has {} entries, the values {}", inside.len(), h.len()))));
    }
    let d = &domain.inner;
    let out = py
        .detach(|| {
            toposmooth::parallel::with_threads(threads, || match d {
                AnyDomain::Volume(g) => {
                    let m = toposmooth::domain::MaskedVolume::new(g, inside)?;
                    toposmooth::pipeline::smooth_masked(&m, h, &settings)
                }
                AnyDomain::Grid(g) => {
                    let m = toposmooth::domain::MaskedGrid::new(g, inside)?;
                    toposmooth::pipeline::smooth_masked_grid(&m, h, &settings)
                }
                _ => Err(Error::input("mask= is for grids and volumes (2-D and 3-D values)")),
            })
        })
        .map_err(|e| to_py(py, e))?;
    result_dict(py, out)
}

/// The extrema of `h` with their persistence: a dict of arrays `vertex`, `is_max`, `value`,
/// `persistence` (inf for each part's essential minimum and maximum), `partner` (the vertex it
/// pairs with, −1 for none), `strict`, and `kept` for `settings`' selection.
#[pyfunction]
fn extrema<'py>(
    py: Python<'py>,
    domain: &Domain,
    h: PyReadonlyArray1<'py, f64>,
    settings: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    let sel = selection(py, settings)?;
    let d = &domain.inner;
    let h = field(py, d, "values", &h)?;
    let (table, kept) = py.detach(|| table_and_kept(d, h, &sel)).map_err(|e| to_py(py, e))?;
    let out = PyDict::new(py);
    let col = |f: &dyn Fn(&toposmooth::topology::ExtremumInfo) -> f64| table.iter().map(f).collect::<Vec<f64>>();
    out.set_item("vertex", PyArray1::from_vec(py, table.iter().map(|e| e.index as i64).collect::<Vec<_>>()))?;
    out.set_item(
        "is_max",
        PyArray1::from_vec(py, table.iter().map(|e| e.kind != ExtremumKind::Min).collect::<Vec<_>>()),
    )?;
    out.set_item("value", PyArray1::from_vec(py, col(&|e| e.value)))?;
    out.set_item(
        "persistence",
        PyArray1::from_vec(
            py,
            col(&|e| match (e.persistence, e.kind) {
                (Some(p), _) => p,
                // a series' endpoint maximum never merges components: no persistence
                (None, ExtremumKind::End) => f64::NAN,
                (None, _) => f64::INFINITY,
            }),
        ),
    )?;
    out.set_item(
        "partner",
        PyArray1::from_vec(py, table.iter().map(|e| e.partner.map_or(-1, |p| p as i64)).collect::<Vec<_>>()),
    )?;
    out.set_item("endpoint", PyArray1::from_vec(py, table.iter().map(|e| e.endpoint).collect::<Vec<_>>()))?;
    out.set_item("strict", PyArray1::from_vec(py, table.iter().map(|e| e.strict).collect::<Vec<_>>()))?;
    let is_kept = |e: &toposmooth::topology::ExtremumInfo| match e.kind {
        ExtremumKind::Min => kept.roles[e.index] == Role::Min,
        ExtremumKind::Max | ExtremumKind::End => kept.roles[e.index] == Role::Max,
    };
    out.set_item("kept", PyArray1::from_vec(py, table.iter().map(is_kept).collect::<Vec<_>>()))?;
    Ok(out)
}

/// The persistence pairs of `h` in TTK's terms (`toposmooth::io::ttk::diagram_of`: each
/// connected part's essential pair first): a dict of arrays `vertices` (k, 2) int64 (birth,
/// death), `types` (k, 2) int32 (TTK's CriticalType), `pair_type` int32, `values` (k, 2),
/// `finite` and `kept` (by `settings`' selection) bool.
#[pyfunction]
fn diagram<'py>(
    py: Python<'py>,
    domain: &Domain,
    h: PyReadonlyArray1<'py, f64>,
    settings: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    let sel = selection(py, settings)?;
    let d = &domain.inner;
    let h = field(py, d, "values", &h)?;
    let (pairs, kept) = py
        .detach(|| -> toposmooth::Result<_> {
            let (table, kept) = table_and_kept(d, h, &sel)?;
            Ok((toposmooth::io::ttk::diagram_from_table(d, h, &table), kept))
        })
        .map_err(|e| to_py(py, e))?;
    let k = pairs.len();
    let flat =
        |f: &dyn Fn(&toposmooth::io::ttk::DiagramPair) -> [f64; 2]| pairs.iter().flat_map(f).collect::<Vec<f64>>();
    let out = PyDict::new(py);
    let vertices: Vec<i64> = pairs.iter().flat_map(|p| p.vertices.map(|v| v as i64)).collect();
    let types: Vec<i32> = pairs.iter().flat_map(|p| p.types).collect();
    out.set_item("vertices", PyArray1::from_vec(py, vertices).reshape([k, 2])?)?;
    out.set_item("types", PyArray1::from_vec(py, types).reshape([k, 2])?)?;
    out.set_item("values", PyArray1::from_vec(py, flat(&|p| p.values)).reshape([k, 2])?)?;
    out.set_item("pair_type", PyArray1::from_vec(py, pairs.iter().map(|p| p.pair_type).collect::<Vec<i32>>()))?;
    out.set_item("finite", PyArray1::from_vec(py, pairs.iter().map(|p| p.finite).collect::<Vec<bool>>()))?;
    let is_kept = |p: &toposmooth::io::ttk::DiagramPair| kept.roles.get(p.extremum).is_some_and(|r| r.is_fixed());
    out.set_item("kept", PyArray1::from_vec(py, pairs.iter().map(is_kept).collect::<Vec<bool>>()))?;
    Ok(out)
}

/// Certifies `f` against the roles (int8 codes as `Smoother.smooth` returns them) and, when
/// given, the input's kept values: a dict with `passed`, the counts and the failures as text.
#[pyfunction]
#[pyo3(signature = (domain, f, roles, input=None))]
fn certify<'py>(
    py: Python<'py>,
    domain: &Domain,
    f: PyReadonlyArray1<'py, f64>,
    roles: PyReadonlyArray1<'py, i8>,
    input: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let f = values(py, "smoothed", &f)?;
    let codes = roles.as_slice().map_err(|_| usage(py, "roles must be a contiguous int8 array".into()))?;
    let roles: Vec<Role> = codes
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            Role::from_code(f64::from(c))
                .ok_or_else(|| to_py(py, Error::input(format!("roles[{i}] = {c} is not a role code"))))
        })
        .collect::<PyResult<_>>()?;
    let input = match &input {
        Some(a) => Some(values(py, "input", a)?),
        None => None,
    };
    let d = &domain.inner;
    let cert = py.detach(|| toposmooth::certify_any(d, f, &roles, input));
    let out = PyDict::new(py);
    out.set_item("passed", cert.passed)?;
    out.set_item("strict_minima", cert.strict_minima)?;
    out.set_item("strict_maxima", cert.strict_maxima)?;
    out.set_item("flat", cert.flat)?;
    out.set_item("summary", cert.summary())?;
    out.set_item(
        "failures",
        cert.failures.iter().map(|f| format!("item {}, vertex {}: {}", f.item, f.vertex, f.reason)).collect::<Vec<_>>(),
    )?;
    out.set_item("report", serde_json::to_string(&cert).map_err(|e| to_py(py, Error::internal(e.to_string())))?)?;
    Ok(out)
}

/// Geodesic distance on a mesh from the source vertices (the heat method): float64 per vertex.
#[pyfunction]
fn geodesic<'py>(py: Python<'py>, domain: &Domain, sources: Vec<usize>) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let AnyDomain::Mesh(mesh) = &domain.inner else {
        return Err(usage(py, format!("geodesic distance needs a mesh, got a {}", domain.kind())));
    };
    let (d, _) = py.detach(|| toposmooth::apps::geodesic::heat_geodesic(mesh, &sources)).map_err(|e| to_py(py, e))?;
    Ok(PyArray1::from_vec(py, d))
}

/// Weights for handles (lists of vertex indices): a dict with `weights` (one float64 array
/// per handle, a partition of unity), `raw` (as certified), `certified` and
/// `max_normalisation_change`.
#[pyfunction]
fn weights<'py>(
    py: Python<'py>,
    domain: &Domain,
    handles: Vec<Vec<usize>>,
    settings: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    let method = choice(
        py,
        "method",
        get(py, settings, "method")?,
        &[
            ("monotone", WeightMethod::Monotone),
            ("bounded", WeightMethod::Bounded),
            ("unconstrained", WeightMethod::Unconstrained),
            ("harmonic", WeightMethod::Harmonic),
        ],
        WeightMethod::Monotone,
    )?;
    let ws = WeightSettings {
        order: get::<u8>(py, settings, "order")?.unwrap_or(2),
        method,
        edges: edges(py, settings)?,
        qp: qp_settings(py, settings)?,
        threads: get::<usize>(py, settings, "threads")?.unwrap_or(2).max(1),
    };
    let d = &domain.inner;
    let cap = ws.threads;
    let w = py
        .detach(|| {
            toposmooth::parallel::with_threads(
                cap,
                || toposmooth::with_domain!(d, g => toposmooth::apps::weights::weights(g, &handles, &ws)),
            )
        })
        .map_err(|e| to_py(py, e))?;
    let out = PyDict::new(py);
    let certified = w.functions.iter().all(|f| f.certificate.passed);
    out.set_item("certified", certified)?;
    out.set_item("max_normalisation_change", w.max_normalisation_change)?;
    let raw: Vec<_> = w.functions.into_iter().map(|f| PyArray1::from_vec(py, f.raw)).collect();
    let normalised: Vec<_> = w.normalised.into_iter().map(|v| PyArray1::from_vec(py, v)).collect();
    out.set_item("raw", raw)?;
    out.set_item("weights", normalised)?;
    Ok(out)
}

/// A filled copy and the mask of filled samples.
type Filled<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<bool>>);

/// `values` with its NaN samples filled as the CLI's `--fill-missing` fills them: linearly in x
/// on a series (the ends stepped one ulp per sample), harmonically on grids and meshes. Returns
/// the filled copy and the mask of filled samples; infinities are refused.
#[pyfunction]
fn fill_missing<'py>(py: Python<'py>, domain: &Domain, h: PyReadonlyArray1<'py, f64>) -> PyResult<Filled<'py>> {
    let d = &domain.inner;
    let mut v = field(py, d, "values", &h)?.to_vec();
    if let Some(i) = v.iter().position(|x| x.is_infinite()) {
        return Err(to_py(py, Error::input(format!("values[{i}] is infinite: only NaN samples are filled"))));
    }
    let mask = py
        .detach(|| -> toposmooth::Result<Vec<bool>> {
            match d {
                AnyDomain::Series(s) => toposmooth::series_fill::fill_missing_series(s.x(), &mut v),
                _ => {
                    let mask: Vec<bool> = v.iter().map(|x| x.is_nan()).collect();
                    if mask.iter().any(|&m| m) {
                        match d {
                            AnyDomain::Grid(g) => toposmooth::derive::fill_missing(g, &mut v)?,
                            AnyDomain::Mesh(m) => {
                                let k = toposmooth::operators::positive_cotan_stiffness(m.positions(), m.faces());
                                toposmooth::derive::fill_missing_with(&k, &mut v)?
                            }
                            AnyDomain::Volume(g) => {
                                let k = toposmooth::operators::volume_stiffness(g);
                                toposmooth::derive::fill_missing_with(&k, &mut v)?
                            }
                            AnyDomain::Tets(m) => {
                                let k = toposmooth::operators::positive_tet_stiffness(m.positions(), m.tets());
                                toposmooth::derive::fill_missing_with(&k, &mut v)?
                            }
                            AnyDomain::Series(_) => unreachable!("handled above"),
                        };
                    }
                    Ok(mask)
                }
            }
        })
        .map_err(|e| to_py(py, e))?;
    Ok((PyArray1::from_vec(py, v), PyArray1::from_vec(py, mask)))
}

/// Runs one CLI command in this process (`args` without the program's name, e.g.
/// `["smooth", "a.vti", "-o", "b.vti"]`) and returns what the tool prints on standard output;
/// errors are raised as the package's exceptions with the CLI's message.
/// `threads` caps the threads the command uses (default 2).
#[pyfunction]
#[pyo3(signature = (args, threads=None))]
fn run(py: Python<'_>, args: Vec<String>, threads: Option<usize>) -> PyResult<String> {
    let cap = threads.unwrap_or(toposmooth::parallel::DEFAULT_THREADS).max(1);
    py.detach(|| {
        toposmooth::parallel::with_threads(cap, || {
            toposmooth::commands::catch_panics(|| toposmooth::commands::cli::run_args(&args))
        })
    })
    .map_err(|e| to_py(py, e))
}

/// The `toposmooth` console script: the CLI's `main` on `argv` (program name first); returns
/// its exit status.
#[pyfunction]
fn main(py: Python<'_>, argv: Vec<String>) -> i32 {
    py.detach(|| toposmooth::commands::cli::main(argv.into_iter().map(std::ffi::OsString::from)))
}

/// Handles in the JSON format of `toposmooth weights --handles` (SPEC.md: points, bones,
/// vertex lists) resolved on a mesh: their names and vertex sets.
#[pyfunction]
fn resolve_handles(py: Python<'_>, domain: &Domain, json: &str) -> PyResult<(Vec<String>, Vec<Vec<usize>>)> {
    use toposmooth::apps::handles::{parse_handles, resolve, HandleFile};
    let AnyDomain::Mesh(mesh) = &domain.inner else {
        return Err(usage(py, format!("handles are placed on a mesh, got a {}", domain.kind())));
    };
    match parse_handles(json).map_err(|e| to_py(py, e))? {
        HandleFile::Handles(list) => {
            let sets = resolve(mesh, &list).map_err(|e| to_py(py, e))?;
            Ok((list.into_iter().map(|h| h.name).collect(), sets))
        }
        HandleFile::Cage(_) => Err(usage(py, "a cage: use the CLI (`toposmooth weights --handles cage.json`)".into())),
    }
}

/// The library's version.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _toposmooth(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Domain>()?;
    m.add_class::<Smoother>()?;
    m.add_function(wrap_pyfunction!(extrema, m)?)?;
    m.add_function(wrap_pyfunction!(certify, m)?)?;
    m.add_function(wrap_pyfunction!(diagram, m)?)?;
    m.add_function(wrap_pyfunction!(geodesic, m)?)?;
    m.add_function(wrap_pyfunction!(weights, m)?)?;
    m.add_function(wrap_pyfunction!(fill_missing, m)?)?;
    m.add_function(wrap_pyfunction!(smooth_masked, m)?)?;
    m.add_function(wrap_pyfunction!(resolve_handles, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(main, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    Ok(())
}

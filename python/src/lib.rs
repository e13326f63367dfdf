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
use pyo3::types::{PyBool, PyDict, PyString, PyType};
use std::sync::{Arc, Condvar, Mutex};
use toposmooth::apps::weights::{WeightMethod, WeightSettings};
use toposmooth::domain::{AnyDomain, Domain as _, Grid2d, Grid3d, Series, TetMesh, TriMesh};
use toposmooth::io::import::{InputOption, ReadOptions, INPUT_OPTIONS};
use toposmooth::pipeline::schema::{self, Group, Kind, Setting};
use toposmooth::progress::{CancelToken, Observer};
use toposmooth::topology::{extrema_table, select, ExtremumKind, Role, Selection};
use toposmooth::{AnySmoother, Error, ErrorKind, SmoothSettings};

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
        ErrorKind::Cancelled => "Cancelled",
        ErrorKind::Memory => "MemoryLimitError",
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

/// A token Python holds to stop a run (`toposmooth.CancelToken`): `cancel()`, from any thread,
/// stops every call given it (`cancel=token`) at its next check; the call raises
/// `toposmooth.Cancelled` and leaves no output or temporary behind.
#[pyclass(module = "toposmooth._toposmooth", name = "CancelToken", frozen)]
#[derive(Default)]
struct PyCancelToken {
    inner: CancelToken,
}

#[pymethods]
impl PyCancelToken {
    #[new]
    fn new() -> Self {
        Self::default()
    }

    /// Asks the runs holding this token to stop.
    fn cancel(&self) {
        self.inner.cancel();
    }

    /// Whether `cancel()` was called.
    #[getter]
    fn cancelled(&self) -> bool {
        self.inner.is_cancelled()
    }

    fn __repr__(&self) -> String {
        format!("CancelToken(cancelled={})", if self.inner.is_cancelled() { "True" } else { "False" })
    }
}

/// What a long call is watched with: a progress callable `(stage, fraction, message)` and the
/// caller's token.
#[derive(Default)]
struct Watch {
    progress: Option<Py<PyAny>>,
    cancel: Option<CancelToken>,
}

impl Watch {
    fn new(progress: Option<Bound<'_, PyAny>>, cancel: Option<PyRef<'_, PyCancelToken>>) -> Self {
        Watch {
            progress: progress.filter(|p| !p.is_none()).map(Bound::unbind),
            cancel: cancel.map(|c| c.inner.clone()),
        }
    }
}

/// One progress event for Python: stage, fraction (None where unknown), message.
type Event = (String, Option<f64>, String);

/// The stages of a run collected for the Python thread ([`watched`]), consecutive updates of
/// one stage merged.
#[derive(Default)]
struct Relay {
    events: Mutex<Vec<Event>>,
    /// The last fraction and message per stage.
    last: Mutex<std::collections::HashMap<String, (Option<f64>, String)>>,
}

impl Relay {
    fn push(&self, stage: &str, fraction: Option<f64>, message: Option<&str>, merge: bool) {
        let (f, m) = {
            let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
            let entry = last.entry(stage.to_string()).or_insert((None, String::new()));
            if let Some(f) = fraction {
                entry.0 = Some(f);
            }
            if let Some(m) = message {
                entry.1 = m.to_string();
            }
            entry.clone()
        };
        let mut events = self.events.lock().unwrap_or_else(|e| e.into_inner());
        if merge {
            if let Some(e) = events.last_mut().filter(|e| e.0 == stage && e.1 != Some(1.0)) {
                *e = (stage.to_string(), f, m);
                return;
            }
        }
        events.push((stage.to_string(), f, m));
    }

    fn take(&self) -> Vec<Event> {
        std::mem::take(&mut *self.events.lock().unwrap_or_else(|e| e.into_inner()))
    }
}

impl Observer for Relay {
    fn begin(&self, stage: &str) {
        self.last.lock().unwrap_or_else(|e| e.into_inner()).remove(stage);
        self.push(stage, None, Some(""), false);
    }
    fn update(&self, stage: &str, message: &str) {
        self.push(stage, None, Some(message), true);
    }
    fn fraction(&self, stage: &str, done: f64) {
        self.push(stage, Some(done), None, true);
    }
    fn end(&self, stage: &str, _seconds: f64, summary: &str) {
        self.push(stage, Some(1.0), Some(summary), false);
    }
}

/// How often the Python thread looks at its signals and hands on the progress.
const WATCH_PERIOD: std::time::Duration = std::time::Duration::from_millis(50);

/// Runs `work` without the GIL on a thread of its own, under the caller's token, while this
/// thread, every [`WATCH_PERIOD`] and with the GIL, checks Python's signals (Ctrl-C cancels the
/// run, and its `KeyboardInterrupt` is raised once the run has stopped) and calls the progress
/// callable with what the run told (an exception it raises cancels the run and is raised).
fn watched<T: Send>(py: Python<'_>, watch: &Watch, work: impl FnOnce() -> toposmooth::Result<T> + Send) -> PyResult<T> {
    let token = watch.cancel.clone().unwrap_or_default();
    let relay = watch.progress.as_ref().map(|_| Arc::new(Relay::default()));
    let finished = (Mutex::new(false), Condvar::new());
    let mut raised: Option<PyErr> = None;
    let out = std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let run = || match &relay {
                Some(r) => toposmooth::progress::observe(r.clone(), work),
                None => work(),
            };
            let out = toposmooth::progress::cancellable(token.clone(), run);
            *finished.0.lock().unwrap_or_else(|e| e.into_inner()) = true;
            finished.1.notify_all();
            out
        });
        loop {
            let done = py.detach(|| {
                let guard = finished.0.lock().unwrap_or_else(|e| e.into_inner());
                let (guard, _) =
                    finished.1.wait_timeout_while(guard, WATCH_PERIOD, |d| !*d).unwrap_or_else(|e| e.into_inner());
                *guard
            });
            if let (Some(callback), Some(relay)) = (&watch.progress, &relay) {
                for (stage, fraction, message) in relay.take() {
                    if raised.is_none() {
                        if let Err(e) = callback.call1(py, (stage, fraction, message)) {
                            token.cancel();
                            raised = Some(e);
                        }
                    }
                }
            }
            // checked before the end too: a signal raised while the last batch's callable ran
            // (or since the last check) belongs to this call, not to the caller's next line
            if raised.is_none() {
                if let Err(e) = py.check_signals() {
                    token.cancel();
                    raised = Some(e);
                }
            }
            if done {
                break;
            }
        }
        worker.join().unwrap_or_else(|payload| std::panic::resume_unwind(payload))
    });
    match raised {
        Some(e) => Err(e),
        None => out.map_err(|e| to_py(py, e)),
    }
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

/// One keyword's value as the schema's text ([`schema::SETTINGS`]), its Python type checked
/// here (a number is not a string, a count not a bool or a float, a list not a string); what
/// the text holds is checked by the library, as for every front end. `None` and `False` are
/// "not given".
fn setting_text(py: Python<'_>, spec: &Setting, v: &Bound<'_, PyAny>) -> PyResult<Option<String>> {
    if v.is_none() {
        return Ok(None);
    }
    let type_name = || v.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into());
    let wrong = |what: &str| usage(py, format!("{}: expected {what}, got {} {}", spec.name, type_name(), repr(v)));
    let is_bool = v.is_instance_of::<PyBool>();
    let is_text = v.is_instance_of::<PyString>();
    let number = || -> PyResult<String> {
        if is_bool || is_text {
            return Err(wrong("a number"));
        }
        // the shortest text that reads back to the same double
        v.extract::<f64>().map(|x| format!("{x:?}")).map_err(|_| wrong("a number"))
    };
    let whole = |what: &str| -> PyResult<String> {
        if is_bool || is_text {
            return Err(wrong(what));
        }
        v.extract::<i64>().map(|n| n.to_string()).map_err(|_| wrong(what))
    };
    let text = |what: &str| -> PyResult<String> { v.extract::<String>().map_err(|_| wrong(what)) };
    Ok(Some(match spec.kind {
        Kind::Switch => match v.extract::<bool>() {
            Ok(true) => "true".into(),
            Ok(false) => return Ok(None),
            Err(_) => return Err(wrong("True or False")),
        },
        Kind::Count { .. } => whole("a whole number")?,
        Kind::Real { .. } => number()?,
        Kind::Threshold if is_text => text("a number or a percentage")?,
        Kind::Threshold => number().map_err(|_| wrong("a number or a percentage such as \"5%\""))?,
        Kind::Choice(names) => text(&format!("one of {}", names.join(", ")))?,
        Kind::Size if is_text => text("a size")?,
        Kind::Size => whole("a size such as \"6G\" or a number of bytes")?,
        Kind::Orders if is_text => text("an order")?,
        Kind::Orders => whole("an order 1..4 or a blend such as \"1:0.2,2:1\"")?,
        Kind::Indices => {
            if is_text {
                return Err(wrong("a list of vertex indices"));
            }
            let list = v.extract::<Vec<i64>>().map_err(|_| wrong("a list of vertex indices"))?;
            list.iter().map(i64::to_string).collect::<Vec<_>>().join(",")
        }
    }))
}

fn repr(v: &Bound<'_, PyAny>) -> String {
    v.repr().map(|r| r.to_string()).unwrap_or_default()
}

/// The `(name, text)` of the keywords in `d` (unknown ones refused), those of `groups` only.
fn setting_texts(py: Python<'_>, d: &Bound<'_, PyDict>, groups: &[Group]) -> PyResult<Vec<(&'static str, String)>> {
    let mut texts = Vec::new();
    for (key, value) in d.iter() {
        let key: String = key.extract()?;
        let Some(spec) = schema::find(&key) else {
            let names: Vec<&str> = schema::SETTINGS.iter().map(|s| s.name).collect();
            return Err(usage(py, format!("unknown setting `{key}` (the settings are {})", names.join(", "))));
        };
        if !groups.contains(&spec.group) {
            continue;
        }
        if let Some(text) = setting_text(py, spec, &value)? {
            texts.push((spec.name, text));
        }
    }
    Ok(texts)
}

const ALL_GROUPS: [Group; 4] = [Group::Selection, Group::Energy, Group::Solver, Group::Run];

/// The library's settings from the package's keyword arguments, read as every front end's are
/// ([`SmoothSettings::from_texts`]).
fn smooth_settings(py: Python<'_>, d: &Bound<'_, PyDict>) -> PyResult<SmoothSettings> {
    let texts = setting_texts(py, d, &ALL_GROUPS)?;
    SmoothSettings::from_texts(texts.iter().map(|(n, t)| (*n, t.as_str()))).map_err(|e| to_py(py, e))
}

/// The selection from the selection's keywords in `d` (other settings are not looked at).
fn selection(py: Python<'_>, d: &Bound<'_, PyDict>) -> PyResult<Selection> {
    let texts = setting_texts(py, d, &[Group::Selection])?;
    let settings = SmoothSettings::from_texts(texts.iter().map(|(n, t)| (*n, t.as_str()))).map_err(|e| to_py(py, e))?;
    Ok(settings.selection)
}

/// The settings' schema: one dict per setting with `name`, `kind`, `default` (text or None),
/// `group`, `help`, `partner`, and per kind `choices`, `min`, `max`, `inclusive`.
#[pyfunction]
fn settings_schema(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    schema::SETTINGS
        .iter()
        .map(|s| {
            let d = PyDict::new(py);
            d.set_item("name", s.name)?;
            d.set_item("default", s.default)?;
            d.set_item("group", format!("{:?}", s.group).to_lowercase())?;
            d.set_item("help", s.help)?;
            d.set_item("partner", s.partner)?;
            let kind = match s.kind {
                Kind::Threshold => "threshold",
                Kind::Count { min, max } => {
                    d.set_item("min", min)?;
                    d.set_item("max", max)?;
                    "count"
                }
                Kind::Real { min, inclusive } => {
                    d.set_item("min", min)?;
                    d.set_item("inclusive", inclusive)?;
                    "real"
                }
                Kind::Switch => "switch",
                Kind::Choice(names) => {
                    d.set_item("choices", names.to_vec())?;
                    "choice"
                }
                Kind::Indices => "indices",
                Kind::Size => "size",
                Kind::Orders => {
                    d.set_item("min", 1)?;
                    d.set_item("max", 4)?;
                    "orders"
                }
            };
            d.set_item("kind", kind)?;
            Ok(d)
        })
        .collect()
}

fn role_codes(roles: &[Role]) -> Vec<i8> {
    roles.iter().map(|r| r.code() as i8).collect()
}

/// Smooths many fields on one domain with one set of settings, reusing the domain's operators
/// and analyses (`toposmooth.Smoother`).
#[pyclass(module = "toposmooth._toposmooth")]
struct Smoother {
    inner: AnySmoother,
}

#[pymethods]
impl Smoother {
    #[new]
    fn new(py: Python<'_>, domain: &Domain, settings: &Bound<'_, PyDict>) -> PyResult<Self> {
        let settings = smooth_settings(py, settings)?;
        let domain = domain.inner.clone();
        let inner = py.detach(|| AnySmoother::new(domain, settings)).map_err(|e| to_py(py, e))?;
        Ok(Smoother { inner })
    }

    /// Smooths one field: a dict with `smoothed`, `representative` (float64), `roles` (int8
    /// codes: −1 kept minimum, 1 kept maximum, 0 other, 2 fixed, 3 free end), `report` (the
    /// JSON report as text) and `certified`.
    #[pyo3(signature = (h, progress=None, cancel=None))]
    fn smooth<'py>(
        &mut self,
        py: Python<'py>,
        h: PyReadonlyArray1<'py, f64>,
        progress: Option<Bound<'py, PyAny>>,
        cancel: Option<PyRef<'py, PyCancelToken>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let watch = Watch::new(progress, cancel);
        let h = values(py, "values", &h)?;
        let n = self.inner.n_vertices();
        if h.len() != n {
            let msg = format!("values has {} entries, the domain {n} vertices", h.len());
            return Err(to_py(py, Error::input(msg)));
        }
        let inner = &mut self.inner;
        let out = watched(py, &watch, || inner.smooth(h))?;
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
#[pyo3(signature = (domain, settings, h, mask, progress=None, cancel=None))]
fn smooth_masked<'py>(
    py: Python<'py>,
    domain: &Domain,
    settings: &Bound<'py, PyDict>,
    h: PyReadonlyArray1<'py, f64>,
    mask: PyReadonlyArray1<'py, bool>,
    progress: Option<Bound<'py, PyAny>>,
    cancel: Option<PyRef<'py, PyCancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    let watch = Watch::new(progress, cancel);
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
    let out = watched(py, &watch, || match d {
        AnyDomain::Volume(g) => {
            let m = toposmooth::domain::MaskedVolume::new(g, inside)?;
            toposmooth::pipeline::smooth_masked(&m, h, &settings)
        }
        AnyDomain::Grid(g) => {
            let m = toposmooth::domain::MaskedGrid::new(g, inside)?;
            toposmooth::pipeline::smooth_masked_grid(&m, h, &settings)
        }
        _ => Err(Error::input("mask= is for grids and volumes (2-D and 3-D values)")),
    })?;
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
#[pyo3(signature = (domain, handles, settings, progress=None, cancel=None))]
fn weights<'py>(
    py: Python<'py>,
    domain: &Domain,
    handles: Vec<Vec<usize>>,
    settings: &Bound<'py, PyDict>,
    progress: Option<Bound<'py, PyAny>>,
    cancel: Option<PyRef<'py, PyCancelToken>>,
) -> PyResult<Bound<'py, PyDict>> {
    let watch = Watch::new(progress, cancel);
    let method = match settings.get_item("method")?.filter(|v| !v.is_none()) {
        None => WeightMethod::Monotone,
        Some(m) => {
            let text: String =
                m.extract().map_err(|_| usage(py, format!("method must be a string, got {}", repr(&m))))?;
            text.parse::<WeightMethod>().map_err(|e| to_py(py, e))?
        }
    };
    // the constraint set and the solver as `smooth` reads them
    let shared = PyDict::new(py);
    for key in ["edges", "max_iter", "solver", "formulation"] {
        if let Some(v) = settings.get_item(key)? {
            shared.set_item(key, v)?;
        }
    }
    let common = smooth_settings(py, &shared)?;
    let order = match settings.get_item("order")?.filter(|v| !v.is_none()) {
        None => 2,
        Some(o) => o.extract::<u8>().map_err(|_| usage(py, format!("order must be 1, 2, 3 or 4, got {}", repr(&o))))?,
    };
    let threads = match settings.get_item("threads")?.filter(|v| !v.is_none()) {
        None => 2,
        Some(t) => t
            .extract::<usize>()
            .map_err(|_| usage(py, format!("threads must be a count ≥ 1, got {}", repr(&t))))?
            .max(1),
    };
    let ws = WeightSettings { order, method, edges: common.edges, qp: common.qp, threads };
    let d = &domain.inner;
    let cap = ws.threads;
    let w = watched(py, &watch, || {
        toposmooth::parallel::with_threads(
            cap,
            || toposmooth::with_domain!(d, g => toposmooth::apps::weights::weights(g, &handles, &ws)),
        )
    })?;
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
/// `threads` caps the threads the command uses (default: every core); `progress` and `cancel` as for
/// [`Smoother::smooth`] (a cancelled command leaves no output or temporary behind).
#[pyfunction]
#[pyo3(signature = (args, threads=None, progress=None, cancel=None))]
fn run<'py>(
    py: Python<'py>,
    args: Vec<String>,
    threads: Option<usize>,
    progress: Option<Bound<'py, PyAny>>,
    cancel: Option<PyRef<'py, PyCancelToken>>,
) -> PyResult<String> {
    let watch = Watch::new(progress, cancel);
    let cap = threads.unwrap_or_else(toposmooth::parallel::default_threads).max(1);
    watched(py, &watch, || {
        toposmooth::parallel::with_threads(cap, || {
            toposmooth::commands::catch_panics(|| toposmooth::commands::cli::run_args(&args))
        })
    })
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

/// One input option's value as text (its Python type checked: a switch is a bool, a spacing a
/// sequence of numbers, a threshold a number, the rest text or a path already made text).
fn input_text(py: Python<'_>, spec: &InputOption, v: &Bound<'_, PyAny>) -> PyResult<Option<String>> {
    if v.is_none() {
        return Ok(None);
    }
    let wrong = |what: &str| usage(py, format!("{}: expected {what}, got {}", spec.name, repr(v)));
    let is_text = v.is_instance_of::<PyString>();
    let is_bool = v.is_instance_of::<PyBool>();
    Ok(Some(match spec.name {
        _ if spec.switch => match v.extract::<bool>() {
            Ok(true) => "true".into(),
            Ok(false) => return Ok(None),
            Err(_) => return Err(wrong("True or False")),
        },
        "spacing" if !is_text => {
            let s = v.extract::<Vec<f64>>().map_err(|_| wrong("a sequence of 2 or 3 numbers"))?;
            s.iter().map(|d| format!("{d:?}")).collect::<Vec<_>>().join(",")
        }
        "mask_below" if !is_text && !is_bool => {
            v.extract::<f64>().map(|t| format!("{t:?}")).map_err(|_| wrong("a number"))?
        }
        "column" | "x_column" if !is_text && !is_bool => {
            v.extract::<i64>().map(|i| i.to_string()).map_err(|_| wrong("a column name or index"))?
        }
        _ => v.extract::<String>().map_err(|_| wrong("text"))?,
    }))
}

/// A point array as numpy: `(n,)` for one component, `(n, c)` for more.
fn array_of<'py>(py: Python<'py>, a: &toposmooth::io::vtk::PointArray) -> PyResult<Bound<'py, PyAny>> {
    let flat = PyArray1::from_vec(py, a.values.clone());
    if a.components == 1 {
        return Ok(flat.into_any());
    }
    Ok(flat.reshape([a.values.len() / a.components.max(1), a.components])?.into_any())
}

/// Reads a file as the CLI reads its input (`toposmooth::io::import::read`): the options are
/// the input options' names (`toposmooth.INPUT_OPTIONS`); returns a dict the package wraps as
/// a `Dataset`.
#[pyfunction]
#[pyo3(signature = (path, options))]
fn read<'py>(py: Python<'py>, path: Option<String>, options: &Bound<'py, PyDict>) -> PyResult<Bound<'py, PyDict>> {
    let mut texts = Vec::new();
    for (key, value) in options.iter() {
        let key: String = key.extract()?;
        let Some(spec) = INPUT_OPTIONS.iter().find(|o| o.name == key) else {
            let names: Vec<&str> = INPUT_OPTIONS.iter().map(|o| o.name).collect();
            return Err(usage(py, format!("unknown input option `{key}` (the options are {})", names.join(", "))));
        };
        if let Some(text) = input_text(py, spec, &value)? {
            texts.push((spec.name, text));
        }
    }
    let opts = ReadOptions::from_texts(texts.iter().map(|(n, t)| (*n, t.as_str()))).map_err(|e| to_py(py, e))?;
    let field = py
        .detach(|| toposmooth::io::import::read(path.as_deref().map(std::path::Path::new), &opts))
        .map_err(|e| to_py(py, e))?;
    let out = PyDict::new(py);
    let domain = Domain { inner: field.domain.clone() };
    out.set_item("kind", domain.kind())?;
    let shape: Vec<usize> = match &field.domain {
        AnyDomain::Grid(g) => {
            out.set_item("spacing", g.spacing().to_vec())?;
            out.set_item("origin", g.origin().to_vec())?;
            vec![g.ny(), g.nx()]
        }
        AnyDomain::Volume(g) => {
            out.set_item("spacing", g.spacing().to_vec())?;
            out.set_item("origin", g.origin().to_vec())?;
            vec![g.nz(), g.ny(), g.nx()]
        }
        AnyDomain::Mesh(m) => {
            let v: Vec<f64> = m.positions().iter().flatten().copied().collect();
            let f: Vec<i64> = m.faces().iter().flatten().map(|&i| i as i64).collect();
            out.set_item("vertices", PyArray1::from_vec(py, v).reshape([m.n_vertices(), 3])?)?;
            out.set_item("faces", PyArray1::from_vec(py, f).reshape([m.faces().len(), 3])?)?;
            vec![m.n_vertices()]
        }
        AnyDomain::Tets(m) => {
            let v: Vec<f64> = m.positions().iter().flatten().copied().collect();
            let t: Vec<i64> = m.tets().iter().flatten().map(|&i| i as i64).collect();
            out.set_item("vertices", PyArray1::from_vec(py, v).reshape([m.n_vertices(), 3])?)?;
            out.set_item("faces", PyArray1::from_vec(py, t).reshape([m.tets().len(), 4])?)?;
            vec![m.n_vertices()]
        }
        AnyDomain::Series(s) => vec![s.n_vertices()],
    };
    out.set_item("shape", shape)?;
    if let Some(axis) = &field.axis {
        out.set_item("x", PyArray1::from_vec(py, axis.x.clone()))?;
        out.set_item("x_name", &axis.x_name)?;
        out.set_item("x_text", axis.x_text.to_vec())?;
        out.set_item("dates", matches!(axis.source, toposmooth::io::series_csv::XSource::Dates(..)))?;
    }
    out.set_item("domain", Py::new(py, domain)?)?;
    out.set_item("values", PyArray1::from_vec(py, field.values))?;
    out.set_item("description", field.description)?;
    out.set_item("path", field.path.display().to_string())?;
    out.set_item("notes", field.notes)?;
    out.set_item("filled", field.filled.map(|m| PyArray1::from_vec(py, m)))?;
    out.set_item("mask", field.mask.map(|m| PyArray1::from_vec(py, m)))?;
    let arrays = PyDict::new(py);
    if let Some(c) = &field.carried {
        for a in &c.point {
            arrays.set_item(&a.name, array_of(py, a)?)?;
        }
    }
    out.set_item("arrays", arrays)?;
    out.set_item("source_array", field.carried.as_ref().and_then(|c| c.source.clone()))?;
    Ok(out)
}

/// The input options (`toposmooth.INPUT_OPTIONS`): one dict each with `name`, `switch`,
/// `choices` and `help`.
#[pyfunction]
fn input_options(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    INPUT_OPTIONS
        .iter()
        .map(|o| {
            let d = PyDict::new(py);
            d.set_item("name", o.name)?;
            d.set_item("switch", o.switch)?;
            d.set_item("choices", o.choices.map(<[&str]>::to_vec))?;
            d.set_item("help", o.help)?;
            Ok(d)
        })
        .collect()
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
    m.add_class::<PyCancelToken>()?;
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
    m.add_function(wrap_pyfunction!(settings_schema, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(input_options, m)?)?;
    Ok(())
}

//! `pelage.Groom`: a groom file, or a groom built from Python values, and
//! its generation (Sik §4) part by part.
//!
//! A groom built in Python becomes the groom file it would have been: the
//! dicts are written as TOML and read by the library's own groom-file
//! front end, so every setting is checked by the same code and an error
//! names the same key (`ops[1].clump.count`). `Groom.settings` shows that
//! text; save it and `pelage groom` grows the same hairs.

use crate::curves::PyCurves;
use crate::mesh::PyMesh;
use crate::to_py_err;
use pelage::groom::{
    AnimatedFiles, AnimatedGroom, AnimatedPlanError, Assembly, FarmRun, Generator, Groom,
    GroomError, GroomInputs, GroomReport, GroomWriteError, PreflightError, ReportBuilder, Timings,
};
use pelage::settings::SettingsSource;
use pyo3::exceptions::{PyIndexError, PyMemoryError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// What errors call a groom built from Python values.
const PYTHON_GROOM: &str = "<python groom>";

/// A groom: a surface, guides, roots, operators and a finish, ready to
/// grow hair curves part by part.
///
/// Load a groom file with `Groom.load("fur.toml")`, or build one from
/// values::
///
///     groom = pelage.Groom(
///         mesh=pelage.Mesh.load("model.obj"),
///         guides={"generate": {"count": 400, "length": 0.05}},
///         roots={"count": 200_000, "seed": 3},
///         ops=[pelage.ops.clump(count=2_000, rate=0.6)],
///     )
///
/// The tables are those of the groom file format (docs/groom-format.md):
/// `roots`, `guides`, `interpolation`, `ops`, `finish`, `output`,
/// `animation`, `simulation` (with `animation={"mode": "simulate"}`),
/// `regions`, `look`. `mesh` is a `Mesh` or a path; `guides` is a table, a
/// path, or `Curves` to bind to the mesh (`{"curves": c, "points": 8}`
/// binds them with the table's settings).
#[pyclass(name = "Groom", module = "pelage", frozen)]
pub struct PyGroom {
    groom: Groom,
    /// Whether the settings are Python values (errors then name keys, not
    /// lines of a text the user never wrote).
    from_values: bool,
    /// The generator for the groom's own seed, built on first use.
    generator: OnceLock<Arc<Generator>>,
    /// An animated groom bound to its skin, built on first use.
    animated: OnceLock<Arc<AnimatedGroom>>,
}

impl PyGroom {
    /// Wraps a loaded groom and prepares its generator, so that a setting
    /// the generator refuses (`clump.count = 0`) is an error here, where
    /// the groom is made, not at its first `grow()`.
    fn wrap(py: Python<'_>, groom: Groom, from_values: bool) -> PyResult<Self> {
        let this = Self {
            groom,
            from_values,
            generator: OnceLock::new(),
            animated: OnceLock::new(),
        };
        this.generator(py, None)?;
        Ok(this)
    }

    /// The groom (a session opens it for editing).
    pub(crate) fn groom(&self) -> &Groom {
        &self.groom
    }

    fn error(&self, error: GroomError) -> PyErr {
        groom_error(error, self.from_values)
    }

    /// Where `write` or `assemble` (`what`) goes: `path`, else the groom's
    /// own output path, which a groom built from values has only when its
    /// `output` table names one.
    fn output(&self, path: Option<PathBuf>, what: &str) -> PyResult<PathBuf> {
        if let Some(path) = path {
            return Ok(path);
        }
        let own = self.groom.output_path();
        if own.file_stem().and_then(|s| s.to_str()) == Some(PYTHON_GROOM) {
            return Err(PyValueError::new_err(format!(
                "{what}(): give a path, e.g. groom.{what}(\"fur.usdc\"): a groom built from values has no file to name its output after (or set output={{\"path\": \"fur.usdc\"}})"
            )));
        }
        Ok(own)
    }

    /// The groom bound to its animated skin (cached); an error for a still
    /// groom.
    fn animated(&self, py: Python<'_>) -> PyResult<Arc<AnimatedGroom>> {
        if let Some(a) = self.animated.get() {
            return Ok(a.clone());
        }
        let interrupt = Interrupt::default();
        let animated = py.detach(|| self.groom.animated_until(None, &|| interrupt.seen()));
        interrupt.raise()?;
        let animated = animated
            .map_err(|e| self.error(e))?
            .ok_or_else(|| {
                PyValueError::new_err(
                    "the groom is not animated: give it an [animation] table (animation={\"frames\": \"1-24\"}) or load it with frames=",
                )
            })?;
        Ok(self.animated.get_or_init(|| Arc::new(animated)).clone())
    }

    /// The generator for `seed` (the groom's own when `None`, cached).
    fn generator(&self, py: Python<'_>, seed: Option<u64>) -> PyResult<Arc<Generator>> {
        if seed.is_some() {
            return py
                .detach(|| self.groom.generator(seed))
                .map(Arc::new)
                .map_err(|e| self.error(e));
        }
        if let Some(g) = self.generator.get() {
            return Ok(g.clone());
        }
        let generator = py
            .detach(|| self.groom.generator(None))
            .map_err(|e| self.error(e))?;
        Ok(self.generator.get_or_init(|| Arc::new(generator)).clone())
    }
}

#[pymethods]
impl PyGroom {
    #[new]
    #[pyo3(signature = (*, mesh, guides, roots, ops = None, interpolation = None, finish = None, output = None, animation = None, simulation = None, regions = None, look = None, base_dir = None, skin = None))]
    #[allow(
        clippy::too_many_arguments,
        reason = "one keyword argument a groom-file table"
    )]
    fn new(
        py: Python<'_>,
        mesh: &Bound<'_, PyAny>,
        guides: &Bound<'_, PyAny>,
        roots: &Bound<'_, PyAny>,
        ops: Option<&Bound<'_, PyAny>>,
        interpolation: Option<&Bound<'_, PyAny>>,
        finish: Option<&Bound<'_, PyAny>>,
        output: Option<&Bound<'_, PyAny>>,
        animation: Option<&Bound<'_, PyAny>>,
        simulation: Option<&Bound<'_, PyAny>>,
        regions: Option<&Bound<'_, PyAny>>,
        look: Option<&Bound<'_, PyAny>>,
        base_dir: Option<PathBuf>,
        skin: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let mut table = toml::Table::new();
        let mut inputs = GroomInputs::default();
        // The surface: a Mesh value (moved by `skin` when given), or what
        // `[mesh]` takes.
        if let Ok(m) = mesh.cast::<PyMesh>() {
            let mesh = m.get().inner.clone();
            match skin.filter(|s| !s.is_none()) {
                Some(frames) => inputs.skin = Some(Arc::new(skin_from_frames(&mesh, frames)?)),
                None => inputs.mesh = Some(mesh),
            }
        } else if skin.is_some_and(|s| !s.is_none()) {
            return Err(PyTypeError::new_err(
                "skin: give mesh= as a pelage.Mesh (the skin's triangles and UVs) with it",
            ));
        } else if let Ok(path) = mesh.extract::<PathBuf>() {
            table.insert("mesh".into(), one_key("path", path_value(&path, "mesh")?));
        } else {
            table.insert("mesh".into(), to_toml(mesh, "mesh")?);
        }
        // The guides: curves to bind, a file, or the `[guides]` table.
        if let Ok(c) = guides.cast::<PyCurves>() {
            inputs.guides = Some(c.get().inner.clone());
        } else if let Ok(path) = guides.extract::<PathBuf>() {
            table.insert(
                "guides".into(),
                one_key("file", path_value(&path, "guides")?),
            );
        } else if let Ok(section) = guides.cast::<PyDict>() {
            // `{"curves": Curves, "points": 8, "tolerance": 1e-3}`: curves
            // with the `[guides]` settings that bind them.
            let section = section.copy()?;
            if let Some(curves) = section.get_item("curves")? {
                let curves = curves
                    .cast::<PyCurves>()
                    .map_err(|_| PyTypeError::new_err("guides.curves: expected pelage.Curves"))?;
                inputs.guides = Some(curves.get().inner.clone());
                section.del_item("curves")?;
            }
            table.insert("guides".into(), to_toml(section.as_any(), "guides")?);
        } else {
            table.insert("guides".into(), to_toml(guides, "guides")?);
        }
        // `roots=200_000` is short for `roots={"count": 200_000}`; so is
        // `roots=2e5`, a whole number written as a float.
        let roots = if roots.is_instance_of::<pyo3::types::PyBool>() {
            return Err(PyTypeError::new_err(
                "roots: a number of hairs (roots=200_000) or a table (roots={\"count\": 200_000, \"seed\": 3}), not a bool",
            ));
        } else if let Ok(count) = roots.extract::<u64>() {
            one_key("count", to_toml_int(count, "roots")?)
        } else if roots.is_instance_of::<pyo3::types::PyFloat>() {
            let x: f64 = roots.extract()?;
            if !(x.is_finite() && x >= 0.0 && x.fract() == 0.0 && x <= u64::MAX as f64) {
                return Err(PyValueError::new_err(format!(
                    "roots = {x}: a whole number of hairs (roots=200_000) or a table (roots={{\"count\": 200_000}})"
                )));
            }
            one_key("count", to_toml_int(x as u64, "roots")?)
        } else if roots.is_instance_of::<PyDict>() {
            to_toml(roots, "roots")?
        } else {
            return Err(PyTypeError::new_err(format!(
                "roots: a number of hairs (roots=200_000) or a table (roots={{\"count\": 200_000, \"seed\": 3}}), not a {}",
                roots.get_type().name()?
            )));
        };
        table.insert("roots".into(), roots);
        for (key, value) in [
            ("interpolation", interpolation),
            ("ops", ops),
            ("finish", finish),
            ("output", output),
            ("animation", animation),
            ("simulation", simulation),
            ("regions", regions),
            ("look", look),
        ] {
            if let Some(value) = value.filter(|v| !v.is_none()) {
                table.insert(key.into(), to_toml(value, key)?);
            }
        }
        let text = toml::to_string(&table)
            .map_err(|e| PyValueError::new_err(format!("the groom's settings: {e}")))?;
        let path = match base_dir {
            Some(dir) => dir.join(PYTHON_GROOM),
            None => PathBuf::from(PYTHON_GROOM),
        };
        let source = SettingsSource { path, text };
        let groom = py
            .detach(|| Groom::from_source_with_inputs(source, None, inputs))
            .map_err(|e| groom_error(e, true))?;
        Self::wrap(py, groom, true)
    }

    /// Loads a groom file (docs/groom-format.md) with its mesh and guides.
    /// `frames` ("1-24", "1-48x2") makes it animated, or replaces the
    /// frames of its `[animation]`. `mesh` replaces the file's `[mesh]`
    /// (a DCC's mesh under a groom written for the command line).
    /// `fraction` (0 to 1) grows that share of the hairs, a subset of the
    /// groom by id with wider hairs (`[output] fraction`).
    #[staticmethod]
    #[pyo3(signature = (path, *, frames = None, mesh = None, fraction = None, skin = None))]
    fn load(
        py: Python<'_>,
        path: PathBuf,
        frames: Option<&str>,
        mesh: Option<&PyMesh>,
        fraction: Option<f64>,
        skin: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let frames = frames
            .map(pelage::anim::FrameRange::parse)
            .transpose()
            .map_err(|e| PyValueError::new_err(format!("frames: {e}")))?;
        let mut inputs = GroomInputs::default();
        match (mesh, skin.filter(|s| !s.is_none())) {
            (Some(mesh), Some(frames)) => {
                inputs.skin = Some(Arc::new(skin_from_frames(&mesh.inner, frames)?));
            }
            (None, Some(_)) => {
                return Err(PyTypeError::new_err(
                    "skin: give mesh= as a pelage.Mesh (the skin's triangles and UVs) with it",
                ));
            }
            (mesh, None) => inputs.mesh = mesh.map(|m| m.inner.clone()),
        }
        let groom = py
            .detach(|| {
                let source = SettingsSource::read_groom(&path)?;
                let mut groom = Groom::from_source_with_inputs(source, frames, inputs)?;
                if let Some(fraction) = fraction {
                    groom.set_fraction(fraction)?;
                }
                Ok(groom)
            })
            .map_err(|e| groom_error(e, false))?;
        Self::wrap(py, groom, false)
    }

    /// A groom from groom-file text; `path` names it in errors and is the
    /// folder relative paths start from. `mesh` replaces its `[mesh]`.
    #[staticmethod]
    #[pyo3(signature = (text, *, path = PathBuf::from("<groom>"), mesh = None))]
    fn from_text(
        py: Python<'_>,
        text: String,
        path: PathBuf,
        mesh: Option<&PyMesh>,
    ) -> PyResult<Self> {
        let inputs = GroomInputs {
            mesh: mesh.map(|m| m.inner.clone()),
            ..GroomInputs::default()
        };
        let groom = py
            .detach(|| Groom::from_source_with_inputs(SettingsSource { path, text }, None, inputs))
            .map_err(|e| groom_error(e, false))?;
        Self::wrap(py, groom, false)
    }

    /// The groom's settings as groom-file text (for a groom built from
    /// values: the file it amounts to).
    #[getter]
    fn settings(&self) -> String {
        self.groom.source().text.clone()
    }

    /// The surface.
    #[getter]
    fn mesh(&self) -> PyMesh {
        PyMesh {
            inner: Arc::new(self.groom.mesh().clone()),
        }
    }

    /// The guides, bound to the surface and resampled, as curves.
    #[getter]
    fn guides(&self) -> PyCurves {
        PyCurves::new(self.groom.guides().curves().clone())
    }

    /// Number of parts (spatially compact groups of roots; each grows
    /// alone, in any order, in any process).
    #[getter]
    fn part_count(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(self.generator(py, None)?.parts().len())
    }

    /// Hairs in each part (before `strands` multiplies them).
    #[getter]
    fn part_hair_counts(&self, py: Python<'_>) -> PyResult<Vec<u64>> {
        Ok(self
            .generator(py, None)?
            .parts()
            .iter()
            .map(|p| p.hair_count)
            .collect())
    }

    /// Where `write()` writes by default: `[output] path`, or the groom
    /// file's name with .usdc.
    #[getter]
    fn output_path(&self) -> PathBuf {
        self.groom.output_path()
    }

    /// The frames of an animated groom ("1-24"), or `None`.
    #[getter]
    fn frames(&self) -> Option<Vec<f64>> {
        let animation = self.groom.animation()?;
        Some(
            animation
                .frames
                .frames()
                .iter()
                .map(|&f| f64::from(f))
                .collect(),
        )
    }

    /// Grows hair curves: one part (`part=k`), or all of them joined
    /// (`part=None`). `seed` replaces the groom's. `progress(done, total)`
    /// is called after each part. The interpreter is released while
    /// hairs grow. `gpu=True` grows them on the GPU with the real-time
    /// evaluator (docs/realtime.md): the same hairs within 1e-4 of the
    /// groom's size; a `RuntimeError` without a GPU adapter.
    #[pyo3(signature = (part = None, *, seed = None, progress = None, gpu = false))]
    fn grow(
        &self,
        py: Python<'_>,
        part: Option<usize>,
        seed: Option<u64>,
        progress: Option<Py<PyAny>>,
        gpu: bool,
    ) -> PyResult<PyCurves> {
        let generator = self.generator(py, seed)?;
        let parts = generator.parts().len();
        let context = gpu.then(gpu_context).transpose()?;
        let grower = context
            .as_ref()
            .map(|ctx| pelage_gpu::GpuPartGrower::new(ctx, &generator));
        let grow_part = |p: usize| match &grower {
            Some(g) => g.part(p),
            None => generator.part(p),
        };
        if let Some(p) = part {
            check_part(p, parts)?;
            let hairs = generator.parts()[p]
                .hair_count
                .saturating_mul(generator.most_hairs_per_root());
            check_memory(hairs, generator.points_per_hair(), "this part")?;
            let curves = py.detach(|| grow_part(p)).map_err(|e| self.error(e))?;
            return Ok(PyCurves::grown_by(curves, generator));
        }
        // Counted after `strands`, which multiplies the hairs of a root.
        let roots: u64 = generator.parts().iter().map(|p| p.hair_count).sum();
        let hairs = roots.saturating_mul(generator.most_hairs_per_root());
        check_memory(hairs, generator.points_per_hair(), "the whole groom")?;
        let mut grown = Vec::with_capacity(parts);
        for p in 0..parts {
            grown.push(py.detach(|| grow_part(p)).map_err(|e| self.error(e))?);
            if let Some(progress) = &progress {
                progress.call1(py, (p + 1, parts))?;
            }
            // Ctrl-C between parts (the interpreter only sees it here).
            py.check_signals()?;
        }
        let joined = py
            .detach(|| pelage::curves::join(grown.iter()))
            .map_err(to_py_err)?;
        Ok(PyCurves::new(joined))
    }

    /// An animated groom at time code `time` (a frame number; fractions
    /// are sub-frames): one part (`part=k`) or all of them joined. Roots
    /// are bound at the rest frame and carried with the skin (`deform`),
    /// or regrown from the guides at that time (`regrow`). For every
    /// frame at once, `write()` is faster: it poses the skin once a frame.
    #[pyo3(signature = (time, part = None))]
    fn grow_frame(&self, py: Python<'_>, time: f64, part: Option<usize>) -> PyResult<PyCurves> {
        if !time.is_finite() {
            return Err(PyValueError::new_err(format!(
                "time = {time}: a finite frame number"
            )));
        }
        let animated = self.animated(py)?;
        let parts = animated.generator().parts().len();
        let range = match part {
            Some(p) => check_part(p, parts).map(|()| p..p + 1)?,
            None => 0..parts,
        };
        let mut grown = Vec::with_capacity(range.len());
        for p in range {
            grown.push(
                py.detach(|| animated.part(p, time))
                    .map_err(|e| self.error(e))?,
            );
            // Ctrl-C between parts (the interpreter only sees it here).
            py.check_signals()?;
        }
        let curves = match grown.len() {
            1 => grown.into_iter().next().unwrap_or_default(),
            _ => py
                .detach(|| pelage::curves::join(grown.iter()))
                .map_err(to_py_err)?,
        };
        Ok(PyCurves::new(curves))
    }

    /// Simulates the guides of an animated groom with `mode = "simulate"`
    /// over its whole frame range (through `[simulation] cache` when it
    /// names one) and, with `path` (.usdc, .usd or .abc), writes them
    /// there with a time sample a frame, as `pelage simulate` does.
    /// Returns `{"frames": (first, last), "guides": n, "cache": "read" |
    /// "written" | "replaced" | None, "path": path or None}`.
    #[pyo3(signature = (path = None))]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        path: Option<std::path::PathBuf>,
    ) -> PyResult<Bound<'py, PyAny>> {
        // Refused before the simulation, not after it.
        if let Some(path) = &path {
            pelage::io::check_writable(path).map_err(to_py_err)?;
        }
        let interrupt = Interrupt::default();
        let simulated = py.detach(|| self.groom.simulated_guides_until(&|| interrupt.seen()));
        interrupt.raise()?;
        let (guides, cache) = simulated.map_err(|e| self.error(e))?;
        if let Some(path) = &path {
            let options = self.groom.usd_options();
            py.detach(|| guides.write(path, &options))
                .map_err(to_py_err)?;
        }
        let frames = guides.frames();
        let count = guides.at(*frames.start()).map_or(0, |g| g.curve_count());
        let cache = cache.map(|c| match c {
            pelage::groom::CacheUse::Read => "read",
            pelage::groom::CacheUse::Written => "written",
            pelage::groom::CacheUse::Replaced => "replaced",
        });
        let out = pyo3::types::PyDict::new(py);
        out.set_item("frames", (*frames.start(), *frames.end()))?;
        out.set_item("guides", count)?;
        out.set_item("cache", cache)?;
        out.set_item("path", path)?;
        Ok(out.into_any())
    }

    /// Iterates over the parts, growing each as it is asked for, so memory
    /// holds one part at a time: `for curves in groom.parts(): ...`.
    #[pyo3(signature = (*, seed = None))]
    fn parts(&self, py: Python<'_>, seed: Option<u64>) -> PyResult<PartIter> {
        Ok(PartIter {
            generator: self.generator(py, seed)?,
            from_values: self.from_values,
            next: std::sync::atomic::AtomicUsize::new(0),
        })
    }

    /// Grows and writes the groom to `path` (default `output_path`),
    /// format by extension (.usdc, .usda, .abc, .hair, .ply, .rib, .pbrt),
    /// atomically. USD and Alembic stream: memory holds about two parts.
    /// `part=(k, n)` writes run k of n of a farm (docs/farm.md) to the
    /// part file beside `path`. An animated groom writes every frame.
    /// `progress(done, total)` is called as parts (and frames) are
    /// written. Returns `{"path", "hairs", "points", "report"}`:
    /// `report` (a still groom's) is what `pelage groom --report` writes —
    /// hairs per part and region, the guides left out and why, timings.
    /// `gpu=True` grows the hairs on the GPU, as `grow(gpu=True)` (an
    /// animated groom's at rest, carried to each frame as without it).
    #[pyo3(signature = (path = None, *, part = None, seed = None, progress = None, gpu = false))]
    fn write<'py>(
        &self,
        py: Python<'py>,
        path: Option<PathBuf>,
        part: Option<(usize, usize)>,
        seed: Option<u64>,
        progress: Option<Py<PyAny>>,
        gpu: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let output = self.output(path, "write")?;
        // The farm's errors, said of the argument as the user wrote it.
        let (k, n) = part.unwrap_or_default();
        let part_error =
            |e: pelage::groom::FarmError| PyValueError::new_err(format!("part = ({k}, {n}): {e}"));
        let run = part
            .map(|(k, n)| FarmRun::new(k, n))
            .transpose()
            .map_err(part_error)?;
        let started = std::time::Instant::now();
        // After each part the writer re-attaches to Python: to call the
        // progress callback, and to see a Ctrl-C (signals reach Python
        // code only while it runs). An exception from either stops the
        // write (the file is left as it was) and is raised when it returns.
        let callback_error: std::sync::Mutex<Option<PyErr>> = std::sync::Mutex::new(None);
        let cancel = AtomicBool::new(false);
        let report = |done: usize, total: usize| {
            Python::attach(|py| {
                let called = match &progress {
                    Some(progress) => progress.call1(py, (done, total)).map(drop),
                    None => Ok(()),
                };
                if let Err(e) = called.and_then(|()| py.check_signals()) {
                    cancel.store(true, Ordering::Relaxed);
                    callback_error
                        .lock()
                        .expect("not poisoned")
                        .get_or_insert(e);
                }
            });
        };
        // An animated groom with its own seed is the one grow_frame uses.
        let animated = match (self.groom.animation(), seed) {
            (None, _) => None,
            (Some(_), None) => Some(self.animated(py)?),
            (Some(_), Some(_)) => {
                let interrupt = Interrupt::default();
                let animated = py.detach(|| self.groom.animated_until(seed, &|| interrupt.seen()));
                interrupt.raise()?;
                animated.map_err(|e| self.error(e))?.map(Arc::new)
            }
        };
        let (summary, written, grown) = if let Some(animated) = animated {
            // The library's plan: a farm run's file is named by its frames,
            // as the CLI names it and `assemble` finds it.
            let plan = self
                .groom
                .animated_plan(&animated, &output, run, false)
                .map_err(|e| match e {
                    AnimatedPlanError::Farm(e) => part_error(e),
                    e => PyValueError::new_err(e.to_string()),
                })?;
            let path = plan.outputs[0].path.clone();
            create_folder(&path)?;
            let options = self.groom.run_usd_options(run);
            let files = AnimatedFiles {
                outputs: &plan.outputs,
                parts: plan.parts.clone(),
                options: &options,
                with_skin: self.groom.writes_skin_in(run),
            };
            // With gpu=True the hairs grow at rest on the GPU (each
            // frame's in regrow and simulate modes), carried as without.
            let context = gpu.then(gpu_context).transpose()?;
            let grower = context
                .as_ref()
                .map(|ctx| pelage_gpu::GpuPartGrower::new(ctx, animated.generator()));
            let grow = |g: &Generator, p: usize| match &grower {
                Some(gpu) => gpu.part_of(g, p),
                None => g.part(p),
            };
            let summary = py.detach(|| {
                animated.write_files_grown_until(files, &grow, &cancel, |p| report(p.done, p.total))
            });
            (summary, path, None)
        } else {
            // The CLI's pre-flight: a format pelage writes, a path it may
            // write, room for the run, all before preparing anything.
            let (range, path) = self.groom.preflight(&output, run).map_err(|e| match e {
                PreflightError::Farm(e) => part_error(e),
                e => to_py_err(e),
            })?;
            let generator = self.generator(py, seed)?;
            create_folder(&path)?;
            let export = self.groom.export_for(&generator, run);
            let total = range.len();
            let mut done = 0;
            let mut gathered = ReportBuilder::new(&generator);
            let setup = started.elapsed().as_secs_f64();
            let context = gpu.then(gpu_context).transpose()?;
            let grower = context
                .as_ref()
                .map(|ctx| pelage_gpu::GpuPartGrower::new(ctx, &generator));
            let grow_part = |p: usize| match &grower {
                Some(g) => g.part(p),
                None => generator.part(p),
            };
            let summary = py.detach(|| {
                generator.write_grown_until(
                    &path,
                    range,
                    &export,
                    &cancel,
                    &grow_part,
                    |p, curves| {
                        gathered.add_part(&generator, p, curves);
                        done += 1;
                        report(done, total);
                    },
                )
            });
            let timings = Timings {
                setup,
                grow_and_write: started.elapsed().as_secs_f64() - setup,
            };
            let grown = gathered.finish(&generator, Some(&self.groom), Some(&path), timings);
            (summary, path, Some(grown))
        };
        if let Some(e) = callback_error.into_inner().expect("not poisoned") {
            return Err(e);
        }
        let summary = summary.map_err(|e| match e {
            GroomWriteError::Groom(e) => self.error(e),
            e => to_py_err(e),
        })?;
        let result = PyDict::new(py);
        result.set_item("path", written)?;
        result.set_item("hairs", summary.hairs)?;
        result.set_item("points", summary.points)?;
        let report = match grown {
            Some(grown) => report_dict(py, &grown)?,
            None => py.None().into_bound(py),
        };
        result.set_item("report", report)?;
        Ok(result)
    }

    /// The groom's report before it grows: the guides kept, those left out
    /// when binding and those the style mesh never uses, each with why,
    /// and each region's guides (`write` returns the full report, with
    /// hairs per part and region).
    #[pyo3(signature = (*, seed = None))]
    fn report<'py>(&self, py: Python<'py>, seed: Option<u64>) -> PyResult<Bound<'py, PyAny>> {
        let generator = self.generator(py, seed)?;
        let report = ReportBuilder::new(&generator).finish(
            &generator,
            Some(&self.groom),
            None,
            Timings::default(),
        );
        report_dict(py, &report)
    }

    /// Ties a farm's files beside `path` (default `output_path`) together,
    /// as `pelage groom FILE --assemble` does: a still groom's part files
    /// referenced from one USD layer (name it .usda), an animated groom's
    /// frame files stitched with value clips. Returns `{"path", "files"}`
    /// and, for a still groom, `"extent"` (lowest and highest corner).
    #[pyo3(signature = (path = None))]
    fn assemble<'py>(
        &self,
        py: Python<'py>,
        path: Option<PathBuf>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let output = self.output(path, "assemble")?;
        let assembled = py
            .detach(|| self.groom.assemble(&output))
            .map_err(to_py_err)?;
        let result = PyDict::new(py);
        result.set_item("path", &output)?;
        match assembled {
            Assembly::Parts { files, extent } => {
                result.set_item("files", files)?;
                result.set_item("extent", (extent.0.to_array(), extent.1.to_array()))?;
            }
            Assembly::Frames(stitched) => {
                result.set_item("files", stitched.files)?;
            }
        }
        Ok(result)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let parts = self
            .generator(py, None)
            .map(|g| g.parts().len().to_string())
            .unwrap_or_else(|_| "?".into());
        format!(
            "<pelage.Groom {}: {} guides on {:?}, {} parts>",
            self.groom.source().path.display(),
            self.groom.guides().len(),
            self.groom.mesh().name(),
            parts
        )
    }
}

/// The parts of a groom, grown one at a time as they are iterated.
#[pyclass(name = "PartIterator", module = "pelage", frozen)]
pub struct PartIter {
    generator: Arc<Generator>,
    from_values: bool,
    next: std::sync::atomic::AtomicUsize,
}

#[pymethods]
impl PartIter {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__(&self, py: Python<'_>) -> PyResult<Option<PyCurves>> {
        let p = self.next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if p >= self.generator.parts().len() {
            return Ok(None);
        }
        let curves = py
            .detach(|| self.generator.part(p))
            .map_err(|e| groom_error(e, self.from_values))?;
        Ok(Some(PyCurves::grown_by(curves, self.generator.clone())))
    }

    fn __len__(&self) -> usize {
        self.generator.parts().len()
    }
}

/// Bytes a grown hair point takes at most in memory (positions, normals,
/// colours, widths, opacities) and a hair besides its points (offset, id,
/// root UV, triangle and barycentrics).
const BYTES_PER_POINT: u64 = 12 + 12 + 12 + 4 + 4;
const BYTES_PER_HAIR: u64 = 4 + 8 + 8 + 4 + 8;

/// Refuses to grow `hairs` hairs into memory where they cannot fit: an
/// allocation that fails aborts the interpreter, a `MemoryError` does not.
pub(crate) fn check_memory(hairs: u64, points: usize, what: &str) -> PyResult<()> {
    let need =
        hairs.saturating_mul((points as u64).saturating_mul(BYTES_PER_POINT) + BYTES_PER_HAIR);
    let Some(available) = available_memory() else {
        return Ok(());
    };
    if need <= available {
        return Ok(());
    }
    let gb = |b: u64| b as f64 / 1e9;
    Err(PyMemoryError::new_err(format!(
        "growing {what} holds {} hairs of {points} points in memory, up to {:.1} GB, and this machine has {:.1} GB available: iterate over groom.parts() (one part in memory at a time) or groom.write() it (streamed)",
        pelage::limits::grouped(hairs as f64),
        gb(need),
        gb(available)
    )))
}

/// Memory the system can give this process now (`MemAvailable`), where
/// it says.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb.saturating_mul(1024))
}

/// Creates the folder `path` will be written in, as a user of `write()`
/// expects of `groom.write("out/fur.usdc")`.
fn create_folder(path: &Path) -> PyResult<()> {
    match path.parent() {
        Some(folder) if !folder.as_os_str().is_empty() => {
            std::fs::create_dir_all(folder).map_err(|e| {
                crate::PelageError::new_err(format!("cannot create {}: {e}", folder.display()))
            })
        }
        _ => Ok(()),
    }
}

/// An error unless `p` names one of `parts` parts.
fn check_part(p: usize, parts: usize) -> PyResult<()> {
    if p < parts {
        return Ok(());
    }
    Err(PyIndexError::new_err(format!(
        "part {p}: the groom has {parts} parts (0 to {})",
        parts.saturating_sub(1)
    )))
}

/// An animated skin from `{frame: (n, 3) array}`: `mesh`'s triangles and
/// UVs with its vertices at each frame given (a DCC's evaluated mesh),
/// blended linearly between two frames given and held before the first
/// and after the last.
fn skin_from_frames(
    mesh: &Arc<pelage::Mesh>,
    frames: &Bound<'_, PyAny>,
) -> PyResult<pelage::anim::AnimatedSkin> {
    let shape = "skin: a dict {frame: (n, 3) array of the mesh's vertices at that frame}";
    let frames = frames
        .cast::<PyDict>()
        .map_err(|_| PyTypeError::new_err(shape))?;
    // Counted before any frame is copied: a million frames aborted the
    // interpreter.
    let most = pelage::limits::MAX_FRAMES;
    if frames.len() as u64 > most {
        return Err(PyValueError::new_err(format!(
            "skin: {} frames; pelage's limit is {} (docs/limits.md)",
            pelage::limits::grouped(frames.len() as f64),
            pelage::limits::grouped(most as f64)
        )));
    }
    let bytes = (frames.len() as u64).saturating_mul(mesh.vertex_count() as u64 * 12);
    if available_memory().is_some_and(|available| bytes > available) {
        return Err(PyMemoryError::new_err(format!(
            "skin: {} frames of {} vertices take {:.1} GB, more than this machine has available",
            frames.len(),
            mesh.vertex_count(),
            bytes as f64 / 1e9
        )));
    }
    let mut samples: Vec<(f64, Vec<glam::Vec3>)> = Vec::with_capacity(frames.len());
    for (frame, positions) in frames.iter() {
        let frame: f64 = frame.extract().map_err(|_| PyTypeError::new_err(shape))?;
        if !frame.is_finite() {
            return Err(PyValueError::new_err(format!(
                "skin: frame {frame} is not a finite number"
            )));
        }
        let what = format!("skin[{frame}]");
        let points = crate::convert::vec3s(crate::convert::rows::<f32, 3>(&positions, &what)?);
        if points.len() != mesh.vertex_count() {
            return Err(PyValueError::new_err(format!(
                "{what}: {} vertices; the mesh has {} (the skin's topology must not change)",
                points.len(),
                mesh.vertex_count()
            )));
        }
        if let Some(bad) = points.iter().position(|p| !p.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "{what}: vertex {bad} is not finite"
            )));
        }
        samples.push((frame, points));
    }
    if samples.is_empty() {
        return Err(PyValueError::new_err("skin: no frames"));
    }
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    let samples = Arc::new(samples);
    Ok(pelage::anim::AnimatedSkin::from_fn(mesh, move |time| {
        skin_between(&samples, time)
    }))
}

/// The skin's vertices at `time` from its frames (ascending).
fn skin_between(samples: &[(f64, Vec<glam::Vec3>)], time: f64) -> Vec<glam::Vec3> {
    let after = samples.partition_point(|(frame, _)| *frame <= time);
    let (a, b) = match after {
        0 => return samples[0].1.clone(),
        n if n == samples.len() => return samples[n - 1].1.clone(),
        n => (&samples[n - 1], &samples[n]),
    };
    let w = ((time - a.0) / (b.0 - a.0)) as f32;
    if w == 0.0 {
        return a.1.clone();
    }
    a.1.iter().zip(&b.1).map(|(p, q)| p.lerp(*q, w)).collect()
}

/// A groom report as the dict `json.loads` makes of the CLI's `--report`
/// (one schema: the library's).
fn report_dict<'py>(py: Python<'py>, report: &GroomReport) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(report)
        .map_err(|e| PyValueError::new_err(format!("the report: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// A groom error as a `PelageError`. For a groom built from values, the
/// line (of a text the user never wrote) is left out: the key says where.
fn groom_error(error: GroomError, from_values: bool) -> PyErr {
    if !from_values {
        return to_py_err(error);
    }
    let mut message = String::from("groom");
    if let Some(key) = &error.at.key {
        message.push_str(": ");
        message.push_str(key);
    }
    message.push_str(": ");
    message.push_str(&error.kind.to_string());
    let message = crate::with_causes(message, std::error::Error::source(&error.kind));
    crate::PelageError::new_err(in_python_terms(&message))
}

/// A groom-file reader's message about a value of the wrong type, in
/// the words of the values the user gave: serde names the Rust struct a
/// table becomes ("expected struct GuidesSection"), which a Python user
/// never wrote.
fn in_python_terms(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(at) = rest.find("expected struct ") {
        out.push_str(&rest[..at]);
        out.push_str("expected a table (a dict)");
        let after = &rest[at + "expected struct ".len()..];
        let end = after
            .find(|c: char| !c.is_alphanumeric() && c != '_')
            .unwrap_or(after.len());
        rest = &after[end..];
    }
    out.push_str(rest);
    out
}

/// A table of one setting, `{ key = value }`.
fn one_key(key: &str, value: toml::Value) -> toml::Value {
    toml::Value::Table(toml::Table::from_iter([(key.to_string(), value)]))
}

fn path_value(path: &Path, what: &str) -> PyResult<toml::Value> {
    path.to_str()
        .map(|s| toml::Value::String(s.to_string()))
        .ok_or_else(|| PyValueError::new_err(format!("{what}: the path is not valid UTF-8")))
}

fn to_toml_int(value: u64, what: &str) -> PyResult<toml::Value> {
    i64::try_from(value)
        .map(toml::Value::Integer)
        .map_err(|_| PyValueError::new_err(format!("{what}: {value} is too large")))
}

/// A Python value as a TOML value: dicts (string keys), lists and tuples,
/// bools, integers, floats, strings and paths. `key` names it in errors
/// (`ops[1].clump`).
fn to_toml(value: &Bound<'_, PyAny>, key: &str) -> PyResult<toml::Value> {
    if let Ok(dict) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in dict.iter() {
            let name: String = k.extract().map_err(|_| {
                PyTypeError::new_err(format!("{key}: keys must be strings, got {k:?}"))
            })?;
            if v.is_none() {
                continue; // None: the setting's default
            }
            let child = format!("{key}.{name}");
            table.insert(name, to_toml(&v, &child)?);
        }
        return Ok(toml::Value::Table(table));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items = value
            .try_iter()?
            .enumerate()
            .map(|(i, v)| to_toml(&v?, &format!("{key}[{i}]")))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    if value.is_instance_of::<pyo3::types::PyBool>() {
        return Ok(toml::Value::Boolean(value.extract()?));
    }
    if let Ok(s) = value.extract::<String>() {
        return Ok(toml::Value::String(s));
    }
    if (value.is_instance_of::<pyo3::types::PyInt>() || value.hasattr("__index__")?)
        && let Ok(i) = value.extract::<i64>()
    {
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(x) = value.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    if let Ok(p) = value.extract::<PathBuf>() {
        return path_value(&p, key);
    }
    // A numpy array of numbers (a comb direction, a colour).
    if value.hasattr("tolist")? {
        return to_toml(&value.call_method0("tolist")?, key);
    }
    Err(PyTypeError::new_err(format!(
        "{key}: cannot use a {} as a groom setting (use dicts, lists, numbers, strings)",
        value.get_type().name()?
    )))
}

/// A Ctrl-C seen while the library works without the interpreter (a
/// simulation, frame after frame): signals reach Python code only while
/// it runs, so [`Self::seen`] attaches to look, and keeps the
/// `KeyboardInterrupt` for [`Self::raise`] once the work has returned.
#[derive(Default)]
struct Interrupt(std::sync::Mutex<Option<PyErr>>);

impl Interrupt {
    /// Whether a signal handler raised (the library's `stop`).
    fn seen(&self) -> bool {
        Python::attach(|py| match py.check_signals() {
            Ok(()) => false,
            Err(e) => {
                self.0.lock().expect("not poisoned").get_or_insert(e);
                true
            }
        })
    }

    /// The interrupt seen, raised.
    fn raise(self) -> PyResult<()> {
        match self.0.into_inner().expect("not poisoned") {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

/// A headless GPU for `gpu=True`, or a `RuntimeError` saying why there is
/// none.
fn gpu_context() -> PyResult<pelage_gpu::GpuContext> {
    pelage_gpu::GpuContext::headless().map_err(|e| {
        pyo3::exceptions::PyRuntimeError::new_err(format!(
            "gpu=True: no GPU to grow on ({e}); grow without gpu=True"
        ))
    })
}

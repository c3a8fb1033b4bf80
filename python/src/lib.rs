//! `gantry._gantry`: the simulator as a Python extension module.
//!
//! This crate is a converter, like the Lua host and the ZMQ transport: it turns Python
//! objects into [`Value`]s, calls the one implementation of each function
//! ([`gantry_sim_core::api::MODULES`], the Lua host's script functions, and the
//! remote API's simulation control, [`api::HOST_FUNCTIONS`]), and turns
//! the results back with the shapes CoppeliaSim's Python client gives. The Python
//! package around it (`python/gantry/`) adds `Client`, `require` and the extras.

mod convert;
mod direct;
mod plan;
mod plan_server;
mod served;

use std::net::IpAddr;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use gantry_engine::HostCall;
use gantry_engine::{EngineConfig, RecorderFactory};
use gantry_lua::ScriptLimits;
use gantry_record::{RecordParams, Recorder, RunDescription, RunRecorder};
use gantry_server::sim_thread::SimConfig;
use gantry_server::zmq::no_module;
use gantry_server::{AccessToken, ServeConfig, Shutdown, Signals};
use gantry_sim_core::Value;
use gantry_sim_core::api::{self, Cost, Target};
use gantry_sim_core::scene::{
    BUNDLED_SCENES, DiskFiles, EmbeddedFiles, Files, LoadOptions, LoggedFiles, bundled_files, load_client_scene,
    load_scene, normalize_path,
};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyException, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::convert::{results, to_value};
use crate::direct::Direct;
use crate::plan::StepPlan;
use crate::plan_server::PlanServer;
use crate::served::Served;

/// A function resolved once, when its function object is made (or per call of
/// `client.call(name, ...)`): the edge where a name becomes a typed target.
#[derive(Clone, Copy)]
struct Resolved {
    target: Target,
    /// Whether an in-process call releases the GIL (see [`releases_gil`]).
    release_gil: bool,
}

/// Looks a name up as the remote API does: `getObject` or `sim.getObject` in `sim`,
/// `simIK.handleGroup` in another module.
fn resolve(name: &str) -> Option<Resolved> {
    let target = Target::resolve(name)?;
    Some(Resolved {
        target,
        release_gil: releases_gil(&target),
    })
}

/// Whether an in-process call of `target` releases the GIL: when the registry says it
/// may run long (renders, IK solves, planning, geometric queries, script code). The
/// quick ones (a pose, a signal) keep it, since releasing and retaking it costs more
/// than they do. Decided once per function object.
fn releases_gil(target: &Target) -> bool {
    target.cost() == Cost::Long
}

/// Where the simulation runs.
enum Backend {
    /// In the calling thread.
    Direct(Box<Direct>),
    /// On gantry's simulation thread, with listeners.
    Served(Box<Served>),
}

/// A simulation and the client driving it. Bound to the thread that created it (the
/// Lua state cannot move between threads); several engines in several threads run in
/// parallel, since steps release the GIL.
#[pyclass(unsendable, module = "gantry._gantry")]
pub struct Engine {
    backend: Option<Backend>,
    /// The thread that made it, which its functions must be called from.
    owner: std::thread::ThreadId,
}

impl Engine {
    fn backend(&mut self) -> PyResult<&mut Backend> {
        self.backend
            .as_mut()
            .ok_or_else(|| PyRuntimeError::new_err("this gantry client is closed"))
    }

    /// Carries out one call.
    fn invoke(&mut self, py: Python<'_>, f: Resolved, args: &[Value]) -> PyResult<Vec<Value>> {
        let host = match f.target {
            Target::FrontEnd(h) => Some(HostCall::parse(h, args).map_err(|e| PyException::new_err(e.to_string()))?),
            _ => None,
        };
        let out = match (self.backend()?, host) {
            (Backend::Direct(d), None) => d.call(py, &f.target, f.release_gil, args).map_err(|e| e.to_string()),
            (Backend::Direct(d), Some(call)) => d.host(py, call).map_err(|e| e.to_string()),
            (Backend::Served(s), None) => s.call(py, f.target, args).map_err(|e| e.to_string()),
            (Backend::Served(s), Some(call)) => s.host(py, &f.target.qualified(), call).map_err(|e| e.to_string()),
        };
        // The edge: the remote client raises a plain Exception with the server's message.
        out.map_err(PyException::new_err)
    }
}

#[pymethods]
impl Engine {
    /// Loads `scene` (a gantry `.toml` scene, a `.urdf` robot, or the name of a bundled
    /// scene such as `bubble_rob`; `None`: an empty scene)
    /// and creates its simulation, in this thread, or with listeners when a port is
    /// given.
    #[new]
    #[pyo3(signature = (scene=None, *, dt=None, substeps=None, autostart=true, realtime=true,
                        package_paths=Vec::new(), free_base=false, scripts=true, bind=None, http_port=None,
                        zmq_port=None, text_port=None, token=None, record=None, record_rate=None, seed=None,
                        ros2=false))]
    #[expect(clippy::too_many_arguments, reason = "Python keyword arguments")]
    fn new(
        py: Python<'_>,
        scene: Option<PathBuf>,
        dt: Option<f64>,
        substeps: Option<u32>,
        autostart: bool,
        realtime: bool,
        package_paths: Vec<PathBuf>,
        free_base: bool,
        scripts: bool,
        bind: Option<String>,
        http_port: Option<u16>,
        zmq_port: Option<u16>,
        text_port: Option<u16>,
        token: Option<String>,
        record: Option<PathBuf>,
        record_rate: Option<f64>,
        seed: Option<i64>,
        ros2: bool,
    ) -> PyResult<Self> {
        let options = LoadOptions {
            package_paths,
            free_base,
        };
        if let Some(r) = record_rate
            && !(r.is_finite() && r > 0.0)
        {
            return Err(PyValueError::new_err(format!(
                "record_rate={r}: snapshots per simulated second must be a positive number"
            )));
        }
        // Every file read is kept for a recording's attachments.
        let (mut model, scene_path, files_read) = py
            .detach(|| -> Result<_, String> {
                let bundled = bundled_files();
                let (files, path): (&dyn Files, PathBuf) = match &scene {
                    Some(path) => match path.to_str().and_then(|n| BUNDLED_SCENES.iter().find(|(b, _)| *b == n)) {
                        Some((_, rel)) => (&bundled, EmbeddedFiles::path(rel)),
                        None => (&DiskFiles, path.clone()),
                    },
                    None => {
                        let model = load_client_scene(None, &options).map_err(|e| e.to_string())?;
                        return Ok((model, PathBuf::new(), Vec::new()));
                    }
                };
                let logged = LoggedFiles::new(files);
                // The load error names the file.
                let model = load_scene(&logged, &path, &options).map_err(|e| e.to_string())?;
                Ok((model, normalize_path(&path), logged.into_read()))
            })
            .map_err(PyValueError::new_err)?;
        if !scripts {
            // The Python program is then the only controller (reinforcement learning).
            model.scripts.clear();
        }
        if let Some(dt) = dt {
            // A lower bound too: real-time pacing takes up to a simulated second of steps
            // per call, which a vanishing step would make endless.
            if !(dt.is_finite() && (1e-4..=1.0).contains(&dt)) {
                return Err(PyValueError::new_err(format!(
                    "dt={dt}: the time step must be in [0.0001, 1] s"
                )));
            }
            model.settings.dt = dt;
        }
        if let Some(n) = substeps {
            if !(1..=1000).contains(&n) {
                return Err(PyValueError::new_err(format!("substeps={n}: use 1 to 1000")));
            }
            model.settings.substeps = n;
        }
        if let Some(seed) = seed {
            model.settings.seed = seed;
        }
        for w in &model.warnings {
            tracing::warn!("{w}");
        }
        let run = RunDescription {
            scene_name: model.name.clone(),
            scene_path,
            files: files_read,
            package_paths: options.package_paths.clone(),
            free_base: options.free_base,
            scripts,
            dt: model.settings.dt,
            substeps: model.settings.substeps,
            seed: model.settings.seed,
            command_line: format!("gantry.Client({:?})", scene.as_deref().unwrap_or(Path::new(""))),
        };
        let record = record.map(|path| RecordParams::for_run(path, record_rate, run.clone()));
        let recorder_factory: Arc<dyn RecorderFactory> = Arc::new(RunRecorder::new(run));
        let limits = ScriptLimits::default();
        let ros2 = ros2_setup(ros2)?;
        let backend = if http_port.is_some() || zmq_port.is_some() || text_port.is_some() {
            let bind: IpAddr = match bind.as_deref() {
                Some(b) => b
                    .parse()
                    .map_err(|_| PyValueError::new_err(format!("bind={b:?}: not an IP address")))?,
                None => IpAddr::from([127, 0, 0, 1]),
            };
            let token = token
                .map(|t| AccessToken::new(&t).map_err(|e| PyValueError::new_err(format!("token: {e}"))))
                .transpose()?;
            let serve = ServeConfig {
                bind,
                token,
                http_port,
                zmq_port,
                text_port,
                ..ServeConfig::default()
            };
            let config = SimConfig {
                fast: !realtime,
                limits,
                autostart,
                load_options: options,
                record,
                recorder_factory: Some(recorder_factory),
                ros2: Some(ros2),
                ..SimConfig::default()
            };
            let running = gantry_server::start(model, config, serve, Shutdown::default(), Signals::Leave)
                .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
            Backend::Served(Box::new(Served::new(running)))
        } else {
            // First, so that a file that cannot be written fails before anything runs.
            let recorder = record
                .map(Recorder::create)
                .transpose()
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
            let config = EngineConfig {
                limits,
                load_options: options,
                listeners: None,
                realtime,
                recorder: Some(recorder_factory),
                ros: Some(ros2.network.clone()),
            };
            let d = Direct::new(py, model, config, autostart, recorder, ros2.graph())
                .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
            Backend::Direct(Box::new(d))
        };
        Ok(Self {
            backend: Some(backend),
            owner: std::thread::current().id(),
        })
    }

    /// The callable functions of `module` (`sim`, `simIK`, `simUI`, `simVision`) as
    /// `(name, Function)` pairs.
    fn functions(slf: &Bound<'_, Self>, module: &str) -> PyResult<Vec<(String, Function)>> {
        let m = api::module(module).ok_or_else(|| PyException::new_err(no_module(Some(module))))?;
        let mut names: Vec<&'static str> = m.callable().map(|(n, _)| n).collect();
        if module == "sim" {
            names.extend(api::host::remote_names());
        }
        let owner = slf.borrow().owner;
        let engine = slf.clone().unbind();
        names
            .into_iter()
            .filter_map(|n| {
                let qualified = format!("{module}.{n}");
                resolve(&qualified).map(|f| (n, qualified, f))
            })
            .map(|(n, qualified, f)| {
                Ok((
                    n.to_owned(),
                    Function {
                        engine: engine.clone_ref(slf.py()),
                        f,
                        qualified,
                        owner,
                    },
                ))
            })
            .collect()
    }

    /// The constants of `module` as `(name, value)` pairs.
    #[staticmethod]
    fn constants(module: &str) -> PyResult<Vec<(&'static str, i64)>> {
        let m = api::module(module).ok_or_else(|| PyException::new_err(no_module(Some(module))))?;
        Ok(m.constants.iter().map(|(n, v)| (*n, *v)).collect())
    }

    /// The names of the scenes compiled into gantry (`Client("bubble_rob")`).
    #[staticmethod]
    fn bundled_scenes() -> Vec<&'static str> {
        BUNDLED_SCENES.iter().map(|(n, _)| *n).collect()
    }

    /// The module names gantry provides.
    #[staticmethod]
    fn modules() -> Vec<&'static str> {
        api::MODULES.iter().map(|m| m.name).collect()
    }

    /// `client.call("sim.getObject", ["/arm"])`: a call by name, as
    /// `RemoteAPIClient.call` makes it.
    fn call(&mut self, py: Python<'_>, name: &str, args: Vec<Bound<'_, PyAny>>) -> PyResult<Py<PyAny>> {
        let qualified = if name.contains('.') {
            name.to_owned()
        } else {
            format!("sim.{name}")
        };
        let f = resolve(&qualified).ok_or_else(|| PyException::new_err(format!("No such function: {qualified}")))?;
        let values = args.iter().map(to_value).collect::<PyResult<Vec<_>>>()?;
        let out = self.invoke(py, f, &values)?;
        results(py, &out)
    }

    /// Takes `n` steps as fast as possible, whatever the stepping mode (starting a
    /// stopped simulation first); returns the steps taken (fewer if a script stops
    /// it). In-process only.
    fn advance(&mut self, py: Python<'_>, n: u64) -> PyResult<u64> {
        match self.backend()? {
            Backend::Direct(d) => d.advance(py, n),
            Backend::Served(_) => Err(PyRuntimeError::new_err(
                "advance() is for in-process clients; a served simulation steps with sim.step()",
            )),
        }
    }

    /// One action of a step plan (see `StepPlan`): `action` is the task's `float32`
    /// action; returns the observation's numbers as a `float64` array. The whole call
    /// runs with the GIL released. In-process only.
    fn run_plan<'py>(
        &mut self,
        py: Python<'py>,
        plan: &StepPlan,
        action: PyReadonlyArray1<'py, f32>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let action = action.as_slice()?;
        if action.len() < plan.action_size {
            return Err(PyValueError::new_err(format!(
                "run_plan: the plan reads {} action values, got {}",
                plan.action_size,
                action.len()
            )));
        }
        let values = match self.backend()? {
            Backend::Direct(d) => d
                .run_plan(py, plan, action)
                .map_err(|e| PyException::new_err(e.to_string()))?,
            Backend::Served(_) => {
                return Err(PyRuntimeError::new_err(
                    "run_plan() is for in-process clients; a served simulation steps with sim.step()",
                ));
            }
        };
        Ok(PyArray1::from_vec(py, values))
    }

    /// `run_plan` on several in-process clients of this thread, row `k` of `actions`
    /// for `engines[k]` with `plans[k]`, the GIL released once for all (a vector
    /// environment's block). Returns the observations as a `(n, m)` `float64` array
    /// (every plan must observe `m` numbers). A failing call raises an `Exception`
    /// whose `args` are `(message, k)`.
    #[staticmethod]
    fn run_plans<'py>(
        py: Python<'py>,
        engines: Vec<Bound<'py, Engine>>,
        plans: Vec<PyRef<'py, StepPlan>>,
        actions: PyReadonlyArray2<'py, f32>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let [n, width] = [actions.shape()[0], actions.shape()[1]];
        if engines.len() != n || plans.len() != n {
            return Err(PyValueError::new_err(format!(
                "run_plans: {} engines, {} plans and {n} action rows",
                engines.len(),
                plans.len()
            )));
        }
        if let Some(p) = plans.iter().find(|p| p.action_size > width) {
            return Err(PyValueError::new_err(format!(
                "run_plans: a plan reads {} action values, got {width}",
                p.action_size
            )));
        }
        let actions = actions.as_slice()?;
        let mut borrowed = borrow_all(&engines, "run_plans")?;
        let mut sims = in_process(&mut borrowed, "run_plans")?;
        let work: Vec<(&StepPlan, &[f32])> = plans
            .iter()
            .zip(actions.chunks(width.max(1)))
            .map(|(p, a)| (&**p, a))
            .collect();
        let rows =
            Direct::run_plans(py, &mut sims, &work).map_err(|(k, e)| PyException::new_err((e.to_string(), k)))?;
        plan::rows_array(py, rows)
    }

    /// Parks this thread in `server` (see `plan_server`) until it is released: for each
    /// batch of actions the server is sent, runs `plans[k]` on `engines[k]` with the GIL
    /// released throughout, and sends back the observations. For a vector environment's
    /// worker thread; the clients are in-process clients of this thread that do not
    /// pace themselves (`realtime=False`).
    #[staticmethod]
    fn serve_plans(
        py: Python<'_>,
        server: Bound<'_, PlanServer>,
        engines: Vec<Bound<'_, Engine>>,
        plans: Vec<PyRef<'_, StepPlan>>,
    ) -> PyResult<()> {
        let server = server.get();
        let mut borrowed = borrow_all(&engines, "serve_plans");
        let found = borrowed
            .as_mut()
            .map_err(|e| e.to_string())
            .and_then(|b| in_process(b, "serve_plans").map_err(|e| e.to_string()));
        // Served even when the plans cannot run: each batch is then answered with the
        // refusal, so that the caller, which has sent it already, hears of it.
        let mut sims = Vec::new();
        let refusal = match found {
            _ if engines.len() != plans.len() => Some(format!(
                "serve_plans: {} engines and {} plans",
                engines.len(),
                plans.len()
            )),
            Ok(found) if found.iter().any(|d| d.paced()) => {
                Some("serve_plans: a client runs in real time; its calls must catch up with the clock".to_owned())
            }
            Ok(found) => {
                sims = found;
                None
            }
            Err(e) => Some(e),
        };
        let plans: Vec<&StepPlan> = plans.iter().map(|p| &**p).collect();
        Direct::detached_all(py, &mut sims, |sims| server.serve(sims, &plans, refusal.as_deref()));
        Ok(())
    }

    /// A vision sensor's image as a numpy array `(height, width, channels)` of `uint8`
    /// (channels 3, 1 with `options` bit 0, 4 with `rgba_cutoff`), without copying the
    /// pixels again; `top_first` reorders the rows so that row 0 is the top, as numpy,
    /// OpenCV, PIL and PyBullet have it (CoppeliaSim stores the bottom row first). The
    /// array is the caller's own and C-contiguous either way.
    #[pyo3(signature = (sensor, options=0, rgba_cutoff=0.0, top_first=true))]
    fn image<'py>(
        &mut self,
        py: Python<'py>,
        sensor: i64,
        options: i64,
        rgba_cutoff: f64,
        top_first: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let args = [Value::Int(sensor), Value::Int(options), Value::Float(rgba_cutoff)];
        let (mut bytes, [w, h]) = self.sensor_bytes(py, "getVisionSensorImg", &args)?;
        let channels = bytes.len().checked_div(w * h).unwrap_or(3);
        flip_rows(&mut bytes, h, top_first);
        Ok(PyArray1::from_vec(py, bytes).reshape([h, w, channels])?.into_any())
    }

    /// A vision sensor's depth map as a numpy array `(height, width)` of `float32`:
    /// normalised 0..1 between the clipping planes, or metres with `metres`. The
    /// floats are reinterpreted in place, not copied; `top_first` as for `image`.
    #[pyo3(signature = (sensor, metres=false, top_first=true))]
    fn depth<'py>(
        &mut self,
        py: Python<'py>,
        sensor: i64,
        metres: bool,
        top_first: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let args = [Value::Int(sensor), Value::Int(i64::from(metres))];
        let (mut bytes, [w, h]) = self.sensor_bytes(py, "getVisionSensorDepth", &args)?;
        flip_rows(&mut bytes, h, top_first);
        let bytes = PyArray1::from_vec(py, bytes);
        let floats = bytes.call_method1("view", ("<f4",))?;
        floats.call_method1("reshape", ((h, w),))
    }

    /// A vision sensor's segmentation mask as a numpy array `(height, width)` of
    /// `int32`: the handle of the shape seen at each pixel, -1 where nothing is
    /// (`sim.getVisionSensorMask`), from the same render as `image` and `depth`;
    /// reinterpreted in place, not copied; `top_first` as for `image`.
    #[pyo3(signature = (sensor, top_first=true))]
    fn mask<'py>(&mut self, py: Python<'py>, sensor: i64, top_first: bool) -> PyResult<Bound<'py, PyAny>> {
        let (mut bytes, [w, h]) = self.sensor_bytes(py, "getVisionSensorMask", &[Value::Int(sensor)])?;
        flip_rows(&mut bytes, h, top_first);
        let bytes = PyArray1::from_vec(py, bytes);
        let handles = bytes.call_method1("view", ("<i4",))?;
        handles.call_method1("reshape", ((h, w),))
    }

    /// The listeners' addresses (`{"http": "127.0.0.1:8080", ...}`) of a served
    /// simulation; empty in-process.
    fn addresses<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        if let Backend::Served(s) = self.backend()?
            && let Some(b) = s.bound()
        {
            for (name, addr) in [("http", b.http), ("zmq", b.zmq), ("text", b.text)] {
                if let Some(a) = addr {
                    d.set_item(name, a.to_string())?;
                }
            }
        }
        Ok(d)
    }

    /// Whether this client runs the simulation in its own thread (not served).
    fn in_process(&mut self) -> PyResult<bool> {
        Ok(matches!(self.backend()?, Backend::Direct(_)))
    }

    /// Ends the simulation: cleanup hooks run, listeners close. Later calls fail.
    fn close(&mut self, py: Python<'_>) {
        match self.backend.take() {
            Some(Backend::Direct(mut d)) => d.close(),
            Some(Backend::Served(mut s)) => s.close(py),
            None => {}
        }
    }
}

impl Engine {
    /// `bytes, {width, height}` of a vision sensor reply.
    fn sensor_bytes(&mut self, py: Python<'_>, name: &'static str, args: &[Value]) -> PyResult<(Vec<u8>, [usize; 2])> {
        let qualified = format!("sim.{name}");
        let f = resolve(&qualified).ok_or_else(|| PyRuntimeError::new_err(format!("{qualified} is missing")))?;
        let out = self.invoke(py, f, args)?;
        let mut it = out.into_iter();
        match (it.next(), it.next()) {
            (Some(Value::Bytes(b)), Some(Value::Array(size))) => {
                let dim = |i: usize| {
                    size.get(i)
                        .and_then(Value::as_i64)
                        .and_then(|v| usize::try_from(v).ok())
                };
                match (dim(0), dim(1)) {
                    (Some(w), Some(h)) => Ok((b, [w, h])),
                    _ => Err(PyRuntimeError::new_err(format!("{qualified}: malformed size"))),
                }
            }
            _ => Err(PyRuntimeError::new_err(format!("{qualified}: unexpected reply"))),
        }
    }
}

/// The ROS 2 network of scripts' `simROS2` (started on first use), and with
/// `ros2=True` the graph's topics as `gantry run --ros2` publishes them, started now so
/// that a domain that cannot be joined fails here.
fn ros2_setup(graph: bool) -> PyResult<gantry_ros2::RosSetup> {
    gantry_ros2::RosSetup::from_env(graph.then(gantry_ros2::GraphOptions::default))
        .map_err(|e| PyRuntimeError::new_err(format!("ros2=True: {e}")))
}

/// Each engine borrowed for a call of several (`what`): an error if one is busy or
/// given twice.
fn borrow_all<'py>(engines: &[Bound<'py, Engine>], what: &str) -> PyResult<Vec<PyRefMut<'py, Engine>>> {
    engines
        .iter()
        .map(|e| {
            e.try_borrow_mut()
                .map_err(|_| PyRuntimeError::new_err(format!("{what}: a client is busy or given twice")))
        })
        .collect()
}

/// The in-process simulations of borrowed engines; an error for a served one.
fn in_process<'a>(borrowed: &'a mut [PyRefMut<'_, Engine>], what: &str) -> PyResult<Vec<&'a mut Direct>> {
    let mut sims = Vec::with_capacity(borrowed.len());
    for engine in borrowed {
        match engine.backend()? {
            Backend::Direct(d) => sims.push(&mut **d),
            Backend::Served(_) => return Err(PyRuntimeError::new_err(format!("{what}() is for in-process clients"))),
        }
    }
    Ok(sims)
}

/// Reverses the order of an image's `rows` in place when `top_first`, so that the
/// array handed to Python is C-contiguous with row 0 at the top. A reversed view
/// (negative strides) was free here but cost its readers: `torch.from_numpy` refuses
/// it and `np.array` copies it a second time.
fn flip_rows(bytes: &mut [u8], rows: usize, top_first: bool) {
    let Some(row_bytes) = bytes.len().checked_div(rows) else {
        return;
    };
    if !top_first || row_bytes == 0 {
        return;
    }
    let (mut low, mut high) = (0, rows - 1);
    while low < high {
        let (head, tail) = bytes.split_at_mut(high * row_bytes);
        head[low * row_bytes..(low + 1) * row_bytes].swap_with_slice(&mut tail[..row_bytes]);
        low += 1;
        high -= 1;
    }
}

/// One function of a module, bound to its engine: `sim.getObjectPosition` and the
/// like. Calling it converts the arguments, runs the one implementation, and converts
/// the results.
#[pyclass(frozen, module = "gantry._gantry")]
pub struct Function {
    engine: Py<Engine>,
    f: Resolved,
    qualified: String,
    /// The engine's thread. Checked here, before PyO3's own check of an `unsendable`
    /// class, which panics (a `BaseException` that `except Exception` misses).
    owner: std::thread::ThreadId,
}

#[pymethods]
impl Function {
    #[pyo3(signature = (*args))]
    fn __call__(&self, py: Python<'_>, args: &Bound<'_, PyTuple>) -> PyResult<Py<PyAny>> {
        if std::thread::current().id() != self.owner {
            return Err(PyRuntimeError::new_err(format!(
                "{}: a gantry client belongs to the thread that created it; make one client per thread",
                self.qualified
            )));
        }
        let values = args.iter().map(|a| to_value(&a)).collect::<PyResult<Vec<_>>>()?;
        let mut engine = self.engine.bind(py).try_borrow_mut().map_err(|_| {
            PyRuntimeError::new_err(format!(
                "{}: the client is busy (a call from inside another call)",
                self.qualified
            ))
        })?;
        let out = engine.invoke(py, self.f, &values)?;
        results(py, &out)
    }

    fn __repr__(&self) -> String {
        format!("<gantry function {}>", self.qualified)
    }

    /// The qualified name, e.g. `sim.getObject`.
    #[getter]
    fn __name__(&self) -> &str {
        &self.qualified
    }
}

/// Sends gantry's log (scripts' `print` and `sim.addLog` at "info", warnings, errors)
/// to stderr. `level` is a filter as `RUST_LOG` takes it ("info", "warn", ...). Only the
/// first call in a process takes effect.
#[pyfunction]
#[pyo3(signature = (level="info"))]
fn log_to_stderr(level: &str) -> PyResult<bool> {
    let filter = tracing_subscriber::EnvFilter::try_new(level)
        .map_err(|e| PyValueError::new_err(format!("level={level:?}: {e}")))?;
    Ok(tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .try_init()
        .is_ok())
}

#[pymodule]
fn _gantry(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Engine>()?;
    m.add_class::<Function>()?;
    m.add_class::<StepPlan>()?;
    m.add_class::<PlanServer>()?;
    m.add_function(wrap_pyfunction!(log_to_stderr, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

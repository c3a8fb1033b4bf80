//! Graph streams (`sim.addGraphStream`): named time series kept in memory (bounded) and
//! exportable to CSV.
//!
//! Each stream belongs to a graph object and records `(time, value)` samples. The API
//! stamps a value set during a step with the step's end time `t + dt`, because
//! CoppeliaSim records stream values in `sim.handleGraph` at the end of the sensing
//! phase with that time; setting a value twice in one step keeps the last one, as
//! CoppeliaSim does. A stream keeps its newest [`MAX_STREAM_SAMPLES`] samples.
//!
//! A curve (`sim.addGraphCurve`) draws two or three streams of a graph against each
//! other (x/y or x/y/z); it holds no samples of its own, and its points are read from
//! its streams, a stream without a value at a time taking the curve's default.
//!
//! Non-goals: stream transformations and the graph's own plotting options; `options`,
//! `cyclicRange`, colours and widths are stored for the viewer only.

use std::collections::{BTreeMap, VecDeque};
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};

use crate::error::SimError;
use crate::handle::Handle;
use crate::scene::normalize_path;

/// Samples kept per stream; older ones are dropped (a ring buffer). At 20 steps per
/// second this is 83 minutes of simulated time, 1.6 MB per stream.
pub const MAX_STREAM_SAMPLES: usize = 100_000;

/// Cap on streams in the scene, so memory stays bounded (at most 410 MB of samples).
/// Re-adding a stream with an existing name updates it and does not count.
pub const MAX_STREAMS: usize = 256;

/// The first stream id; ids are unique across graphs.
pub const FIRST_STREAM_ID: i64 = 1;

/// What `sim.addGraphStream` asks for.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamParams {
    /// Stream name, unique within its graph; a CSV column header.
    pub name: String,
    /// Unit label, e.g. `m`; may be empty.
    pub unit: String,
    /// CoppeliaSim options: bit 0 hidden, bit 1 no label, bit 2 points not linked.
    pub options: i64,
    /// Curve colour, RGB in [0, 1].
    pub color: [f64; 3],
    /// Range of a cyclic quantity (e.g. 2π for a wrapping angle), 0 when not cyclic.
    pub cyclic_range: f64,
}

/// What `sim.addGraphCurve` asks for.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveParams {
    /// Curve name, unique among the curves of its graph.
    pub name: String,
    /// The streams giving x, y and, for a 3D curve, z: 2 or 3 ids of the same graph.
    pub streams: Vec<i64>,
    /// One value per stream, used where that stream has no sample.
    pub defaults: Vec<f64>,
    /// Unit label; may be empty.
    pub unit: String,
    /// CoppeliaSim options (bit 0 hidden, bit 1 no label, bit 2 points not linked, ...).
    pub options: i64,
    /// Colour, RGB in [0, 1].
    pub color: [f64; 3],
    /// Line width, pixels.
    pub width: i64,
}

/// A curve of a graph.
#[derive(Debug, Clone, PartialEq)]
pub struct GraphCurve {
    id: i64,
    graph: Handle,
    params: CurveParams,
}

impl GraphCurve {
    /// The id `sim.addGraphCurve` returned.
    pub fn id(&self) -> i64 {
        self.id
    }

    /// The graph object the curve belongs to.
    pub fn graph(&self) -> Handle {
        self.graph
    }

    /// Name, streams, defaults, unit, options, colour and width.
    pub fn params(&self) -> &CurveParams {
        &self.params
    }
}

/// One time series.
#[derive(Debug, Clone, PartialEq)]
pub struct GraphStream {
    id: i64,
    graph: Handle,
    params: StreamParams,
    /// `(time s, value)` in recording order.
    samples: VecDeque<(f64, f64)>,
}

impl GraphStream {
    /// The stream id `sim.addGraphStream` returned.
    pub fn id(&self) -> i64 {
        self.id
    }

    /// The graph object the stream belongs to.
    pub fn graph(&self) -> Handle {
        self.graph
    }

    /// Name, unit, options and colour.
    pub fn params(&self) -> &StreamParams {
        &self.params
    }

    /// The CSV column header: `name [unit]`, or `name` without a unit.
    pub fn label(&self) -> String {
        if self.params.unit.is_empty() {
            self.params.name.clone()
        } else {
            format!("{} [{}]", self.params.name, self.params.unit)
        }
    }

    /// Recorded samples, `(simulation time s, value)`, oldest first.
    pub fn samples(&self) -> impl ExactSizeIterator<Item = (f64, f64)> + '_ {
        self.samples.iter().copied()
    }

    /// Number of samples kept.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether no sample was recorded (or all were cleared).
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }
}

/// Where `sim.exportGraphStreams` may write. The API function is reachable from
/// scripts and from remote clients, neither of which should be able to write anywhere
/// the gantry process can; `--export-graphs DIR` is the user's own choice and does not
/// go through this.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub enum ExportScope {
    /// Anywhere the process may write: the default for a world built directly in Rust,
    /// whose caller is trusted. A host that runs scripts or serves remote clients
    /// confines it (gantry's `Simulation` does, to the scene's folder).
    #[default]
    Anywhere,
    /// Only inside this folder (the scene's). Relative paths resolve against it; an
    /// absolute path is accepted only when it lies inside it.
    Within(PathBuf),
    /// Nowhere: the scene has no folder on disk (the scene embedded in the binary).
    Nowhere,
}

/// Why [`ExportScope::resolve`] refused a directory.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ExportDenied {
    /// The directory lies outside the scene's folder: an absolute path elsewhere, `..`
    /// climbing out of it, or a symbolic link pointing out of it.
    #[error(
        "{dir} is outside the scene's folder {root}; scripts and remote clients may only read and write files inside it (give a path relative to the scene; graph exports go elsewhere with --export-graphs DIR)"
    )]
    Outside {
        /// The directory asked for, as given.
        dir: PathBuf,
        /// The scene's folder.
        root: PathBuf,
    },
    /// The scene's folder cannot be resolved (removed while running?).
    #[error("the scene's folder {root} is not accessible ({reason}), so nothing can be exported into it")]
    RootUnavailable {
        /// The scene's folder.
        root: PathBuf,
        /// The operating system's reason.
        reason: String,
    },
    /// The scene has no folder on disk.
    #[error(
        "this scene has no folder on disk (it is embedded in gantry), so scripts and remote clients cannot export; run gantry with --export-graphs DIR"
    )]
    NoFolder,
}

impl ExportScope {
    /// The directory `dir` designates under this scope: `dir` itself for
    /// [`ExportScope::Anywhere`], else `dir` resolved against the folder and checked to
    /// stay inside it, both as written (`..` components) and on disk (symbolic links
    /// are followed as far as the path exists).
    ///
    /// # Errors
    /// The directory is outside the folder, the folder is not accessible, or the scope
    /// is [`ExportScope::Nowhere`].
    pub fn resolve(&self, dir: &Path) -> Result<PathBuf, ExportDenied> {
        let root = match self {
            ExportScope::Anywhere => return Ok(dir.to_owned()),
            ExportScope::Nowhere => return Err(ExportDenied::NoFolder),
            ExportScope::Within(root) => root,
        };
        let unavailable = |e: io::Error| ExportDenied::RootUnavailable {
            root: root.clone(),
            reason: e.to_string(),
        };
        let outside = || ExportDenied::Outside {
            dir: dir.to_owned(),
            root: root.clone(),
        };
        // An empty folder is the current directory (a scene file given without folder).
        let base = if root.as_os_str().is_empty() {
            Path::new(".")
        } else {
            root
        };
        let base = normalize_path(&std::path::absolute(base).map_err(unavailable)?);
        // `join` keeps an absolute `dir` as it is, so both cases go through one check.
        let target = normalize_path(&base.join(dir));
        if !target.starts_with(&base) {
            return Err(outside());
        }
        // The path as written stays inside; a symbolic link on the way could still lead
        // out, so compare real paths as far as the target exists.
        let real_base = std::fs::canonicalize(&base).map_err(unavailable)?;
        // `symlink_metadata`, so a dangling link counts as existing and is refused below
        // (it cannot be resolved) instead of being skipped over.
        let existing = target
            .ancestors()
            .find(|p| p.symlink_metadata().is_ok())
            .unwrap_or(&base);
        let real = std::fs::canonicalize(existing).map_err(|_| outside())?;
        if !real.starts_with(&real_base) {
            return Err(outside());
        }
        Ok(target)
    }
}

/// Every graph stream of the scene, in creation order.
#[derive(Debug, Clone)]
pub struct Graphs {
    streams: Vec<GraphStream>,
    curves: Vec<GraphCurve>,
    next_id: i64,
    /// Where the API may export to; see [`ExportScope`].
    export_scope: ExportScope,
}

impl Default for Graphs {
    fn default() -> Self {
        Self {
            streams: Vec::new(),
            curves: Vec::new(),
            next_id: FIRST_STREAM_ID,
            export_scope: ExportScope::default(),
        }
    }
}

impl Graphs {
    /// Where `sim.exportGraphStreams` may write.
    pub fn export_scope(&self) -> &ExportScope {
        &self.export_scope
    }

    /// Confines (or frees) `sim.exportGraphStreams`; see [`ExportScope`].
    pub fn set_export_scope(&mut self, scope: ExportScope) {
        self.export_scope = scope;
    }

    /// Adds a stream to `graph`, or updates the unit, options, colour and cyclic range
    /// of the stream of that name (keeping its samples), and returns its id. The caller
    /// checks that `graph` is a graph object.
    ///
    /// # Errors
    /// An empty name, a non-finite colour or cyclic range, or [`MAX_STREAMS`] streams.
    pub fn add_stream(&mut self, graph: Handle, params: StreamParams) -> Result<i64, SimError> {
        if params.name.is_empty() {
            return Err(SimError::BadArgument("stream name must not be empty".into()));
        }
        if !params.color.iter().all(|c| c.is_finite()) || !params.cyclic_range.is_finite() {
            return Err(SimError::BadArgument(
                "stream colour and cyclic range must be finite".into(),
            ));
        }
        let params = StreamParams {
            color: params.color.map(|c| c.clamp(0.0, 1.0)),
            ..params
        };
        if let Some(s) = self
            .streams
            .iter_mut()
            .find(|s| s.graph == graph && s.params.name == params.name)
        {
            s.params = params;
            return Ok(s.id);
        }
        if self.streams.len() >= MAX_STREAMS {
            return Err(SimError::BadArgument(format!("too many graph streams ({MAX_STREAMS})")));
        }
        let id = self.next_id;
        self.next_id += 1;
        self.streams.push(GraphStream {
            id,
            graph,
            params,
            samples: VecDeque::new(),
        });
        Ok(id)
    }

    /// The stream `id` of `graph`.
    ///
    /// # Errors
    /// No such stream on that graph.
    pub fn stream(&self, graph: Handle, id: i64) -> Result<&GraphStream, SimError> {
        self.streams
            .iter()
            .find(|s| s.id == id && s.graph == graph)
            .ok_or_else(|| no_such(graph, id))
    }

    /// Records `value` at `time` (s). A sample at exactly the same time as the last one
    /// replaces it (one value per step); past [`MAX_STREAM_SAMPLES`] the oldest is dropped.
    ///
    /// # Errors
    /// No such stream on that graph, or a non-finite time or value.
    pub fn record(&mut self, graph: Handle, id: i64, time: f64, value: f64) -> Result<(), SimError> {
        if !value.is_finite() || !time.is_finite() {
            return Err(SimError::BadArgument(format!(
                "stream value must be a finite number, got {value}"
            )));
        }
        let s = self
            .streams
            .iter_mut()
            .find(|s| s.id == id && s.graph == graph)
            .ok_or_else(|| no_such(graph, id))?;
        match s.samples.back_mut() {
            Some(last) if last.0 == time => last.1 = value,
            _ => {
                if s.samples.len() >= MAX_STREAM_SAMPLES {
                    s.samples.pop_front();
                }
                s.samples.push_back((time, value));
            }
        }
        Ok(())
    }

    /// Adds a curve to `graph` over streams of that graph, or updates the curve of that
    /// name, and returns its id (ids are shared with streams, so never equal to one).
    /// The caller checks that `graph` is a graph object.
    ///
    /// # Errors
    /// An empty name, other than 2 or 3 streams, a stream not on `graph`, not one
    /// finite default per stream, a non-finite colour, or [`MAX_STREAMS`] curves.
    pub fn add_curve(&mut self, graph: Handle, params: CurveParams) -> Result<i64, SimError> {
        if params.name.is_empty() {
            return Err(SimError::BadArgument("curve name must not be empty".into()));
        }
        if !(2..=3).contains(&params.streams.len()) {
            return Err(SimError::BadArgument(format!(
                "a curve combines 2 (x, y) or 3 (x, y, z) streams, got {}",
                params.streams.len()
            )));
        }
        for &id in &params.streams {
            self.stream(graph, id)?;
        }
        if params.defaults.len() != params.streams.len() || !params.defaults.iter().all(|d| d.is_finite()) {
            return Err(SimError::BadArgument(format!(
                "a curve needs one finite default value per stream ({}), got {}",
                params.streams.len(),
                params.defaults.len()
            )));
        }
        if !params.color.iter().all(|c| c.is_finite()) {
            return Err(SimError::BadArgument("curve colour must be finite".into()));
        }
        let params = CurveParams {
            color: params.color.map(|c| c.clamp(0.0, 1.0)),
            ..params
        };
        if let Some(c) = self
            .curves
            .iter_mut()
            .find(|c| c.graph == graph && c.params.name == params.name)
        {
            c.params = params;
            return Ok(c.id);
        }
        if self.curves.len() >= MAX_STREAMS {
            return Err(SimError::BadArgument(format!("too many graph curves ({MAX_STREAMS})")));
        }
        let id = self.next_id;
        self.next_id += 1;
        self.curves.push(GraphCurve { id, graph, params });
        Ok(id)
    }

    /// Every curve, in creation order.
    pub fn curves(&self) -> impl Iterator<Item = &GraphCurve> {
        self.curves.iter()
    }

    /// The points of a curve, one per time at which any of its streams has a sample,
    /// ascending: `(time, [x, y] or [x, y, z])`, a stream without a sample then giving
    /// its default.
    pub fn curve_points(&self, curve: &GraphCurve) -> Vec<(f64, Vec<f64>)> {
        let dim = curve.params.streams.len();
        let mut rows: BTreeMap<i64, (f64, Vec<f64>)> = BTreeMap::new();
        for (k, &id) in curve.params.streams.iter().enumerate() {
            let Ok(s) = self.stream(curve.graph, id) else {
                continue;
            };
            for (t, v) in s.samples() {
                rows.entry(time_key(t))
                    .or_insert_with(|| (t, curve.params.defaults.clone()))
                    .1[k] = v;
            }
        }
        rows.into_values().filter(|(_, p)| p.len() == dim).collect()
    }

    /// The CSV table of a curve: `time`, then one column per stream (its label), one
    /// row per point of [`Graphs::curve_points`].
    pub fn curve_csv(&self, curve: &GraphCurve) -> String {
        let mut out = String::from("time");
        for &id in &curve.params.streams {
            out.push(',');
            let label = self
                .stream(curve.graph, id)
                .map_or_else(|_| id.to_string(), GraphStream::label);
            out.push_str(&csv_field(&label));
        }
        out.push('\n');
        for (t, point) in self.curve_points(curve) {
            out.push_str(&number(t));
            for v in point {
                out.push(',');
                out.push_str(&number(v));
            }
            out.push('\n');
        }
        out
    }

    /// Every stream, in creation order.
    pub fn streams(&self) -> impl Iterator<Item = &GraphStream> {
        self.streams.iter()
    }

    /// Graph objects that have at least one stream, ascending.
    pub fn graphs(&self) -> Vec<Handle> {
        let mut g: Vec<Handle> = self.streams.iter().map(|s| s.graph).collect();
        g.sort_unstable();
        g.dedup();
        g
    }

    /// Drops every stream (simulation end for script-created streams).
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// Drops every sample but keeps the streams (a new simulation run).
    pub fn clear_samples(&mut self) {
        for s in &mut self.streams {
            s.samples.clear();
        }
    }

    /// Drops the samples of one graph's streams (`sim.resetGraph`).
    pub fn clear_graph_samples(&mut self, graph: Handle) {
        for s in self.streams.iter_mut().filter(|s| s.graph == graph) {
            s.samples.clear();
        }
    }

    /// The CSV table of one graph: a `time` column, then one `name [unit]` column per
    /// stream in creation order; one row per distinct sample time, ascending, with an
    /// empty cell where a stream has no value at that time. Times are in seconds.
    pub fn to_csv(&self, graph: Handle) -> String {
        let streams: Vec<&GraphStream> = self.streams.iter().filter(|s| s.graph == graph).collect();
        // Rows keyed by time in total order; streams record step-end times computed the
        // same way, so equal steps give bit-equal keys.
        let mut rows: BTreeMap<i64, (f64, Vec<Option<f64>>)> = BTreeMap::new();
        for (col, s) in streams.iter().enumerate() {
            for (t, v) in s.samples() {
                rows.entry(time_key(t))
                    .or_insert_with(|| (t, vec![None; streams.len()]))
                    .1[col] = Some(v);
            }
        }
        let mut out = String::from("time");
        for s in &streams {
            out.push(',');
            out.push_str(&csv_field(&s.label()));
        }
        out.push('\n');
        for (t, values) in rows.values() {
            out.push_str(&number(*t));
            for v in values {
                out.push(',');
                if let Some(v) = v {
                    out.push_str(&number(*v));
                }
            }
            out.push('\n');
        }
        out
    }

    /// Writes one CSV file per graph that has streams (see [`Graphs::to_csv`]) into
    /// `dir`, creating it if needed, and returns the paths in graph-handle order. Each
    /// file is named `names(graph)` (characters other than letters, digits, `-`, `_`
    /// and `.` become `_`; a clash gets `_<handle>` appended) plus `.csv`, and is
    /// written atomically: to a temporary file in `dir`, then renamed. Each curve of the
    /// graph follows its graph's file as `<graph>.<curve>.csv` ([`Graphs::curve_csv`]).
    ///
    /// # Errors
    /// Creating the directory or writing a file; files already written stay.
    pub fn export_csv(&self, dir: &Path, names: impl Fn(Handle) -> String) -> io::Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir)?;
        let mut used = Vec::new();
        let mut paths = Vec::new();
        for graph in self.graphs() {
            let mut stem = sanitize(&names(graph));
            if used.contains(&stem) {
                stem = format!("{stem}_{graph}");
            }
            let path = dir.join(format!("{stem}.csv"));
            write_atomically(dir, &path, self.to_csv(graph).as_bytes())?;
            paths.push(path);
            for curve in self.curves.iter().filter(|c| c.graph == graph) {
                let path = dir.join(format!("{stem}.{}.csv", sanitize(&curve.params.name)));
                write_atomically(dir, &path, self.curve_csv(curve).as_bytes())?;
                paths.push(path);
            }
            used.push(stem);
        }
        Ok(paths)
    }
}

fn no_such(graph: Handle, id: i64) -> SimError {
    SimError::BadArgument(format!("graph {graph} has no stream with id {id}"))
}

/// A key with the order of `f64::total_cmp`, for grouping rows by time.
fn time_key(t: f64) -> i64 {
    let bits = t.to_bits() as i64;
    bits ^ ((((bits >> 63) as u64) >> 1) as i64)
}

/// A number that reads back exactly: shortest round-trip digits, with an exponent for
/// very large or small magnitudes so a cell never runs to hundreds of digits.
fn number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-6..1e16).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Quotes a CSV field when it holds a comma, quote or line break (RFC 4180).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        let mut q = String::from("\"");
        for c in s.chars() {
            if c == '"' {
                q.push('"');
            }
            q.push(c);
        }
        q.push('"');
        q
    } else {
        s.to_owned()
    }
}

/// A safe file stem: no path separators, no leading dot, never empty.
fn sanitize(name: &str) -> String {
    let mut s = String::with_capacity(name.len());
    for c in name.chars() {
        let ok = c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
        s.push(if ok { c } else { '_' });
    }
    let s = s.trim_start_matches('.').to_owned();
    if s.is_empty() { "graph".to_owned() } else { s }
}

fn write_atomically(dir: &Path, path: &Path, bytes: &[u8]) -> io::Result<()> {
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{file_name}.tmp"));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        // Best effort: do not leave a half-written temporary behind.
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(name: &str, unit: &str) -> StreamParams {
        StreamParams {
            name: name.into(),
            unit: unit.into(),
            options: 0,
            color: [1.0, 0.0, 0.0],
            cyclic_range: 0.0,
        }
    }

    #[test]
    fn same_name_updates_and_same_time_replaces() {
        let mut g = Graphs::default();
        let a = g.add_stream(7, params("a", "m")).expect("add");
        assert_eq!(g.add_stream(7, params("a", "mm")).expect("update"), a);
        assert_ne!(g.add_stream(8, params("a", "m")).expect("other graph"), a);
        g.record(7, a, 0.05, 1.0).expect("record");
        g.record(7, a, 0.05, 2.0).expect("record");
        g.record(7, a, 0.10, 3.0).expect("record");
        let s = g.stream(7, a).expect("stream");
        assert_eq!(s.samples().collect::<Vec<_>>(), [(0.05, 2.0), (0.10, 3.0)]);
        assert_eq!(s.label(), "a [mm]");
        assert!(g.record(8, a, 0.2, 1.0).is_err(), "stream of another graph");
        assert!(g.record(7, a, 0.2, f64::NAN).is_err());
    }

    #[test]
    fn csv_aligns_rows_and_quotes_headers() {
        let mut g = Graphs::default();
        let a = g.add_stream(1, params("x, y", "")).expect("add");
        let b = g.add_stream(1, params("b", "s")).expect("add");
        g.record(1, a, 0.1, 1.5).expect("record");
        g.record(1, b, 0.2, -2.0).expect("record");
        g.record(1, a, 0.2, 1e-300).expect("record");
        assert_eq!(g.to_csv(1), "time,\"x, y\",b [s]\n0.1,1.5,\n0.2,1e-300,-2\n");
    }

    #[test]
    fn time_key_orders_like_total_cmp() {
        let ts = [-1.0, -0.0, 0.0, 1e-9, 0.05, 1.0, 1e20];
        for w in ts.windows(2) {
            assert!(time_key(w[0]) < time_key(w[1]), "{} < {}", w[0], w[1]);
        }
    }

    /// A fresh folder under the system temp dir for one test.
    fn temp_root(tag: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("gantry-graph-scope-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("scene")).expect("temp dir");
        dir
    }

    #[test]
    fn export_scope_keeps_paths_inside_the_scene_folder() {
        let top = temp_root("inside");
        let root = top.join("scene");
        let scope = ExportScope::Within(root.clone());
        assert_eq!(scope.resolve(Path::new("out")), Ok(root.join("out")));
        assert_eq!(scope.resolve(Path::new("./a/../b/c")), Ok(root.join("b/c")));
        assert_eq!(scope.resolve(Path::new(".")), Ok(root.clone()));
        assert_eq!(
            scope.resolve(&root.join("abs")),
            Ok(root.join("abs")),
            "absolute inside"
        );
        for bad in ["..", "../x", "a/../../x", "/tmp", "/"] {
            let e = scope.resolve(Path::new(bad)).expect_err(bad);
            assert!(matches!(e, ExportDenied::Outside { .. }), "{bad}: {e}");
            assert!(e.to_string().contains("outside the scene's folder"), "{e}");
        }
        // The scene folder's own name after `..` is inside again: only the result counts.
        assert_eq!(scope.resolve(Path::new("../scene/x")), Ok(root.join("x")));
        assert_eq!(
            ExportScope::Nowhere.resolve(Path::new("x")),
            Err(ExportDenied::NoFolder)
        );
        assert_eq!(
            ExportScope::Anywhere.resolve(Path::new("/tmp/x")),
            Ok(PathBuf::from("/tmp/x"))
        );
        let _ = std::fs::remove_dir_all(&top);
    }

    #[cfg(unix)]
    #[test]
    fn export_scope_refuses_a_symlink_out_of_the_scene_folder() {
        let top = temp_root("symlink");
        let root = top.join("scene");
        std::fs::create_dir_all(top.join("elsewhere")).expect("dir");
        std::os::unix::fs::symlink(top.join("elsewhere"), root.join("link")).expect("symlink");
        let scope = ExportScope::Within(root.clone());
        let e = scope.resolve(Path::new("link/sub")).expect_err("through the link");
        assert!(matches!(e, ExportDenied::Outside { .. }), "{e}");
        let _ = std::fs::remove_dir_all(&top);
    }

    #[test]
    fn sanitize_makes_safe_stems() {
        assert_eq!(sanitize("../etc/passwd"), "_etc_passwd");
        assert_eq!(sanitize(""), "graph");
        assert_eq!(sanitize("bubbleRob graph"), "bubbleRob_graph");
    }
}

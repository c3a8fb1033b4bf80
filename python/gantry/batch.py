"""Many simulations at once, on Ray: parameter sweeps, seed studies, regression batches.

::

    import gantry.batch

    def trial(client, sim, slider):
        # BubbleRob's speed slider: 0..10 is 50..300 deg/s at the wheels.
        rover = sim.getObject("/bubbleRob")
        script = sim.getScript(sim.scripttype_childscript, rover)
        sim.callScriptFunction("speedChange_callback", script, 0, 1, slider)
        client.advance(1200)                       # 60 s of simulated time
        x, y, _ = sim.getObjectPosition(rover, sim.handle_world)
        return {"x": x, "y": y}

    result = gantry.batch.run(trial, gantry.batch.grid(slider=range(11)), scene="bubble_rob")
    result.to_csv("sweep.csv")
    for row in result.failures:
        print(row["run"], row["error"])

Design
------
*Ray tasks, no scheduler of our own.* Every run is one Ray task that makes a fresh
``gantry.Client``, calls ``fn(client, sim, **params)`` and closes the client. Ray
places the tasks on the CPUs it knows of (``num_cpus_per_run`` each) and
``run`` collects them with ``ray.wait`` as they finish. A simulation is
single-threaded and a client costs milliseconds to make, so long-lived actors
holding clients would save nothing and would let one run's state leak into the
next.

*Determinism.* A gantry simulation gives identical results for the same scene and
inputs, in whichever process (or Ray worker) it runs. The clients are made with
``realtime=False`` unless ``client_options`` says otherwise, so that wall-clock
pacing cannot change what a run computes. ``run_local`` runs the same batch one run
after another in this process, without Ray; its rows equal ``run``'s, except for
the wall times. Use it to debug ``fn`` (breakpoints work) and to check that a
batch is reproducible.

*Failure isolation.* An exception in ``fn``, in making the client (a scene that does
not load) or in closing it is caught in the task and reported in the run's row
(``ok`` false, ``error`` holding the traceback); the other runs go on. A worker
that dies (a crash, the out-of-memory killer) is retried by Ray as usual (its
``max_retries``) and, if it keeps failing, reported in its row the same way.

*Cluster use.* Nothing changes but the address: ``ray.init(address="ray://head:10001")``
before calling ``run``, or ``run(..., ray_address="ray://head:10001")``, or the
``RAY_ADDRESS`` environment variable (``ray.init()`` reads it). Every node needs the
same gantry build installed. Scene files must exist at the same path on every
node, or travel with the job through Ray's runtime environment
(``ray.init(address=..., runtime_env={"working_dir": "."})``, relative scene
paths then being relative to that directory); the bundled scenes
(``gantry.bundled_scenes()``) are always there. ``fn`` is sent to the workers with
cloudpickle: a function defined in the main script travels by value, one imported
from a module needs that module importable on the workers (``py_modules`` in the
runtime environment).

gantry does not depend on Ray: ``import gantry.batch`` works without it, and only
``run`` needs it (``pip install ray``).
"""

from __future__ import annotations

import csv
import itertools
import json
import os
import re
import sys
import time
import traceback
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from typing import Any, Optional, Union

# The package itself, not `from . import Client`: gantry/__init__ may import this
# module before it has defined Client.
import gantry

__all__ = ["BatchResult", "RunFn", "RunSpec", "grid", "run", "run_local"]

#: One run as given to ``run``: a dict of parameters for ``fn`` (a ``"scene"`` key
#: selects the run's scene), a scene path or name, or an integer seed (``{"seed": n}``).
RunSpec = Union[Mapping[str, Any], str, os.PathLike, int]

#: The function a run calls: ``fn(client, sim, **params) -> dict``.
RunFn = Callable[..., Mapping[str, Any]]

# Columns every row has, whatever fn returns; a result field of the same name would
# overwrite them, so fn may not use these names.
_RUN, _OK, _ERROR, _WALL = "run", "ok", "error", "wall_s"
_RESERVED = frozenset((_RUN, _OK, _ERROR, _WALL))

_ANSI_COLOUR = re.compile(r"\x1b\[[0-9;]*m")

# Without client_options, batch runs are not paced by the wall clock (see Determinism).
_DEFAULT_CLIENT_OPTIONS: dict[str, Any] = {"realtime": False}


def grid(**axes: Iterable[Any]) -> list[dict[str, Any]]:
    """The runs of a full parameter grid, one dict per combination, the last axis
    varying fastest: ``grid(speed=[1, 2], seed=range(3))`` gives six runs.

    A ``scene`` axis sweeps scenes; a ``seed`` axis repeats each combination for
    several seeds (meaningful when ``fn`` uses the seed, since the simulation itself
    is deterministic).
    """
    names = list(axes)
    values = [list(v) for v in axes.values()]
    return [dict(zip(names, combo)) for combo in itertools.product(*values)]


class BatchResult:
    """The table of a batch: one row (a dict) per run, in the order the runs were
    given, whatever order they finished in.

    A row holds ``run`` (the run's index), the run's parameters, the fields ``fn``
    returned (absent from a failed row), ``ok``, ``error`` (the text and traceback of
    the failure, else ``None``) and ``wall_s`` (wall seconds of the run in its worker:
    client creation, ``fn`` and ``close``; not time spent waiting in Ray's queue).
    """

    def __init__(self, rows: list[dict[str, Any]], columns: list[str], wall_s: float):
        self.rows = rows
        #: Every key of every row: ``run``, the parameters, the result fields (each
        #: group in first-seen order), ``ok``, ``error``, ``wall_s``.
        self.columns = columns
        #: Wall seconds of the whole batch, as the caller waited for it.
        self.wall_s = wall_s

    @property
    def failures(self) -> list[dict[str, Any]]:
        """The rows of the runs that failed."""
        return [row for row in self.rows if not row[_OK]]

    @property
    def ok(self) -> bool:
        """Whether every run succeeded."""
        return all(row[_OK] for row in self.rows)

    def to_csv(self, path: Union[str, os.PathLike]) -> None:
        """Writes the table with a header of ``columns``. Missing values are empty;
        lists, tuples and dicts are written as JSON so that they read back with
        ``json.loads``; floats keep every digit (``repr``)."""
        columns = self.columns
        with open(path, "w", newline="", encoding="utf-8") as f:
            writer = csv.DictWriter(f, fieldnames=columns)
            writer.writeheader()
            for row in self.rows:
                writer.writerow({k: _csv_value(row.get(k)) for k in columns})

    def to_pandas(self) -> Any:
        """The table as a ``pandas.DataFrame`` (pandas must be installed)."""
        try:
            import pandas
        except ImportError as e:
            raise ImportError("BatchResult.to_pandas needs pandas: pip install pandas") from e
        return pandas.DataFrame(self.rows, columns=self.columns)

    def __len__(self) -> int:
        return len(self.rows)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        return iter(self.rows)

    def __getitem__(self, index: int) -> dict[str, Any]:
        return self.rows[index]

    def __repr__(self) -> str:
        return f"<BatchResult {len(self.rows)} runs, {len(self.failures)} failed, {self.wall_s:.1f} s>"


def run(
    fn: RunFn,
    runs: Iterable[RunSpec],
    *,
    scene: Optional[Union[str, os.PathLike]] = None,
    client_options: Optional[Mapping[str, Any]] = None,
    ray_address: Optional[str] = None,
    num_cpus_per_run: float = 1,
    ray_options: Optional[Mapping[str, Any]] = None,
    progress: bool = True,
    timeout: Optional[float] = None,
) -> BatchResult:
    """Runs ``fn(client, sim, **params)`` once per entry of ``runs``, each in its own
    Ray task with a fresh ``gantry.Client``, and returns the table of results.

    ``runs``: parameter dicts, scene paths/names, or integer seeds (see ``RunSpec``,
    and ``grid``). A run's scene is its ``"scene"`` parameter, else ``scene``; the
    ``"scene"`` parameter is not passed on to ``fn`` (the client is made from it).
    A relative scene path is opened from the worker's working directory: the
    caller's on a local Ray, the runtime environment's ``working_dir`` if it has one.

    ``client_options``: keyword arguments of ``gantry.Client`` (default
    ``{"realtime": False}``; pass ``realtime`` explicitly to change it).

    ``fn`` returns a dict of what to keep (picklable values; plain numbers, strings
    and lists of them are best for ``to_csv``); its keys become columns and must not
    be a parameter name or ``run``, ``ok``, ``error``, ``wall_s``.

    If Ray is not initialised, calls ``ray.init(address=ray_address)``: ``None``
    starts a local Ray on this machine, or joins the cluster named by ``RAY_ADDRESS``;
    on a cluster only the address changes. Ray stays initialised for later batches.
    An already-initialised Ray is used as it is (``ray_address`` is then ignored).

    ``num_cpus_per_run``: the CPUs Ray reserves for each run (a simulation uses one).
    ``ray_options``: more options for the tasks (``memory``, ``resources``,
    ``scheduling_strategy``, ``runtime_env``, ``max_retries``...), as
    ``ray.remote(...).options(...)`` takes them.

    ``progress``: a progress bar as runs finish (tqdm if installed, else a line on
    stderr). ``timeout``: seconds for the whole batch; runs not finished by then are
    cancelled and reported as failed.
    """
    ray = _import_ray()
    if not ray.is_initialized():
        ray.init(address=ray_address)
    specs = _specs(runs, scene, client_options)
    options: dict[str, Any] = {"num_cpus": num_cpus_per_run, **(ray_options or {})}
    task = ray.remote(_execute).options(**options)

    start = time.perf_counter()
    deadline = None if timeout is None else start + timeout
    # Put fn in the object store once rather than pickling it into every task.
    fn_ref = ray.put(fn)
    refs = [task.remote(fn_ref, params, scene_arg, opts) for params, scene_arg, opts in specs]
    index = {ref: i for i, ref in enumerate(refs)}
    outcomes: list[Optional[dict[str, Any]]] = [None] * len(refs)
    bar = _Progress(len(refs), enabled=progress)
    pending = list(refs)
    try:
        while pending:
            remaining = None if deadline is None else max(0.0, deadline - time.perf_counter())
            done, pending = ray.wait(pending, num_returns=1, timeout=remaining)
            if not done:  # the deadline passed
                break
            for ref in done:
                outcomes[index[ref]] = _collect(ray, ref)
                bar.update(ok=outcomes[index[ref]][_OK])
    finally:
        # On a timeout, or Ctrl-C in the driver: do not leave runs occupying the
        # cluster after run() has returned or raised.
        for ref in pending:
            ray.cancel(ref, force=True)
        bar.close()
    for ref in pending:
        outcomes[index[ref]] = _failed(f"timed out: the batch's timeout of {timeout} s passed first", 0.0)
    return _table(specs, outcomes, time.perf_counter() - start)


def run_local(
    fn: RunFn,
    runs: Iterable[RunSpec],
    *,
    scene: Optional[Union[str, os.PathLike]] = None,
    client_options: Optional[Mapping[str, Any]] = None,
    ray_address: Optional[str] = None,
    num_cpus_per_run: float = 1,
    ray_options: Optional[Mapping[str, Any]] = None,
    progress: bool = True,
    timeout: Optional[float] = None,
) -> BatchResult:
    """``run`` without Ray: the runs one after another in this process and thread,
    with the same rows (but for ``wall_s``). For debugging ``fn`` and for checking a
    batch's determinism.

    ``ray_address``, ``num_cpus_per_run`` and ``ray_options`` are accepted, so that
    a call switches between ``run`` and ``run_local`` by name alone, and ignored.
    ``timeout`` cannot interrupt a run in progress: runs not started when it has
    passed are reported as failed. Results are not pickled here, so a result that
    Ray cannot send back (an open file, a lock) fails only under ``run``.
    """
    del ray_address, num_cpus_per_run, ray_options  # no Ray here
    specs = _specs(runs, scene, client_options)
    start = time.perf_counter()
    deadline = None if timeout is None else start + timeout
    outcomes: list[Optional[dict[str, Any]]] = []
    bar = _Progress(len(specs), enabled=progress)
    try:
        for params, scene_arg, opts in specs:
            if deadline is not None and time.perf_counter() >= deadline:
                outcome = _failed(f"timed out: the batch's timeout of {timeout} s passed first", 0.0)
            else:
                outcome = _execute(fn, params, scene_arg, opts)
            outcomes.append(outcome)
            bar.update(ok=outcome[_OK])
    finally:
        bar.close()
    return _table(specs, outcomes, time.perf_counter() - start)


# --- the run itself (in a Ray worker, or in this process for run_local) --------------


def _execute(
    fn: RunFn,
    params: dict[str, Any],
    scene: Optional[str],
    client_options: dict[str, Any],
) -> dict[str, Any]:
    """One run: a fresh client, ``fn``, close. Returns the result fields with ``ok``,
    ``error`` and ``wall_s``; never raises for a failure of the run itself, so that
    one bad run cannot take the batch down."""
    start = time.perf_counter()
    client = None
    try:
        client = gantry.Client(scene, **client_options)
        sim = client.require("sim")
        fn_params = {k: v for k, v in params.items() if k != "scene"}
        fields = fn(client, sim, **fn_params)
        if not isinstance(fields, Mapping):
            raise TypeError(f"fn must return a dict of what to keep, not {type(fields).__name__}")
        clash = sorted(set(fields) & (_RESERVED | set(params)))
        if clash:
            raise ValueError(f"fn returned keys that are parameters or reserved columns: {clash}")
        fields = dict(fields)
        client.close()
    except Exception:
        error = traceback.format_exc()
        if client is not None:
            try:
                client.close()
            except Exception:
                error += "\nwhile closing the client after that:\n" + traceback.format_exc()
        return _failed(error, time.perf_counter() - start)
    return {**fields, _OK: True, _ERROR: None, _WALL: time.perf_counter() - start}


def _failed(error: str, wall_s: float) -> dict[str, Any]:
    return {_OK: False, _ERROR: error, _WALL: wall_s}


# --- driver side ---------------------------------------------------------------------


def _import_ray() -> Any:
    try:
        import ray
    except ImportError as e:
        raise ImportError(
            "gantry.batch.run needs Ray: pip install ray (or gantry[ray]), "
            "or use gantry.batch.run_local"
        ) from e
    return ray


def _specs(
    runs: Iterable[RunSpec],
    scene: Optional[Union[str, os.PathLike]],
    client_options: Optional[Mapping[str, Any]],
) -> list[tuple[dict[str, Any], Optional[str], dict[str, Any]]]:
    """(params, scene for the client, client options) of every run, checked before
    anything starts, so that a malformed batch fails at once rather than per run."""
    if isinstance(runs, (str, bytes, Mapping)) or not isinstance(runs, Iterable):
        raise TypeError("runs must be a list of parameter dicts, scenes or seeds")
    opts = {**_DEFAULT_CLIENT_OPTIONS, **(client_options or {})}
    specs = []
    for i, spec in enumerate(runs):
        if isinstance(spec, Mapping):
            params = dict(spec)
        elif isinstance(spec, (str, os.PathLike)):
            params = {"scene": os.fspath(spec)}
        elif isinstance(spec, int) and not isinstance(spec, bool):
            params = {"seed": spec}
        else:
            raise TypeError(f"run {i}: {spec!r} is not a parameter dict, a scene or an integer seed")
        bad = sorted(k for k in params if not isinstance(k, str) or k in _RESERVED)
        if bad:
            raise ValueError(
                f"run {i}: parameter names must be strings other than {sorted(_RESERVED)}: {bad}"
            )
        run_scene = params.get("scene", scene)
        specs.append((params, None if run_scene is None else os.fspath(run_scene), opts))
    return specs


def _collect(ray: Any, ref: Any) -> dict[str, Any]:
    """The outcome of a finished task. _execute catches the run's own errors, so an
    error here is Ray's: the worker died, the task was cancelled, or fn's result
    could not be pickled."""
    try:
        return ray.get(ref)
    except Exception as e:
        # Ray colours its error texts for terminals; a table wants plain text.
        text = _ANSI_COLOUR.sub("", f"{type(e).__name__}: {e}")
        return _failed(f"the Ray task failed: {text}", 0.0)


def _table(
    specs: list[tuple[dict[str, Any], Optional[str], dict[str, Any]]],
    outcomes: Sequence[Optional[dict[str, Any]]],
    wall_s: float,
) -> BatchResult:
    rows = []
    # Dicts as ordered sets: parameters first, then results, whatever row has them.
    params_seen: dict[str, None] = {}
    fields_seen: dict[str, None] = {}
    for i, ((params, _, _), outcome) in enumerate(zip(specs, outcomes)):
        assert outcome is not None, "every run has an outcome by now"
        rows.append({_RUN: i, **params, **outcome})
        params_seen.update(dict.fromkeys(params))
        fields_seen.update(dict.fromkeys(k for k in outcome if k not in _RESERVED))
    columns = [_RUN, *params_seen, *fields_seen, _OK, _ERROR, _WALL]
    return BatchResult(rows, columns, wall_s)


def _csv_value(value: Any) -> Any:
    if isinstance(value, (list, tuple, dict)):
        return json.dumps(value)
    if isinstance(value, float):
        return repr(value)
    return value


class _Progress:
    """Runs finished out of the total: tqdm's bar when tqdm is installed, else a
    line on stderr (rewritten in place on a terminal, at most once a second in a
    log)."""

    def __init__(self, total: int, enabled: bool):
        self.total, self.done, self.failed = total, 0, 0
        self.enabled = enabled and total > 0
        self.start = self.last = time.perf_counter()
        self.tty = sys.stderr.isatty()
        self.bar = None
        if self.enabled:
            try:
                from tqdm.auto import tqdm
            except ImportError:
                pass
            else:
                self.bar = tqdm(total=total, desc="gantry.batch", unit="run")

    def update(self, ok: bool) -> None:
        if not self.enabled:
            return
        self.done += 1
        self.failed += not ok
        if self.bar is not None:
            self.bar.update(1)
            if not ok:
                self.bar.set_postfix(failed=self.failed)
            return
        now = time.perf_counter()
        if self.tty or now - self.last >= 1.0 or self.done == self.total:
            self.last = now
            self._line(now)

    def _line(self, now: float) -> None:
        text = (f"gantry.batch: {self.done}/{self.total} runs done, {self.failed} failed, "
                f"{now - self.start:.1f} s")
        if self.tty:
            sys.stderr.write("\r" + text + ("\n" if self.done == self.total else ""))
        else:
            sys.stderr.write(text + "\n")
        sys.stderr.flush()

    def close(self) -> None:
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.close()
        elif self.tty and self.done < self.total:
            sys.stderr.write("\n")  # end the line an interrupted batch left open
            sys.stderr.flush()

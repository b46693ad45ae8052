"""Run bond-graph model files (bg-sim) from Python.

    >>> import bgsim
    >>> model = bgsim.load("models/mass_spring_damper.toml", set={"k": 20.0})
    >>> df = model.run(t_end=2.0)            # a pandas DataFrame: t, then the [outputs]
    >>> summary = bgsim.sweep("models/mass_spring_damper.toml", "sweep.toml")
    >>> sim = model.start()                  # advanced call by call, the solver kept warm
    >>> sim.advance_to(0.5); sim.get("x")
    >>> lin = model.linearize(outputs=["x"])  # A, B, C, D as numpy arrays, with names

A model is named by its file and its overrides (``set``: the ``--set`` values of the
command line; a bare name is a parameter, ``"simulation.rtol"`` any other value), and is
built anew by each run, so a :class:`Model` pickles and runs on Dask workers
(:func:`dask_sweep`). Problems raise :class:`BgSimError` with ``file``, ``line``,
``column``, ``element``, ``hint`` and ``kind`` attributes.
"""

from __future__ import annotations

import json
import os
import threading
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np
import pandas as pd

from . import _bgsim
from ._bgsim import BgSimError

__all__ = [
    "BgSimError",
    "LinearModel",
    "Model",
    "Results",
    "RunError",
    "Simulation",
    "load",
    "sweep",
    "sweep_points",
    "dask_sweep",
]

PathLike = Union[str, "os.PathLike[str]"]
Scalar = Union[float, int, str]


class RunError(BgSimError):
    """A run stopped before its end time; ``partial`` holds the rows computed so far."""

    def __init__(self, message: str, partial: pd.DataFrame, stats: Dict[str, Any]):
        super().__init__(message)
        self.partial = partial
        self.stats = stats


def _overrides(set: Optional[Mapping[str, Scalar]]) -> List[str]:
    out = []
    for key, value in (set or {}).items():
        path = key if "." in key else f"parameters.{key}"
        if isinstance(value, str):
            text = value
        elif isinstance(value, bool):
            text = "true" if value else "false"
        else:
            text = repr(float(value))
        out.append(f"{path}={text}")
    return out


InputData = Union[pd.DataFrame, Mapping[str, Any]]


def _input_data(inputs: Optional[InputData], interp: str) -> List[tuple]:
    """Input data as (name, times, values, interp) tuples.

    ``inputs`` is a DataFrame with a ``t`` column (or a time index named ``t``) and one
    column per input, or a dict mapping an input's name to a pandas Series indexed by time
    or to a ``(times, values)`` pair of array-likes (numpy arrays, lists).
    """
    if inputs is None:
        return []
    out = []
    if isinstance(inputs, pd.DataFrame):
        if "t" in inputs.columns:
            t = inputs["t"].to_numpy(dtype=np.float64)
            cols = [c for c in inputs.columns if c != "t"]
        elif inputs.index.name == "t":
            t = inputs.index.to_numpy(dtype=np.float64)
            cols = list(inputs.columns)
        else:
            raise BgSimError("input data: the DataFrame needs a `t` column (or an index named `t`)")
        for c in cols:
            out.append((str(c), t.tolist(), inputs[c].to_numpy(dtype=np.float64).tolist(), interp))
        return out
    for name, data in dict(inputs).items():
        if isinstance(data, pd.Series):
            t, v = data.index.to_numpy(dtype=np.float64), data.to_numpy(dtype=np.float64)
        else:
            try:
                t, v = data
            except (TypeError, ValueError):
                raise BgSimError(
                    f"input data `{name}`: expected a pandas Series indexed by time or a (times, values) pair"
                ) from None
            t, v = np.asarray(t, dtype=np.float64), np.asarray(v, dtype=np.float64)
        if t.ndim != 1 or v.ndim != 1:
            raise BgSimError(f"input data `{name}`: times and values must be one-dimensional")
        out.append((str(name), t.tolist(), v.tolist(), interp))
    return out


class LinearModel:
    """The model linearised at one point: ``dδx/dt = A δx + B δu``, ``δy = C δx + D δu``.

    ``A, B, C, D`` are numpy arrays; ``states``, ``inputs`` and ``outputs`` name their rows
    and columns; ``t`` and ``x`` are the operating point. All four are exact (the model's
    own Jacobian, carried through the inputs and outputs).
    """

    def __init__(self, d: Mapping[str, Any]):
        self.t: float = d["t"]
        self.x = np.asarray(d["x"], dtype=np.float64)
        self.states: List[str] = list(d["states"])
        self.inputs: List[str] = list(d["inputs"])
        self.outputs: List[str] = list(d["outputs"])
        n, m, p = len(self.states), len(self.inputs), len(self.outputs)
        self.A = np.asarray(d["A"], dtype=np.float64).reshape(n, n)
        self.B = np.asarray(d["B"], dtype=np.float64).reshape(n, m)
        self.C = np.asarray(d["C"], dtype=np.float64).reshape(p, n)
        self.D = np.asarray(d["D"], dtype=np.float64).reshape(p, m)

    def __iter__(self):
        return iter((self.A, self.B, self.C, self.D))

    def __repr__(self) -> str:
        return (
            f"LinearModel(t={self.t}, {len(self.states)} states, inputs={self.inputs}, "
            f"outputs={self.outputs})"
        )

    def poles(self) -> np.ndarray:
        """The eigenvalues of A (1/s)."""
        return np.linalg.eigvals(self.A)

    def response(self, input: str, output: str, f_hz: Any) -> np.ndarray:
        """G(j2πf) = C (j2πf I − A)⁻¹ B + D of one input–output pair, complex."""
        i, o = self.inputs.index(input), self.outputs.index(output)
        f = np.atleast_1d(np.asarray(f_hz, dtype=np.float64))
        n = self.A.shape[0]
        g = np.empty(f.shape, dtype=complex)
        for k, fk in enumerate(f):
            v = np.linalg.solve(2j * np.pi * fk * np.eye(n) - self.A, self.B[:, i])
            g[k] = self.C[o] @ v + self.D[o, i]
        return g

    def dc_gain(self, input: str, output: str) -> float:
        """G(0) = D − C A⁻¹ B of one pair."""
        return float(self.response(input, output, 0.0)[0].real)


class Simulation:
    """A model advanced call by call; see :meth:`Model.start`.

    The solver (Radau IIA) keeps its step size, Jacobian and LU between calls: a call
    costs what the steps inside it cost, plus one short step landing on its end. Setting an
    input to a new value costs one evaluation of the equations; the same value costs
    nothing. Nothing is restarted unless a scheduled ``[[events]]`` entry replaces elements.
    """

    def __init__(self, sim: Any, model: "Model"):
        self._owner = sim
        #: The thread that started it: the compiled simulation stays on that thread.
        self._thread = threading.get_ident()
        self.model = model
        #: The inputs' names.
        self.inputs: List[str] = list(sim.input_names())
        #: The ``[outputs]`` columns.
        self.outputs: List[str] = list(sim.output_names())

    def __repr__(self) -> str:
        return f"bgsim.Simulation({self.model.path!r}, t={self.t})"

    @property
    def _sim(self) -> Any:
        # the compiled simulation cannot cross threads (PyO3 would raise a PanicException)
        if threading.get_ident() != self._thread:
            raise BgSimError(
                "this Simulation was started on another thread and can only be used there\n"
                "  hint: call model.start() on the thread that advances it (one Simulation "
                "per thread)"
            )
        return self._owner

    @property
    def t(self) -> float:
        """The current time (s)."""
        return self._sim.t

    def advance_to(self, t: float) -> "Simulation":
        """Integrate on to time ``t`` (landing on it exactly). Raises :class:`BgSimError` if
        ``t`` lies behind, or the run fails on the way (the simulation then stays failed)."""
        self._sim.advance_to(float(t))
        return self

    def advance(self, dt: float) -> "Simulation":
        """Integrate on by ``dt`` seconds."""
        self._sim.advance(float(dt))
        return self

    def get(self, name: str) -> float:
        """The value of an ``[outputs]`` column or any variable (``mass.p``, ``spring.e``,
        an input's name) now."""
        return self._sim.get(name)

    def get_many(self, names: Sequence[str]) -> Dict[str, float]:
        """Several values now, from one evaluation."""
        return dict(zip(names, self._sim.get_many(list(names))))

    def state(self) -> pd.Series:
        """The state now, named (``mass.p``, ``spring.q``, …)."""
        names, values = self._sim.state()
        return pd.Series(values, index=names, dtype=np.float64, name=self.t)

    def set_inputs(
        self,
        values: Optional[Mapping[str, Any]] = None,
        extrapolate: Optional[str] = None,
        **kw: Any,
    ) -> "Simulation":
        """Set inputs by name: a number holds the input at that value from now on; a pandas
        Series indexed by time or a ``(times, values)`` pair makes it follow that data
        (linear between samples; its sample times become stops). ``sim.set_inputs(F=10.0)``
        or ``sim.set_inputs({"F": 10.0})``.

        As for :meth:`Model.run`, data must start at or before now, and advancing past
        their last sample raises :class:`BgSimError`, unless ``extrapolate="hold"`` (then
        the ends are held). An input driven by the data given to :meth:`Model.start` cannot
        be set to a number (:class:`BgSimError`); new data for it replace the old."""
        if extrapolate not in (None, "hold"):
            raise BgSimError(f"extrapolate={extrapolate!r}: only \"hold\" (or None) is known")
        all_values = {**dict(values or {}), **kw}
        for name, v in all_values.items():
            if isinstance(v, (int, float, np.floating, np.integer)):
                self._sim.set_input(name, float(v))
            else:
                for n, t, vals, interp in _input_data({name: v}, "linear"):
                    self._sim.set_input_series(n, t, vals, interp, extrapolate == "hold")
        return self

    def stats(self) -> Dict[str, Any]:
        """Solver work since the start: steps, rhs_evals, jac_evals, lu_factorisations,
        error_test_failures, newton_failures, events, wall_s (time spent advancing)."""
        return dict(self._sim.stats())

    def linearize(self, inputs: Sequence[str] = (), outputs: Sequence[str] = ()) -> LinearModel:
        """The linear model at the current time and state (see :meth:`Model.linearize`)."""
        return LinearModel(self._sim.linearize(list(inputs), list(outputs)))


class Model:
    """A model file with its overrides; see :func:`load`."""

    def __init__(self, path: PathLike, set: Optional[Mapping[str, Scalar]] = None):
        self.path = os.fspath(path)
        self.set: Dict[str, Scalar] = dict(set or {})
        info = _bgsim.describe(self.path, _overrides(self.set))
        #: Title from the file.
        self.title: Optional[str] = info["title"]
        #: Named parameters and their values (after the overrides).
        self.parameters: Dict[str, float] = dict(info["parameters"])
        #: The result columns, ``t`` first.
        self.columns: List[str] = list(info["columns"])
        #: Run settings from the file: t_end, dt_out, rtol, atol.
        self.settings: Dict[str, float] = {k: info[k] for k in ("t_end", "dt_out", "rtol", "atol")}
        #: What loads but was likely meant otherwise.
        self.notes: List[str] = list(info["notes"])

    def __repr__(self) -> str:
        return f"bgsim.Model({self.path!r}, set={self.set!r})"

    def with_set(self, **values: Scalar) -> "Model":
        """The same model with more overrides (a bare name is a parameter)."""
        return Model(self.path, {**self.set, **values})

    def run(
        self,
        t_end: Optional[float] = None,
        rtol: Optional[float] = None,
        atol: Optional[float] = None,
        dt_out: Optional[float] = None,
        solver: Optional[str] = None,
        as_dict: bool = False,
        inputs: Optional[InputData] = None,
        inputs_interp: str = "linear",
        extrapolate: Optional[str] = None,
        energy: bool = False,
    ) -> Union["Results", Dict[str, np.ndarray]]:
        """Run the model and return its rows: a DataFrame (``t`` and the ``[outputs]``, a
        :class:`Results`), or with ``as_dict=True`` a dict of numpy arrays.

        With ``energy=True`` the run is audited (docs/energy.md): ``run(...).energy()`` is
        the table of ``bg-sim energy`` as a DataFrame (``energy(expand=True)``: every
        element), and ``.energy_totals()`` its totals, balance and efficiency.

        Settings not given are the file's. ``inputs`` drives the model's inputs with data:
        a DataFrame with a ``t`` column and one column per input (any subset; the others
        keep their default), or a dict of name → pandas Series (indexed by time) or
        ``(times, values)`` numpy arrays; linear between samples, or held with
        ``inputs_interp="hold"``. The run stops and restarts at the samples' times. The data
        must cover the run's span unless ``extrapolate="hold"``.

        The run's statistics are in ``df.attrs["stats"]`` (steps, rhs_evals, wall_s,
        failed_checks, …). A run that stops early raises :class:`RunError`, which carries
        the rows computed so far.
        """
        if extrapolate not in (None, "hold"):
            raise BgSimError(f"extrapolate={extrapolate!r}: only \"hold\" (or None) is known")
        columns, data, stats, error = _bgsim.run(
            self.path,
            _overrides(self.set),
            t_end,
            rtol,
            atol,
            dt_out,
            solver,
            _input_data(inputs, inputs_interp),
            extrapolate == "hold",
            energy,
        )
        values = np.frombuffer(data, dtype=np.float64).reshape(-1, len(columns))
        if as_dict and error is None:
            return {c: values[:, j].copy() for j, c in enumerate(columns)}
        df = Results(values.copy(), columns=columns)
        stats = dict(stats)
        for key in ("energy", "energy_expanded"):
            if key in stats:
                df.attrs[key] = json.loads(stats.pop(key))
        df.attrs["stats"] = stats
        if error is not None:
            raise RunError(f"{self.path}: {error}", df, stats)
        return df

    def fit(
        self,
        data: Union[pd.DataFrame, Sequence[pd.DataFrame]],
        params: Mapping[str, Sequence[float]],
        outputs: Optional[Sequence[str]] = None,
        weights: Optional[Mapping[str, float]] = None,
        loss: str = "l2",
        method: str = "lm",
        t_end: Optional[float] = None,
        rtol: Optional[float] = None,
        inputs_interp: Optional[str] = None,
        max_iterations: int = 50,
    ) -> Dict[str, Any]:
        """Fit parameters to measured data, as ``bg-sim fit`` (docs/fit.md).

        ``data`` is one DataFrame or a list of them (one per experiment), each with a ``t``
        column, columns named after ``[outputs]`` (fitted) and after ``[inputs]`` (driving
        the run). ``params`` maps a name (``"beta"``, ``"elements.cyl1.beta"``) to
        ``(lo, hi)`` or ``(lo, hi, start)``. Returns the report of ``bg-sim fit --format
        json``: ``{"estimates": {name: {"value", "stderr", "ci95", "at_bound"}},
        "correlation": {"names", "matrix"}, "cost", "iterations", "runs", "converged",
        "warnings", "covariance": {"names", "matrix"}}``. Bad input raises
        :class:`BgSimError` with file, line and column.
        """
        frames = [data] if isinstance(data, pd.DataFrame) else list(data)
        texts = [(f"data[{k}]", df.to_csv(index=False, float_format="%.17g")) for k, df in enumerate(frames)]
        ps = []
        for name, b in params.items():
            b = tuple(float(v) for v in b)
            if len(b) not in (2, 3):
                raise BgSimError(f"params[{name!r}]: give (lo, hi) or (lo, hi, start)")
            ps.append((name, b[0], b[1], b[2] if len(b) == 3 else None))
        report = _bgsim.fit(
            self.path,
            _overrides(self.set),
            texts,
            ps,
            list(outputs) if outputs is not None else None,
            [(k, float(v)) for k, v in (weights or {}).items()],
            loss,
            method,
            t_end,
            rtol,
            inputs_interp,
            max_iterations,
        )
        return json.loads(report)

    def sensitivity(
        self,
        params: Sequence[str],
        t_end: Optional[float] = None,
        rtol: Optional[float] = None,
        dt_out: Optional[float] = None,
        inputs: Optional[InputData] = None,
        inputs_interp: str = "linear",
        extrapolate: Optional[str] = None,
    ) -> pd.DataFrame:
        """Run the model once with the forward sensitivities of its ``[outputs]`` to
        ``params`` (``--set`` keys: ``"beta"``, ``"elements.cyl1.beta"``,
        ``'initial."spring.q"'``; docs/sensitivity.md) and return a DataFrame: ``t``, the
        outputs, then one column ``dy/dp`` per output and parameter. ``df.attrs`` holds the
        parameters' ``values`` and the run's ``steps``. Other arguments as :meth:`run`."""
        if isinstance(params, str):
            params = [params]
        if extrapolate not in (None, "hold"):
            raise BgSimError(f"extrapolate={extrapolate!r}: only \"hold\" (or None) is known")
        columns, data, info = _bgsim.sensitivity(
            self.path,
            _overrides(self.set),
            list(params),
            t_end,
            rtol,
            dt_out,
            _input_data(inputs, inputs_interp),
            extrapolate == "hold",
        )
        values = np.frombuffer(data, dtype=np.float64).reshape(-1, len(columns))
        df = pd.DataFrame(values.copy(), columns=columns)
        df.attrs.update(dict(info))
        return df

    def start(
        self,
        t0: Optional[float] = None,
        inputs: Optional[InputData] = None,
        inputs_interp: str = "linear",
        extrapolate: Optional[str] = None,
    ) -> Simulation:
        """Start the model at ``t0`` (its ``t_start`` if None) to be advanced call by call:
        ``sim.set_inputs(F=10.0)``, ``sim.advance_to(t)`` / ``sim.advance(dt)``,
        ``sim.get("x")``, ``sim.state()``, ``sim.t``. ``inputs`` gives inputs data from the
        start (as for :meth:`run`): they must start at or before ``t0``, and advancing past
        their last sample raises :class:`BgSimError`, unless ``extrapolate="hold"``. Each
        call to ``start`` loads the file anew."""
        if extrapolate not in (None, "hold"):
            raise BgSimError(f"extrapolate={extrapolate!r}: only \"hold\" (or None) is known")
        sim = _bgsim.start(
            self.path,
            _overrides(self.set),
            None if t0 is None else float(t0),
            _input_data(inputs, inputs_interp),
            extrapolate == "hold",
        )
        return Simulation(sim, self)

    def linearize(
        self,
        t: Optional[float] = None,
        inputs: Sequence[str] = (),
        outputs: Sequence[str] = (),
    ) -> LinearModel:
        """The model linearised at its initial state (``t`` None or ``t_start``) or at time
        ``t`` of a run: ``A, B, C, D = model.linearize(t=0.0, inputs=["F"], outputs=["x"])``
        (numpy arrays; the result also has ``states``, ``inputs``, ``outputs``). Inputs are
        names from the model's ``[inputs]``; outputs are ``[outputs]`` columns or any
        variable. Exact, as ``bg-sim linearize``."""
        d = _bgsim.linearize(
            self.path,
            _overrides(self.set),
            None if t is None else float(t),
            list(inputs),
            list(outputs),
        )
        return LinearModel(d)


class Results(pd.DataFrame):
    """A run's rows (``t`` and the ``[outputs]``): a pandas DataFrame, with the run's energy
    audit when it was run with ``energy=True``."""

    @property
    def _constructor(self):
        return Results

    def _audit(self, expand: bool) -> Dict[str, Any]:
        key = "energy_expanded" if expand else "energy"
        if key not in self.attrs:
            raise BgSimError("this run was not audited: run it with energy=True")
        return self.attrs[key]

    def energy(self, expand: bool = False) -> pd.DataFrame:
        """The energy audit as a DataFrame, one row per composite (``expand=True``: per
        element, junctions and transformers included), indexed by name, largest activity
        first: kind, composite, role, supplied, stored, dissipated, net, activity (J) and
        share (of the total activity), as ``bg-sim energy --format json``."""
        rows = self._audit(expand)["rows"]
        cols = ["name", "kind", "composite", "role", "supplied", "stored", "dissipated",
                "net", "activity", "share", "stored_by_function"]
        return pd.DataFrame(rows, columns=cols).set_index("name")

    def energy_totals(self) -> Dict[str, Any]:
        """The audit's totals (supplied, stored, dissipated, residual, relative_residual,
        …), its efficiency (input, useful, losses, efficiency) and its span (t_start, t_end,
        steps), as a dict."""
        a = self._audit(False)
        return {
            **a["totals"],
            "efficiency": dict(a["efficiency"]),
            "t_start": a["t_start"],
            "t_end": a["t_end"],
            "steps": a["steps"],
        }


def load(path: PathLike, set: Optional[Mapping[str, Scalar]] = None) -> Model:
    """Load the model file at ``path`` with overrides ``set`` (``{"k": 20.0,
    "simulation.solver": "bdf"}``). Raises :class:`BgSimError` (file, line, element, hint)
    if it does not load."""
    return Model(path, set)


def sweep(
    model: PathLike,
    spec: PathLike,
    out_dir: PathLike = "out/sweep",
    jobs: int = 0,
) -> pd.DataFrame:
    """Run the sweep ``spec`` (a TOML file, see docs/sweeps.md) over ``model`` on this
    machine's cores, as ``bg-sim sweep``, and return the summary table (one row per run:
    run id, index, the values, the metrics, status, steps, wall_s, error). Runs already in
    ``out_dir/summary.csv`` are skipped. ``df.attrs["sweep"]`` has the counts and wall time.
    """
    path, stats = _bgsim.sweep(os.fspath(model), os.fspath(spec), os.fspath(out_dir), jobs)
    df = pd.read_csv(path, keep_default_na=False, na_values=[""])
    df["error"] = df["error"].fillna("").astype(str)
    df.attrs["sweep"] = dict(stats)
    return df


def sweep_points(spec: PathLike) -> List[Dict[str, Scalar]]:
    """The runs of a sweep spec, each a dict of ``--set`` path → value, in design order."""
    return [dict(p) for p in _bgsim.spec_points(os.fspath(spec))]


def _run_one(model: str, values: Dict[str, Scalar], metrics: Dict[str, str], index: int) -> Dict[str, Any]:
    return dict(_bgsim.run_one(model, values, metrics, index))


def dask_sweep(
    client: Any,
    model: PathLike,
    points: Union[PathLike, Sequence[Mapping[str, Scalar]]],
    metrics: Optional[Mapping[str, str]] = None,
) -> pd.DataFrame:
    """Map the runs of a sweep over a ``dask.distributed`` ``client`` and gather the summary.

    ``points`` is a sweep spec file (its runs and, unless ``metrics`` is given, its metrics)
    or a list of dicts (``{"k": 10.0, "simulation.rtol": 1e-6}``). Each run is one task:
    the worker loads the model file, runs it and reduces the metrics (the same
    ``REDUCTION(EXPR)`` syntax as ``bg-sim sweep``). The model file must be readable by the
    workers at the same path (a shared file system, or ``client.upload_file``). A failed run
    is a row with its status and error. Rows come back in the order of ``points``.
    """
    model = os.path.abspath(os.fspath(model))
    if isinstance(points, (str, os.PathLike)):
        spec = os.fspath(points)
        pts: List[Mapping[str, Scalar]] = sweep_points(spec)
        if metrics is None:
            metrics = dict(_bgsim.spec_metrics(spec))
    else:
        pts = list(points)
    m = dict(metrics or {})
    futures = client.map(
        _run_one,
        [model] * len(pts),
        [dict(p) for p in pts],
        [m] * len(pts),
        list(range(len(pts))),
        pure=False,
    )
    rows = client.gather(futures)
    return pd.DataFrame(rows)


def _run_columns(model: str, values: Dict[str, Scalar], columns: List[str]) -> Dict[str, np.ndarray]:
    d = Model(model, set=values).run(as_dict=True)
    return {c: np.asarray(d[c]) for c in ["t", *columns]}


def dask_band(
    client: Any,
    model: PathLike,
    spec: PathLike,
    columns: Sequence[str],
) -> pd.DataFrame:
    """The band of ``columns`` over time across the runs of a sweep spec (its sampled
    points: distributions, ``[from_fit]``), the runs mapped over a ``dask.distributed``
    ``client``: per output row the mean and the 5 % and 95 % quantiles, as ``bg-sim sweep``
    writes them to ``band.csv`` (``t``, ``COL_mean``, ``COL_q05``, ``COL_q95``,
    ``COL_width``). A run that fails raises. The model file must be readable by the workers
    at the same path."""
    model = os.path.abspath(os.fspath(model))
    pts = sweep_points(spec)
    cols = list(columns)
    futures = client.map(_run_columns, [model] * len(pts), [dict(p) for p in pts], [cols] * len(pts), pure=False)
    runs = client.gather(futures)
    n = min(len(r["t"]) for r in runs)
    out = {"t": runs[0]["t"][:n]}
    for c in cols:
        a = np.vstack([r[c][:n] for r in runs])
        lo, hi = np.quantile(a, 0.05, axis=0), np.quantile(a, 0.95, axis=0)
        out[f"{c}_mean"] = a.mean(axis=0)
        out[f"{c}_q05"] = lo
        out[f"{c}_q95"] = hi
        out[f"{c}_width"] = hi - lo
    return pd.DataFrame(out)

"""Run bond-graph model files (bg-sim) from Python.

    >>> import bgsim
    >>> model = bgsim.load("models/mass_spring_damper.toml", set={"k": 20.0})
    >>> df = model.run(t_end=2.0)            # a pandas DataFrame: t, then the [outputs]
    >>> summary = bgsim.sweep("models/mass_spring_damper.toml", "sweep.toml")

A model is named by its file and its overrides (``set``: the ``--set`` values of the
command line; a bare name is a parameter, ``"simulation.rtol"`` any other value), and is
built anew by each run, so a :class:`Model` pickles and runs on Dask workers
(:func:`dask_sweep`). Problems raise :class:`BgSimError` with ``file``, ``line``,
``column``, ``element``, ``hint`` and ``kind`` attributes.
"""

from __future__ import annotations

import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np
import pandas as pd

from . import _bgsim
from ._bgsim import BgSimError

__all__ = ["BgSimError", "Model", "RunError", "load", "sweep", "sweep_points", "dask_sweep"]

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
    ) -> Union[pd.DataFrame, Dict[str, np.ndarray]]:
        """Run the model and return its rows: a DataFrame (``t`` and the ``[outputs]``), or
        with ``as_dict=True`` a dict of numpy arrays.

        Settings not given are the file's. The run's statistics are in ``df.attrs["stats"]``
        (steps, rhs_evals, wall_s, failed_checks, …). A run that stops early raises
        :class:`RunError`, which carries the rows computed so far.
        """
        columns, data, stats, error = _bgsim.run(
            self.path, _overrides(self.set), t_end, rtol, atol, dt_out, solver
        )
        values = np.frombuffer(data, dtype=np.float64).reshape(-1, len(columns))
        if as_dict and error is None:
            return {c: values[:, j].copy() for j, c in enumerate(columns)}
        df = pd.DataFrame(values.copy(), columns=columns)
        df.attrs["stats"] = stats
        if error is not None:
            raise RunError(f"{self.path}: {error}", df, stats)
        return df


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

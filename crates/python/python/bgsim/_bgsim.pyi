"""Type stubs of the compiled half of bgsim (crates/python/src/lib.rs)."""

import os
from typing import Any, Dict, List, Optional, Tuple, Union

class BgSimError(Exception):
    """A problem with a model file, a sweep spec or a run. Model errors carry ``file``,
    ``line``, ``column``, ``element``, ``hint`` and ``kind``."""

    file: str
    line: Optional[int]
    column: Optional[int]
    element: Optional[str]
    hint: Optional[str]
    kind: str

def describe(path: str, set: List[str]) -> Dict[str, Any]: ...
def run(
    path: str,
    set: List[str],
    t_end: Optional[float] = None,
    rtol: Optional[float] = None,
    atol: Optional[float] = None,
    dt_out: Optional[float] = None,
    solver: Optional[str] = None,
    inputs: List[Any] = ...,
    extrapolate: bool = False,
    energy: bool = False,
) -> Tuple[List[str], bytes, Dict[str, Any], Optional[str]]: ...
def sensitivity(
    path: str,
    set: List[str],
    params: List[str],
    t_end: Optional[float] = None,
    rtol: Optional[float] = None,
    dt_out: Optional[float] = None,
    inputs: List[Any] = ...,
    extrapolate: bool = False,
) -> Tuple[List[str], bytes, Dict[str, Any]]: ...
def run_one(
    path: str,
    values: Dict[str, Union[float, str]],
    metrics: Dict[str, str],
    index: int = 0,
) -> Dict[str, Any]: ...
def spec_points(spec: str) -> List[Dict[str, Union[float, str]]]: ...
def spec_metrics(spec: str) -> List[Tuple[str, str]]: ...
def sweep(
    model: str, spec: str, out_dir: str, jobs: int = 0
) -> Tuple["os.PathLike[str]", Dict[str, Any]]: ...
def fit(
    path: str,
    set: List[str],
    data: List[Tuple[str, str]],
    params: List[Tuple[str, float, float, Optional[float]]],
    outputs: Optional[List[str]] = None,
    weights: List[Tuple[str, float]] = ...,
    loss: str = "l2",
    method: str = "lm",
    t_end: Optional[float] = None,
    rtol: Optional[float] = None,
    inputs_interp: Optional[str] = None,
    max_iterations: int = 50,
) -> str: ...

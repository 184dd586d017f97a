"""Type stubs of misalign (SI units: m, Pa, N, rad, s, m/s; see the module's docs)."""

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Iterator, Literal, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt
import pandas as pd

ArrayLike = Union[npt.ArrayLike, float]
Model = Literal["reference", "f32", "fixed"]
Contact = Literal["auto", "elliptic", "line"]

STATES: Tuple[str, str, str, str, str]
FLAGS: Tuple[str, ...]
SCENE: Tuple[float, float, float, float, float]

class Result(Mapping[str, np.ndarray]):
    def __getitem__(self, key: str) -> np.ndarray: ...
    def __iter__(self) -> Iterator[str]: ...
    def __len__(self) -> int: ...
    def to_frame(self) -> pd.DataFrame: ...

def estimate(
    R1: ArrayLike,
    R2: ArrayLike,
    G: ArrayLike,
    nu: ArrayLike,
    mu: ArrayLike,
    P: ArrayLike,
    phi: ArrayLike,
    *,
    length: Optional[ArrayLike] = None,
    model: Model = "reference",
    contact: Contact = "auto",
    details: bool = False,
    counts: Literal["exact", "adc"] = "exact",
    load_lsb: Optional[float] = None,
    angle_lsb: Optional[float] = None,
    threads: bool = True,
) -> Result: ...
def solve_mu(
    R1: ArrayLike,
    R2: ArrayLike,
    G: ArrayLike,
    nu: ArrayLike,
    P: ArrayLike,
    phi: ArrayLike,
    F: ArrayLike,
    *,
    length: Optional[ArrayLike] = None,
    model: Literal["reference", "f32"] = "reference",
    contact: Contact = "auto",
) -> Result: ...
def solve_phi(
    R1: ArrayLike,
    R2: ArrayLike,
    G: ArrayLike,
    nu: ArrayLike,
    mu: ArrayLike,
    P: ArrayLike,
    F: ArrayLike,
    *,
    length: Optional[ArrayLike] = None,
    model: Literal["reference", "f32"] = "reference",
    contact: Contact = "auto",
) -> Result: ...
def scenario() -> pd.DataFrame: ...
@dataclass
class Replay:
    events: pd.DataFrame
    summary: dict[str, Any]
    states: pd.DataFrame

def replay(
    t: npt.ArrayLike,
    P: npt.ArrayLike,
    phi: npt.ArrayLike,
    *,
    V: Optional[ArrayLike] = None,
    F: Optional[ArrayLike] = None,
    scene: Optional[Tuple[float, float, float, float, float]] = None,
    length: Optional[float] = None,
    model: Literal["f32", "fixed"] = "f32",
    config: Optional[dict[str, Any]] = None,
    progress: bool = False,
    chunk: int = 200_000,
) -> Replay: ...
def thresholds(
    P: Optional[npt.ArrayLike] = None,
    *,
    scene: Optional[Tuple[float, float, float, float, float]] = None,
    length: Optional[float] = None,
    model: Literal["f32", "fixed"] = "f32",
    load_max: Optional[float] = None,
    config: Optional[dict[str, Any]] = None,
) -> pd.DataFrame: ...

"""The compiled half of misalign (called by misalign/__init__.py; not an API)."""

from typing import Any, Optional, Sequence

import numpy as np

def error_messages() -> list[str]: ...
def estimate(
    columns: Sequence[np.ndarray],
    has_length: bool,
    n: int,
    model: str,
    contact: str,
    details: bool,
    load_lsb: float,
    angle_lsb: Optional[float],
    threads: bool,
) -> dict[str, np.ndarray]: ...
def solve(
    unknown: str,
    columns: Sequence[np.ndarray],
    has_length: bool,
    n: int,
    model: str,
    contact: str,
) -> dict[str, Any]: ...
def scenario_samples() -> dict[str, Any]: ...
def thresholds(
    scene: tuple[float, float, float, float, float],
    length: Optional[float],
    model: str,
    load_max: float,
    trace_load_max: float,
    config: Optional[dict[str, Any]] = None,
) -> list[list[float]]: ...

class Replay:
    def __init__(
        self,
        scene: tuple[float, float, float, float, float],
        length: Optional[float],
        model: str,
        load_max: float,
        config: Optional[dict[str, Any]] = None,
    ) -> None: ...
    def feed(
        self,
        time_s: np.ndarray,
        load: np.ndarray,
        phi: np.ndarray,
        speed: np.ndarray,
        force: np.ndarray,
    ) -> None: ...
    def events(self) -> dict[str, Any]: ...
    def summary(self) -> dict[str, Any]: ...

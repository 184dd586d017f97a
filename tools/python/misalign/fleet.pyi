"""Type stubs of misalign.fleet."""

from os import PathLike
from typing import Any, Optional, Union

import pandas as pd

COLUMNS: list[str]

def meta() -> pd.DataFrame: ...
def roller_summary(
    pdf: pd.DataFrame,
    *,
    scene: Optional[tuple[float, float, float, float, float]] = None,
    length: Optional[float] = None,
    model: str = "f32",
    config: Optional[dict[str, Any]] = None,
) -> pd.DataFrame: ...
def synthetic(
    rollers: int, hours: float, *, seed: int = 1, period_s: float = 1.0
) -> dict[str, pd.DataFrame]: ...
def write_parquet(fleet: dict[str, pd.DataFrame], directory: Union[str, PathLike[str]]) -> int: ...
def run_dask(directory: Union[str, PathLike[str]], client: Any = None, **kwargs: Any) -> pd.DataFrame: ...

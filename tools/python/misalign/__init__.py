"""misalign: microslip, critical misalignment angle and axial force of two misaligned
rolling cylinders, after "The rolling contact of misaligned elastic cylinders", on
numpy arrays; and the condition monitor over a recorded trace.

SI units throughout: radii R1, R2 and length in m (R2 = inf is a plane), shear modulus
G in Pa, Poisson's ratio nu and friction coefficient mu without unit, load P in N (the
total load; N/m only for line contact without a length), misalignment phi in rad
(signed), axial force F in N with the sign of phi, time t in s, speed V in m/s.

Functions: :func:`estimate` (the forward model), :func:`solve_mu` and
:func:`solve_phi` (the inverses from a measured axial force), :func:`replay` (the
condition monitor over a trace), :func:`thresholds` (where each state is raised and
cleared over a load range), :func:`scenario` (the built-in shift). The per-roller
summary for a fleet on Dask or Spark is :func:`misalign.fleet.roller_summary`.
"""

from __future__ import annotations

import numbers
import sys
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Iterator, Optional, Sequence, Tuple

import numpy as np

from . import _misalign

__all__ = [
    "estimate",
    "solve_mu",
    "solve_phi",
    "replay",
    "thresholds",
    "scenario",
    "Result",
    "Replay",
    "STATES",
    "FLAGS",
]

#: The monitor's states, in the order of its per-state statistics.
STATES = ("stopped", "normal", "microslip", "gross_slip", "sensor_fault")
#: The validity flags, in bit order (bit 0 first).
FLAGS = (
    "large_angle",
    "high_pressure",
    "longer_than_rollers",
    "near_model_switch",
    "round_ellipse",
    "no_critical_angle",
)
_MODELS = ("reference", "f32", "fixed")
_CONTACTS = ("auto", "elliptic", "line")
_DETAILS = ("theta", "kprime", "m", "n", "a", "b", "p0", "d", "Pstar", "P0star", "theta0", "R")
_MESSAGES = _misalign.error_messages()
#: The message of every status code (a u8): the row's error, "" for a fine row.
_ERRORS = np.array(_MESSAGES + ["unknown error"] * (256 - len(_MESSAGES)), dtype=object)
_FLAG_TEXT = np.array(
    [";".join(name for bit, name in enumerate(FLAGS) if code >> bit & 1) for code in range(256)],
    dtype=object,
)
_REGIMES = np.array(["partial", "gross"] + [""] * 254, dtype=object)
_CONTACT_MODELS = np.array(["elliptic", "line"] + [""] * 254, dtype=object)
#: The built-in scenario's operating range: the replay's model choice takes at least it.
_SCENARIO_LOAD_MAX = 5e3


def _is_real_type(t: type) -> bool:
    """A type whose values are real numbers: not a bool (a flag, not a quantity),
    not a string, not complex."""
    return issubclass(t, numbers.Real) and not issubclass(t, (bool, np.bool_))


def _as_float(name: str, x: Any) -> np.ndarray:
    """`x` as a float64 array; ValueError for what is not a real number. One rule
    whatever holds the values: strings, bools, complex numbers, None and other objects
    are refused, as an array of them (``<U1``, ``bool``) or inside an object array."""
    a = np.asarray(x)
    if a.dtype == object:
        for t in {type(v) for v in a.flat}:
            if not _is_real_type(t):
                raise ValueError(f"{name}: not an array of real numbers (holds {t.__name__})")
        try:
            a = a.astype(np.float64)
        except (TypeError, ValueError, OverflowError) as e:
            raise ValueError(f"{name}: not an array of real numbers ({e})") from None
    if a.dtype.kind not in "iuf":
        raise ValueError(f"{name}: dtype {a.dtype} is not a real number type")
    return a.astype(np.float64, copy=False)


def _real(name: str, x: Any, *, positive: bool = False) -> float:
    """An option that is one real number (not a bool, not a string), finite; above 0
    where ``positive``."""
    if not _is_real_type(type(x)):
        raise ValueError(f"{name} must be a real number, not {x!r}")
    try:
        v = float(x)
    except (OverflowError, ValueError, TypeError):
        v = float("nan")
    if not np.isfinite(v) or (positive and not v > 0):
        what = "a finite number above 0" if positive else "a finite number"
        raise ValueError(f"{name} must be {what}, not {x!r}")
    return v


def _flag(name: str, x: Any) -> bool:
    """An option that is True or False (Python's or numpy's), nothing else."""
    if not isinstance(x, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, not {x!r}")
    return bool(x)


def _scene(scene: Any) -> Tuple[float, float, float, float, float]:
    """A scene (R1, R2, G, nu, mu) of real numbers; R2 may be inf (a plane); the
    values' physics is checked by the library (ValueError "scene: ...")."""
    if scene is None:
        return SCENE
    if isinstance(scene, (str, bytes)) or not isinstance(scene, (Sequence, np.ndarray)) \
            or len(scene) != 5:
        raise ValueError(f"scene must be (R1, R2, G, nu, mu), not {scene!r}")
    out = []
    for name, x in zip(("R1", "R2", "G", "nu", "mu"), scene):
        if not _is_real_type(type(x)):
            raise ValueError(f"scene: {name} must be a real number, not {x!r}")
        try:
            out.append(float(x))
        except OverflowError:
            raise ValueError(f"scene: {name} = {x!r} is beyond f64's range") from None
    return tuple(out)  # type: ignore[return-value]


def _length(length: Any) -> Optional[float]:
    """The rollers' contact length of the replay and the planner: None or a number."""
    if length is None:
        return None
    if not _is_real_type(type(length)):
        raise ValueError(f"length must be a real number (m) or None, not {length!r}")
    return float(length)


def _config(config: Any) -> Optional[dict]:
    """The monitor's settings: None or a mapping of field names (each field's type and
    range is checked by the library: ValueError "config: <field> ...")."""
    if config is None:
        return None
    if not isinstance(config, Mapping):
        raise ValueError(f"config must be a dict of the monitor's settings, not {config!r}")
    return dict(config)


def _columns(named: Sequence[Tuple[str, Any]]) -> Tuple[Tuple[int, ...], list]:
    """Broadcasts the named inputs; returns the common shape and, per input, a
    contiguous float64 column of 1 row (a scalar) or of every row."""
    arrays = [(name, _as_float(name, x)) for name, x in named]
    try:
        shape = np.broadcast_shapes(*(a.shape for _, a in arrays))
    except ValueError:
        shapes = ", ".join(f"{name} {a.shape}" for name, a in arrays)
        raise ValueError(f"inputs do not broadcast to one shape: {shapes}") from None
    columns = []
    for _, a in arrays:
        if a.size == 1:
            columns.append(np.ascontiguousarray(a.reshape(1)))
        else:
            columns.append(np.ascontiguousarray(np.broadcast_to(a, shape)).reshape(-1))
    return shape, columns


def _option(name: str, value: str, allowed: Sequence[str]) -> str:
    if not isinstance(value, str) or value not in allowed:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, allowed))}, not {value!r}")
    return value


class Result(Mapping):
    """The answer of :func:`estimate` and the inverses: a mapping of numpy arrays of
    the inputs' broadcast shape. Text columns (``regime``, ``model``, ``error``,
    ``flags``) are numpy object arrays of a few shared str objects, built from the
    rows' codes on first access. ``to_frame()`` gives a pandas DataFrame."""

    def __init__(self, shape: Tuple[int, ...], numbers: dict, text: dict):
        self._shape = shape
        self._numbers = numbers
        self._text = text
        self._cache: dict = {}

    def __getitem__(self, key: str) -> np.ndarray:
        if key in self._numbers:
            return self._numbers[key].reshape(self._shape)
        if key in self._text:
            if key not in self._cache:
                table, codes = self._text[key]
                self._cache[key] = table[codes].reshape(self._shape)
            return self._cache[key]
        raise KeyError(key)

    def __iter__(self) -> Iterator[str]:
        yield from self._numbers
        yield from self._text

    def __len__(self) -> int:
        return len(self._numbers) + len(self._text)

    def __repr__(self) -> str:
        return f"misalign.Result(shape={self._shape}, columns={list(self)})"

    def to_frame(self):
        """The columns as a pandas DataFrame (one row per element, flattened)."""
        import pandas as pd

        return pd.DataFrame({k: np.asarray(self[k]).reshape(-1) for k in self})


def estimate(
    R1,
    R2,
    G,
    nu,
    mu,
    P,
    phi,
    *,
    length=None,
    model: str = "reference",
    contact: str = "auto",
    details: bool = False,
    counts: str = "exact",
    load_lsb: Optional[float] = None,
    angle_lsb: Optional[float] = None,
    threads: bool = True,
) -> Result:
    """The forward model per element of numpy arrays that broadcast (scalars allowed).

    Parameters: ``R1``, ``R2`` radii (m; R2 = inf is a plane), ``G`` shear modulus
    (Pa), ``nu`` Poisson's ratio, ``mu`` friction coefficient, ``P`` load (N; N/m in
    line contact without a length), ``phi`` misalignment (rad, signed), ``length`` the
    rollers' contact length (m) or None. ``model``: ``"reference"`` (f64, the whole
    paper), ``"f32"`` (the Cortex-M4F core) or ``"fixed"`` (the fixed-point core).
    ``counts``, for the fixed-point core, how P and phi become its integer counts:
    ``"exact"`` (the core: each row in counts of an LSB that holds its values exactly,
    as the CSV estimator's ``--counts exact``, so that the answer carries the core's
    own error only) or ``"adc"`` (the node with its ADC: P in counts of ``load_lsb`` N,
    default 10 mN, and phi in counts of ``angle_lsb`` rad, default the finest angle the
    scene's tables allow and at least 1e-10 rad, each rounded to the nearest count, as
    ``--counts adc``). ``contact``: ``"auto"`` (section 9 per element: line contact
    when the ellipse is longer than the rollers), ``"elliptic"`` or ``"line"``.
    ``details=True`` adds the reference's theta, kprime, m, n, a, b (m), p0 (Pa), d (m),
    Pstar, P0star, theta0 (rad), R (m). ``threads``: rows in chunks over both cores.

    Returns a :class:`Result` with ``s`` (slip ratio d/b), ``F`` (axial force, N),
    ``phi0`` (critical angle at this load, rad; NaN where none exists), ``regime``
    (``"partial"`` or ``"gross"``), ``model`` (``"elliptic"`` or ``"line"``),
    ``flags`` (where the theory is stretched, ``;``-separated) and ``error`` (empty
    where the element is fine). A bad element (NaN, infinite, negative or zero where
    not allowed) gets NaN and its message; the others their values.

    Raises ValueError for inputs that do not broadcast, are not real numbers, an
    unknown option, or an LSB the fixed-point core cannot take for the scene (named).
    The GIL is released while the rows are computed.
    """
    _option("model", model, _MODELS)
    _option("contact", contact, _CONTACTS)
    _option("counts", counts, ("exact", "adc"))
    details, threads = _flag("details", details), _flag("threads", threads)
    lsbs = [(k, v) for k, v in (("load_lsb", load_lsb), ("angle_lsb", angle_lsb)) if v is not None]
    if lsbs and (model != "fixed" or counts != "adc"):
        raise ValueError(f"{lsbs[0][0]} is the ADC's: it needs model='fixed' with counts='adc'")
    load_lsb = None if load_lsb is None else _real("load_lsb", load_lsb, positive=True)
    angle_lsb = None if angle_lsb is None else _real("angle_lsb", angle_lsb, positive=True)
    named = [("R1", R1), ("R2", R2), ("G", G), ("nu", nu), ("mu", mu),
             ("length", 1.0 if length is None else length), ("P", P), ("phi", phi)]
    shape, cols = _columns(named)
    n = int(np.prod(shape, dtype=np.int64))
    out = _misalign.estimate(cols, length is not None, n, model, contact, details, counts,
                             load_lsb, angle_lsb, threads)
    numbers = {"s": out["s"], "F": out["F"], "phi0": out["phi0"]}
    if details:
        numbers.update({k: out[k] for k in _DETAILS})
    text = {
        "regime": (_REGIMES, out["regime_code"]),
        "model": (_CONTACT_MODELS, out["model_code"]),
        "flags": (_FLAG_TEXT, out["flags"]),
        "error": (_ERRORS, out["status"]),
    }
    return Result(shape, numbers, text)


def _solve(unknown, named, length, model, contact) -> Result:
    if model not in ("reference", "f32"):
        if model == "fixed":
            raise ValueError("the fixed-point core has no inverse: use model='reference' or 'f32'")
        _option("model", model, ("reference", "f32"))
    _option("contact", contact, _CONTACTS)
    named = named[:5] + [("length", 1.0 if length is None else length)] + named[5:]
    shape, cols = _columns(named)
    n = int(np.prod(shape, dtype=np.int64))
    out = _misalign.solve(unknown, cols, length is not None, n, model, contact)
    bounds = np.array(["exact", "at_least", "inconsistent"] + [""] * 253, dtype=object)
    text = {
        "bound": (bounds, out["bound_code"]),
        "error": (np.array(out["messages"], dtype=object), out["code"]),
    }
    return Result(shape, {unknown: out["value"], "sensitivity": out["sensitivity"]}, text)


def solve_mu(R1, R2, G, nu, P, phi, F, *, length=None, model: str = "reference",
             contact: str = "auto") -> Result:
    """The friction coefficient mu from a measured axial force ``F`` (N, signed like
    phi), per element of arrays that broadcast: load ``P`` (N), misalignment ``phi``
    (rad), the scene as in :func:`estimate` (no mu). ``model``: ``"reference"`` or
    ``"f32"``.

    Returns ``mu``, ``bound`` (``"exact"``; ``"at_least"`` where F only bounds mu from
    below, at the no-slip limit; ``"inconsistent"`` where no mu gives F, with the reason
    in ``error``), ``sensitivity`` (d ln mu / d ln F of an exact answer: a relative
    error of F times it is mu's) and ``error``.
    """
    named = [("R1", R1), ("R2", R2), ("G", G), ("nu", nu), ("mu", 1.0), ("P", P),
             ("phi", phi), ("F", F)]
    return _solve("mu", named, length, model, contact)


def solve_phi(R1, R2, G, nu, mu, P, F, *, length=None, model: str = "reference",
              contact: str = "auto") -> Result:
    """The misalignment phi (rad, signed like F) from a measured axial force ``F``
    (N), per element: load ``P`` (N), the scene as in :func:`estimate`.

    Returns ``phi``, ``bound`` (``"exact"``; ``"at_least"`` in gross slip, where F has
    saturated at mu P and |phi| is only bounded from below; ``"inconsistent"`` with the
    reason in ``error``), ``sensitivity`` (d ln phi / d ln F) and ``error``.
    """
    named = [("R1", R1), ("R2", R2), ("G", G), ("nu", nu), ("mu", mu), ("P", P),
             ("phi", 0.0), ("F", F)]
    return _solve("phi", named, length, model, contact)


def scenario():
    """The built-in scenario (one 8 h shift of a press roller pair whose misalignment
    drifts through the critical angle, with noise, spikes, a dropout, a stuck sensor and
    a stop) as a pandas DataFrame: ``t`` (s, the node's wrapping millisecond counter
    over 1000), ``P`` (N), ``phi`` (rad), ``V`` (m/s), ``F`` (N, NaN: not measured).
    Its scene is ``scenario.scene`` below: (R1, R2, G, nu, mu)."""
    import pandas as pd

    s = _misalign.scenario_samples()
    return pd.DataFrame({
        "t": s["time_ms"].astype(np.float64) / 1e3,
        "P": s["P"].astype(np.float64),
        "phi": s["phi"].astype(np.float64),
        "V": s["V"].astype(np.float64),
        "F": s["F"].astype(np.float64),
    })


#: The built-in scenario's scene (R1 m, R2 m, G Pa, nu, mu): the default of replay().
SCENE = tuple(_misalign.scenario_samples()["scene"])
scenario.scene = SCENE  # type: ignore[attr-defined]


def _trace_column(name: str, x, n: int) -> np.ndarray:
    if x is None:
        return np.full(n, np.nan)
    a = _as_float(name, x)
    if a.ndim == 0:
        a = np.full(n, float(a))
    if a.ndim != 1 or a.shape[0] != n:
        raise ValueError(f"{name} has shape {a.shape}; the trace has {n} samples")
    return np.ascontiguousarray(a)


@dataclass
class Replay:
    """What :func:`replay` returns: ``events`` (pandas DataFrame, the monitor example's
    ``--events`` columns ``t,seq,state,from,kind,fault,P,phi,s,F,phi0,margin,
    time_to_critical,time_ms``; t in s since the start, P in N, phi, phi0 and margin in
    rad, F in N, time_to_critical in s), ``summary`` (dict: samples, faults by cause,
    maximum d/b and |F|, minimum margin, friction, final state, time to critical) and
    ``states`` (pandas DataFrame: time in s and energy in J per state)."""

    events: Any
    summary: dict
    states: Any


def _load_range(P32: np.ndarray) -> float:
    """The trace's operating range for the model choice, as the monitor example makes
    it: the largest finite load, at least the scenario's 5 kN."""
    finite = P32[np.isfinite(P32)].astype(np.float64)
    return max(_SCENARIO_LOAD_MAX, float(finite.max())) if finite.size else _SCENARIO_LOAD_MAX


def replay(t, P, phi, *, V=None, F=None, scene=None, length=None, model: str = "f32",
           config: Optional[dict] = None, progress: bool = False,
           chunk: int = 200_000) -> Replay:
    """The condition monitor over a recorded trace, sample by sample, as the node runs
    it (the same events as the monitor example's replay, bit for bit).

    ``t`` time (s; it becomes the node's wrapping u32 millisecond counter, so a time
    that goes backwards or repeats is the monitor's fault or repeated timestamp, as on
    the node), ``P`` load (N), ``phi`` misalignment (rad), ``V`` speed (m/s) and ``F``
    measured axial force (N), each optional, NaN meaning "not measured" there. ``scene``
    (R1 m, R2 m, G Pa, nu, mu), default the built-in scenario's steel rollers;
    ``length`` (m) or None; ``model`` ``"f32"`` (with mu tracked from a measured F) or
    ``"fixed"``; ``config`` a dict of the monitor's settings to change (``thresholds``
    ``"slip_ratio"`` or ``"margin"``, ``warning``, ``alarm``, ``deadband``,
    ``on_delay_ms``, ``off_delay_ms``, ``fault_delay_ms``, ``inhibit_ms``, ``stuck_ms``,
    ``gap_ms``, ``stop_load``, ``stop_speed``, ``nominal_speed``, ``load_min``,
    ``load_max``, ``angle_max``, ``speed_max``, ``force_max``, ``smoothing_tau_s``, and
    ``spikes``, ``trend``, ``friction`` False to switch those off). ``progress=True``
    draws a progress bar on stderr, one step per ``chunk`` samples.

    Raises ValueError for a non-finite or non-numeric time, a time the node's
    millisecond counter cannot hold (beyond 2^53 ms, t in ns say, or a step of 2^31 ms,
    24.8 days, or more between samples outside the counter's own range, 0 to 2^32 ms,
    where a wrap is a wrap: the message names the sample), columns of different
    lengths, a bad scene, model or configuration. The GIL is released while samples
    are processed.
    """
    import pandas as pd

    _option("model", model, ("f32", "fixed"))
    scene, length, config = _scene(scene), _length(length), _config(config)
    progress = _flag("progress", progress)
    if isinstance(chunk, (bool, np.bool_)) or not isinstance(chunk, numbers.Integral) \
            or chunk < 1:
        raise ValueError(f"chunk must be a whole number of samples, at least 1, not {chunk!r}")
    tt = _as_float("t", t)
    if tt.ndim != 1:
        raise ValueError(f"t must be one-dimensional, not of shape {tt.shape}")
    n = tt.shape[0]
    bad = ~np.isfinite(tt)
    if bad.any():
        raise ValueError(f"t is not a finite number at sample {int(np.argmax(bad))}")
    tt = np.ascontiguousarray(tt)
    P64 = _trace_column("P", P, n)
    phi64 = _trace_column("phi", phi, n)
    V64 = _trace_column("V", V, n)
    F64 = _trace_column("F", F, n)
    with np.errstate(over="ignore"):  # beyond f32: inf, as the node's f32 reads it
        P32 = P64.astype(np.float32)
    r = _misalign.Replay(scene, length, model, _load_range(P32), config)
    chunk = int(chunk)
    for start in range(0, n, chunk):
        end = min(n, start + chunk)
        r.feed(tt[start:end], P64[start:end], phi64[start:end], V64[start:end],
               F64[start:end])
        if progress:
            done = end * 100 // max(n, 1)
            bar = "#" * (done // 4) + " " * (25 - done // 4)
            print(f"\r[{bar}] {done:>3} %", end="", file=sys.stderr, flush=True)
    if progress:
        print(file=sys.stderr)
    events = pd.DataFrame(r.events())
    summary = r.summary()
    states = pd.DataFrame({"state": summary.pop("states"), "time_s": summary.pop("time_s"),
                           "energy_J": summary.pop("energy_J")})
    return Replay(events=events, summary=summary, states=states)


def thresholds(P=None, *, scene=None, length=None, model: str = "f32",
               load_max: Optional[float] = None, config: Optional[dict] = None):
    """The threshold planner, as the monitor example's ``--thresholds`` (the same
    code): over 60 loads from above the stop load to the top of the range, the critical
    angle phi0(P) and the misalignment at which each state is raised and cleared. A
    pandas DataFrame with ``P`` (N), ``phi0``, ``phi_warning``, ``phi_warning_clear``,
    ``phi_alarm``, ``phi_alarm_clear`` (rad; NaN where the state is not reached); its
    ``attrs["load_max"]`` is the range's top (N), ``attrs["note"]`` what was changed
    from the range asked for (or None).

    The load range: given ``P`` (a trace's loads, N), up to 1.2 times its 99.9th
    percentile (so that a spike does not stretch it), as the example; kept within the
    configuration's ``load_max``, with a warning that says so. Else up to ``load_max``
    (N, default the configuration's ``load_max``). Scene, length, model and config as
    :func:`replay`.

    Raises ValueError for a range the table cannot honour: not above the
    configuration's stop load (where the machine stands and no state is raised: a
    trace without a finite load, or whose loads stay below it), an explicit
    ``load_max`` above the configuration's, both ``P`` and ``load_max``, or a bad
    scene, model or configuration.
    """
    import pandas as pd

    _option("model", model, ("f32", "fixed"))
    scene, length, config = _scene(scene), _length(length), _config(config)
    if P is not None:
        if load_max is not None:
            raise ValueError("give P (a trace's loads) or load_max, not both")
        with np.errstate(over="ignore"):  # beyond f32: inf, as the node's f32 reads it
            P32 = _as_float("P", P).reshape(-1).astype(np.float32)
        loads = np.sort(P32[np.isfinite(P32)])
        top = float(loads[len(loads) * 999 // 1000]) if len(loads) else None
        trace_range = _load_range(P32)
    else:
        top = None if load_max is None else _real("load_max", load_max)
        trace_range = max(_SCENARIO_LOAD_MAX, top or 0.0)
    rows, top_used, note = _misalign.thresholds(scene, length, model, P is not None, top,
                                                trace_range, config)
    if note is not None:
        warnings.warn(f"thresholds: {note}", stacklevel=2)
    cols = ["P", "phi0", "phi_warning", "phi_warning_clear", "phi_alarm", "phi_alarm_clear"]
    table = pd.DataFrame(rows, columns=cols)
    table.attrs["load_max"] = float(top_used)
    table.attrs["note"] = note
    return table

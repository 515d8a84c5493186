"""mbd: flexible multibody dynamics for rotorcraft, from Python.

Compile a ``.mbd`` model, run it, take its modes and its stability, and sweep it over params
on every core or on a Dask cluster::

    import mbd
    model = mbd.compile("models/windmill.mbd", set={"Omega_bar": 1.5})
    result = model.run(dt=1e-3, until=3.0)
    result.t, result["zeta1"]            # numpy arrays
    stab = model.stability(sweep={"Omega_bar": mbd.grid(0.9, 2.6, 0.05)})
    stab.unstable                         # [(1.1777, 2.3184)]

Every table holds the numbers the command line's CSV holds, to the last bit. The simulation
runs with the GIL released; Ctrl-C stops it before its next step and raises
``KeyboardInterrupt``.
"""

from __future__ import annotations

import csv
import io
import json
import os
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, Iterable, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _mbd

__version__: str = _mbd.__version__

__all__ = [
    "Diagnostic",
    "MbdWarning",
    "Model",
    "ModelError",
    "Record",
    "Result",
    "RunFailure",
    "Stability",
    "Table",
    "compile",
    "grid",
    "sweep",
]


@dataclass(frozen=True)
class Diagnostic:
    """One diagnostic of the compiler or the runtime, as ``mbd check --format json`` gives it.

    ``code`` is e.g. ``"E0202"`` (``mbd explain CODE`` explains it); ``line`` and ``column``
    are 1-based and point into ``file`` (``None`` when the diagnostic has no place)."""

    code: str
    severity: str
    message: str
    file: Optional[str] = None
    line: Optional[int] = None
    column: Optional[int] = None
    end_line: Optional[int] = None
    end_column: Optional[int] = None
    hint: Optional[str] = None
    labels: Tuple[str, ...] = ()

    def __str__(self) -> str:
        where = f"{self.file}:{self.line}:{self.column}: " if self.file and self.line else ""
        hint = f" (hint: {self.hint})" if self.hint else ""
        return f"{where}{self.severity}[{self.code}]: {self.message}{hint}"


def _diagnostics(text: str) -> List[Diagnostic]:
    out = []
    for d in json.loads(text) if text else []:
        out.append(
            Diagnostic(
                code=str(d.get("code", "")),
                severity=str(d.get("severity", "error")),
                message=str(d.get("message", "")),
                file=d.get("file"),
                line=d.get("line"),
                column=d.get("column"),
                end_line=d.get("end_line"),
                end_column=d.get("end_column"),
                hint=d.get("hint"),
                labels=tuple(d.get("labels", ())),
            )
        )
    return out


class ModelError(Exception):
    """The model does not compile, or an analysis cannot start on it: every diagnostic is in
    ``diagnostics`` (code, message, file, line, column, hint)."""

    def __init__(self, diagnostics: Sequence[Diagnostic]):
        self.diagnostics: List[Diagnostic] = list(diagnostics)
        errors = [d for d in self.diagnostics if d.severity == "error"] or self.diagnostics
        lines = [str(d) for d in errors]
        super().__init__("\n".join(lines) if lines else "the model has errors")


class MbdWarning(UserWarning):
    """A warning of the compiler, the sizing lint or the run; ``diagnostic`` holds it."""

    def __init__(self, diagnostic: Diagnostic):
        self.diagnostic = diagnostic
        super().__init__(str(diagnostic))


def _warn(text: str) -> None:
    for d in _diagnostics(text):
        warnings.warn(MbdWarning(d), stacklevel=3)


def _raise(text: str) -> None:
    ds = _diagnostics(text)
    if any(d.code == "usage" for d in ds):
        raise ValueError("; ".join(d.message for d in ds))
    raise ModelError(ds)


class Table(Mapping):
    """Columns of equal length as numpy arrays, by name in the command line's CSV order.

    Numbers are ``float64`` (an empty CSV cell is NaN); a column of words (``method``,
    ``frame``, ``entity``, ``kind``) is an array of ``str``."""

    def __init__(self, columns: Dict[str, np.ndarray]):
        self._columns: Dict[str, np.ndarray] = dict(columns)

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self._columns[name]
        except KeyError:
            raise KeyError(f"no column `{name}`; the columns are: {', '.join(self._columns)}") from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._columns)

    def __len__(self) -> int:
        return len(self._columns)

    @property
    def columns(self) -> List[str]:
        """The column names."""
        return list(self._columns)

    @property
    def rows(self) -> int:
        """The number of rows."""
        return len(next(iter(self._columns.values()))) if self._columns else 0

    def to_pandas(self):
        """The table as a ``pandas.DataFrame`` (pandas must be installed)."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("to_pandas() needs pandas: pip install pandas") from e
        return pd.DataFrame({k: v for k, v in self._columns.items()})

    def __repr__(self) -> str:
        return f"Table({self.rows} rows: {', '.join(self._columns)})"


def _parse_csv(text: str) -> Table:
    """A CSV of mbd as columns: numbers exactly as written (Python's float is correctly
    rounded, and mbd writes the shortest text that reads back to the same f64)."""
    reader = csv.reader(io.StringIO(text))
    header = next(reader, [])
    cells: List[List[str]] = [[] for _ in header]
    for row in reader:
        for k in range(len(header)):
            cells[k].append(row[k] if k < len(row) else "")
    columns: Dict[str, np.ndarray] = {}
    for name, col in zip(header, cells):
        try:
            columns[name] = np.array([float(x) if x != "" else np.nan for x in col], dtype=np.float64)
        except ValueError:
            columns[name] = np.array(col, dtype=str)
    return Table(columns)


@dataclass(frozen=True)
class Record:
    """What a run did: steps, Newton iterations, halved steps, factorizations, the largest
    constraint violation |C| (m), and the CPU seconds of the simulation alone."""

    steps: int
    newton_iterations: int
    halvings: int
    factorizations: int
    max_constraint_violation: float
    cpu_s: float


@dataclass(frozen=True)
class RunFailure:
    """Why a run stopped early: when (``t`` in s, ``step``), where (``entity``, e.g.
    ``"joint hinge"``), and the diagnostic with its code, source position and hint."""

    diagnostic: Diagnostic
    t: float
    step: int
    entity: Optional[str]

    def __str__(self) -> str:
        return str(self.diagnostic)


class Result(Table):
    """A run's output channels by name (``result["zeta1"]``, ``result.t``), one row per
    written step; ``record`` says what the run did, ``failure`` why it stopped early (then
    the table holds every row computed before it)."""

    def __init__(self, columns: Dict[str, np.ndarray], record: Optional[Record], failure: Optional[RunFailure], cpu_s: float):
        super().__init__(columns)
        self.record = record
        self.failure = failure
        self.cpu_s = cpu_s

    @property
    def t(self) -> np.ndarray:
        """The time of each row (s)."""
        return self["t"]

    @property
    def ok(self) -> bool:
        """True when the run reached its end."""
        return self.failure is None

    def __repr__(self) -> str:
        state = "ok" if self.ok else f"failed at t = {self.failure.t} s"
        return f"Result({self.rows} rows, {state}: {', '.join(self.columns)})"


@dataclass(frozen=True)
class Stability:
    """A stability sweep (``mbd stability``): ``table`` holds the CSV's columns (``PARAM,
    max_real, min_damping_ratio, method, freq1, real1, ..., mode1_freq, mode1_real,
    mode1_damping, ...``), ``edges`` each edge ``(value, lo, hi, onset)`` bracketed by the last
    bisection, ``unstable`` the unstable ranges ``(from, to)``; ``failed`` the points that failed
    ``(value, why)``; ``notes`` why an edge was not refined further."""

    param: str
    table: Table
    edges: List[Tuple[float, float, float, bool]] = field(default_factory=list)
    unstable: List[Tuple[float, float]] = field(default_factory=list)
    failed: List[Tuple[float, str]] = field(default_factory=list)
    notes: List[str] = field(default_factory=list)
    csv: str = ""

    def __getitem__(self, name: str) -> np.ndarray:
        return self.table[name]


def _set_text(name: str, value: Any) -> str:
    if isinstance(value, str):
        return f"{name}={value}"
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"param `{name}`: a number or a text with units, not {value!r}")
    return f"{name}={float(value)!r}"


def _sets(set: Optional[Mapping[str, Any]]) -> List[str]:
    return [_set_text(k, v) for k, v in (set or {}).items()]


SolveOption = Union[float, int, str, None]


class Model:
    """A compiled model. Its analyses compile it again from its text with their own settings
    (milliseconds), so a ``Model`` is plain data: it pickles, and Dask ships it to workers.

    ``name``, ``title``, ``channels`` (the output channels), ``params`` (name -> SI value, or
    None when the param is not a scalar), ``dt``, ``until`` and ``steps`` (the solve block's,
    with the command line's defaults)."""

    def __init__(self, name: str, text: str, sets: Sequence[str], info: Mapping[str, Any]):
        self.path = name
        self.text = text
        self.sets: List[str] = list(sets)
        self.name: str = info["name"]
        self.title: Optional[str] = info.get("title")
        self.channels: List[str] = list(info["channels"])
        self.params: Dict[str, Optional[float]] = dict(info["params"])
        self.dt: float = info["dt"]
        self.until: float = info["until"]
        self.steps: int = info["steps"]

    def __repr__(self) -> str:
        return f"Model({self.name!r}, channels={self.channels})"

    def __reduce__(self):
        info = {
            "name": self.name,
            "title": self.title,
            "channels": self.channels,
            "params": list(self.params.items()),
            "dt": self.dt,
            "until": self.until,
            "steps": self.steps,
        }
        return (Model, (self.path, self.text, self.sets, info))

    def with_set(self, set: Mapping[str, Any]) -> "Model":
        """The model with more params set (compiled, so an error raises ``ModelError``)."""
        return compile(self.text, set=None, name=self.path, _sets=self.sets + _sets(set), lint=False)

    def run(
        self,
        dt: Optional[float] = None,
        until: Optional[float] = None,
        integrator: Optional[str] = None,
        every: Optional[int] = None,
        *,
        steps: Optional[int] = None,
        alpha: Optional[float] = None,
        rho_inf: Optional[float] = None,
        rotations: Optional[str] = None,
        start: Optional[str] = None,
        newton: Optional[str] = None,
    ) -> Result:
        """Simulates the model (``mbd run``): the output channels as numpy arrays, one row per
        ``every`` steps and the last. Settings left ``None`` come from the model's ``solve``
        block. ``integrator``: ``"hht"``, ``"generalized-alpha"``, ``"fet"`` or ``"static"``.

        A run that fails at run time returns the rows computed before the failure, with
        ``result.failure`` (time, entity, diagnostic); a model that does not compile raises
        ``ModelError``; a setting out of its range raises ``ValueError``."""
        solve = dict(dt=dt, until=until, integrator=integrator, every=every, steps=steps, alpha=alpha,
                     rho_inf=rho_inf, rotations=rotations, start=start, newton=newton)
        out = _mbd.run(self.path, self.text, self.sets, solve)
        if "errors" in out:
            _raise(out["errors"])
        _warn(out.get("warnings", ""))
        header: List[str] = out["header"]
        rows: int = out["rows"]
        data = np.frombuffer(out["data"], dtype="<f8").reshape(rows, len(header)) if header else np.zeros((0, 0))
        columns = {h: np.ascontiguousarray(data[:, k]) for k, h in enumerate(header)}
        record = None
        if "stats" in out:
            s = out["stats"]
            record = Record(
                steps=int(s["steps"]),
                newton_iterations=int(s["newton_iterations"]),
                halvings=int(s["halvings"]),
                factorizations=int(s["factorizations"]),
                max_constraint_violation=float(s["max_constraint_violation"]),
                cpu_s=float(out["cpu_s"]),
            )
        failure = None
        if "failure" in out:
            ds = _diagnostics(out["failure"])
            failure = RunFailure(ds[0], float(out["failure_t"]), int(out["failure_step"]), out["failure_entity"])
        return Result(columns, record, failure, float(out["cpu_s"]))

    def modes(self, count: Optional[int] = None, frozen: bool = False, shapes: bool = False) -> Union[Table, Tuple[Table, Table]]:
        """Natural frequencies and damping about the initial state (``mbd modes``): the table
        ``mode, frequency_hz, omega_rad_s, damping_ratio, real_per_s, imag_rad_s, frame``;
        with ``shapes`` also the shapes' table ``mode, unknown, entity, kind, real, imag,
        frame``. A state that is not a steady motion raises ``ModelError`` (E0605) unless
        ``frozen``."""
        ok, table, shape_table = _mbd.modes(self.path, self.text, self.sets, frozen, count)
        if not ok:
            _raise(table)
        t = _parse_csv(table)
        return (t, _parse_csv(shape_table)) if shapes else t

    def stability(
        self,
        sweep: Union[Mapping[str, Iterable[float]], Tuple[str, Iterable[float]]],
        method: str = "floquet",
        *,
        period: Optional[float] = None,
        monodromy: Optional[str] = None,
        modes: Optional[int] = None,
        signals: Optional[Sequence[str]] = None,
        window: Optional[Tuple[float, float]] = None,
        samples: int = 300,
        threshold: float = 1e-2,
        refine: int = 6,
    ) -> Stability:
        """A stability sweep (``mbd stability``): for each value of the param (SI), the
        characteristic exponents by Floquet analysis (``method="floquet"``), a transient's
        matrix-pencil fit (``"prony"``) or both, and the edges of the unstable ranges,
        bisected ``refine`` times. ``sweep``: ``{"Omega_bar": values}`` or ``("Omega_bar",
        values)``; ``mbd.grid(start, stop, step)`` gives the command line's values exactly.
        Points run on every core."""
        param, values = _one_param(sweep)
        options = _stability_options(method, period, monodromy, modes, signals, window, samples, threshold, refine)
        ok, text, report = _mbd.stability(self.path, self.text, self.sets, param, values, options)
        if not ok:
            _raise(text)
        return _stability(param, text, report)

    def study(
        self,
        channel: str,
        integrators: Union[str, Sequence[str], None] = None,
        *,
        alphas: Union[str, Sequence[float], None] = None,
        steps: Union[str, Sequence[int], None] = None,
        dt: Union[str, Sequence[float], None] = None,
        until: Optional[float] = None,
        at: Optional[float] = None,
        reference: Optional[str] = None,
    ) -> Table:
        """A study (``mbd study``), as its CSV's table. With ``integrators`` (e.g.
        ``["hht", "generalized-alpha"]``) a convergence study: one run per integrator and step
        (``steps=[100, 200, 400]`` or ``dt=[...]``), its error in ``channel`` against
        ``reference`` (``"finest"``, ``"exact"`` or a CSV file's path), its CPU time and
        Newton iterations. With ``alphas`` (e.g. ``[0, -0.1]``) a stability study: each
        HHT alpha's onset of instability in ``channel``."""
        def text(v: Any) -> Optional[str]:
            if v is None or isinstance(v, str):
                return v
            return ",".join(repr(float(x)) if isinstance(x, float) else str(x) for x in v)

        args = dict(channel=channel, integrators=text(integrators), alphas=text(alphas), steps=text(steps),
                    dt=text(dt), until=until, at=at, reference=None if reference is None else os.fspath(reference))
        ok, out = _mbd.study(self.path, self.text, self.sets, args)
        if not ok:
            _raise(out)
        return _parse_csv(out)


def _one_param(sweep: Union[Mapping[str, Iterable[float]], Tuple[str, Iterable[float]]]) -> Tuple[str, List[float]]:
    if isinstance(sweep, Mapping):
        if len(sweep) != 1:
            raise ValueError("a stability sweep takes one param: {'Omega_bar': values}; use mbd.sweep for several")
        ((param, values),) = sweep.items()
    else:
        param, values = sweep
    return str(param), [float(v) for v in np.atleast_1d(np.asarray(values, dtype=np.float64))]


def _stability_options(method, period, monodromy, modes, signals, window, samples, threshold, refine) -> Dict[str, Any]:
    return dict(
        method=method,
        period=period,
        monodromy=monodromy,
        modes=modes,
        signals=list(signals) if signals is not None else None,
        window=tuple(window) if window is not None else None,
        samples=samples,
        threshold=threshold,
        refine=refine,
    )


def _stability(param: str, text: str, report: Mapping[str, Any]) -> Stability:
    return Stability(
        param=param,
        table=_parse_csv(text),
        edges=[tuple(e) for e in report["edges"]],
        unstable=[tuple(r) for r in report["unstable"]],
        failed=[tuple(f) for f in report["failed"]],
        notes=list(report["notes"]),
        csv=text,
    )


def compile(
    source: Union[str, os.PathLike],
    set: Optional[Mapping[str, Any]] = None,
    *,
    lint: bool = True,
    name: Optional[str] = None,
    _sets: Optional[List[str]] = None,
) -> Model:
    """Compiles a model from a file path (``"models/windmill.mbd"``, a ``pathlib.Path``) or
    from its text. ``set`` overrides params: numbers in SI units, or texts with units
    (``{"V0": "5m/s"}``). Modules it ``use``s are found next to the file, then in the
    directories of ``MBD_PATH``.

    Errors raise ``ModelError`` with every diagnostic; warnings (the compiler's and, with
    ``lint``, the sizing lint's, as ``mbd check`` gives them) go through ``warnings`` as
    ``MbdWarning``."""
    if isinstance(source, os.PathLike) or (isinstance(source, str) and "\n" not in source and source.endswith(".mbd")):
        path = os.fspath(source)
        with open(path, "r", encoding="utf-8") as f:
            text = f.read()
        name = name or path
    else:
        text = str(source)
        name = name or "<string>"
    sets = _sets if _sets is not None else _sets_of(set)
    ok, diagnostics, info = _mbd.check(name, text, sets, lint)
    if not ok:
        _raise(diagnostics)
    _warn(diagnostics)
    return Model(name, text, sets, info)


_sets_of = _sets


def grid(start: float, stop: float, step: float) -> np.ndarray:
    """The values ``mbd stability --sweep NAME=START:STOP:STEP`` takes (STOP included),
    exactly."""
    return np.array(_mbd.grid(float(start), float(stop), float(step)), dtype=np.float64)


from ._sweep import sweep  # noqa: E402  (needs the names above)

"""``mbd.sweep``: a model over a grid of params, on every core or on a Dask cluster."""

from __future__ import annotations

import itertools
import os
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import Model, Stability, Table, _mbd, _raise, _stability, _stability_options, _sets, compile

Analysis = Union[str, Callable[[Model], Mapping[str, float]]]


class SweepTable(Table):
    """A sweep's one table: the params' columns first, then the analysis's. ``stabilities``
    keeps each stability sweep (its edges and unstable ranges), one per combination of the
    other params."""

    def __init__(self, columns: Dict[str, np.ndarray], stabilities: Optional[List[Tuple[Dict[str, float], Stability]]] = None):
        super().__init__(columns)
        self.stabilities: List[Tuple[Dict[str, float], Stability]] = stabilities or []


def sweep(
    model: Union[str, os.PathLike, Model],
    params: Mapping[str, Iterable[float]],
    analysis: Analysis = "stability",
    client: Any = None,
    *,
    shards: Optional[int] = None,
    set: Optional[Mapping[str, Any]] = None,
    **options: Any,
) -> SweepTable:
    """Runs ``analysis`` over the grid of ``params`` (``{"Omega_bar": values, "k_zeta":
    values}``, SI values; the grid is their product) and returns one table.

    ``analysis``:
    - ``"stability"`` (default): the first param is swept by ``Model.stability`` (its edges
      bisected; ``options`` are its keywords), once per combination of the others;
    - ``"modes"``: ``Model.modes`` at each point (``options``: ``count``, ``frozen``);
    - a function ``f(model) -> {name: number}``, called with the model at each point (e.g.
      ``lambda m: {"peak": abs(m.run(until=3)["zeta1"]).max()}``).

    ``client``: ``None`` runs locally on every core; a ``dask.distributed.Client`` runs the
    points on its cluster's workers (a stability sweep in ``shards`` shares per combination,
    default two per worker, joined as ``mbd merge`` joins them: the same table, bit for bit).
    """
    base = model if isinstance(model, Model) else compile(model, lint=False)
    if set:
        base = base.with_set(set)
    if not params:
        raise ValueError("give at least one param to sweep: {'Omega_bar': values}")
    names = list(params)
    grids = [[float(v) for v in np.atleast_1d(np.asarray(params[n], dtype=np.float64))] for n in names]
    for n, g in zip(names, grids):
        if not g:
            raise ValueError(f"param `{n}` has no values")
        if n not in base.params:
            raise ValueError(f"model `{base.name}` has no param `{n}`; its params are: {', '.join(base.params)}")
    if analysis == "stability":
        return _stability_sweep(base, names, grids, client, shards, options)
    if analysis == "modes":
        work: Callable[[Model], Table] = _Modes(options)
    elif callable(analysis):
        work = _Function(analysis)
        if options:
            raise TypeError(f"options {sorted(options)} belong to the built-in analyses, not to a function")
    else:
        raise ValueError(f"analysis must be 'stability', 'modes' or a function, got {analysis!r}")
    points = [dict(zip(names, p)) for p in itertools.product(*grids)]
    models = [base.with_set(p) if client is None else None for p in points]
    if client is None:
        with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
            tables = list(pool.map(work, models))
    else:
        futures = client.map(_at_point, [base] * len(points), points, [work] * len(points), pure=False)
        tables = client.gather(futures)
    return SweepTable(_stack(names, points, tables))


class _Modes:
    def __init__(self, options: Mapping[str, Any]):
        unknown = set(options) - {"count", "frozen"}
        if unknown:
            raise TypeError(f"modes takes count and frozen, not {sorted(unknown)}")
        self.options = dict(options)

    def __call__(self, m: Model) -> Table:
        t = m.modes(**self.options)
        assert isinstance(t, Table)
        return t


class _Function:
    def __init__(self, f: Callable[[Model], Mapping[str, float]]):
        self.f = f

    def __call__(self, m: Model) -> Table:
        row = self.f(m)
        if not isinstance(row, Mapping):
            raise TypeError(f"the analysis must return a mapping of names to numbers, got {type(row).__name__}")
        return Table({k: np.array([float(v)], dtype=np.float64) for k, v in row.items()})


def _at_point(base: Model, point: Dict[str, float], work: Callable[[Model], Table]) -> Table:
    return work(base.with_set(point))


def _stack(names: Sequence[str], points: Sequence[Dict[str, float]], tables: Sequence[Table]) -> Dict[str, np.ndarray]:
    """One table: each point's rows with its params' columns first; a column a point lacks
    is NaN (numbers) or empty (words) there."""
    order: List[str] = []
    for t in tables:
        order.extend(c for c in t.columns if c not in order and c not in names)
    columns: Dict[str, List[Any]] = {c: [] for c in list(names) + order}
    for p, t in zip(points, tables):
        n = t.rows
        for c in names:
            columns[c].extend([p[c]] * n)
        for c in order:
            columns[c].extend(list(t[c]) if c in t else [np.nan] * n)
    out: Dict[str, np.ndarray] = {}
    for c, v in columns.items():
        if any(isinstance(x, str) for x in v):
            out[c] = np.array(["" if (isinstance(x, float) and np.isnan(x)) else x for x in v], dtype=str)
        else:
            out[c] = np.array(v, dtype=np.float64)
    return out


def _share(base: Model, outer: Dict[str, float], param: str, values: List[float], options: Dict[str, Any], k: int, n: int) -> str:
    m = base.with_set(outer) if outer else base
    ok, text = _mbd.stability_share(m.path, m.text, m.sets, param, values, options, k, n)
    if not ok:
        _raise(text)
    return text


def _stability_sweep(base: Model, names: List[str], grids: List[List[float]], client: Any, shards: Optional[int], options: Dict[str, Any]) -> SweepTable:
    keywords = {"method", "period", "monodromy", "modes", "signals", "window", "samples", "threshold", "refine"}
    unknown = set(options) - keywords
    if unknown:
        raise TypeError(f"stability takes {sorted(keywords)}, not {sorted(unknown)}")
    param, values = names[0], grids[0]
    outers = [dict(zip(names[1:], p)) for p in itertools.product(*grids[1:])]
    results: List[Stability] = []
    if client is None:
        for outer in outers:
            m = base.with_set(outer) if outer else base
            results.append(m.stability({param: values}, **options))
    else:
        opts = _stability_options(
            options.get("method", "floquet"), options.get("period"), options.get("monodromy"), options.get("modes"),
            options.get("signals"), options.get("window"), options.get("samples", 300), options.get("threshold", 1e-2),
            options.get("refine", 6),
        )
        if shards is None:
            workers = len(client.scheduler_info().get("workers", {})) or 1
            shards = 2 * workers
        n = max(1, min(int(shards), len(values)))
        jobs = [(outer, k) for outer in outers for k in range(1, n + 1)]
        futures = client.map(
            _share,
            [base] * len(jobs),
            [o for o, _ in jobs],
            [param] * len(jobs),
            [values] * len(jobs),
            [opts] * len(jobs),
            [k for _, k in jobs],
            [n] * len(jobs),
            pure=False,
        )
        texts = client.gather(futures)
        for i, _ in enumerate(outers):
            csv_text, report = _mbd.merge(texts[i * n:(i + 1) * n])
            results.append(_stability(param, csv_text, report))
    table = _stack(names[1:], outers, [r.table for r in results])
    # The swept param's column is the stability table's first; keep the others before it.
    return SweepTable(table, list(zip(outers, results)))

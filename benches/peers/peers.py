"""Side-by-side benchmark of mbd against Exudyn (issue 20, item 6).

For each problem, both codes run along the same ladder of time steps; every run is compared
with one reference at common output times, and the CPU time each code needs to reach relative
errors 1e-3 and 1e-6 is interpolated (log-log) along its ladder. See README.md.

Usage (run.sh sets up the virtual environment):  python peers.py [--quick] [--only NAME] [--cli]
mbd runs in this process through its Python package, as Exudyn does (its record's `cpu_s`:
the run's thread CPU, start, time loop and rows); `--cli` times the `mbd run` binary instead
(its printed solve time, in a fresh process each run).
Environment: MBD (the mbd binary; default target/release/mbd from the repository root),
             MBD_ARGS (integrator flags for mbd under --cli; default generalized-alpha,
             rho_inf 0.9, which the in-process runs use),
             PEERS_REPEAT (repeats of runs shorter than 0.2 s, the fastest kept; default 3).
"""

import argparse
import csv
import math
import os
import re
import resource
import shlex
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
OUT = os.path.join(HERE, "out")

_t = time.process_time()
import numpy as np  # noqa: E402
import exudyn as exu  # noqa: E402
EXUDYN_IMPORT_CPU = time.process_time() - _t

sys.path.insert(0, HERE)
import exudyn_models  # noqa: E402

try:  # the repository's Python package, which run.sh builds into the venv
    import mbd as mbd_package  # noqa: E402
except ImportError:
    mbd_package = None

MBD = os.environ.get("MBD", os.path.join(ROOT, "target", "release", "mbd"))
MBD_ARGS = shlex.split(os.environ.get("MBD_ARGS", "--integrator generalized-alpha --rho-inf 0.9"))
REPEAT = int(os.environ.get("PEERS_REPEAT", "3"))
# How mbd is timed: "package" (in this process, as Exudyn) or "cli" (main() sets it).
MODE = {"mbd": "package"}
RHO_INF = 0.9
TARGETS = (1e-3, 1e-6)
# Two references closer than this (relative) are taken as agreeing.
AGREE = 1e-7


def ladder(dt0, n):
    return [dt0 / 2 ** k for k in range(n)]


# Each problem: the mbd model and its --set overrides, the end time, the step ladder, the
# output period (a multiple of every step of the ladder), the compared channels and the Exudyn
# builder with its arguments.
PROBLEMS = [
    dict(name="pendulum", title="P2 pendulum, 1 s", model="models/pendulum.mbd", sets=[],
         until=1.0, dts=ladder(0.02, 7), period=0.02, channels=["x", "y"],
         build=exudyn_models.pendulum, kwargs={}, sparse=False),
    dict(name="two_bar", title="P3 two-bar, theta2_0 = 0, 50 s", model="models/two_bar.mbd",
         sets=["theta2_0=0"], until=50.0, dts=ladder(0.00625, 6), period=0.05,
         channels=["xc2", "yc2", "zc2"], build=exudyn_models.two_bar,
         kwargs=dict(theta2_0=0.0), sparse=False),
    dict(name="windmill_1", title="P5 windmill, Omega_bar = 1, 3 s", model="models/windmill.mbd",
         sets=["Omega_bar=1"], until=3.0, dts=ladder(0.0025, 6), period=0.005,
         channels=["x_hub", "zeta1", "zeta2", "zeta3", "zeta4"], build=exudyn_models.windmill,
         kwargs=dict(Omega_bar=1.0), sparse=True),
    dict(name="windmill_2", title="P5 windmill, Omega_bar = 2, 3 s", model="models/windmill.mbd",
         sets=["Omega_bar=2"], until=3.0, dts=ladder(0.0025, 6), period=0.005,
         channels=["x_hub", "zeta1", "zeta2", "zeta3", "zeta4"], build=exudyn_models.windmill,
         kwargs=dict(Omega_bar=2.0), sparse=True),
]


def grid(p):
    n = int(round(p["until"] / p["period"]))
    return np.arange(n + 1) * p["period"]


def on_grid(t, values, p):
    """The rows of `values` at the problem's output times (they must be there exactly)."""
    g = grid(p)
    idx = np.rint(t / p["period"]).astype(int)
    keep = (np.abs(t - idx * p["period"]) < 1e-9 * max(1.0, p["until"])) & (idx <= len(g) - 1)
    out = np.full((len(g), values.shape[1]), np.nan)
    out[idx[keep]] = values[keep]
    if np.isnan(out).any():
        raise RuntimeError(f"{p['name']}: output missing at {np.isnan(out[:, 0]).sum()} grid times")
    return out


def children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_mbd(p, dt):
    """One mbd run: (values on the grid, solve time [s], other CPU [s], Newton iterations).
    In this process through the Python package: the run's thread CPU, and the compile's CPU
    as the other; under --cli: the binary's reported solve time, and its whole process."""
    if MODE["mbd"] == "package":
        return run_mbd_package(p, dt)
    return run_mbd_cli(p, dt)


def run_mbd_package(p, dt):
    every = int(round(p["period"] / dt))
    t0 = time.process_time()
    sets = dict(s.split("=", 1) for s in p["sets"])
    model = mbd_package.compile(os.path.join(ROOT, p["model"]), set=sets or None, lint=False)
    build = time.process_time() - t0
    r = model.run(dt=dt, until=p["until"], integrator="generalized-alpha", every=every,
                  rho_inf=RHO_INF)
    if not r.ok:
        raise Failed(f"mbd failed at t = {r.failure.t} s: {r.failure}")
    values = on_grid(r.t, np.column_stack([r[c] for c in p["channels"]]), p)
    return values, r.record.cpu_s, build, r.record.newton_iterations


def run_mbd_cli(p, dt):
    every = int(round(p["period"] / dt))
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "run.csv")
        cmd = [MBD, "run", os.path.join(ROOT, p["model"]), *MBD_ARGS, "--dt", repr(dt),
               "--until", repr(p["until"]), "--every", str(every), "-o", out]
        for s in p["sets"]:
            cmd += ["--set", s]
        before = children_cpu()
        r = subprocess.run(cmd, capture_output=True, text=True)
        process = children_cpu() - before
        if r.returncode != 0:
            if r.returncode == 3:
                m = re.search(r"failed at t = ([^ ]+ s)", r.stderr)
                raise Failed(f"mbd exit 3, Newton failed at t = {m.group(1) if m else '?'}")
            raise RuntimeError(f"mbd failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr}")
        m = re.search(r"(\d+) Newton iterations.* in ([0-9.]+) ms", r.stderr)
        if not m:
            raise RuntimeError(f"no solve time in mbd's report: {r.stderr}")
        with open(out) as f:
            header = f.readline().strip().split(",")
        data = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    cols = [header.index(c) for c in p["channels"]]
    values = on_grid(data[:, 0], data[:, cols], p)
    return values, float(m.group(2)) / 1e3, process, int(m.group(1))


def run_exudyn(p, dt):
    """One Exudyn run: (values on the grid, SolveDynamic CPU [s], model-building CPU [s])."""
    t0 = time.process_time()
    mbs, chans, keep = p["build"](**p["kwargs"])  # keep: symbolic functions stay alive
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.solverType = exu.DynamicSolverType.GeneralizedAlpha
    ti.generalizedAlpha.spectralRadius = RHO_INF
    ti.endTime = p["until"]
    ti.numberOfSteps = int(round(p["until"] / dt))
    ti.adaptiveStep = False           # a fixed step, as the ladder requires
    ti.verboseMode = 0
    ti.newton.useModifiedNewton = True
    if p["sparse"]:
        s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    s.solution.file.write = False     # no solution file; the sensors keep the channels
    s.solution.sensors.writePeriod = p["period"]
    s.show.globalTimers = False
    build = time.process_time() - t0
    t1 = time.process_time()
    try:
        ok = exu.SolveDynamic(mbs, s)
    except Exception as x:  # Exudyn raises on a Newton failure with a fixed step
        raise Failed(f"Exudyn SolveDynamic raised: {str(x).splitlines()[0] if str(x) else x}")
    solve = time.process_time() - t1
    if not ok:
        raise Failed("Exudyn SolveDynamic returned failure")
    cols, t = [], None
    for c in p["channels"]:
        sensor, f = chans[c]
        if isinstance(sensor, tuple):
            stored = [mbs.GetSensorStoredData(x) for x in sensor]
            t = stored[0][:, 0]
            cols.append(f(*[d[:, 1:] for d in stored]))
        else:
            d = mbs.GetSensorStoredData(sensor)
            t = d[:, 0]
            cols.append(f(d[:, 1:]))
    del keep
    return on_grid(t, np.column_stack(cols), p), solve, build


class Failed(Exception):
    """A run that stopped before the end time (Newton failure): recorded, not fatal."""


def best_of(run, p, dt, timed):
    """Repeat a short run (its timed entry under 0.2 s) and keep the fastest; None (and a
    printed line) if the run fails."""
    try:
        best = run(p, dt)
    except Failed as f:
        print(f"  failed at dt = {dt:g} s: {f}", flush=True)
        return None
    if best[timed] < 0.2:
        for _ in range(REPEAT - 1):
            again = run(p, dt)
            if again[timed] < best[timed]:
                best = again
    return best


def rel_error(values, ref):
    """Largest over the channels of (max |error| over the output times) / (max |reference|)."""
    err = np.max(np.abs(values - ref), axis=0) / np.max(np.abs(ref), axis=0)
    return float(np.max(err))


def cpu_at(points, target, floor):
    """CPU to reach `target` along a ladder [(cpu, error)] of successful runs ordered coarse
    to fine: log-log interpolation between the two runs that bracket it, else extrapolation
    along the two finest runs. A target below `floor` (what the reference resolves for this
    code) is not measured. Returns (cpu or None, note)."""
    if target < floor:
        return None, f"not resolved (reference floor {floor:.0e})"
    if points[0][1] <= target:
        return points[0][0], "at or below the coarsest successful step"
    for (c0, e0), (c1, e1) in zip(points, points[1:]):
        if e0 > target >= e1:
            w = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(c0) + w * (math.log(c1) - math.log(c0))), ""
    if len(points) >= 2:
        (c0, e0), (c1, e1) = points[-2], points[-1]
        # Only along a converging tail: an error that stalls (observed order under 1 between
        # the two finest runs, e.g. at a Newton-tolerance floor) is not extrapolated.
        if e1 < e0 / 2 and c1 > c0:
            w = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(c0) + w * (math.log(c1) - math.log(c0))), "extrapolated"
    return None, f"not reached (finest {points[-1][1]:.1e})"


def fmt_cpu(c, note):
    if c is None:
        return note
    s = f"{c * 1e3:.3g} ms" if c < 1 else f"{c:.3g} s"
    if note.startswith("at or below"):
        return "<= " + s
    return s + (" (extrap.)" if note == "extrapolated" else "")


def fmt_ratio(a, b):
    if a[0] is None or b[0] is None:
        return "-"
    r = a[0] / b[0]
    if a[1].startswith("at or below") or b[1].startswith("at or below"):
        return f"~{r:.2f} (bound)"
    return f"{r:.2f}" + (" (extrap.)" if a[1] or b[1] else "")


def study(p, rows, quick):
    dts = p["dts"][:3] if quick else p["dts"]
    fine = dts[-1] / 4
    print(f"\n== {p['title']}: steps {dts[0]:g} .. {dts[-1]:g} s, references at {fine:g} s",
          flush=True)
    ref_m = run_mbd(p, fine)
    ref_e = run_exudyn(p, fine)
    ladder_m = [best_of(run_mbd, p, dt, 1) for dt in dts]
    ladder_e = [best_of(run_exudyn, p, dt, 1) for dt in dts]
    if ladder_m[-1] is None or ladder_e[-1] is None:
        raise RuntimeError(f"{p['name']}: the finest ladder run failed")

    apart = rel_error(ref_e[0], ref_m[0])
    # Each reference's own error, estimated from its code's finest ladder run: at order 2 the
    # finest run's error is 16 times the reference's, so |finest - fine| ~ 15 e_ref.
    own_m = rel_error(ladder_m[-1][0], ref_m[0]) / 15
    own_e = rel_error(ladder_e[-1][0], ref_e[0]) / 15
    ref, ref_name = (ref_m[0], "mbd") if own_m <= own_e else (ref_e[0], "Exudyn")
    notes = [f"references at dt = {fine:g} s: mbd and Exudyn {apart:.2e} apart (relative); "
             f"estimated own errors mbd {own_m:.1e}, Exudyn {own_e:.1e}; "
             f"reference used: {ref_name}'s (the smaller estimated own error)"]
    if apart > AGREE:
        notes.append(f"the references disagree by more than {AGREE:g}: errors below about "
                     f"{apart:.0e} are not resolved for the other code, whose error includes "
                     f"this floor")
    for n in notes:
        print("  " + n)

    pts = {"mbd": [], "Exudyn": []}
    for code, ladder in (("mbd", ladder_m), ("Exudyn", ladder_e)):
        for dt, r in zip(dts, ladder):
            steps = int(round(p["until"] / dt))
            row = dict(problem=p["name"], code=code, dt=dt, steps=steps)
            if r is None:
                rows.append(dict(row, rel_error="failed", solve_cpu_s="", process_cpu_s="",
                                 build_cpu_s="", newton=""))
                continue
            e = rel_error(r[0], ref)
            pts[code].append((r[1], e))
            # mbd: (csv, solve, process or compile, newton); Exudyn: (csv, solve, build).
            cli = code == "mbd" and MODE["mbd"] == "cli"
            extra = (dict(process_cpu_s=r[2], build_cpu_s="", newton=r[3]) if cli
                     else dict(process_cpu_s="", build_cpu_s=r[2],
                               newton=r[3] if code == "mbd" else ""))
            rows.append(dict(row, rel_error=e, solve_cpu_s=r[1], **extra))
    third_m = "mbd proc" if MODE["mbd"] == "cli" else "mbd build"
    print(f"  {'dt [s]':>11} {'mbd error':>11} {'mbd solve':>11} {third_m:>10} "
          f"{'Exu error':>11} {'Exu solve':>11} {'Exu build':>10}")
    for dt in dts:
        m = [r for r in rows if r["problem"] == p["name"] and r["dt"] == dt]
        cells = []
        for r in m:
            if r["rel_error"] == "failed":
                cells.append(f"{'failed':>11} {'':>11} {'':>10}")
            else:
                third = r["process_cpu_s"] or r["build_cpu_s"]
                cells.append(f"{r['rel_error']:11.3e} {r['solve_cpu_s']:11.3e} {third:10.3e}")
        print(f"  {dt:11.4e} " + " ".join(cells))

    # What the reference resolves: its own estimated error for its code, and for the other
    # code also the distance between the two references.
    own = {"mbd": own_m, "Exudyn": own_e}[ref_name]
    floor = {c: own if c == ref_name else max(own, apart) for c in pts}
    result = dict(p=p, notes=notes, pts=pts, apart=apart, ref_name=ref_name,
                  at={c: [cpu_at(pts[c], t, floor[c]) for t in TARGETS] for c in pts})
    print(f"  {'code':8} {'CPU to 1e-3':>22} {'CPU to 1e-6':>34}")
    for code in ("mbd", "Exudyn"):
        a = result["at"][code]
        print(f"  {code:8} {fmt_cpu(*a[0]):>22} {fmt_cpu(*a[1]):>34}")
    ratios = [fmt_ratio(result["at"]["Exudyn"][k], result["at"]["mbd"][k]) for k in range(2)]
    print(f"  {'ratio Exudyn/mbd':16} {ratios[0]:>14} {ratios[1]:>34}", flush=True)
    result["ratios"] = ratios
    chart(result)
    return result


def chart(r):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    p = r["p"]
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for code, style in (("mbd", "o-"), ("Exudyn", "s--")):
        c, e = zip(*r["pts"][code])
        ax.loglog(c, e, style, label=code)
    for t in TARGETS:
        ax.axhline(t, color="grey", linestyle=":", linewidth=1)
    ax.axhline(r["apart"], color="tab:red", linestyle="-.", linewidth=1,
               label=f"references apart ({r['apart']:.1e})")
    ax.set_xlabel("solve CPU time [s] (mbd: " + ("its reported solve time" if MODE["mbd"] == "cli"
                  else "Model.run's cpu_s") + "; Exudyn: SolveDynamic)")
    ax.set_ylabel("relative error (max over channels)")
    ax.set_title(f"{p['title']}: {', '.join(p['channels'])}\n"
                 f"reference: {r['ref_name']} at dt = {p['dts'][-1] / 4:g} s", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, f"{p['name']}.png"), dpi=110)
    plt.close(fig)


def write(results, rows, started):
    with open(os.path.join(OUT, "ladder.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    version = subprocess.run([MBD, "--version"], capture_output=True, text=True).stdout.strip()
    lines = [
        "# mbd against Exudyn",
        "",
        f"Generated by `benches/peers/peers.py` on {time.strftime('%Y-%m-%d %H:%M')} "
        f"({os.cpu_count()} cores), {time.time() - started:.0f} s wall.",
        (f"mbd: `{MBD}` ({version or 'version unknown'}) with `{' '.join(MBD_ARGS)}`; "
         if MODE["mbd"] == "cli" else
         f"mbd: its Python package ({getattr(mbd_package, '__file__', '?')}), "
         f"generalized-alpha rho_inf {RHO_INF} (whole-process figures: `--cli`); ") +
        f"Exudyn {exu.config.Version() if hasattr(exu, 'config') else exu.__version__}, "
        f"generalized-alpha rho_inf {RHO_INF}, modified Newton, dense solver "
        "(EigenSparse on the windmill).",
        "",
        "CPU is each code's solve time: " + (
            "mbd's reported solve time (the figure `mbd run` prints, wall-clock around its "
            "time loop, in a fresh process each run)" if MODE["mbd"] == "cli" else
            "mbd's run in this process through its Python package (`Record.cpu_s`, the "
            "run's thread CPU: start, time loop, rows)") +
        ", Exudyn's `SolveDynamic` (process CPU), both the fastest of repeated runs. "
        f"Exudyn's import took {EXUDYN_IMPORT_CPU:.2f} s CPU once; model building (mbd's "
        "compile) and, under `--cli`, mbd's whole-process CPU are in `ladder.csv`.",
        "",
        "| problem | code | CPU to 1e-3 | CPU to 1e-6 |",
        "|---|---|---|---|",
    ]
    for r in results:
        for code in ("mbd", "Exudyn"):
            a = r["at"][code]
            lines.append(f"| {r['p']['title']} | {code} | {fmt_cpu(*a[0])} | {fmt_cpu(*a[1])} |")
        lines.append(f"| | ratio Exudyn/mbd | {r['ratios'][0]} | {r['ratios'][1]} |")
    lines += ["", "Reference notes:", ""]
    for r in results:
        for n in r["notes"]:
            lines.append(f"- {r['p']['title']}: {n}")
    lines += ["", "Charts: " + ", ".join(f"`{r['p']['name']}.png`" for r in results), ""]
    with open(os.path.join(OUT, "summary.md"), "w") as f:
        f.write("\n".join(lines))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="three ladder steps only (a smoke test)")
    ap.add_argument("--only", help="run one problem (pendulum, two_bar, windmill_1, windmill_2)")
    ap.add_argument("--cli", action="store_true",
                    help="time the mbd binary (a fresh process a run) instead of the package")
    a = ap.parse_args()
    MODE["mbd"] = "cli" if a.cli or mbd_package is None else "package"
    if mbd_package is None and not a.cli:
        print("mbd's Python package is not installed here: timing the binary (--cli)")
    if not os.access(MBD, os.X_OK):
        sys.exit(f"no mbd binary at {MBD}: run `cargo build --release` or set MBD")
    os.makedirs(OUT, exist_ok=True)
    started = time.time()
    who = f"{MBD} {' '.join(MBD_ARGS)}" if MODE["mbd"] == "cli" else "Python package"
    print(f"mbd: {who}; Exudyn {exu.__version__} "
          f"(import {EXUDYN_IMPORT_CPU:.2f} s CPU), generalized-alpha rho_inf {RHO_INF}")
    rows, results = [], []
    for p in PROBLEMS:
        if a.only and p["name"] != a.only:
            continue
        results.append(study(p, rows, a.quick))
    write(results, rows, started)
    print(f"\nwrote {OUT}/summary.md, ladder.csv and one chart per problem "
          f"({time.time() - started:.0f} s)")


if __name__ == "__main__":
    main()

"""The Python API against the command line: every function, its error paths, numpy dtypes and
shapes, and tables equal to the CLI's CSV to the last bit. Run by `tests/python.rs` (in
`cargo test`), which builds the package into its own virtual environment."""

import csv
import io
import os
import pathlib
import signal
import subprocess
import sys
import threading
import time
import warnings

import numpy as np
import pytest

import mbd

ROOT = pathlib.Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"
BIN = os.environ.get("MBD_BIN", str(ROOT / "target" / "release" / "mbd"))


def cli(*args, cwd=ROOT):
    out = subprocess.run([BIN, *map(str, args)], cwd=cwd, capture_output=True, text=True)
    return out


def csv_columns(text):
    """A CSV as columns, numbers read exactly (empty cells NaN), words kept."""
    rows = list(csv.reader(io.StringIO(text)))
    header, body = rows[0], rows[1:]
    out = {}
    for k, name in enumerate(header):
        cells = [r[k] if k < len(r) else "" for r in body]
        try:
            out[name] = np.array([float(c) if c else np.nan for c in cells])
        except ValueError:
            out[name] = np.array(cells, dtype=str)
    return out


def same_bits(a, b):
    """Equal to the last bit (NaN where both are NaN)."""
    if a.dtype.kind == "U" or b.dtype.kind == "U":
        return a.shape == b.shape and bool(np.all(a == b))
    return a.shape == b.shape and a.dtype == b.dtype and bool(np.all(a.view(np.uint64) == b.view(np.uint64)))


# -- compile -------------------------------------------------------------------------------

def test_compile_from_a_path_a_pathlib_path_and_text():
    m = mbd.compile(str(MODELS / "pendulum.mbd"))
    assert m.name == "pendulum"
    assert m.channels == ["x", "y", "vx", "vy", "ax", "ay", "tension"]
    assert m.params == {"m": 1.0, "L": 0.5, "V0": 1.5, "e": 0.1}
    assert (m.dt, m.until, m.steps) == (0.005, 1.0, 200)
    assert mbd.compile(MODELS / "pendulum.mbd").channels == m.channels
    text = (MODELS / "pendulum.mbd").read_text()
    assert mbd.compile(text).name == "pendulum"


def test_set_takes_numbers_in_si_and_texts_with_units():
    m = mbd.compile(MODELS / "pendulum.mbd", set={"V0": 2.5, "L": "50cm"})
    assert m.params["V0"] == 2.5
    assert m.params["L"] == 0.5
    with pytest.raises(mbd.ModelError) as e:
        mbd.compile(MODELS / "pendulum.mbd", set={"L": "5 kg"})
    assert e.value.diagnostics[0].code.startswith("E")


def test_a_model_error_carries_every_diagnostic_with_its_place_and_hint():
    text = (ROOT / "tests" / "ui" / "several_errors.mbd").read_text()
    with pytest.raises(mbd.ModelError) as e:
        mbd.compile(text)
    ds = e.value.diagnostics
    assert len([d for d in ds if d.severity == "error"]) >= 2
    for d in ds:
        assert isinstance(d, mbd.Diagnostic)
        assert len(d.code) == 5 and d.code[0] in "EW"
        assert d.file == "<string>"
        assert isinstance(d.line, int) and d.line >= 1
        assert isinstance(d.column, int) and d.column >= 1
        assert d.message
    assert any(d.hint for d in ds)
    assert str(ds[0]).startswith("<string>:")
    # The same diagnostics as `mbd check --format json`.
    out = cli("check", "tests/ui/several_errors.mbd", "--format", "json")
    assert out.returncode == 1
    assert [d.code for d in ds] == [d["code"] for d in __import__("json").loads(out.stderr)]


def test_warnings_go_through_pythons_warnings():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mbd.compile(ROOT / "tests" / "ui" / "unused_param.mbd")
    found = [w for w in caught if issubclass(w.category, mbd.MbdWarning)]
    assert found, [str(w.message) for w in caught]
    d = found[0].message.diagnostic
    assert d.severity == "warning" and d.code.startswith("W") and d.line == 2


# -- run -----------------------------------------------------------------------------------

@pytest.mark.parametrize(
    "model, flags, kwargs",
    [
        ("pendulum.mbd", [], {}),
        ("two_bar.mbd", ["--until", "2", "--every", "10"], dict(until=2.0, every=10)),
        ("windmill.mbd", ["--dt", "0.002", "--until", "1", "--integrator", "generalized-alpha"],
         dict(dt=0.002, until=1.0, integrator="generalized-alpha")),
    ],
)
def test_a_run_equals_the_cli_csv_to_the_last_bit(tmp_path, model, flags, kwargs):
    out = tmp_path / "run.csv"
    done = cli("run", MODELS / model, "-o", out, *flags)
    assert done.returncode == 0, done.stderr
    want = csv_columns(out.read_text())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", mbd.MbdWarning)
        r = mbd.compile(MODELS / model).run(**kwargs)
    assert r.ok and r.failure is None
    assert r.columns == list(want)
    assert r.columns[0] == "t"
    for name, col in want.items():
        assert r[name].dtype == np.float64
        assert r[name].shape == (len(col),)
        assert same_bits(r[name], col), name
    assert same_bits(r.t, want["t"])
    rec = r.record
    assert rec.steps == int(round(r.t[-1] / (kwargs.get("dt") or mbd.compile(MODELS / model).dt)))
    assert rec.newton_iterations >= rec.steps
    assert rec.cpu_s >= 0.0 and r.cpu_s == rec.cpu_s


def test_to_pandas_gives_the_same_columns():
    pd = pytest.importorskip("pandas")
    r = mbd.compile(MODELS / "pendulum.mbd").run(until=0.1)
    df = r.to_pandas()
    assert isinstance(df, pd.DataFrame)
    assert list(df.columns) == r.columns
    assert df.shape == (r.rows, len(r))
    assert same_bits(df["tension"].to_numpy(), r["tension"])


def test_settings_out_of_range_raise_value_error():
    m = mbd.compile(MODELS / "pendulum.mbd")
    with pytest.raises(ValueError, match="dt must be a positive"):
        m.run(dt=-1.0)
    with pytest.raises(ValueError, match="integrator must be one of"):
        m.run(integrator="euler")
    with pytest.raises(ValueError, match="alpha"):
        m.run(alpha=0.5)
    with pytest.raises(KeyError, match="no column `nope`"):
        m.run(until=0.01)["nope"]


def test_a_failed_run_returns_the_rows_so_far_with_the_failure():
    # A pendulum kicked by an absurd load from 0.05 s: Newton fails in the step from 0.05 s,
    # the CLI exits 3 and keeps the rows written.
    text = (
        'model bad "a pendulum kicked by an absurd load at 0.05 s"\n'
        "ground earth\n"
        "point_mass bob { mass = 1 kg, at = (0, -1, 0) m, velocity = (1, 0, 0) m/s }\n"
        "joint rope = distance(earth, bob) { length = 1 m }\n"
        "force kick on bob = (1e40 N * piecewise { 0 s: 0, 0.05 s: 0, 0.06 s: 1 }, 0, 0)\n"
        "output y = bob.position.y\n"
        "solve hht { dt = 0.01 s, until = 1 s }\n"
    )
    path = ROOT / "target" / "py_failing.mbd"
    path.write_text(text)
    csv_path = ROOT / "target" / "py_failing.csv"
    done = cli("run", path, "-o", csv_path)
    assert done.returncode == 3, done.stderr
    want = csv_columns(csv_path.read_text())
    r = mbd.compile(path).run()
    assert not r.ok
    f = r.failure
    assert isinstance(f, mbd.RunFailure)
    assert f.diagnostic.code == "E0601" and "E0601" in done.stderr
    assert f.t == 0.05 and f.step == 6 and f.entity == "point mass bob"
    assert f.diagnostic.line == 3 and f.diagnostic.file.endswith("py_failing.mbd")
    assert f.diagnostic.hint
    assert r.rows == len(want["t"]) >= 2
    assert same_bits(r["y"], want["y"])
    assert r.record is None


def test_the_gil_is_released_while_simulating():
    m = mbd.compile(MODELS / "windmill.mbd")
    started, done = threading.Event(), threading.Event()
    ticks = 0

    def work():
        started.set()
        m.run(until=1.0)
        done.set()

    t = threading.Thread(target=work)
    t.start()
    started.wait()
    while not done.is_set():
        ticks += 1
    t.join()
    # With the GIL held through the run, this thread would not run between the two events.
    assert ticks > 1000, ticks


def test_ctrl_c_stops_a_run_cleanly_and_the_next_run_goes_on():
    script = (
        "import mbd, sys, time\n"
        "m = mbd.compile(sys.argv[1])\n"
        "print('ready', flush=True)\n"
        "t0 = time.time()\n"
        "try:\n"
        "    m.run(until=1e4)\n"
        "    print('finished')\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted after', round(time.time() - t0, 1), flush=True)\n"
        "r = m.run(until=0.01)\n"
        "print('again', r.ok, r.rows)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", script, str(MODELS / "pendulum.mbd")],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "ready"
    time.sleep(1.0)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 0, err
    assert "interrupted after" in out, out + err
    assert "again True 3" in out, out + err


def test_runs_from_several_threads_at_once_and_one_after_another_agree():
    m = mbd.compile(MODELS / "two_bar.mbd")
    want = m.run(until=0.5)
    results = [None] * 4

    def work(k):
        results[k] = m.run(until=0.5)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results + [m.run(until=0.5)]:
        assert r.ok and r.rows == want.rows
        assert same_bits(r["xc2"], want["xc2"])


def test_a_worker_is_reused_and_ends_when_idle():
    def workers():
        tasks = pathlib.Path("/proc/self/task")
        return sum((t / "comm").read_text().strip() == "mbd" for t in tasks.iterdir())

    def none_left():
        # A worker ends 1 s after its last call (a loaded machine may wake it later).
        deadline = time.monotonic() + 10.0
        while workers() > 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        return workers() == 0

    m = mbd.compile(MODELS / "pendulum.mbd")
    assert none_left()
    for _ in range(5):
        m.run(until=0.1)
        assert workers() == 1
    assert none_left()


def test_a_child_forked_after_a_run_runs_too():
    # The parent's worker threads are not in the child: a child that sent its run to one
    # of them would wait for ever.
    script = (
        "import mbd, os, sys\n"
        "m = mbd.compile(sys.argv[1])\n"
        "print('parent', m.run(until=0.1).rows, flush=True)\n"
        "pid = os.fork()\n"
        "if pid == 0:\n"
        "    print('child', m.run(until=0.1).rows, flush=True)\n"
        "    os._exit(0)\n"
        "os.waitpid(pid, 0)\n"
        "print('parent again', m.run(until=0.1).rows, flush=True)\n"
    )
    p = subprocess.run([sys.executable, "-c", script, str(MODELS / "pendulum.mbd")],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    lines = [line.rsplit(" ", 1) for line in p.stdout.splitlines()]
    assert [who for who, _ in lines] == ["parent", "child", "parent again"], p.stdout
    assert len({rows for _, rows in lines}) == 1 and int(lines[0][1]) > 1, p.stdout


# -- modes ---------------------------------------------------------------------------------

def test_modes_equal_the_cli_tables(tmp_path):
    table, shapes = tmp_path / "modes.csv", tmp_path / "shapes.csv"
    done = cli("modes", MODELS / "rotating_beam.mbd", "-o", table, "--shapes", shapes, "--count", "4")
    assert done.returncode == 0, done.stderr
    m = mbd.compile(MODELS / "rotating_beam.mbd")
    t, s = m.modes(count=4, shapes=True)
    for got, path in ((t, table), (s, shapes)):
        want = csv_columns(path.read_text())
        assert got.columns == list(want)
        for name in want:
            assert same_bits(got[name], want[name]), name
    assert t["frame"].dtype.kind == "U" and list(t["frame"]) == ["rotating"] * 4
    assert t["omega_rad_s"].dtype == np.float64 and t.rows == 4
    assert m.modes().rows > 4


def test_modes_of_a_periodic_model_raise_e0605():
    with pytest.raises(mbd.ModelError) as e:
        mbd.compile(MODELS / "windmill.mbd").modes()
    assert e.value.diagnostics[0].code == "E0605"
    assert mbd.compile(MODELS / "windmill.mbd").modes(frozen=True)["frame"][0] == "frozen"


# -- stability and sweeps ------------------------------------------------------------------

SWEEP = (0.9, 2.6, 0.1)


@pytest.fixture(scope="module")
def cli_stability(tmp_path_factory):
    out = tmp_path_factory.mktemp("stab") / "stab.csv"
    done = cli("stability", MODELS / "windmill.mbd", "--sweep", "Omega_bar=0.9:2.6:0.1", "-o", out)
    assert done.returncode == 0, done.stderr
    return out.read_text()


def test_stability_equals_the_cli_csv(cli_stability):
    m = mbd.compile(MODELS / "windmill.mbd")
    s = m.stability({"Omega_bar": mbd.grid(*SWEEP)})
    assert s.csv == cli_stability
    want = csv_columns(cli_stability)
    for name in want:
        assert same_bits(s[name], want[name]), name
    assert s["method"].dtype.kind == "U"
    assert len(s.edges) == 2
    (lo, hi), = s.unstable
    # The multiblade equations' edges are 1.17736 and 2.31860 (tests/rotor_stability.rs).
    assert abs(lo - 1.17736) < 2e-3 and abs(hi - 2.31860) < 2e-3
    assert s.failed == []
    assert list(mbd.grid(*SWEEP)) == [float(x) for x in want["Omega_bar"]]


def test_stability_errors():
    m = mbd.compile(MODELS / "windmill.mbd")
    with pytest.raises(mbd.ModelError) as e:
        m.stability({"nope": [1.0]})
    assert e.value.diagnostics[0].code == "E0208" and "Omega_bar" in e.value.diagnostics[0].hint
    with pytest.raises(ValueError, match="method must be"):
        m.stability({"Omega_bar": [1.0]}, method="guess")
    with pytest.raises(ValueError, match="no joint driven at a constant speed"):
        mbd.compile(MODELS / "pendulum.mbd").stability({"V0": [1.0]})
    with pytest.raises(ValueError):
        mbd.grid(1.0, 0.0, 0.1)


def test_sweep_locally_and_on_a_dask_cluster_give_the_cli_table(cli_stability):
    distributed = pytest.importorskip("distributed")
    want = csv_columns(cli_stability)
    local = mbd.sweep(MODELS / "windmill.mbd", {"Omega_bar": mbd.grid(*SWEEP)})
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        pids = set(client.run(os.getpid).values())
        assert len(pids) == 2 and os.getpid() not in pids
        remote = mbd.sweep(MODELS / "windmill.mbd", {"Omega_bar": mbd.grid(*SWEEP)}, client=client, shards=3)
        # Two params, a function of the model at each point, on the cluster and locally.
        grid = {"Omega_bar": [1.0, 1.5], "e": [0.0, 0.1]}
        peak = lambda m: {"peak": float(np.abs(m.run(until=0.2)["zeta1"]).max()), "os_pid": float(os.getpid())}
        f_remote = mbd.sweep(MODELS / "windmill.mbd", grid, peak, client=client)
        modes_remote = mbd.sweep(MODELS / "rotating_beam.mbd", {"Omega": [5.0, 10.0]}, "modes", client=client, count=3)
    for table in (local, remote):
        assert table.columns == list(want)
        for name in want:
            assert same_bits(table[name], want[name]), name
    (_, stab), = remote.stabilities
    assert len(stab.edges) == 2
    f_local = mbd.sweep(MODELS / "windmill.mbd", grid, peak)
    assert f_remote.columns == ["Omega_bar", "e", "peak", "os_pid"]
    assert list(f_remote["Omega_bar"]) == [1.0, 1.0, 1.5, 1.5]
    assert list(f_remote["e"]) == [0.0, 0.1, 0.0, 0.1]
    assert same_bits(f_remote["peak"], f_local["peak"])
    assert set(f_remote["os_pid"]) <= {float(p) for p in pids}
    assert set(f_local["os_pid"]) == {float(os.getpid())}
    modes_local = mbd.sweep(MODELS / "rotating_beam.mbd", {"Omega": [5.0, 10.0]}, "modes", count=3)
    assert modes_local.columns == ["Omega", "mode", "frequency_hz", "omega_rad_s", "damping_ratio",
                                   "real_per_s", "imag_rad_s", "frame"]
    assert modes_local.rows == 6
    for name in modes_local:
        assert same_bits(modes_local[name], modes_remote[name]), name


def test_sweep_errors():
    with pytest.raises(ValueError, match="no param `nope`"):
        mbd.sweep(MODELS / "windmill.mbd", {"nope": [1.0]})
    with pytest.raises(ValueError, match="analysis must be"):
        mbd.sweep(MODELS / "windmill.mbd", {"Omega_bar": [1.0]}, "guess")
    with pytest.raises(TypeError, match="stability takes"):
        mbd.sweep(MODELS / "windmill.mbd", {"Omega_bar": [1.0]}, bogus=1)


def test_a_model_pickles():
    import pickle
    m = mbd.compile(MODELS / "pendulum.mbd", set={"V0": 2.0})
    m2 = pickle.loads(pickle.dumps(m))
    assert m2.params == m.params and m2.sets == m.sets
    assert same_bits(m2.run(until=0.05)["x"], m.run(until=0.05)["x"])


# -- studies -------------------------------------------------------------------------------

def test_a_convergence_study_equals_the_cli_csv(tmp_path):
    out = tmp_path / "study.csv"
    done = cli("study", MODELS / "pendulum.mbd", "--channel", "x", "--integrator", "hht,generalized-alpha",
               "--steps", "50,100", "-o", out)
    assert done.returncode == 0, done.stderr
    want = csv_columns(out.read_text())
    got = mbd.compile(MODELS / "pendulum.mbd").study("x", ["hht", "generalized-alpha"], steps=[50, 100])
    assert got.columns == list(want)
    for name in want:
        if name in ("cpu_s",):
            continue
        assert same_bits(got[name], want[name]), name
    assert got.rows == 4


def test_a_stability_study_and_study_errors(tmp_path):
    out = tmp_path / "alpha.csv"
    done = cli("study", MODELS / "pendulum.mbd", "--channel", "x", "--alpha", "0,-0.1", "-o", out)
    assert done.returncode == 0, done.stderr
    want = csv_columns(out.read_text())
    got = mbd.compile(MODELS / "pendulum.mbd").study("x", alphas=[0, -0.1])
    assert got.columns == list(want) and got.rows == 2
    assert same_bits(got["alpha"], want["alpha"])
    m = mbd.compile(MODELS / "pendulum.mbd")
    with pytest.raises(ValueError, match="needs the steps"):
        m.study("x", ["hht"])
    with pytest.raises(ValueError, match="no output channel `nope`"):
        m.study("nope", alphas=[0])
    with pytest.raises(ValueError, match="one of them"):
        m.study("x")


# -- the example ---------------------------------------------------------------------------

@pytest.mark.parametrize("flags", [[], ["--dask", "2"]])
def test_the_example_draws_the_windmill_stability_map(tmp_path, flags):
    out = tmp_path / "map.png"
    done = subprocess.run([sys.executable, str(ROOT / "examples" / "windmill_stability.py"), "--step", "0.1",
                           "-o", str(out), *flags], capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "unstable: 1.17" in done.stdout and "< 2.31" in done.stdout, done.stdout

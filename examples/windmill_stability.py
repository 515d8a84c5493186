"""The windmill's stability map from Python: the growth rates of its modes against the rotor
speed Omega_bar (the paper's P5 ground resonance), drawn with matplotlib, and the same sweep
on a Dask cluster.

    pip install .  matplotlib            # the package, from the repository's root
    python examples/windmill_stability.py -o windmill_stability.png
    python examples/windmill_stability.py --dask 2 -o windmill_stability.png   # 2 Dask workers

With --dask N the sweep runs on a local Dask cluster of N worker processes; give
--scheduler ADDRESS to use an existing cluster instead (e.g. one started by dask-jobqueue on
Slurm). Either way the table is the one `mbd stability` writes, bit for bit.
"""

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import mbd  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--step", type=float, default=0.05, help="the grid's step in Omega_bar")
    ap.add_argument("--dask", type=int, metavar="N", help="run on a local Dask cluster of N workers")
    ap.add_argument("--scheduler", help="the address of a running Dask scheduler")
    ap.add_argument("-o", "--output", default="windmill_stability.png")
    a = ap.parse_args()

    model = mbd.compile(ROOT / "models" / "windmill.mbd")
    values = mbd.grid(0.8, 2.6, a.step)
    if a.dask or a.scheduler:
        from distributed import Client, LocalCluster

        cluster = None if a.scheduler else LocalCluster(n_workers=a.dask, threads_per_worker=1, dashboard_address=None)
        with Client(a.scheduler or cluster) as client:
            table = mbd.sweep(model, {"Omega_bar": values}, client=client)
        if cluster is not None:
            cluster.close()
        (_, stab), = table.stabilities
    else:
        stab = model.stability({"Omega_bar": values})
        table = stab.table

    fig, ax = plt.subplots(figsize=(8, 4.5))
    x = table["Omega_bar"]
    k = 1
    while f"real{k}" in table:
        ax.plot(x, table[f"real{k}"], ".", color="0.6", ms=3, label="Re s of each mode" if k == 1 else None)
        k += 1
    ax.plot(x, table["max_real"], "-", color="C3", label="largest Re s")
    for lo, hi in stab.unstable:
        ax.axvspan(lo, hi, color="C3", alpha=0.12, label="unstable")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("Omega_bar = Omega / omega_T")
    ax.set_ylabel("Re s [1/s]")
    ax.set_title(f"{model.name}: growth rates against the rotor speed ({'Dask' if a.dask or a.scheduler else 'local'})")
    ax.set_ylim(min(-0.5, float(np.nanmin(table['max_real'])) - 0.1), float(np.nanmax(table["max_real"])) * 1.2 + 0.1)
    ax.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(a.output, dpi=110)
    for lo, hi in stab.unstable:
        print(f"unstable: {lo:.6g} < Omega_bar < {hi:.6g}")
    print(f"chart written to {a.output}")


if __name__ == "__main__":
    main()

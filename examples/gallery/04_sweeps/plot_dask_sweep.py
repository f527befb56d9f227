"""
A grid sweep on Dask, resumable, and its map
============================================

Where should the absorber sit, and how heavy should it be? A sweep runs the scene at every point of a grid
over dotted scene keys (``absorber.mass``, ``contact.gap``...) and writes one row per point. The same call
runs on a local process pool or on any Dask cluster (``recoil sweep --scheduler tcp://HOST:PORT``; from
Python, ``scheduler=`` takes the address or a ``dask.distributed.Client``). Rows go to the file as they
finish, and running the same sweep again on that file resumes it: only the points not yet in the file run.
"""

# %%
# A Dask cluster in this process
# ------------------------------
# A real cluster is started with ``dask scheduler`` and ``dask worker`` on its machines (or by
# dask-jobqueue on a batch system). For this example a ``LocalCluster`` of two worker threads of this
# process stands in for it: the sweep sees a Dask scheduler either way.
import tempfile
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from dask.distributed import Client, LocalCluster

from mbs_models import model_ii, run_sweep

cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None)
client = Client(cluster)
print(f"Dask scheduler {cluster.scheduler_address} with {len(client.scheduler_info()['workers'])} workers")

# %%
# The grid and the table
# ----------------------
# Model (ii), the absorber on the ground: 6 masses from 100 to 2000 kg times 7 gaps from 0 to 120 mm, 42
# points. Each run simulates up to 10 s at ``draft`` accuracy but stops as soon as the recoil length and
# the peak force on the mount are proven final (``stop_when_final``), which is all the map needs.
outputs = tempfile.TemporaryDirectory(prefix="recoil-gallery-")   # removed at the end
table_file = Path(outputs.name) / "absorber_map.csv"
grid = {"absorber.mass": "100:2000:6", "contact.gap": "0:0.12:7"}
settings = dict(end_time=10.0, accuracy="draft", stop_when_final=["max_barrel_displacement", "peak_support_force"],
                progress=False)

start = time.perf_counter()
table = run_sweep(model_ii(), grid, scheduler=client, out=table_file, **settings)
print(f"{len(table)} points in {time.perf_counter() - start:.1f} s on Dask; statuses: "
      f"{table['status'].value_counts().to_dict()}")
print(table[["absorber.mass", "contact.gap", "max_barrel_displacement", "peak_support_force", "end_time"]].head(8)
      .to_string(index=False))

# %%
# Resuming a killed sweep
# -----------------------
# A sweep of thousands of points is killed some day (a wall-time limit, a reboot). Here we cut the file after
# its first 20 rows, as a killed sweep leaves it, and run the same call again: only the 22 missing points
# run, and the finished table equals the uninterrupted one (``wall_time`` aside). Every row read back is
# checked first; a half-written last line would be dropped and its point run again.
lines = table_file.read_text().splitlines(keepends=True)
table_file.write_text("".join(lines[:21]))          # the header and 20 rows
summary = run_sweep(model_ii(), grid, scheduler=client, out=table_file, table=False, **settings)
print({key: summary[key] for key in ("points", "resumed", "run", "failed")})
resumed = run_sweep(model_ii(), grid, scheduler=client, out=table_file, **settings)   # nothing left to run
metrics = ["max_barrel_displacement", "peak_support_force"]
print("resumed table equals the uninterrupted one:", resumed[metrics].equals(table[metrics]))
client.close()
cluster.close()

# %%
# The numbers do not depend on what ran them: the same grid in this process alone (``workers=1``) gives the
# same table, to the last bit.
serial = run_sweep(model_ii(), grid, workers=1, **settings)
print("serial run equals the Dask run:", serial[metrics].equals(table[metrics]))

# %%
# The map
# -------
# The recoil length and the peak force on the mount over the grid, each cell drawn as the point it is (no
# interpolation across a coarse grid). A heavier absorber shortens the recoil at every gap, and a wider gap
# lengthens it. The force on the mount varies far less, and everywhere on this grid it stays above the
# simplified model's peak (the first example): with the absorber on the ground, its actuator passes its load
# to the mount, so a shorter recoil is not a smaller load on the mount.
masses = np.sort(table["absorber.mass"].unique())
gaps = np.sort(table["contact.gap"].unique())
fig, axes = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
for ax, (column, scale, label) in zip(axes, (("max_barrel_displacement", 1e3, "recoil length [mm]"),
                                             ("peak_support_force", 1e-3, "peak force on the mount [kN]"))):
    values = table.pivot(index="absorber.mass", columns="contact.gap", values=column).loc[masses, gaps] * scale
    image = ax.pcolormesh(np.arange(len(gaps) + 1), np.arange(len(masses) + 1), values.to_numpy(), cmap="viridis")
    for i in range(len(masses)):
        for j in range(len(gaps)):
            ax.text(j + 0.5, i + 0.5, f"{values.iloc[i, j]:.0f}" if scale > 1 else f"{values.iloc[i, j]:.1f}",
                    ha="center", va="center", fontsize=7, color="white")
    ax.set_xticks(np.arange(len(gaps)) + 0.5, [f"{1e3 * g:.0f}" for g in gaps])
    ax.set_yticks(np.arange(len(masses)) + 0.5, [f"{m:.0f}" for m in masses])
    ax.set_xlabel("gap [mm]")
    ax.set_ylabel("absorber mass [kg]")
    fig.colorbar(image, ax=ax, label=label)
best = table.loc[table["max_barrel_displacement"].idxmin()]
for column, scale, unit in (("max_barrel_displacement", 1e3, "mm"), ("peak_support_force", 1e-3, "kN")):
    print(f"{column} [{unit}] by mass (rows) and gap (columns):")
    print((table.pivot(index="absorber.mass", columns="contact.gap", values=column) * scale).round(1).to_string())
print(f"shortest recoil {1e3 * best['max_barrel_displacement']:.1f} mm at m = {best['absorber.mass']:.0f} kg, "
      f"gap {1e3 * best['contact.gap']:.0f} mm")
plt.show()
outputs.cleanup()

# %% [markdown]
# # A tinydem study from Python
#
# Run a scenario, plot its kinetic energy, look at it, then step a simulation by hand.
# A notebook in cells (`# %%`): run it cell by cell in VS Code or Jupyter (jupytext), or
# whole with `python3 examples/python/study.py`. Needs `python3 -m pip install ./python`
# (and matplotlib for the plot, if you want one).

# %%
from pathlib import Path

import numpy as np

import tinydem

here = Path(__file__).resolve().parent
scenario = here / "scenario.toml"

# %% [markdown]
# ## 1. Run it as the command line does
# `tinydem.run` writes the output directory: frames, `run.toml` (the resolved scenario),
# `frames.csv` (frame, step, time), `log.csv` (the state per frame) and a checkpoint.

# %%
out = tinydem.run(scenario, output=here / "output", overwrite=True)
run = tinydem.read_output(out)
print(run, "- last frame at", run.times[-1], "s")

# %% [markdown]
# ## 2. Plot the kinetic energy
# The log has one row per frame; no scenario needed a second time.

# %%
log = run.log
peak = int(np.argmax(log["kinetic_energy"]))
print(
    f"kinetic energy peaks at t = {log['time'][peak]:.3f} s: "
    f"{log['kinetic_energy'][peak]:.3e} J"
)
print(
    f"at the end: {log['kinetic_energy'][-1]:.3e} J, "
    f"{log['contacts_per_particle'][-1]:.2f} contacts per particle"
)
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.semilogy(log["time"], log["kinetic_energy"])
    ax.set_xlabel("time [s]")
    ax.set_ylabel("kinetic energy [J]")
    fig.tight_layout()
    fig.savefig(here / "output" / "kinetic_energy.png", dpi=150)
except ImportError:
    print("(no matplotlib: `tinydem analyze output --plot ke.png` draws the same)")

# %% [markdown]
# ## 3. Pictures and an animation
# One view and one colour range for all frames; a GIF (or MP4 with ffmpeg installed).

# %%
pictures = tinydem.render(out, gif=True, scale_bar=True, width=640, height=480)
print(len(pictures["pictures"]), "pictures,", "animation in", pictures["animation"])

# %% [markdown]
# ## 4. A frame as numpy arrays
# Columns by name, rows in particle id order.

# %%
frame = run[-1]
below = np.mean(frame["z"] < 0.15)  # the throat is at z = 0.15 m
print(f"{below:.0%} of the grains are below the throat at t = {run.times[-1]:.2f} s")

# %% [markdown]
# ## 5. Step it yourself
# The engine itself, stepped from Python: the same bits as the command line. Here, half way
# through, every grain is given an upward kick.

# %%
sim = tinydem.Simulation(scenario)
sim.step(10_000)
print(sim)
v = sim.velocities
v[:, 2] += 0.5  # m/s upward
sim.velocities = v
sim.step(2_000)
print(
    f"after the kick: mean height {sim.positions[:, 2].mean():.4f} m, "
    f"kinetic energy {sim.thermo()['kinetic_energy']:.3e} J"
)
sim.checkpoint(here / "output" / "kicked.bin")  # `tinydem run --resume` goes on from here

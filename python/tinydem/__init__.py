"""tinydem: a granular DEM simulator (the model of the TinyDEM paper), from Python.

The engine itself, not a wrapper around the command line: stepping a ``Simulation`` gives
bitwise the states ``tinydem run`` computes.

    import tinydem
    out = tinydem.run("scenario.toml", output="out")       # as `tinydem run`
    log = tinydem.read_output(out).log                     # log.csv as numpy columns
    sim = tinydem.Simulation("scenario.toml")               # or step it yourself
    sim.step(1000)
    sim.positions                                           # (N, 3) numpy array, id order
    tinydem.render(out, gif=True)                           # pictures and an animation

Arrays are numpy copies in id order, the order of the frames' rows.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Dict, Iterator, List, Optional, Sequence, Union, overload

import numpy as np

from ._tinydem import Simulation, __version__, fields, read_csv, render, run

__all__ = [
    "Simulation",
    "Output",
    "run",
    "render",
    "fields",
    "read_frame",
    "read_output",
    "read_table",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]

#: Columns that hold whole numbers; read as int64, the others as float64.
WHOLE_COLUMNS = frozenset(
    {
        "tag",
        "id",
        "material",
        "fixed",
        "frame",
        "step",
        "particles",
        "pair_contacts",
        "wall_contacts",
        "removed",
        "outlet",
        "count",
        "mesh",
        "id_i",
        "id_j",
        "face",
    }
)


def read_table(path: PathLike) -> Dict[str, np.ndarray]:
    """Reads a numeric CSV file of tinydem (a frame, ``log.csv``, ``frames.csv``,
    ``walls.csv``, ``outlets.csv``, a contact network) as a dict of numpy arrays by column
    name, in the file's column order. Whole-number columns (ids, tags, counts) are int64."""
    names, values = read_csv(os.fspath(path))
    table: Dict[str, np.ndarray] = {}
    for k, name in enumerate(names):
        column = np.ascontiguousarray(values[:, k])
        table[name] = column.astype(np.int64) if name in WHOLE_COLUMNS else column
    return table


def read_frame(path: PathLike) -> Dict[str, np.ndarray]:
    """Reads a frame ``particlesNNNNNN.csv`` as a dict of numpy arrays by column: ``x``,
    ``y``, ``z``, ``R``, ``vx`` ... ``wz`` (float64) and, where the frame has them, ``tag``,
    ``id``, ``material``, ``fixed`` (int64). Rows are particles in id order. A frame that a
    split run wrote in pieces (``particlesNNNNNN_K.csv``, ``[output] gather``) is read as
    one; so is a contact network ``contactsNNNNNN.csv``."""
    path = Path(path)
    if path.is_file():
        return read_table(path)
    found = {}
    for piece in path.parent.glob(f"{path.stem}_*{path.suffix}"):
        number = piece.stem[len(path.stem) + 1 :]
        if number.isdigit():
            found[int(number)] = piece
    if not found:
        raise FileNotFoundError(f"{path}: no such frame, nor pieces {path.stem}_K{path.suffix}")
    missing = [k for k in range(max(found) + 1) if k not in found]
    if missing:
        raise FileNotFoundError(f"{path}: the piece {path.stem}_{missing[0]}{path.suffix} is missing")
    tables = [read_table(found[k]) for k in sorted(found)]
    joined = {name: np.concatenate([t[name] for t in tables]) for name in tables[0]}
    if "id" in joined:
        order = np.argsort(joined["id"], kind="stable")
    else:  # a contact network: the order of the gathered file
        face = joined["face"] >= 0
        order = np.lexsort((np.where(face, joined["face"], joined["id_j"]), joined["id_i"], face))
    return {name: column[order] for name, column in joined.items()}


class Frames(Sequence[Dict[str, np.ndarray]]):
    """The frames of an output directory, read when indexed (``frames[k]``, negative
    indices and slices too), each as ``read_frame`` returns it."""

    def __init__(self, paths: List[Path]):
        self._paths = paths

    def __len__(self) -> int:
        return len(self._paths)

    @overload
    def __getitem__(self, k: int) -> Dict[str, np.ndarray]: ...

    @overload
    def __getitem__(self, k: slice) -> List[Dict[str, np.ndarray]]: ...

    def __getitem__(self, k):
        if isinstance(k, slice):
            return [read_frame(p) for p in self._paths[k]]
        return read_frame(self._paths[k])

    def __iter__(self) -> Iterator[Dict[str, np.ndarray]]:
        return (read_frame(p) for p in self._paths)

    @property
    def paths(self) -> List[Path]:
        """The frame files, in frame order."""
        return list(self._paths)


class Output:
    """An output directory of a run: its frames (lazily loaded), their times and steps, and
    its logs. ``len(out)`` is the number of frames, ``out[k]`` frame k."""

    def __init__(self, directory: PathLike):
        self.dir = Path(directory)
        listing = self.dir / "frames.csv"
        if not listing.is_file():
            raise FileNotFoundError(
                f"{self.dir}: no frames.csv (not the output directory of a tinydem run)"
            )
        frames = read_table(listing)
        self.numbers: np.ndarray = frames["frame"]
        #: Simulated time of each frame [s] and its time step number.
        self.times: np.ndarray = frames["time"]
        self.steps: np.ndarray = frames["step"]
        paths = [self.dir / f"particles{k:06d}.csv" for k in self.numbers]
        self.frames = Frames(paths)

    @property
    def scenario(self) -> Path:
        """The resolved scenario of the run (``run.toml``): every default filled in."""
        return self.dir / "run.toml"

    @property
    def checkpoint(self) -> Path:
        """The run's last checkpoint, for ``Simulation(..., resume=...)`` or a new stage."""
        return self.dir / "checkpoint.bin"

    @property
    def log(self) -> Dict[str, np.ndarray]:
        """``log.csv``: per frame the time, particles, kinetic energy, contacts per
        particle, the deepest overlap relative to the radius, particles removed."""
        return read_table(self.dir / "log.csv")

    def table(self, name: str) -> Dict[str, np.ndarray]:
        """Another log of the directory by file name (``walls.csv``, ``outlets.csv``)."""
        return read_table(self.dir / name)

    def __len__(self) -> int:
        return len(self.frames)

    def __getitem__(self, k: int) -> Dict[str, np.ndarray]:
        return self.frames[k]

    def __iter__(self) -> Iterator[Dict[str, np.ndarray]]:
        return iter(self.frames)

    def __repr__(self) -> str:
        end = f", t = {self.times[-1]:.6g} s" if len(self.times) else ""
        return f"<tinydem.Output {str(self.dir)!r}: {len(self)} frames{end}>"


def read_output(directory: PathLike) -> Output:
    """The output directory of a run (``tinydem run`` or ``tinydem.run``), read lazily."""
    return Output(directory)

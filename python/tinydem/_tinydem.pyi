"""Type stubs of the engine module (Rust, pyo3): see tinydem/__init__.py for the readers."""

import os
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]

__version__: str

class Simulation:
    """A simulation of a scenario file, stepped from Python; arrays are copies in id order.

    Stepping gives bitwise the states of `tinydem run` for any number of threads."""

    def __init__(
        self,
        scenario: _Path,
        threads: Optional[int] = None,
        resume: Optional[_Path] = None,
        from_checkpoint: Optional[_Path] = None,
        force: bool = False,
    ) -> None: ...
    def step(self, n: int = 1, force: bool = False) -> None:
        """Advances by n >= 0 time steps; RuntimeError when the run becomes unstable, and at
        every later call (with that diagnosis, doing nothing) unless force=True. Overlaps past
        the smaller radius are said as RuntimeWarnings, as the command line says them."""
    @property
    def time(self) -> float:
        """Simulated time [s]."""
    @property
    def steps(self) -> int:
        """Time steps taken."""
    @property
    def timestep(self) -> float:
        """The time step [s]."""
    def __len__(self) -> int: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """(N, 3) centres [m]; settable with an (N, 3) array-like."""
    @positions.setter
    def positions(self, x: npt.ArrayLike) -> None: ...
    def add(
        self,
        positions: npt.ArrayLike,
        radii: npt.ArrayLike,
        velocities: Optional[npt.ArrayLike] = None,
        angular_velocities: Optional[npt.ArrayLike] = None,
        material: int = 0,
        tag: int = 0,
        allow_overlap: bool = False,
    ) -> npt.NDArray[np.int64]:
        """Adds particles with the next ids, which it returns. ValueError for radii outside
        [geometry] radius_min..radius_max, and for overlaps with other particles or mesh
        faces deeper than a tenth of the smaller radius unless allow_overlap=True."""
    def add_clump(
        self,
        clump: Union[str, int],
        position: Sequence[float],
        orientation: Optional[Sequence[float]] = None,
        velocity: Optional[Sequence[float]] = None,
        angular_velocity: Optional[Sequence[float]] = None,
        scale: float = 1.0,
        allow_overlap: bool = False,
    ) -> int:
        """Adds a clump of a [[clumps]] template (its name or index) with its centre of mass at
        position; returns the body's id (that of its first sphere). ValueError for overlaps
        deeper than a tenth of the smaller radius unless allow_overlap=True."""
    @property
    def bodies(self) -> npt.NDArray[np.int64]:
        """(N,) the body each particle is a sphere of (its id), -1 for a plain sphere."""
    def remove(self, ids: npt.ArrayLike) -> None:
        """Removes the particles of these ids."""
    def freeze(self, ids: npt.ArrayLike) -> None:
        """Fixes the particles of these ids: they stay where they are, at rest."""
    def unfreeze(self, ids: npt.ArrayLike) -> None:
        """Lets the particles of these ids move again."""
    @property
    def fixed(self) -> npt.NDArray[np.bool_]:
        """(N,) whether each particle is fixed."""
    @property
    def velocities(self) -> npt.NDArray[np.float64]:
        """(N, 3) velocities [m/s]; settable with an (N, 3) array."""
    @velocities.setter
    def velocities(self, v: npt.ArrayLike) -> None: ...
    @property
    def angular_velocities(self) -> npt.NDArray[np.float64]:
        """(N, 3) angular velocities [rad/s]; settable with an (N, 3) array."""
    @angular_velocities.setter
    def angular_velocities(self, w: npt.ArrayLike) -> None: ...
    @property
    def orientations(self) -> npt.NDArray[np.float64]:
        """(N, 4) unit quaternions (w, x, y, z)."""
    @property
    def radii(self) -> npt.NDArray[np.float64]:
        """(N,) radii [m]."""
    @property
    def ids(self) -> npt.NDArray[np.int64]:
        """(N,) particle ids, ascending."""
    @property
    def tags(self) -> npt.NDArray[np.int64]: ...
    @property
    def materials(self) -> npt.NDArray[np.int64]: ...
    def thermo(self) -> Dict[str, float]:
        """The columns of log.csv for the current state."""
    def write_frame(self, path: _Path) -> None:
        """Writes a CSV frame in the format of the run's particlesNNNNNN.csv."""
    def checkpoint(self, path: _Path) -> None:
        """Writes a checkpoint (resume=path continues it exactly)."""

def run(
    scenario: _Path,
    output: Optional[_Path] = None,
    threads: Optional[int] = None,
    overwrite: bool = False,
    force: bool = False,
    resume: Optional[_Path] = None,
    from_checkpoint: Optional[_Path] = None,
    quiet: bool = True,
) -> Path:
    """Runs a scenario as `tinydem run` does; returns the output directory."""

def read_csv(path: _Path) -> Tuple[List[str], npt.NDArray[np.float64]]:
    """A numeric CSV file: its column names and an (rows, columns) array."""

def render(
    path: _Path,
    output: Optional[_Path] = None,
    color: str = "speed",
    view: str = "iso",
    width: int = 1600,
    height: int = 1200,
    gif: bool = False,
    movie: bool = False,
    range: Optional[Tuple[float, float]] = None,
    bounds: Optional[Tuple[Tuple[float, float, float], Tuple[float, float, float]]] = None,
    scale_bar: bool = False,
    scenario: Optional[_Path] = None,
) -> Dict[str, object]:
    """Pictures of a frame or of every frame of a directory in one view and colour range;
    returns {"pictures": [paths], "animation": path or None, "notes": [str]}."""

def fields(
    directory: _Path,
    scenario: Optional[_Path] = None,
    spacing: Optional[float] = None,
    kernel: str = "gaussian",
    width: Optional[float] = None,
    slices: Optional[str] = None,
    frames: Optional[Tuple[int, int]] = None,
    average: bool = False,
    bounds: Optional[Tuple[Tuple[float, float, float], Tuple[float, float, float]]] = None,
) -> List[Dict[str, object]]:
    """Coarse-grained density, velocity and stress of a run's frames (as `tinydem analyze
    --fields`): a dict of numpy arrays per set, also written as fieldsNNNNNN.vti and .csv
    (slices_zNNNNNN.* in slices along z)."""

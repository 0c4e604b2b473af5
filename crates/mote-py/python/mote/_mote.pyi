"""Type stubs of mote's native module (see docs/python.md)."""

from os import PathLike
from typing import Any, Callable, Optional, Union

import numpy as np
import numpy.typing as npt

__version__: str

Path = Union[str, PathLike]

class MoteError(RuntimeError):
    """A run that could not go on (an I/O error, a refused request)."""

class UnstableError(MoteError):
    """A run that went unstable: the message names the step and the particle;
    the simulation keeps the state it reached."""

class Simulation:
    """A time-stepped simulation (gravity, springs, Lennard-Jones, granular,
    dipoles, Brownian dynamics) built from a scene: a file, a TOML string or a
    dict with the keys of docs/scene-format.md."""

    @staticmethod
    def from_file(path: Path, seed: Optional[int] = None, output: Optional[Path] = None) -> "Simulation":
        """A scene file or ``example:NAME``; ``seed`` replaces the scene's."""
    @staticmethod
    def from_toml(text: str, seed: Optional[int] = None, name: str = "<string>", output: Optional[Path] = None) -> "Simulation":
        """A scene given as TOML text; ``name`` labels its messages."""
    @staticmethod
    def from_dict(scene: dict[str, Any], seed: Optional[int] = None, output: Optional[Path] = None) -> "Simulation":
        """A scene given as a dict of the scene file's tables and keys."""
    @staticmethod
    def resume(path: Path) -> "Simulation":
        """The simulation a checkpoint holds, ready to go on bit for bit."""
    def save_checkpoint(self, path: Path) -> None:
        """Writes a checkpoint that ``Simulation.resume`` continues bit for bit."""
    def step(self, n: int = 1) -> None:
        """Advances ``n`` steps (the GIL is released meanwhile)."""
    def run(
        self,
        steps: Optional[int] = None,
        until: Optional[float] = None,
        callback: Optional[Callable[["Simulation"], Any]] = None,
        every: int = 100,
        progress: bool = False,
    ) -> None:
        """Runs ``steps`` steps or until time ``until`` (the scene's length when
        neither is given), calling ``callback(sim)`` every ``every`` steps."""
    time: float
    """Simulated time (settable between runs)."""
    dt: float
    """Time step (settable between runs)."""
    @property
    def steps(self) -> int:
        """Steps taken."""
    @property
    def seed(self) -> int:
        """The seed of the run's random numbers."""
    def __len__(self) -> int: ...
    positions: npt.NDArray[np.float64]
    """(N, 3) view of mote's memory; writes reach the next step; assigning
    an (N, 3) array copies it in (another shape raises ValueError)."""
    velocities: npt.NDArray[np.float64]
    """(N, 3) writable view; assignable like ``positions``."""
    @property
    def omegas(self) -> npt.NDArray[np.float64]:
        """(N, 3) angular velocities, writable view."""
    @property
    def dipoles(self) -> npt.NDArray[np.float64]:
        """(N, 3) magnetic dipole moments, writable view."""
    @property
    def masses(self) -> npt.NDArray[np.float64]:
        """(N,) writable view."""
    @property
    def radii(self) -> npt.NDArray[np.float64]:
        """(N,) writable view."""
    @property
    def charges(self) -> npt.NDArray[np.float64]:
        """(N,) writable view."""
    @property
    def box(self) -> Optional[tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], list[bool]]]:
        """(lo, hi, periodic), or None for an open system."""
    @property
    def output(self) -> Optional[Path]:
        """The folder the run writes its files to, or None."""
    @property
    def species(self) -> list[str]:
        """Species names of the particles."""
    @property
    def numbers(self) -> npt.NDArray[np.uint64]:
        """The scene's number of each row (from 0); granular scenes store
        their particles in space order, so row k is particle numbers[k]."""
    def render(self, output: Optional[Path] = None, width: int = 800, height: int = 600) -> Optional[npt.NDArray[np.uint8]]:
        """Ray-traces the current state: a (height, width, 3) image, or a PNG
        written to ``output``."""
    @property
    def observables(self) -> dict[str, npt.NDArray[np.float64]]:
        """The observables measured so far: time, kinetic, potential, total,
        rotational, kT, pressure, momentum, angular_momentum, magnetisation."""


class HardSpheres:
    """Event-driven hard disks or spheres (a scene with ``[event_driven]``):
    free flight between exact elastic collisions. A step is one output
    interval; ``run()`` goes to the scene's end in ``mote run``'s bits."""

    @staticmethod
    def from_file(path: Path, seed: Optional[int] = None, force: bool = False) -> "HardSpheres": ...
    @staticmethod
    def from_toml(text: str, seed: Optional[int] = None, name: str = "<string>", force: bool = False) -> "HardSpheres": ...
    @staticmethod
    def from_dict(scene: dict[str, Any], seed: Optional[int] = None, force: bool = False) -> "HardSpheres": ...
    def step(self, n: int = 1) -> None:
        """Advances n output intervals."""
    def run(
        self,
        steps: Optional[int] = None,
        until: Optional[float] = None,
        callback: Optional[Callable[["HardSpheres"], Any]] = None,
        every: int = 1,
        progress: bool = False,
    ) -> None:
        """steps output intervals, or to the scene's end; until is refused."""
    @property
    def time(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def last_step(self) -> int: ...
    @property
    def dimension(self) -> int: ...
    @property
    def seed(self) -> int: ...
    @property
    def box(self) -> npt.NDArray[np.float64]:
        """(D,) edge lengths of the box [0, L_0] x ..."""
    def __len__(self) -> int: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """(N, D) positions now, a copy."""
    @property
    def velocities(self) -> npt.NDArray[np.float64]: ...
    @property
    def radii(self) -> npt.NDArray[np.float64]: ...
    @property
    def masses(self) -> npt.NDArray[np.float64]: ...
    @property
    def observables(self) -> dict[str, npt.NDArray[np.float64]]:
        """The columns of mote run's observables.csv."""
    def render(self, output: Optional[Path] = None, width: int = 800, height: int = 600) -> Optional[npt.NDArray[np.uint8]]: ...


class Packing:
    """A packing from a ``[packing]`` scene: hard disks or spheres grown by
    Lubachevsky–Stillinger (a step is one pressure window), or soft spheres
    pressed by the SP method (``method = "soft"``: a step is a chunk of 100
    steps of the barostat or minimiser); ``run()`` takes it until it stops
    by itself (jammed, the scene's ``phi``, ``max_collisions`` or
    ``time_limit``, the soft method's finish), in ``mote run``'s bits."""

    @staticmethod
    def from_file(path: Path, seed: Optional[int] = None) -> "Packing": ...
    @staticmethod
    def from_toml(text: str, seed: Optional[int] = None, name: str = "<string>") -> "Packing": ...
    @staticmethod
    def from_dict(scene: dict[str, Any], seed: Optional[int] = None) -> "Packing": ...
    def step(self, n: int = 1) -> None:
        """Advances n packing steps (fewer where the packing stops)."""
    def run(
        self,
        steps: Optional[int] = None,
        until: Optional[float] = None,
        callback: Optional[Callable[["Packing"], Any]] = None,
        every: int = 1,
        progress: bool = False,
    ) -> None:
        """steps packing steps, or until the packing stops; until is refused."""
    @property
    def time(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def dimension(self) -> int: ...
    @property
    def seed(self) -> int: ...
    @property
    def stopped(self) -> Optional[str]:
        """pressure (jammed), target-phi, collisions, wall-clock (soft: done), or None while it goes on."""
    @property
    def phi(self) -> float: ...
    @property
    def pressure(self) -> float:
        """Reduced pressure Z = PV/(NkT) of the last window (soft: P/K of the last held or minimised state)."""
    @property
    def collisions(self) -> Optional[int]: ...
    @property
    def box(self) -> npt.NDArray[np.float64]: ...
    def __len__(self) -> int: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """(N, D) positions now, a copy."""
    @property
    def radii(self) -> npt.NDArray[np.float64]: ...
    @property
    def windows(self) -> dict[str, npt.NDArray[np.float64]]:
        """mote run's packing.csv so far: collisions, time, phi, pressure of every window (soft: steps, phi, pressure, minimised)."""
    def render(self, output: Optional[Path] = None, width: int = 800, height: int = 600) -> Optional[npt.NDArray[np.uint8]]: ...


class RigidSimulation:
    """Rigid clumps of overlapping spheres (a scene with ``[rigid]``) stepped
    by the Fast Rigid Bodies Integrator, on ``mote run``'s schedule."""

    @staticmethod
    def from_file(path: Path, seed: Optional[int] = None) -> "RigidSimulation": ...
    @staticmethod
    def from_toml(text: str, seed: Optional[int] = None, name: str = "<string>") -> "RigidSimulation": ...
    @staticmethod
    def from_dict(scene: dict[str, Any], seed: Optional[int] = None) -> "RigidSimulation": ...
    @staticmethod
    def resume(path: Path) -> "RigidSimulation":
        """The rigid simulation a checkpoint holds, ready to go on bit for bit."""
    def save_checkpoint(self, path: Path) -> None: ...
    def step(self, n: int = 1) -> None: ...
    def run(
        self,
        steps: Optional[int] = None,
        until: Optional[float] = None,
        callback: Optional[Callable[["RigidSimulation"], Any]] = None,
        every: int = 100,
        progress: bool = False,
    ) -> None: ...
    @property
    def time(self) -> float: ...
    dt: float
    @property
    def steps(self) -> int: ...
    def __len__(self) -> int: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """(N, 3) centres of mass, a writable view."""
    @property
    def velocities(self) -> npt.NDArray[np.float64]: ...
    @property
    def omegas(self) -> npt.NDArray[np.float64]: ...
    @property
    def rotations(self) -> npt.NDArray[np.float64]:
        """(N, 3) rotation vectors r = n tan(φ/2), a writable view."""
    @property
    def orientations(self) -> npt.NDArray[np.float64]:
        """(N, 4) unit quaternions (w, x, y, z), a copy."""
    @property
    def masses(self) -> npt.NDArray[np.float64]: ...
    @property
    def numbers(self) -> npt.NDArray[np.uint64]:
        """The scene's number of each body row (from 0); rigid scenes store
        their bodies in space order, so row k is body numbers[k]."""
    def spheres(self) -> dict[str, npt.NDArray[Any]]:
        """positions, velocities, radii and body (its scene number) of
        every sphere, body after body in the scene's numbering."""
    @property
    def observables(self) -> dict[str, npt.NDArray[np.float64]]: ...

def run(
    scene: Union[Path, str, dict[str, Any], None] = None,
    *,
    output: Optional[Path] = None,
    seed: Optional[int] = None,
    steps: Optional[int] = None,
    until: Optional[float] = None,
    dt: Optional[float] = None,
    checkpoint_every: Optional[int] = None,
    trajectory_format: Optional[str] = None,
    resume: Optional[Path] = None,
    progress: bool = False,
) -> dict[str, Any]:
    """Runs a scene of any engine to its end as ``mote run`` does; returns
    engine, seed, dir, summary and ending."""

def pack(
    n: int = 1000,
    *,
    dimension: int = 3,
    dist: str = "mono",
    rate: float = 0.01,
    max_pressure: float = 1e12,
    phi: Optional[float] = None,
    walls: str = "",
    jam: bool = True,
    seed: Optional[int] = None,
    start: Optional[str] = None,
    output: Optional[Path] = None,
    format: str = "xyz",
    method: str = "hard",
    min_pressure: float = 1e-8,
) -> dict[str, Any]:
    """A packing by growing hard spheres (method="hard") or by soft spheres
    under a barostat (method="soft", phi extrapolated to zero pressure);
    returns positions, radii, box, phi, pressure, seed and summary. With
    ``output`` (a folder), writes output/packing.EXT in ``format`` (xyz,
    dump, gsd, vtk) with its CSV of windows and POV-Ray scene."""

def rcp(
    *,
    sigma: Optional[float] = None,
    diameters: Optional[list[float]] = None,
    volumes: Optional[list[float]] = None,
    rods: int = 16000,
) -> float:
    """The rod-packing estimate of the random close packing fraction."""

def render(
    trajectory: Path,
    *,
    frame: Optional[int] = None,
    output: Optional[Path] = None,
    width: int = 800,
    height: int = 600,
) -> Optional[npt.NDArray[np.uint8]]:
    """Ray-traces a frame of a trajectory file: a (height, width, 3) image, or
    a PNG written to ``output``."""

def rcp_optimise(
    diameters: list[float],
    *,
    sigmas: Optional[list[float]] = None,
    volumes: Optional[list[float]] = None,
    target: Optional[float] = None,
    widths: bool = False,
    rods: int = 16000,
    max_evaluations: int = 600,
) -> dict[str, Any]:
    """The volume fractions (and widths) that pack densest, or closest to
    ``target``, by the rod-packing estimator; returns volumes, sigmas, phi,
    evaluations."""

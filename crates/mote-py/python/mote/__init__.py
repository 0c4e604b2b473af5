"""mote: many-particle simulation from Python.

The scene format is the one of ``mote run`` (docs/scene-format.md), given as a
file, a TOML string or a dict; ``Simulation`` steps time-stepped scenes,
``run`` runs any engine whole, ``pack`` grows packings and ``rcp`` estimates
random close packing fractions. See docs/python.md.
"""

from ._mote import (  # noqa: F401
    MoteError,
    Simulation,
    UnstableError,
    __version__,
    pack,
    rcp,
    run,
)

__all__ = ["MoteError", "Simulation", "UnstableError", "pack", "rcp", "run"]

"""haptic2d: passive planar rigid-body simulation for haptic rendering, driven from Python.

The Rust core runs every loop (with the GIL released); this package checks inputs, documents the
API in SI units and hands results back as NumPy arrays.

- :class:`World`: a scene (built-in name or TOML file) stepped at its sample period ``T``.
- :mod:`haptic2d.harness`: the 1-D harnesses of Figs. 4 (walls) and 7 (friction, peg in hole).
- :class:`HapticSystem`: device estimator + controller + world, ticked from encoder angles or closed
  around the simulated twin pantograph and a simulated hand.
- :func:`sweep_walls`: stiffness x damping sweeps of the wall laws on any executor.
- :func:`reproduce`: the paper's figures, as ``haptic2d reproduce`` writes them.
- :func:`present`: one stimulus of a study file, explored by the simulated hand (for PsychoPy loops).
- :func:`connect`, :func:`serve`, :class:`StudyServer`: present a study's stimuli on the real-time
  loop and a device through ``haptic2d study serve`` (for PsychoPy loops with people).
- :func:`read_log`: a CSV written by ``haptic2d simulate --out`` or ``haptic2d run --log``.
- :func:`devices`: the real devices ``haptic2d run --device`` can drive (the shared registry).
"""

from __future__ import annotations

from ._haptic2d import SceneError, __version__
from ._world import World, CONTACT_DTYPE
from ._haptic import HapticSystem
from ._lab import sweep_walls, reproduce, read_log, SWEEP_CLASSES
from ._study import present
from ._server import StudyServer, StudyServerError, connect, serve
from ._devices import devices
from . import harness

__all__ = [
    "World",
    "SceneError",
    "CONTACT_DTYPE",
    "HapticSystem",
    "sweep_walls",
    "reproduce",
    "read_log",
    "present",
    "StudyServer",
    "StudyServerError",
    "connect",
    "serve",
    "devices",
    "SWEEP_CLASSES",
    "harness",
    "__version__",
]

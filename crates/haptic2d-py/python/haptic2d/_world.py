"""The :class:`World` wrapper."""

from __future__ import annotations

import os
from typing import Dict, List, Optional, Union

import numpy as np

from . import _haptic2d
from ._checks import count, positive, real

#: dtype of :meth:`World.contacts`: one row per contact record of the last step.
CONTACT_DTYPE = np.dtype(
    [
        ("body_a", np.int64),  # body owning the vertex
        ("body_b", np.int64),  # body owning the edge
        ("vertex_collider", np.int64),  # feature ids: (vertex collider, vertex, edge collider, edge)
        ("vertex", np.int64),
        ("edge_collider", np.int64),
        ("edge", np.int64),
        ("state", "U10"),  # "colliding" or "continuous"
        ("normal_force", np.float64),  # N, >= 0
        ("friction_force", np.float64),  # N, on A along the edge tangent
        ("penetration", np.float64),  # m, max(0, -d)
        ("distance", np.float64),  # m, signed vertex-edge distance d
        ("point", np.float64, (2,)),  # m, the vertex (world)
        ("normal", np.float64, (2,)),  # outward edge normal (world)
        ("god_object", np.float64, (2,)),  # m, the god-object on the edge (world)
    ]
)

_STATES = np.array(["colliding", "continuous"])

Body = Union[str, int]


class World:
    """A planar world of rigid bodies, simulated passively at its sample period ``T``.

    Make one with :meth:`World.load` (a built-in scene name or a TOML path) or
    :meth:`World.from_toml`. State getters return copies.
    """

    __slots__ = ("_w",)

    def __init__(self, raw: "_haptic2d.World") -> None:
        if not isinstance(raw, _haptic2d.World):
            raise TypeError("use World.load(name_or_path) or World.from_toml(text)")
        self._w = raw

    # -- construction ------------------------------------------------------------------------
    @classmethod
    def load(cls, name_or_path: Union[str, "os.PathLike[str]"], rate: Optional[float] = None) -> "World":
        """Loads a scene file (an existing path) or a built-in scene (``box-in-walls``,
        ``box-in-walls-tilt``, ``peg-in-hole``, ``pile``, ``pile:N``), as ``haptic2d simulate`` does.

        ``rate`` (Hz) overrides the scene's rate. A bad scene raises :class:`SceneError` (a
        ``ValueError``) whose message is the CLI's; ``field`` and ``fix`` name the first problem.
        """
        if rate is not None:
            rate = positive("rate", rate)
        return cls(_haptic2d.World.load(os.fspath(name_or_path), rate))

    @classmethod
    def from_toml(cls, text: str, source: str = "<string>", rate: Optional[float] = None) -> "World":
        """Parses and validates scene TOML ``text`` (format: docs/SCENES.md)."""
        if not isinstance(text, str):
            raise TypeError("text must be a str of TOML")
        if rate is not None:
            rate = positive("rate", rate)
        return cls(_haptic2d.World.from_toml(text, source, rate))

    def copy(self) -> "World":
        """An independent copy in the same state."""
        return World(self._w.copy())

    # -- stepping ----------------------------------------------------------------------------
    def step(self, n: int = 1) -> None:
        """Advances ``n`` samples of ``T`` seconds each (``n >= 256`` releases the GIL). Raises
        ``FloatingPointError`` if the world diverges (a non-finite state or one beyond the
        divergence bounds, docs/MODELS.md §0.5 step 12)."""
        self._w.step(n)

    def run(self, duration: float, every: int = 1) -> Dict[str, np.ndarray]:
        """Runs ``duration`` s (rounded to whole samples) with the scene's loads and returns the
        columns of ``haptic2d simulate``'s CSV (docs/CSV.md): ``t, energy.kinetic, energy.stored,
        work.applied, contacts, overlap`` and per dynamic body ``NAME.x, NAME.y, NAME.theta, NAME.vx,
        NAME.vy, NAME.omega`` (m, rad, m/s, rad/s, J). The first row is the state before the run,
        then every ``every``-th sample. The loop runs in Rust with the GIL released. Raises
        ``FloatingPointError`` if the world diverges (a non-finite state or one beyond the
        divergence bounds, docs/MODELS.md §0.5 step 12).
        """
        duration = positive("duration", duration)
        every = count("every", every, 1)
        return self._w.run(duration, every)

    # -- state -------------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """Simulated time ``k*T`` (s)."""
        return self._w.time

    @property
    def tick(self) -> int:
        """Index ``k`` of the next sample."""
        return self._w.tick

    @property
    def dt(self) -> float:
        """Sample period ``T`` (s)."""
        return self._w.dt

    @property
    def bodies(self) -> List[str]:
        """Body names, in body order (the order of :meth:`state`'s arrays)."""
        return self._w.bodies

    @property
    def dynamic(self) -> List[bool]:
        """Whether each body moves, in body order."""
        return self._w.dynamic

    @property
    def name(self) -> str:
        """Scene name."""
        return self._w.name

    @property
    def source(self) -> str:
        """Scene file path or ``built-in:<name>``."""
        return self._w.source

    @property
    def warnings(self) -> List[str]:
        """Non-fatal remarks from scene validation."""
        return self._w.warnings

    @property
    def normal_law(self) -> str:
        """Name of the wall (normal) law of every contact."""
        return self._w.normal_law

    @property
    def friction_model(self) -> str:
        """Name of the friction model of every contact."""
        return self._w.friction_model

    def state(self) -> Dict[str, np.ndarray]:
        """Copies of the body states: arrays ``x, y`` (m), ``theta`` (rad, unwrapped), ``vx, vy``
        (m/s), ``omega`` (rad/s), one entry per body in :attr:`bodies` order."""
        return self._w.state()

    def energy(self) -> Dict[str, float]:
        """The energy ledger after the last step (J): ``kinetic``, ``stored`` (contact and friction
        springs), ``applied_work`` (loads and drives, cumulative), ``impact_loss`` (removed by
        impacts, >= 0) and ``initial``."""
        return self._w.energy()

    def contacts(self) -> np.ndarray:
        """The contact records of the last step as a structured array of :data:`CONTACT_DTYPE`:
        bodies, feature ids, state, normal and friction force (N), penetration and signed distance
        (m), contact point, edge normal and god-object point (world, m)."""
        c = self._w.contact_columns()
        n = len(c["body_a"])
        out = np.zeros(n, dtype=CONTACT_DTYPE)
        for f in ("body_a", "body_b", "vertex_collider", "vertex", "edge_collider", "edge",
                  "normal_force", "friction_force", "penetration", "distance"):
            out[f] = c[f]
        out["state"] = _STATES[c["state"]]
        out["point"] = np.stack([c["point_x"], c["point_y"]], axis=-1) if n else out["point"]
        out["normal"] = np.stack([c["normal_x"], c["normal_y"]], axis=-1) if n else out["normal"]
        out["god_object"] = np.stack([c["god_x"], c["god_y"]], axis=-1) if n else out["god_object"]
        return out

    # -- set-up ------------------------------------------------------------------------------
    def set_drive(self, body: Body, fx: float, fy: float, tau: float) -> None:
        """Sets the drive wrench on ``body`` (name or index): ``fx, fy`` (N) and ``tau`` (N*m) at
        the centre of mass, held until changed (counted in ``work.applied``)."""
        self._w.set_drive(body, real("fx", fx), real("fy", fy), real("tau", tau))

    def set_pose(self, body: Body, x: float, y: float, theta: float) -> None:
        """Places ``body`` at ``(x, y)`` (m) with angle ``theta`` (rad), for experiment set-up."""
        self._w.set_pose(body, real("x", x), real("y", y), real("theta", theta))

    def set_velocity(self, body: Body, vx: float, vy: float, omega: float) -> None:
        """Sets the velocity of dynamic ``body``: ``vx, vy`` (m/s), ``omega`` (rad/s)."""
        self._w.set_velocity(body, real("vx", vx), real("vy", vy), real("omega", omega))

    def __repr__(self) -> str:
        return repr(self._w)

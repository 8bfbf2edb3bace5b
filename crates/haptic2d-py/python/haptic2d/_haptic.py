"""The :class:`HapticSystem` wrapper."""

from __future__ import annotations

import os
from typing import Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _haptic2d
from ._checks import nonneg, positive, real
from ._world import World

HandSpec = Union[str, Tuple]


def _hand(hand: HandSpec) -> Tuple[str, List[float]]:
    """``"hold"``, ``"free"``, ``"constant:FX,FY,TAU"``, ``("sine", FPK, FREQ)``, … → kind, numbers."""
    if isinstance(hand, str):
        kind, _, body = hand.partition(":")
        nums = [s for s in body.split(",") if s.strip()] if body else []
        try:
            values = [float(s) for s in nums]
        except ValueError:
            raise ValueError(f"hand {hand!r}: the numbers after ':' must be comma-separated reals") from None
        return kind, [real(f"hand {kind} value", v) for v in values]
    if isinstance(hand, tuple) and hand and isinstance(hand[0], str):
        return hand[0], [real(f"hand {hand[0]} value", v) for v in hand[1:]]
    raise TypeError("hand must be a str such as 'hold' or 'constant:-2,0,0', or a tuple ('sine', 2.1, 1.0)")


class HapticSystem:
    """The haptic system of the paper: twin-pantograph estimator, teleoperation controller
    (``"four-channel"`` or ``"coupling"``), optional passivity controller, and a copy of ``world``
    whose first dynamic body (or ``slave``) the device drives. The tick period is the world's ``T``.

    ``device_file`` is a TOML device file (template: ``devices/twin-pantograph.toml``; default: the
    spec's device). ``hand`` is the simulated operator of :meth:`run_simulated`: ``"hold"`` (a
    spring-damper grip at the start pose), ``"free"``, ``"constant:FX,FY,TAU"`` (N, N, N*m),
    ``"sine:FPK,FREQ[,DIRX,DIRY]"`` (N, Hz), ``"script:HOLD,FX,FY,TAU,PUSH[,RFX,RFY,RTAU]"`` (s, N,
    s), as ``haptic2d run --hand`` takes them, or the same as a tuple ``("sine", 2.1, 1.0)``.

    ``ramp_time`` (s) is the safety layer's start-up ramp: the torques are scaled by
    ``min(1, n*T/ramp_time)`` from the first device reading, so the first tick's torques are zero
    (default 0.5 s, as ``haptic2d run``; 0 = no ramp). The ramp scales the workspace bound too: a
    hand that pushes from the first tick (``"constant:..."``) drives the handle past the workspace
    edge before the wall has its strength and trips the latch. Hold the handle through the ramp
    (``"script:0.5,FX,FY,TAU,PUSH"``, as a user does) or study the loop at full gain with
    ``ramp_time=0``.
    """

    def __init__(
        self,
        world: World,
        controller: str = "four-channel",
        device_file: Optional[Union[str, "os.PathLike[str]"]] = None,
        hand: HandSpec = "hold",
        passivity: bool = False,
        slave: Optional[str] = None,
        ramp_time: float = 0.5,
    ) -> None:
        if not isinstance(world, World):
            raise TypeError("world must be a haptic2d.World")
        text = None
        source = ""
        if device_file is not None:
            path = os.fspath(device_file)
            try:
                with open(path, encoding="utf-8") as f:
                    text = f.read()
            except OSError as e:
                raise ValueError(
                    f"cannot read device file {path}: {e}\n    fix: give the path of a TOML device file; "
                    "copy devices/twin-pantograph.toml and edit it"
                ) from None
            source = f"device file {path}"
        kind, args = _hand(hand)
        self._s = _haptic2d.HapticSystem(
            world._w,
            controller,
            text,
            source,
            kind,
            args,
            bool(passivity),
            slave,
            nonneg("ramp_time", ramp_time),
        )
        #: The plant fault that ended the last :meth:`run_simulated` early, or ``None``.
        self.fault: Optional[str] = None

    #: Names of the per-tick record columns (units: docs/CSV.md, run logs).
    @property
    def columns(self) -> List[str]:
        return self._s.columns()

    @property
    def dt(self) -> float:
        """Tick period ``T`` (s)."""
        return self._s.dt

    @property
    def controller(self) -> str:
        """The controller's name."""
        return self._s.controller

    @property
    def device_start(self) -> Tuple[float, float, float]:
        """Handle pose the device starts at (m, m, rad, handle coordinates)."""
        return tuple(self._s.device_start)  # type: ignore[return-value]

    @property
    def safety_trip(self) -> Optional[str]:
        """Why the safety latch is set (torques held at zero), or ``None``."""
        return self._s.safety_trip

    @property
    def ramp(self) -> float:
        """The start-up ramp factor the next tick applies (0 until the first reading and at it,
        1 once ramped in)."""
        return self._s.ramp

    def tick(self, encoders: Sequence[float]) -> np.ndarray:
        """One haptic tick: four encoder angles (rad) in, four motor torques (N*m) out."""
        q = np.ascontiguousarray(encoders, dtype=np.float64)
        if q.shape != (4,):
            raise ValueError(f"encoders must be 4 angles (rad), got shape {q.shape}")
        if not np.all(np.isfinite(q)):
            raise ValueError("encoders must be finite angles (rad)")
        return self._s.tick((float(q[0]), float(q[1]), float(q[2]), float(q[3])))

    def plant_encoders(self) -> np.ndarray:
        """Encoder angles (rad) of the simulated plant now (what :meth:`run_simulated` reads)."""
        return self._s.plant_encoders()

    def run_simulated(self, duration: float) -> Dict[str, np.ndarray]:
        """Runs ``round(duration/T)`` ticks closed around the simulated twin pantograph and the
        hand, in simulated time (GIL released), and returns one array per record column
        (:attr:`columns`: device pose and twist, hand wrench, slave state, controller forces,
        torques, energies, flags). If the plant fails, the run stops there and :attr:`fault` says why.
        """
        duration = positive("duration", duration)
        n = int(round(duration / self.dt))
        cols, self.fault = self._s.run_simulated(n)
        return cols

    def set_hand(self, hand: HandSpec) -> None:
        """Replaces the simulated hand (forms as in the constructor)."""
        kind, args = _hand(hand)
        self._s.set_hand(kind, args)

    def last_record(self) -> Dict[str, float]:
        """The last tick's record, by column."""
        return self._s.last_record()

    def world(self) -> World:
        """A copy of the world as it is now."""
        return World(self._s.world())

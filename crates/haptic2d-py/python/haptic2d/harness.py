"""The 1-D harnesses of the paper's Figs. 4 and 7, with every wall law and friction model.

:func:`wall` runs the Fig. 4 wall harness (a mass pushed by a constant force into a wall at
``x = 0``; free space is ``x > 0``), :func:`peg` the Fig. 7 peg harness (a peg pressed on ``n``
contacts, pushed along the hole axis). Harness settings and model parameters are keyword
arguments; any keyword that is not a harness setting is a parameter of the law or model, by its
scene-file name (case-insensitive, so ``K=2000`` sets ``k``). Defaults are the spec's (§13).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np

from . import _haptic2d
from ._checks import count, nonneg, positive, real

#: Wall (normal) laws accepted by :func:`wall`.
WALL_LAWS: Tuple[str, ...] = tuple(_haptic2d.model_names()[0])
#: Friction models accepted by :func:`peg`.
FRICTION_MODELS: Tuple[str, ...] = tuple(_haptic2d.model_names()[1])
#: Integration modes of the wall harness.
INTEGRATIONS = ("exact-zoh", "semi-implicit", "explicit-euler")


def law_params(model: str, per_contact: bool = False) -> List[Dict[str, Any]]:
    """The parameters of the wall law or friction model ``model``, as the Rust core declares them.

    One dict per parameter: ``key`` (the keyword :func:`wall`/:func:`peg` and scene files take),
    ``aliases``, ``unit`` (SI; empty for a pure number), ``rule`` (the accepted values, in words),
    ``meaning`` and ``default`` (the 1-D default, or the halved per-contact one with
    ``per_contact=True``). The same declarations generate docs/MODELS.md Part I.
    """
    if not isinstance(model, str):
        raise TypeError(f"model must be a string, got {type(model).__name__}")
    return _haptic2d.law_params(model, bool(per_contact))


@dataclass
class WallRun:
    """One run of the wall harness. Arrays are indexed by sample ``k`` (time ``k*T``); forces are
    held over ``[kT, (k+1)T)``."""

    law: str
    #: time (s)
    t: np.ndarray
    #: position = gap to the wall (m); negative inside
    x: np.ndarray
    #: velocity (m/s), before any entry impulse of the sample
    v: np.ndarray
    #: wall force held over the sample (N, along +x), after the passivity controller
    f: np.ndarray
    #: wall force of the law alone (N)
    f_env: np.ndarray
    #: passivity-controller damping (N*s/m); 0 without one
    alpha: np.ndarray
    #: observed port energy (J); 0 without a passivity controller
    e_obs: np.ndarray
    #: energy stored in the wall law (J)
    stored: np.ndarray
    #: bounce metrics (§13.1): separations, settle_time (s or None), final_penetration and
    #: max_penetration (m), ratios (exit/entry speed of each completed contact), entry_speeds and
    #: exit_speeds (m/s; NaN while in contact), entry_index and exit_index (-1 while in contact),
    #: min_e_obs (J), max_alpha (N*s/m)
    metrics: Dict[str, Any] = field(default_factory=dict)


@dataclass
class PegRun:
    """One run of the peg harness (§13.2). Arrays are indexed by sample ``k``."""

    model: str
    #: time (s)
    t: np.ndarray
    #: peg position (m)
    x: np.ndarray
    #: peg velocity (m/s)
    v: np.ndarray
    #: push F(t) (N)
    f_push: np.ndarray
    #: total friction force (N)
    f_friction: np.ndarray
    #: True where contact 0 slips
    slip: np.ndarray
    #: friction-spring energy (J)
    u_f: np.ndarray
    #: creep and advance per cycle (m), energy_balance per cycle (J), max_abs_x (m)
    metrics: Dict[str, Any] = field(default_factory=dict)


def _law_params(kw: Dict[str, Any]) -> list:
    return [(k.lower(), real(k, v)) for k, v in kw.items()]


def wall(
    law: str = "paper",
    *,
    m: Optional[float] = None,
    mass: float = 0.5,
    T: Optional[float] = None,
    dt: float = 0.002,
    push: float = 2.0,
    duration: float = 10.0,
    gap0: float = 0.02,
    v0: float = 0.0,
    damping: float = 0.0,
    integration: str = "exact-zoh",
    impulse: Union[None, bool, Tuple[float, float]] = None,
    passivity: bool = False,
    per_contact: bool = False,
    **law_params: float,
) -> WallRun:
    """Runs the Fig. 4 wall harness with wall law ``law`` (one of :data:`WALL_LAWS`).

    ``m``/``mass`` (kg), ``T``/``dt`` (s), ``push`` toward the wall (N), ``duration`` (s; the run
    has ``round(duration/T)`` samples), initial gap ``gap0`` (m) and velocity ``v0`` (m/s), plant
    damping ``damping`` (N*s/m), ``integration`` (one of :data:`INTEGRATIONS`), the paper method's
    entry impulse ``impulse`` (``True`` = e 0.5, v_c 0.02 m/s; or ``(e, v_c)``; default: on for
    ``paper`` only), the passivity controller of §12 on the wall port, and ``per_contact`` (the
    halved 2-D defaults). Other keywords set law parameters, e.g. ``K=2000`` (N/m), ``kc``, ``bc``,
    ``b_m``, ``k_i``. Example: ``wall("seh", K=2000, m=0.5, T=0.002, push=2.0, duration=10)``.
    """
    if not isinstance(law, str) or law not in WALL_LAWS:
        raise ValueError(f"unknown wall law {law!r}; valid: {', '.join(WALL_LAWS)}")
    if integration not in INTEGRATIONS:
        raise ValueError(f"unknown integration {integration!r}; valid: {', '.join(INTEGRATIONS)}")
    mass = positive("m" if m is not None else "mass", m if m is not None else mass)
    dt = positive("T" if T is not None else "dt", T if T is not None else dt)
    duration = nonneg("duration", duration)
    if impulse is None:
        impulse = law == "paper"
    if impulse is True:
        imp: Optional[Tuple[float, float]] = (0.5, 0.02)
    elif impulse is False:
        imp = None
    else:
        e, v_c = impulse
        imp = (real("impulse e", e), real("impulse v_c", v_c))
    d = _haptic2d.wall_run(
        law,
        _law_params(law_params),
        mass,
        nonneg("damping", damping),
        real("push", push),
        real("gap0", gap0),
        real("v0", v0),
        dt,
        duration,
        integration,
        imp,
        bool(passivity),
        bool(per_contact),
    )
    return WallRun(**d)


def peg(
    model: str = "reset-integrator",
    *,
    m: Optional[float] = None,
    mass: float = 0.2,
    n_contacts: int = 2,
    f_n: float = 2.0,
    T: Optional[float] = None,
    dt: float = 0.002,
    duration: float = 5.2,
    period: float = 1.0,
    f_pk: float = 2.1,
    freq: float = 1.0,
    push: Union[str, Tuple[str, float, float]] = "raised-cosine",
    per_contact: bool = False,
    **model_params: float,
) -> PegRun:
    """Runs the Fig. 7 peg harness with friction model ``model`` (one of :data:`FRICTION_MODELS`).

    ``m``/``mass`` (kg), ``n_contacts`` each with normal force ``f_n`` (N), ``T``/``dt`` (s),
    ``duration`` (s), cycle ``period`` (s) of the creep/advance metrics. The push is the Fig. 7
    raised cosine ``f_pk*(1 - cos 2*pi*freq*t)/2`` (N, Hz), or ``("ramp", rate, f_max)`` (N/s, N) or
    ``("constant", f, 0)`` (N). Other keywords set model parameters by scene-file name, e.g.
    ``kr``, ``mu_s``, ``mu_k``, ``beta``, ``p0`` (reset integrator), ``v_th`` (classical).
    """
    if not isinstance(model, str) or model not in FRICTION_MODELS:
        raise ValueError(f"unknown friction model {model!r}; valid: {', '.join(FRICTION_MODELS)}")
    mass = positive("m" if m is not None else "mass", m if m is not None else mass)
    dt = positive("T" if T is not None else "dt", T if T is not None else dt)
    if push == "raised-cosine":
        p = ("raised-cosine", nonneg("f_pk", f_pk), positive("freq", freq))
    elif isinstance(push, tuple) and len(push) == 3:
        p = (str(push[0]), real("push[1]", push[1]), real("push[2]", push[2]))
    else:
        raise ValueError("push must be 'raised-cosine', ('ramp', rate, f_max) or ('constant', f, 0)")
    d = _haptic2d.peg_run(
        model,
        _law_params(model_params),
        mass,
        count("n_contacts", n_contacts, 1),
        nonneg("f_n", f_n),
        dt,
        nonneg("duration", duration),
        positive("period", period),
        p,
        bool(per_contact),
    )
    return PegRun(**d)


__all__ = [
    "wall",
    "peg",
    "law_params",
    "WallRun",
    "PegRun",
    "WALL_LAWS",
    "FRICTION_MODELS",
    "INTEGRATIONS",
]

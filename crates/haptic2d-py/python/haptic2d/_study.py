"""Trial execution for labs that run their own experiment loop (PsychoPy's ``StairHandler`` or
``QuestHandler``): :func:`present` shows one stimulus of a study file to the simulated hand and
returns what it felt (docs/STUDIES.md)."""

from __future__ import annotations

import math
import os
from typing import Any, Dict, Optional

from . import _haptic2d


def present(
    study: "str | os.PathLike[str]", condition: str, delta: Optional[float] = None
) -> Dict[str, Any]:
    """Presents one stimulus of the study file ``study`` to the simulated hand.

    ``delta=None`` presents condition ``condition``'s reference; a number presents its comparison
    with the varied parameter (the condition's ``vary``, e.g. ``normal.kc`` in N/m) raised by
    ``delta``. The stimulus's laws are built into a fresh world of the study's scene before the hand
    touches anything (no switch in contact), and the hand explores it as the study's ``[observer]``
    says (press, tap or stroke) through the real world step. This is the simulated hand of the
    simulated observer, a **model**: for people, use ``haptic2d study run FILE --observer browser``.

    Returns ``{"stiffness": felt stiffness (N/m), "x": (x1, x2) (see docs/STUDIES.md),
    "reference_value": the condition's reference value of ``vary``, "vary": the parameter name,
    "value": the presented value of ``vary``}``. Raises ``ValueError`` for an unknown file,
    condition or an invalid parameter value.
    """
    if delta is not None:
        delta = float(delta)
        if not math.isfinite(delta):
            raise ValueError(f"delta = {delta}: give a finite number")
    stiffness, x, ref, vary = _haptic2d.study_present(os.fspath(study), condition, delta)
    return {
        "stiffness": stiffness,
        "x": (x[0], x[1]),
        "reference_value": ref,
        "vary": vary,
        "value": ref + (delta or 0.0),
    }

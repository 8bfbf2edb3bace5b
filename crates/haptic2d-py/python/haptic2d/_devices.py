"""The real devices haptic2d can drive: the device registry shared with ``haptic2d run``."""

from __future__ import annotations

from typing import Any, Dict, List

from . import _haptic2d


def devices() -> List[Dict[str, Any]]:
    """The device registry of ``haptic2d run --device …``, one dict per kind and shipped device file.

    Keys: ``device`` (the ``--device`` form, e.g. ``"udp:ADDR:PORT"``), ``device_file`` (the shipped
    file under ``devices/``, e.g. ``"haply-twin"``), ``model`` (``"twin"``: 4 joints;
    ``"five-bar"``: 2 joints; ``"point"``: a Cartesian point device such as the Inverse3; ``None``
    when the driver is not in this build), ``limit`` (the output limit: N·m for a twin or five-bar,
    N for a point device; ``None`` when not built), ``limit_unit`` (``"N·m"`` or ``"N"``) and
    ``summary`` (what ``run`` prints on its start line, or how to build the driver). Nothing is
    opened.
    """
    return [dict(d) for d in _haptic2d.devices()]

"""haptic2d.devices(): the device registry shared with `haptic2d run`, its limits read from the shipped
device files (devices/*.toml), nothing opened."""

from __future__ import annotations

import tomllib
from pathlib import Path

import haptic2d

DEVICES = Path(__file__).resolve().parents[3] / "devices"


def _file(name: str) -> dict:
    return tomllib.loads((DEVICES / f"{name}.toml").read_text())


def test_every_registry_kind_is_listed_with_the_limit_of_its_shipped_file(capfd) -> None:
    rows = haptic2d.devices()
    # A listing prints nothing (the UDP file's protocol warning is for a run).
    assert capfd.readouterr() == ("", "")
    by_file = {r["device_file"]: r for r in rows}
    assert list(by_file) == [
        "haply-2diy-gen3",
        "haply-2diy-gen2",
        "haply-twin",
        "udp-pantograph",
        "inverse3",
    ]
    for r in rows:
        assert set(r) == {"device", "device_file", "model", "limit", "limit_unit", "summary"}
        assert isinstance(r["summary"], str) and r["summary"]
    for name in ("haply-2diy-gen3", "haply-2diy-gen2"):
        r = by_file[name]
        assert r["device"] == "haply:PATH|haply:auto"
        assert r["model"] == "five-bar"
        assert r["limit_unit"] == "N·m"
        assert r["limit"] == _file(name)["board"]["torque_limit"]
    assert by_file["haply-twin"]["model"] == "twin"
    udp = by_file["udp-pantograph"]
    assert (udp["device"], udp["model"]) == ("udp:ADDR:PORT", "five-bar")
    assert udp["limit"] == _file("udp-pantograph")["protocol"]["torque_limit"]


def test_the_inverse3_is_listed_as_a_point_device_or_says_how_to_build_it() -> None:
    inv = [r for r in haptic2d.devices() if r["device_file"] == "inverse3"][0]
    assert inv["device"] == "inverse3[:URL]"
    assert inv["limit_unit"] == "N"
    if inv["model"] is None:
        # The Python package is built without the `inverse3` feature (no HTTP/TLS stack).
        assert inv["limit"] is None
        assert "--features inverse3" in inv["summary"]
    else:
        assert inv["model"] == "point"
        assert inv["limit"] == _file("inverse3")["limits"]["force_limit"]

#!/usr/bin/env python3
"""Checks `haptic2d run --foxglove` with a client that shares no code with haptic2d (issue 14).

The Foxglove Python packages (`foxglove-sdk` 0.30, `foxglove-websocket` 0.1.4) ship servers only, no
client, so this client is written from the protocol specification
(https://github.com/foxglove/ws-protocol/blob/main/docs/spec.md, `foxglove.websocket.v1`) on the
`websockets` package, and every message is validated against the JSON Schema its channel
advertised with the `jsonschema` package. It:

1. starts `haptic2d run --headless --no-rt --duration D --foxglove 127.0.0.1:PORT`;
2. connects with subprotocol `foxglove.websocket.v1` and reads `serverInfo` and `advertise`;
3. subscribes to every channel, then decodes the binary message-data frames
   (`0x01`, subscription id u32 LE, timestamp u64 LE ns, payload) as JSON and validates the first
   20 of each channel against its channel's schema; checks every channel delivers, per-channel timestamps never go
   back and are Unix-epoch ns (within a minute of this machine's clock), `/haptic2d/tf` places
   `body/NAME`, `device` and `slave` in `world`, and the tick index grows;
4. sends a malformed text message and a binary frame: the server answers with `status` and keeps
   streaming;
5. unsubscribes from `/haptic2d/tick` (then an unsupported operation as a marker: its status reply
   comes after every frame sent before the unsubscribe): no tick messages follow, the others go on;
6. closes; the run must end on its own with exit status 0.

Usage: scripts/foxglove_client_check.py PATH/TO/haptic2d [--duration 10]. Exit 0 = pass; any
failure prints what went wrong and exits 1.
"""

from __future__ import annotations

import argparse
import json
import socket
import struct
import subprocess
import sys
import time
from typing import Any, Dict, List

import jsonschema
from websockets.sync.client import connect

SUBPROTOCOL = "foxglove.websocket.v1"
MESSAGE_DATA = 0x01
HEADER = struct.Struct("<BIQ")  # opcode, subscription id, log time (ns)
# Messages per channel validated against the channel's schema (the rest are JSON-decoded).
VALIDATE_FIRST = 20


def fail(msg: str) -> None:
    print(f"foxglove client check: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def text_message(ws: Any, timeout: float) -> Dict[str, Any]:
    """The next text (JSON) message, skipping binary frames."""
    deadline = time.monotonic() + timeout
    while True:
        left = deadline - time.monotonic()
        if left <= 0:
            fail("no JSON message from the server within the timeout")
        m = ws.recv(timeout=left)
        if isinstance(m, str):
            return json.loads(m)


def connect_retry(url: str, timeout: float) -> Any:
    deadline = time.monotonic() + timeout
    while True:
        try:
            return connect(url, subprotocols=[SUBPROTOCOL], open_timeout=5, max_size=None)
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("haptic2d", help="the haptic2d binary")
    ap.add_argument("--duration", type=float, default=10.0, help="run length (s)")
    args = ap.parse_args()

    port = free_port()
    run = subprocess.Popen(
        [args.haptic2d, "run", "--headless", "--no-rt", "--duration", str(args.duration),
         "--foxglove", f"127.0.0.1:{port}"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )
    try:
        check(port)
    except SystemExit:
        run.kill()
        print(run.communicate()[0], file=sys.stderr)
        raise
    out = run.communicate(timeout=args.duration + 30)[0]
    if run.returncode != 0:
        fail(f"haptic2d run exited with {run.returncode}:\n{out}")
    print("foxglove client check: PASS (haptic2d run ended with exit status 0)")


def check(port: int) -> None:
    with connect_retry(f"ws://127.0.0.1:{port}", timeout=20.0) as ws:
        session(ws)


def session(ws: Any) -> None:
    if ws.subprotocol != SUBPROTOCOL:
        fail(f"negotiated subprotocol {ws.subprotocol!r}, want {SUBPROTOCOL}")

    info = text_message(ws, 5.0)
    if info.get("op") != "serverInfo" or not isinstance(info.get("name"), str):
        fail(f"first message is not serverInfo: {info}")
    if not isinstance(info.get("capabilities"), list):
        fail(f"serverInfo has no capabilities list: {info}")
    adv = text_message(ws, 5.0)
    if adv.get("op") != "advertise":
        fail(f"second message is not advertise: {adv}")
    channels: Dict[int, Dict[str, Any]] = {}
    validators: Dict[int, Any] = {}
    for c in adv["channels"]:
        for k in ("id", "topic", "encoding", "schemaName", "schema"):
            if k not in c:
                fail(f"advertised channel without `{k}`: {c}")
        if c["encoding"] != "json" or c.get("schemaEncoding", "jsonschema") != "jsonschema":
            fail(f"channel {c['topic']}: encoding {c['encoding']}, schema {c.get('schemaEncoding')}")
        schema = json.loads(c["schema"])
        jsonschema.validators.validator_for(schema).check_schema(schema)
        channels[c["id"]] = c
        validators[c["id"]] = jsonschema.validators.validator_for(schema)(schema)
    topics = sorted(c["topic"] for c in channels.values())
    want = ["/haptic2d/bodies", "/haptic2d/contacts", "/haptic2d/energy", "/haptic2d/scene_update",
            "/haptic2d/tf", "/haptic2d/tick"]
    if topics != want:
        fail(f"advertised topics {topics}, want {want}")
    print(f"advertise: {len(channels)} channels, every schema a valid JSON Schema")

    # Subscription ids of our choosing (the spec lets the client pick them).
    subs = {100 + cid: cid for cid in channels}
    ws.send(json.dumps({"op": "subscribe",
                        "subscriptions": [{"id": s, "channelId": c} for s, c in subs.items()]}))

    counts: Dict[str, int] = {c["topic"]: 0 for c in channels.values()}
    last_time: Dict[str, int] = {}
    ticks: List[int] = []

    def receive(seconds: float, statuses: List[Dict[str, Any]], want_statuses: int = -1) -> None:
        """Receives for `seconds`, or until `want_statuses` status messages have come."""
        deadline = time.monotonic() + seconds
        while (left := deadline - time.monotonic()) > 0 and len(statuses) != want_statuses:
            try:
                m = ws.recv(timeout=left)
            except TimeoutError:
                return
            if isinstance(m, str):
                msg = json.loads(m)
                if msg.get("op") == "status":
                    statuses.append(msg)
                else:
                    print(f"(text message {msg.get('op')!r} ignored)")
                continue
            if len(m) < HEADER.size:
                fail(f"binary frame of {len(m)} bytes is shorter than the message-data header")
            op, sub, t = HEADER.unpack_from(m)
            if op != MESSAGE_DATA:
                fail(f"binary opcode {op:#x}, want message data {MESSAGE_DATA:#x}")
            if sub not in subs:
                fail(f"message for subscription {sub}, which was never subscribed (or was dropped)")
            ch = channels[subs[sub]]
            payload = json.loads(m[HEADER.size:])
            # Validating is slow in Python (a SceneUpdate takes milliseconds): the first few of each
            # channel are validated, the rest decoded, so the client keeps up with the stream.
            errors = []
            if counts[ch["topic"]] < VALIDATE_FIRST:
                errors = sorted(validators[ch["id"]].iter_errors(payload), key=str)
            if errors:
                fail(f"{ch['topic']} message does not match its advertised schema: {errors[0].message}")
            topic = ch["topic"]
            # Log times are Unix-epoch ns (docs/LOGS.md, "Clock"): within a minute of this clock.
            if abs(t - time.time_ns()) > 60e9:
                fail(f"{topic}: timestamp {t} ns is not the Unix time now ({time.time_ns()} ns)")
            if topic == "/haptic2d/tf":
                frames = {x["child_frame_id"] for x in payload["transforms"]}
                if not {"device", "slave"} <= frames or not any(f.startswith("body/") for f in frames):
                    fail(f"/haptic2d/tf frames {sorted(frames)}: want body/NAME, device and slave")
                if any(x["parent_frame_id"] != "world" for x in payload["transforms"]):
                    fail("/haptic2d/tf: a transform whose parent is not `world`")
            if topic in last_time and t < last_time[topic]:
                fail(f"{topic}: timestamp went back from {last_time[topic]} to {t} ns")
            last_time[topic] = t
            counts[topic] += 1
            if topic == "/haptic2d/tick":
                ticks.append(int(payload["index"]))

    statuses: List[Dict[str, Any]] = []
    receive(1.0, statuses)
    # 60 frames/s nominal; a heavily loaded machine delivers far fewer, but never none.
    if min(counts.values()) < 5:
        fail(f"too few messages per channel in 1 s: {counts}")
    if ticks != sorted(ticks) or len(set(ticks)) != len(ticks):
        fail("tick indices do not strictly increase")
    print(f"1 s subscribed: {counts} messages, the first {VALIDATE_FIRST} of each valid against its schema")

    # A malformed text message and a binary frame (client publishing is not advertised): a status
    # reply each, and the stream goes on.
    before = dict(counts)
    ws.send("{this is not json")
    ws.send(b"\x01\x00\x00\x00\x00")
    # (A loaded machine delays the replies behind the frames already queued: wait up to 10 s.)
    receive(10.0, statuses, want_statuses=2)
    if len(statuses) != 2 or any(s.get("level") not in (0, 1, 2) for s in statuses):
        fail(f"not one status reply per malformed message: {statuses}")
    receive(1.0, statuses)
    if any(counts[k] - before[k] < 5 for k in counts):
        fail(f"the stream stalled after the malformed messages: {before} -> {counts}")
    print(f"malformed messages: {len(statuses)} status replies, e.g. {statuses[0].get('message')!r}; "
          "the stream continues")

    tick_sub = next(s for s, c in subs.items() if channels[c]["topic"] == "/haptic2d/tick")
    ws.send(json.dumps({"op": "unsubscribe", "subscriptionIds": [tick_sub]}))
    # A marker after it: the server handles a client's messages in order and sends on one stream,
    # so once the marker's status reply is here, every frame queued before the unsubscribe is too.
    ws.send(json.dumps({"op": "haptic2d-check-marker"}))
    marker: List[Dict[str, Any]] = []
    receive(10.0, marker, want_statuses=1)
    if len(marker) != 1 or "haptic2d-check-marker" not in str(marker[0].get("message")):
        fail(f"no status reply naming the unsupported operation: {marker}")
    del subs[tick_sub]
    # From here a tick frame fails receive() as "never subscribed".
    others = {k: v for k, v in counts.items() if k != "/haptic2d/tick"}
    receive(1.0, statuses)
    if any(counts[k] - others[k] < 3 for k in others):
        fail(f"the other channels stopped after the unsubscribe: {others} -> {counts}")
    print("unsubscribe: no further /haptic2d/tick messages; the other channels go on")


if __name__ == "__main__":
    main()

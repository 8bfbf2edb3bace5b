#!/usr/bin/env python3
"""Reads a haptic2d MCAP log with the `mcap` PyPI package (no haptic2d code) and checks it.

    python3 scripts/read_mcap.py RUN.mcap [--csv RUN.csv] [--ticks N]

Checks: every channel has a JSON Schema that parses and JSON messages; /haptic2d/tick has one
message per tick (N, or the `ticks` of the run's timing summary in the metadata record
`haptic2d.timing`), sequence = tick index, log_time = the tick's deadline + the Unix offset of the
metadata record `haptic2d.clock`; /haptic2d/tf places body/NAME, device and slave in world; with --csv (a CSV tick
log of the same deterministic run, `haptic2d run --log RUN.csv`), the first and last ticks the two
logs share match column by column. Prints a summary; exits 1 on the first failed check.
"""
import argparse
import csv
import json
import math
import sys

from mcap.reader import make_reader


def fail(msg):
    print(f"FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def num(v):
    """A float of a message: JSON numbers, and the strings NaN / inf / -inf for non-finite ones."""
    return float(v)


def flat(msg):
    """The tick message as the CSV tick log's columns: {"device": {"x": 1}} -> {"device.x": 1}."""
    out = {}
    for k, v in msg.items():
        if isinstance(v, dict):
            for f, x in v.items():
                out[f"{k}.{f}"] = x
        else:
            out[k] = v
    return out


def same(a, b):
    a, b = num(a), num(b)
    return (math.isnan(a) and math.isnan(b)) or a == b


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mcap_file")
    ap.add_argument("--csv", help="CSV tick log of the same run to compare with")
    ap.add_argument("--ticks", type=int, help="expected tick count (default: from the timing summary)")
    args = ap.parse_args()

    with open(args.mcap_file, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        if summary is None:
            fail("no summary section: the log was not finished")
        for sid, schema in summary.schemas.items():
            if schema.encoding != "jsonschema":
                fail(f"schema {schema.name}: encoding {schema.encoding}, expected jsonschema")
            s = json.loads(schema.data)
            if s.get("type") != "object":
                fail(f"schema {schema.name} is not an object schema")
        metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        # log_time = deadline + offset (Unix-epoch ns; docs/LOGS.md "Clock"), from haptic2d.clock.
        clock = metadata.get("haptic2d.clock", {})
        offset = 0
        if clock.get("source") == "monotonic_deadline":
            offset = int(clock["monotonic_to_unix_offset_ns"])
            if clock.get("log_time") != "unix_epoch_ns" or offset < 1_577_836_800 * 10**9:
                fail(f"haptic2d.clock {clock}: log_time is not Unix-epoch ns")
        tf_frames = set()
        counts = {}
        ticks = []
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            if channel.message_encoding != "json":
                fail(f"{channel.topic}: encoding {channel.message_encoding}")
            body = json.loads(message.data)
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            if channel.topic == "/haptic2d/tick":
                if body["index"] % 2**32 != message.sequence:
                    fail(f"tick {body['index']}: sequence {message.sequence}")
                if body["deadline_ns"] + offset != message.log_time:
                    fail(f"tick {body['index']}: log_time {message.log_time} != deadline {body['deadline_ns']} + offset {offset}")
                ticks.append(flat(body))
            if channel.topic == "/haptic2d/tf":
                for x in body["transforms"]:
                    q = x["rotation"]
                    if x["parent_frame_id"] != "world" or abs(q["z"] ** 2 + q["w"] ** 2 - 1) > 1e-9:
                        fail(f"/haptic2d/tf: {x}")
                    tf_frames.add(x["child_frame_id"])

    stats = summary.statistics
    if stats is not None and stats.message_count != sum(counts.values()):
        fail(f"statistics say {stats.message_count} messages, read {sum(counts.values())}")
    expected = args.ticks
    if expected is None and "haptic2d.timing" in metadata:
        expected = int(metadata["haptic2d.timing"]["ticks"])
    if expected is None:
        fail("no --ticks and no haptic2d.timing metadata to check the tick count against")
    if len(ticks) != expected:
        fail(f"{len(ticks)} tick messages, expected {expected}")
    for k, t in enumerate(ticks):
        if t["index"] != k:
            fail(f"tick message {k} has index {t['index']}: a tick is missing or out of order")
    if "/haptic2d/tf" in counts:
        if not {"device", "slave"} <= tf_frames or not any(f.startswith("body/") for f in tf_frames):
            fail(f"/haptic2d/tf frames {sorted(tf_frames)}: want body/NAME, device and slave")
        print(f"/haptic2d/tf: frames {', '.join(sorted(tf_frames))} in world")
    print(f"{args.mcap_file}: {len(ticks)} ticks = the run's tick count; channels: "
          + ", ".join(f"{t} {n}" for t, n in sorted(counts.items())))

    if args.csv:
        with open(args.csv, newline="") as f:
            rows = list(csv.DictReader(f))
        n = min(len(rows), len(ticks))
        if n == 0:
            fail("no ticks to compare")
        for k in (0, n - 1):
            for col, v in rows[k].items():
                if col not in ticks[k]:
                    fail(f"CSV column {col} is not in the tick message")
                if not same(v, ticks[k][col]):
                    fail(f"tick {k}, {col}: CSV {v}, MCAP {ticks[k][col]}")
        print(f"first and last shared ticks (0 and {n - 1}) match the CSV log column by column")


if __name__ == "__main__":
    main()

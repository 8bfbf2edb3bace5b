#!/usr/bin/env python3
"""A simulated 2-DOF pantograph speaking haptic2d's open UDP device protocol, version 2 (and 1).

The template a device builder copies: everything a device must do is in `serve()`, the class
`Session` and the `pack_*`/`unpack_*` functions (docs/DEVICE-PROTOCOL.md has the byte tables).
Python standard library only (`hmac`, `hashlib`, `os.urandom`).

    python3 devices/udp/sim_device.py --bind 127.0.0.1:5005 --key-file udp.key   # version 2
    haptic2d run --device udp:127.0.0.1:5005 --device-file my-device.toml --headless --duration 3

With --key-file (a file of hex or raw key bytes, mode 600, the same key as the host's device
file's protocol.key_file) the device speaks version 2: it opens a session only for a HELLO with a
valid MAC, acts only on commands with a valid MAC, of the current session, with a sequence number
newer than the last one it acted on, and MACs every state. Without a key it speaks version 1 and
binds only to a loopback address (with a warning).

The simulated device: the end point of the pantograph (devices/udp-pantograph.toml geometry) is a
point mass held by a hand, a spring-damper towards the start point, plus an optional constant
push. Commands are joint torques (tau = J^T f, so f = J^-T tau) or a wrench; they are applied
(zero-order hold) until the next command. The device answers every command with one state: joint
angles (or the pose with --pose), joint rates, status. Its own watchdog zeroes the motors when no
command arrives for --watchdog-ms; the first line on stdout is `listening on ADDR:PORT`.

Real-time priority: on a host computer the device shares the cores with everything else, and at
normal priority a loaded machine delays its answers past the host's timeout (a lost device, exit 4).
It asks for SCHED_FIFO 70 (--rt-priority P; the host's loop has 80) and locked memory; when the
kernel refuses it says so and how to get it, and runs anyway (--no-rt: do not ask).
"""

import argparse
import ctypes
import ctypes.util
import hashlib
import hmac
import ipaddress
import math
import os
import socket
import stat
import struct
import sys
import time

# --- protocol v1 (docs/DEVICE-PROTOCOL.md) --------------------------------------------------
COMMAND = struct.Struct("<2sBBIQQIHH3f")  # 44 bytes
STATE = struct.Struct("<2sBBIIIQQ3f3f3f")  # 68 bytes
MAGIC, VERSION, KIND_COMMAND, KIND_STATE = b"H2", 1, 1, 2
FLAG_ENABLE, FLAG_WRENCH, FLAG_LATCHED, FLAG_BYE = 1, 2, 4, 8
STATUS_POSE, STATUS_VELOCITY, STATUS_FORCE, STATUS_ENABLED, STATUS_LIMITED, STATUS_FAULT = (
    1, 2, 4, 8, 16, 32)


def unpack_command(data):
    """The command's fields as a dict, or None for anything that is not a v1 command."""
    if len(data) != COMMAND.size:
        return None
    magic, version, kind, seq, host_ns, _echo_dev, _echo_seq, flags, _res, c0, c1, c2 = \
        COMMAND.unpack(data)
    if magic != MAGIC or version != VERSION or kind != KIND_COMMAND or flags & ~15:
        return None
    cmd = (c0, c1, c2)
    if not all(math.isfinite(c) for c in cmd):
        return None
    return {"seq": seq, "host_ns": host_ns, "flags": flags, "command": cmd}


def pack_state(seq, echo_seq, status, device_ns, echo_host_ns, position, velocity, force):
    return STATE.pack(MAGIC, VERSION, KIND_STATE, seq & 0xFFFFFFFF, echo_seq, status,
                      device_ns, echo_host_ns, *position, *velocity, *force)


# --- protocol v2: authentication (docs/DEVICE-PROTOCOL.md §3) --------------------------------
VERSION2, KIND_HELLO, KIND_WELCOME = 2, 3, 4
MAC_LEN, NONCE_LEN, HEADER2 = 16, 16, 12
HELLO_LEN = HEADER2 + NONCE_LEN + MAC_LEN  # 44
COMMAND2_LEN = HEADER2 + COMMAND.size - 4 + MAC_LEN  # 68
MIN_KEY = 16


def read_key(path):
    """Key bytes from a key file: hex (whitespace ignored, >= 32 digits) or raw bytes. Refused
    when group or others have any permission on the file."""
    st = os.stat(path)
    if st.st_mode & 0o077:
        raise ValueError(f"key file {path} is open to group or others "
                         f"(mode {stat.S_IMODE(st.st_mode):03o}); fix: chmod 600 {path}")
    with open(path, "rb") as f:
        raw = f.read(4097)
    digits = bytes(c for c in raw if not chr(c).isspace())
    try:
        key = bytes.fromhex(digits.decode()) if len(digits) >= 32 else raw
    except ValueError:
        key = raw
    if len(key) < MIN_KEY:
        raise ValueError(f"key file {path}: a key of {len(key)} bytes is too short "
                         f"(at least {MIN_KEY})")
    return key


def mac(key, data):
    """HMAC-SHA256(key, data), first 16 bytes."""
    return hmac.new(key, data, hashlib.sha256).digest()[:MAC_LEN]


def mac_ok(key, datagram):
    return len(datagram) > MAC_LEN and hmac.compare_digest(
        mac(key, datagram[:-MAC_LEN]), datagram[-MAC_LEN:])


def session_id(key, host_nonce, device_nonce):
    sid = struct.unpack("<Q", mac(key, b"H2v2 session" + host_nonce + device_nonce)[:8])[0]
    return max(sid, 1)


class Session:
    """The device's side of version 2: the active session (the one it acts for), a pending one
    (answered with a WELCOME, active from its first authentic command), and the replay window:
    a command acts only if its seq is newer than the last one acted on in that session."""

    def __init__(self, key):
        self.key = key
        self.active = None  # session id
        self.pending = None
        self.last_seq = 0
        self.drops = {"bad_mac": 0, "wrong_session": 0, "stale": 0, "malformed": 0}

    def receive(self, data, peer, sock):
        """The v1 command bytes of an authentic, fresh command (or None); answers a HELLO."""
        if len(data) < HEADER2 + MAC_LEN or data[:2] != MAGIC or data[2] != VERSION2:
            self.drops["malformed"] += 1
            return None
        if not mac_ok(self.key, data):
            self.drops["bad_mac"] += 1
            return None
        kind, sid = data[3], struct.unpack_from("<Q", data, 4)[0]
        if kind == KIND_HELLO and len(data) == HELLO_LEN and sid == 0:
            host_nonce, device_nonce = data[HEADER2:HEADER2 + NONCE_LEN], os.urandom(NONCE_LEN)
            self.pending = session_id(self.key, host_nonce, device_nonce)
            w = MAGIC + bytes([VERSION2, KIND_WELCOME]) + struct.pack("<Q", self.pending) + \
                host_nonce + device_nonce
            sock.sendto(w + mac(self.key, w), peer)
            return None
        if kind != KIND_COMMAND or len(data) != COMMAND2_LEN:
            self.drops["malformed"] += 1
            return None
        if sid == self.pending and sid is not None:
            # The host proved it holds the key and saw our nonce: this session becomes the one.
            self.active, self.pending, self.last_seq = sid, None, 0
        elif sid != self.active or sid is None:
            self.drops["wrong_session"] += 1
            return None
        seq = struct.unpack_from("<I", data, HEADER2)[0]
        if seq <= self.last_seq:
            self.drops["stale"] += 1
            return None
        v1 = MAGIC + bytes([VERSION, KIND_COMMAND]) + data[HEADER2:-MAC_LEN]
        if unpack_command(v1) is None:
            self.drops["malformed"] += 1
            return None
        self.last_seq = seq
        return v1

    def seal_state(self, v1_state):
        b = MAGIC + bytes([VERSION2, KIND_STATE]) + struct.pack("<Q", self.active) + v1_state[4:]
        return b + mac(self.key, b)


# --- the pantograph (docs/DEVICES.md §2): motor 1 at (0, 0), motor 2 at (d, 0) -----------------------
class Pantograph:
    def __init__(self, d, l1, l2):
        self.d, self.l1, self.l2 = d, l1, l2

    def ik(self, x, y):
        """Motor angles (rad), elbows out, for end point (x, y) (m)."""
        q = []
        for i, bx in enumerate((0.0, self.d)):
            rx, ry = x - bx, y
            rho = math.hypot(rx, ry)
            arg = (self.l1 ** 2 + rho ** 2 - self.l2 ** 2) / (2 * self.l1 * rho)
            arg = max(-1.0, min(1.0, arg))
            phi, gamma = math.atan2(ry, rx), math.acos(arg)
            q.append(phi + gamma if i == 0 else phi - gamma)
        return q

    def jacobian(self, x, y, q):
        """J = dE/dq (m/rad) at end point (x, y) with angles q (U E' = D q', J = U^-1 D)."""
        a = (self.l1 * math.cos(q[0]), self.l1 * math.sin(q[0]))
        b = (self.d + self.l1 * math.cos(q[1]), self.l1 * math.sin(q[1]))
        u1, u2 = (x - a[0], y - a[1]), (x - b[0], y - b[1])
        det = u1[0] * u2[1] - u1[1] * u2[0]
        d1 = self.l1 * (-u1[0] * math.sin(q[0]) + u1[1] * math.cos(q[0]))
        d2 = self.l1 * (-u2[0] * math.sin(q[1]) + u2[1] * math.cos(q[1]))
        return ((u2[1] * d1 / det, -u1[1] * d2 / det), (-u2[0] * d1 / det, u1[0] * d2 / det))


def solve2(m, v):
    """x with m x = v for a 2x2 m."""
    (a, b), (c, d) = m
    det = a * d - b * c
    return ((d * v[0] - b * v[1]) / det, (a * v[1] - c * v[0]) / det)


def serve(args):
    host, _, port = args.bind.rpartition(":")
    session = Session(read_key(args.key_file)) if args.key_file else None
    if session is None:
        if not ipaddress.ip_address(host.strip("[]")).is_loopback:
            print(f"error: --bind {args.bind}: protocol version 1 (no --key-file) is "
                  "unauthenticated and allowed on loopback only; give --key-file", file=sys.stderr)
            sys.exit(2)
        print("warning: protocol version 1 (no --key-file): any local process can command this "
              "device", file=sys.stderr, flush=True)
    sock = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind((host.strip("[]"), int(port)))
    bound = sock.getsockname()
    print(f"listening on {bound[0]}:{bound[1]}", flush=True)
    sock.settimeout(0.01)

    link = Pantograph(args.d, args.l1, args.l2)
    x0, y0 = args.start
    x, y, vx, vy = x0, y0, 0.0, 0.0
    command, wrench = (0.0, 0.0), False  # held until the next command
    seq, last_cmd, t_last = 0, None, time.monotonic()
    t0, limited = t_last, False
    t_first = None  # the first command: --push-after counts from here
    deadline = t0 + args.duration if args.duration else None

    def step(now):
        """Advance the plant from t_last to now (semi-implicit Euler, 0.25 ms sub-steps)."""
        nonlocal x, y, vx, vy, t_last
        total = min(now - t_last, 0.1)
        pushing = t_first is not None and now - t_first >= args.push_after
        n = max(1, math.ceil(total / 0.00025))
        h = total / n
        for _ in range(n):
            q = link.ik(x, y)
            if wrench:
                fx, fy = command
            else:
                j = link.jacobian(x, y, q)
                fx, fy = solve2(((j[0][0], j[1][0]), (j[0][1], j[1][1])), command)  # J^T f = tau
            px, py = args.push if pushing else (0.0, 0.0)
            fx += args.k_hand * (x0 - x) - args.b_hand * vx + px
            fy += args.k_hand * (y0 - y) - args.b_hand * vy + py
            vx += h * fx / args.mass
            vy += h * fy / args.mass
            x += h * vx
            y += h * vy
        t_last = now

    while deadline is None or time.monotonic() < deadline:
        try:
            data, peer = sock.recvfrom(256)
        except socket.timeout:
            data = None
        now = time.monotonic()
        # Device watchdog: no valid command for --watchdog-ms -> motors off.
        if last_cmd is not None and now - last_cmd > args.watchdog_ms * 1e-3:
            if args.trace and command != (0.0, 0.0):
                print("watchdog 0 0", file=args.trace, flush=True)
            command = (0.0, 0.0)
        if data is None:
            continue
        if session is not None:
            data = session.receive(data, peer, sock)  # verify before acting
            if data is None:
                continue
        cmd = unpack_command(data)
        if cmd is None:
            continue  # malformed: ignore, never answer
        if t_first is None:
            t_first = t_last = now  # the plant starts at rest with the first command
        step(now)
        last_cmd = now
        flags = cmd["flags"]
        enabled = bool(flags & FLAG_ENABLE) and not flags & (FLAG_LATCHED | FLAG_BYE)
        c = cmd["command"][:2] if enabled else (0.0, 0.0)
        wrench = bool(flags & FLAG_WRENCH)
        lim = args.force_limit if wrench else args.torque_limit
        limited = any(abs(v) > lim for v in c)
        command = tuple(max(-lim, min(lim, v)) for v in c)
        # The state sampled now.
        q = link.ik(x, y)
        qd = solve2(link.jacobian(x, y, q), (vx, vy))
        status = STATUS_VELOCITY | (STATUS_ENABLED if enabled else 0) | \
            (STATUS_LIMITED if limited else 0)
        if args.pose:
            status |= STATUS_POSE
            position, velocity = (x, y, 0.0), (vx, vy, 0.0)
        else:
            position, velocity = (q[0], q[1], 0.0), (qd[0], qd[1], 0.0)
        seq += 1
        device_ns = int((now - t0) * 1e9)
        state = pack_state(seq, cmd["seq"], status, device_ns, cmd["host_ns"],
                           position, velocity, (0.0, 0.0, 0.0))
        sock.sendto(session.seal_state(state) if session else state, peer)
        if args.trace:
            print(f"applied {command[0]:.6f} {command[1]:.6f}", file=args.trace, flush=True)


def realtime(prio):
    """SCHED_FIFO `prio` and locked memory for this process; says on stderr what it got, and how to
    get it when the kernel refuses (0: normal priority, on purpose)."""
    if prio <= 0:
        print("sim_device.py: normal priority (--no-rt): on a loaded machine its answers come late "
              "and the host may stop with a lost device", file=sys.stderr, flush=True)
        return
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(prio))
    except (OSError, AttributeError) as e:
        print(f"warning: sim_device.py runs without real-time priority (SCHED_FIFO {prio} refused: "
              f"{e}): on a loaded machine its answers come late and the host may stop with a lost "
              f"device (exit 4)\n    fix: run it as root, or raise the rtprio limit "
              f"(`ulimit -r {prio}`; `@audio - rtprio 95` in /etc/security/limits.conf), or start "
              f"it with `sudo chrt -f {prio} python3 {sys.argv[0]} ...`",
              file=sys.stderr, flush=True)
        return
    libc = ctypes.CDLL(ctypes.util.find_library("c"), use_errno=True)
    locked = libc.mlockall(3) == 0  # MCL_CURRENT | MCL_FUTURE
    print(f"sim_device.py: real-time priority SCHED_FIFO {prio}"
          f"{', memory locked' if locked else ' (memory not locked)'}", file=sys.stderr, flush=True)


def priority(text):
    p = int(text)
    if not 1 <= p <= 99:
        raise argparse.ArgumentTypeError(f"{text}: expected 1-99 (default 70)")
    return p


def pair(text):
    a, b = text.split(",")
    return float(a), float(b)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--bind", default="127.0.0.1:5005", help="ADDR:PORT to listen at (port 0: any)")
    p.add_argument("--pose", action="store_true", help="send the pose (x, y, theta), not joints")
    p.add_argument("--d", type=float, default=0.038, help="motor spacing (m)")
    p.add_argument("--l1", type=float, default=0.07, help="proximal links (m)")
    p.add_argument("--l2", type=float, default=0.09, help="distal links (m)")
    p.add_argument("--start", type=pair, default=(0.019, 0.10), help="X,Y start point (m)")
    p.add_argument("--mass", type=float, default=0.15, help="end-point mass (kg)")
    p.add_argument("--k-hand", type=float, default=200.0, help="hand stiffness (N/m)")
    p.add_argument("--b-hand", type=float, default=3.0, help="hand damping (N s/m)")
    p.add_argument("--push", type=pair, default=(0.0, 0.0), help="FX,FY constant hand push (N)")
    p.add_argument("--push-after", type=float, default=0.5,
                   help="push starts this long after the first command (s)")
    p.add_argument("--torque-limit", type=float, default=0.123, help="motor limit (N m)")
    p.add_argument("--force-limit", type=float, default=5.0, help="wrench limit (N)")
    p.add_argument("--watchdog-ms", type=float, default=100.0, help="motors off after (ms)")
    p.add_argument("--duration", type=float, default=None, help="exit after (s)")
    p.add_argument("--key-file", default=None,
                   help="protocol v2: the shared key (hex or raw bytes, mode 600)")
    p.add_argument("--rt-priority", type=priority, default=70, metavar="P",
                   help="SCHED_FIFO priority 1-99 (default 70; the host's loop has 80)")
    p.add_argument("--no-rt", action="store_true", help="normal priority (answers late under load)")
    p.add_argument("--trace", type=argparse.FileType("w"), default=None,
                   help="append each command the device acts on to this file (tests)")
    args = p.parse_args()
    realtime(0 if args.no_rt else args.rt_priority)
    try:
        serve(args)
    except KeyboardInterrupt:
        pass
    except ValueError as e:  # the key file
        print(f"error: {e}", file=sys.stderr)
        sys.exit(2)
    except OSError as e:
        print(f"error: {args.bind}: {e}", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""A simulated 2-DOF pantograph speaking haptic2d's open UDP device protocol, version 1.

The template a device builder copies: everything a device must do is in `serve()` and the two
`pack_*`/`unpack_*` functions (docs/DEVICE-PROTOCOL.md has the byte table). Python standard
library only.

    python3 devices/udp/sim_device.py --bind 127.0.0.1:5005
    haptic2d run --device udp:127.0.0.1:5005 --headless --duration 3

The simulated device: the end point of the pantograph (devices/udp-pantograph.toml geometry) is a
point mass held by a hand, a spring-damper towards the start point, plus an optional constant
push. Commands are joint torques (tau = J^T f, so f = J^-T tau) or a wrench; they are applied
(zero-order hold) until the next command. The device answers every command with one state: joint
angles (or the pose with --pose), joint rates, status. Its own watchdog zeroes the motors when no
command arrives for --watchdog-ms; the first line on stdout is `listening on ADDR:PORT`.
"""

import argparse
import math
import socket
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
        # Device watchdog: no command for --watchdog-ms -> motors off.
        if last_cmd is not None and now - last_cmd > args.watchdog_ms * 1e-3:
            command = (0.0, 0.0)
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
        sock.sendto(pack_state(seq, cmd["seq"], status, device_ns, cmd["host_ns"],
                               position, velocity, (0.0, 0.0, 0.0)), peer)


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
    args = p.parse_args()
    try:
        serve(args)
    except KeyboardInterrupt:
        pass
    except OSError as e:
        print(f"error: {args.bind}: {e}", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()

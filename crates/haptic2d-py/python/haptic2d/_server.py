"""A client of ``haptic2d study serve`` (docs/PYTHON.md, docs/STUDIES.md "Driving trials from Python
or PsychoPy on the device"): present a study's stimuli on the real-time haptic loop and a device from
a Python or PsychoPy experiment. Pure Python (socket + json): one JSON object per line each way, over
TCP on loopback.

- :func:`connect` talks to a server already running (``haptic2d study serve FILE --device ...``).
- :func:`serve` starts the server binary as a child process and connects to it.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import socket
import subprocess
import threading
from typing import Any, Dict, List, Optional, Sequence

__all__ = ["StudyServer", "StudyServerError", "connect", "serve"]


class StudyServerError(RuntimeError):
    """The study server refused a request or ended; the message is the server's reason."""


class StudyServer:
    """A connection to ``haptic2d study serve``, one request at a time.

    Use it as a context manager: leaving the block sends ``stop`` (torques zeroed, the server
    exits) when the server was started by :func:`serve`, and closes the connection otherwise.
    """

    def __init__(self, sock: socket.socket, process: Optional["subprocess.Popen[str]"] = None) -> None:
        self._sock = sock
        self._file = sock.makefile("r", encoding="utf-8", newline="\n")
        self._process = process
        self._stopped = False

    # -- the protocol --------------------------------------------------------------------------

    def _send(self, request: Dict[str, Any]) -> None:
        # A server that is ending may have closed its side: the reply read next then gives its last
        # words (the reason it ended) or raises "closed the connection".
        try:
            self._sock.sendall((json.dumps(request) + "\n").encode("utf-8"))
        except OSError:
            pass

    def _reply(self, cmd: str) -> Dict[str, Any]:
        """The next reply for ``cmd``; an error reply raises :class:`StudyServerError`."""
        while True:
            try:
                line = self._file.readline()
            except OSError as e:
                raise StudyServerError(f"the study server is gone ({e})") from e
            if not line:
                raise StudyServerError(f"the study server closed the connection{self._exit_note()}")
            reply: Dict[str, Any] = json.loads(line)
            if not reply.get("ok", False):
                raise StudyServerError(str(reply.get("error", reply)))
            if reply.get("cmd") == cmd:
                return reply

    def _exit_note(self) -> str:
        if self._process is None:
            return ""
        try:
            code = self._process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            return " (the server process is still running)"
        return f" (the server exited with code {code})"

    @staticmethod
    def _present_request(condition: str, delta: Optional[float], duration: Optional[float]) -> Dict[str, Any]:
        if not isinstance(condition, str):
            raise TypeError(f"condition must be a str, not {type(condition).__name__}")
        for name, value in (("delta", delta), ("duration", duration)):
            if value is not None and not math.isfinite(float(value)):
                raise ValueError(f"{name} = {value}: give a finite number or None")
        if duration is not None and float(duration) <= 0.0:
            raise ValueError(f"duration = {duration}: give a positive time in seconds or None (until end())")
        return {
            "cmd": "present",
            "condition": condition,
            "delta": None if delta is None else float(delta),
            "duration_s": None if duration is None else float(duration),
        }

    def present(self, condition: str, delta: Optional[float] = None, duration: float = 3.0) -> Dict[str, Any]:
        """Presents one stimulus on the device for ``duration`` seconds of loop time and returns what
        the loop measured.

        ``delta=None`` presents condition ``condition``'s reference; a number presents its
        comparison with the varied parameter (the condition's ``vary``, e.g. ``normal.kc`` in N/m)
        raised by ``delta``. The stimulus is switched in only while the probe touches nothing, and
        the neutral stimulus returns after the interval (docs/STUDIES.md).

        Returns ``{"id", "condition", "delta", "start_s", "end_s" (loop time, s), "peak_force_n",
        "mean_force_n" (contact force on the probe, N; the mean over the time in contact),
        "deepest_m" (deepest penetration, m), "contact_s" (time in contact, s), "ticks", "mcap"
        (the interval's log with ``--out``, else None)}``. Raises :class:`StudyServerError` with
        the server's reason (unknown condition, invalid parameter, the probe never left contact, a
        safety stop, ...).
        """
        if duration is None:
            raise ValueError("duration=None: use start() and end() for an interval the client ends")
        self._send(self._present_request(condition, delta, duration))
        return self._reply("present")

    def start(self, condition: str, delta: Optional[float] = None) -> int:
        """Starts an open-ended presentation (it runs until :meth:`end`); returns its id."""
        self._send(self._present_request(condition, delta, None))
        return int(self._reply("present")["id"])

    def end(self) -> Dict[str, Any]:
        """Ends the open-ended presentation and returns its measures (as :meth:`present`)."""
        self._send({"cmd": "end"})
        return self._reply("end")

    def status(self) -> Dict[str, Any]:
        """The server's state: ``{"state": "idle" | "waiting_for_free_space" | "presenting",
        "study", "conditions", "device", "presented", "current", "t_s"}``."""
        self._send({"cmd": "status"})
        return self._reply("status")

    def stop(self) -> None:
        """Stops the server: torques zeroed, the loop stopped, the server exits 0."""
        if self._stopped:
            return
        self._send({"cmd": "stop"})
        try:
            self._reply("stop")
        finally:
            self._stopped = True
            self.close()
            if self._process is not None:
                self._process.wait(timeout=30)

    def close(self) -> None:
        """Closes the connection (the server keeps running and waits for the next client)."""
        try:
            self._file.close()
        finally:
            self._sock.close()

    @property
    def process(self) -> Optional["subprocess.Popen[str]"]:
        """The server process started by :func:`serve`, else None."""
        return self._process

    def __enter__(self) -> "StudyServer":
        return self

    def __exit__(self, *exc: Any) -> None:
        if self._process is not None and not self._stopped and self._process.poll() is None:
            try:
                self.stop()
            except StudyServerError:
                pass
        else:
            self.close()


def connect(host: str = "127.0.0.1", port: int = 7341, timeout: Optional[float] = None) -> StudyServer:
    """Connects to a running ``haptic2d study serve`` (loopback). ``timeout`` (s) bounds each reply
    (None: wait as long as a presentation lasts)."""
    sock = socket.create_connection((host, int(port)), timeout=10)
    sock.settimeout(timeout)
    return StudyServer(sock)


def find_binary(binary: Optional["str | os.PathLike[str]"] = None) -> str:
    """The ``haptic2d`` CLI: ``binary``, else ``$HAPTIC2D_BIN``, else ``haptic2d`` on the PATH."""
    for candidate in (binary, os.environ.get("HAPTIC2D_BIN")):
        if candidate:
            path = os.fspath(candidate)
            if not os.path.isfile(path):
                raise FileNotFoundError(f"the haptic2d CLI {path!r} does not exist; build it with cargo build -p haptic2d-cli")
            return path
    found = shutil.which("haptic2d")
    if found is None:
        raise FileNotFoundError(
            "the haptic2d CLI was not found: pass binary=..., set HAPTIC2D_BIN or put haptic2d on the PATH "
            "(build it with cargo build -p haptic2d-cli)"
        )
    return found


def serve(
    study: "str | os.PathLike[str]",
    device: str = "sim",
    *,
    hand: Optional[str] = None,
    out: Optional["str | os.PathLike[str]"] = None,
    headless: bool = True,
    extra_args: Sequence[str] = (),
    binary: Optional["str | os.PathLike[str]"] = None,
    startup_timeout: float = 60.0,
) -> StudyServer:
    """Starts ``haptic2d study serve STUDY --device DEVICE`` on a free loopback port as a child
    process and connects to it. ``hand`` is the simulated device's ``--hand``; ``out`` writes one MCAP
    per presentation; ``headless=False`` serves the display page too. The child's stderr is passed
    through. Raises :class:`FileNotFoundError` without the binary and :class:`StudyServerError` if
    the server does not start (its output is in the message)."""
    exe = find_binary(binary)
    args: List[str] = [exe, "study", "serve", os.fspath(study), "--device", device, "--listen", "127.0.0.1:0"]
    if hand is not None:
        args += ["--hand", hand]
    if out is not None:
        args += ["--out", os.fspath(out)]
    if headless:
        args.append("--headless")
    args += list(extra_args)
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, text=True)
    lines: List[str] = []
    found: List[str] = []

    def read() -> None:
        assert proc.stdout is not None
        for line in proc.stdout:
            lines.append(line)
            if line.startswith("study server: listening on ") and not found:
                found.append(line.rsplit(" ", 1)[1].strip())

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    waited = 0.0
    while not found and proc.poll() is None and waited < startup_timeout:
        reader.join(0.05)
        waited += 0.05
    if not found:
        if proc.poll() is None:
            proc.kill()
        proc.wait()
        raise StudyServerError(
            f"`{' '.join(args)}` did not start (exit {proc.returncode}):\n{''.join(lines)}"
        )
    host, port = found[0].rsplit(":", 1)
    sock = socket.create_connection((host, int(port)), timeout=10)
    sock.settimeout(None)
    return StudyServer(sock, proc)

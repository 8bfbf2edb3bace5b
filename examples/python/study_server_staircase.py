"""A 1-up/2-down staircase whose stimuli are presented on the real-time haptic loop and a device.

    python examples/python/study_server_staircase.py [--trials 12] [--device sim] [--hand sine:2,0.5,-1,0]

The PsychoPy way of running a haptic2d study on people: the experiment script owns the trials (here
PsychoPy's ``StairHandler`` where installed, else the stand-in of ``study_staircase.py``, which says
so), and ``haptic2d study serve`` owns the device. ``haptic2d.serve`` starts the server binary
(``$HAPTIC2D_BIN`` or ``haptic2d`` on the PATH, or ``--binary``) and each interval is one
``server.present(condition, delta, duration)`` call on the loop: the stimulus is switched in while
the probe touches nothing, the participant explores it, and the call returns what the loop measured.

Here nobody is at the device: the simulated device with a scripted hand (``--hand``, as
``haptic2d run --hand``; default a 2 N push into the left wall rising and falling twice a second)
stands in for the participant, and a **model** observer answers from what the loop measured (the
stiffness it felt, peak force / deepest penetration, with Weber-law noise W = 0.15). To run it on
people, give ``--device haply:auto`` (or any ``haptic2d run --device``), leave ``--hand`` out, and
replace ``answer()`` by your participant's keypress (PsychoPy's ``event.waitKeys``).
"""

from __future__ import annotations

import argparse
import math
import os
import random
import sys

import haptic2d

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from study_staircase import WEBER, Z75, make_staircase  # noqa: E402  (the same staircase)

STUDY = os.path.join(HERE, "..", "..", "studies", "stiffness-walls.toml")
CONDITION = "spring-1000"


def felt_stiffness(m: dict) -> float:
    """The stiffness a press felt (N/m): peak contact force over deepest penetration."""
    if m["deepest_m"] <= 0.0:
        raise RuntimeError(f"the probe never touched the wall in presentation {m['id']}: {m}")
    return m["peak_force_n"] / m["deepest_m"]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=12, help="trials of the staircase")
    ap.add_argument("--seed", type=int, default=1, help="seed of the model observer and interval order")
    ap.add_argument("--device", default="sim", help="as haptic2d run --device")
    ap.add_argument("--hand", default="sine:2,0.5,-1,0", help="the simulated device's hand; 'none' on a real device")
    ap.add_argument("--interval", type=float, default=2.0, help="exploration time per interval (s)")
    ap.add_argument("--binary", default=None, help="the haptic2d CLI (default: $HAPTIC2D_BIN or PATH)")
    args = ap.parse_args()
    rng = random.Random(args.seed)
    sigma = math.log(1 + WEBER) / (math.sqrt(2) * Z75)  # the model's percept noise (log units)
    hand = None if args.hand == "none" else args.hand

    def answer(k1: float, k2: float) -> int:
        # The MODEL observer: which interval felt stiffer, with Weber-law noise (not a person).
        p1 = math.log(k1) + sigma * rng.gauss(0, 1)
        p2 = math.log(k2) + sigma * rng.gauss(0, 1)
        return 1 if p1 > p2 else 2

    stairs = make_staircase(400.0, args.trials)
    with haptic2d.serve(STUDY, args.device, hand=hand, binary=args.binary) as server:
        print(f"server: {server.status()['device']}, conditions {server.status()['conditions']}")
        for n, intensity in enumerate(stairs, 1):
            delta = round(float(intensity), 3)
            comparison_interval = rng.choice([1, 2])
            deltas = (delta, None) if comparison_interval == 1 else (None, delta)
            felt = [felt_stiffness(server.present(CONDITION, d, duration=args.interval)) for d in deltas]
            correct = int(answer(*felt) == comparison_interval)
            stairs.addResponse(correct)
            print(f"trial {n:3d}: delta {delta:8.2f} N/m, felt {felt[0]:7.1f} / {felt[1]:7.1f} N/m on the loop, "
                  f"comparison in {comparison_interval}, {'correct' if correct else 'wrong'}")
    rev = list(stairs.reversalIntensities)[2:]
    if rev:
        est = math.exp(sum(math.log(r) for r in rev) / len(rev))
        print(f"threshold (geometric mean of {len(rev)} reversals after the second): {est:.1f} N/m")
    else:
        print(f"no reversals after the second in {args.trials} trials (a short run: give --trials 60)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""A 1-up/2-down staircase on haptic2d trials, driven the way a PsychoPy experiment drives one.

    python examples/python/study_staircase.py [--trials 60] [--seed 1]

Each trial presents the reference wall of studies/stiffness-walls.toml and a comparison stiffer by
the staircase's intensity (N/m added to kc) to the simulated hand with ``haptic2d.present`` and
asks "which was stiffer?". The answers come from a **model** observer (the simulated observer's
Weber-law perception with W = 0.15, no lapses), never from data: replace ``answer()`` by your
participant's keypress (PsychoPy's ``event.waitKeys``) to run it on people — and present the
stimuli on the device with ``haptic2d study run FILE --observer browser``.

The staircase is PsychoPy's ``psychopy.data.StairHandler`` when PsychoPy is installed. Without it
(CI has no PsychoPy and no display) a tiny stand-in with the same calls (iteration,
``addResponse``, ``reversalIntensities``) runs instead, and the script says so: it is not PsychoPy.
"""

from __future__ import annotations

import argparse
import math
import os
import random
import sys

import haptic2d

STUDY = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "studies", "stiffness-walls.toml")
CONDITION = "spring-1000"
WEBER = 0.15
Z75 = 0.6744897501960817  # the standard normal's 75 % point


class StandInStairHandler:
    """A minimal 1-up/N-down staircase with log10 steps, NOT PsychoPy: the subset of
    ``psychopy.data.StairHandler`` this script uses (``stepType='log'``, fixed step)."""

    def __init__(self, startVal: float, stepSizes: float, nTrials: int, nUp: int = 1, nDown: int = 2,
                 minVal: float = 1.0, maxVal: float = 5000.0) -> None:
        self.intensity = startVal
        self.step = stepSizes
        self.n_trials = nTrials
        self.n_up, self.n_down = nUp, nDown
        self.min, self.max = minVal, maxVal
        self.intensities: list[float] = []
        self.reversalIntensities: list[float] = []
        self._run = 0
        self._direction = 0

    def __iter__(self):
        while len(self.intensities) < self.n_trials:
            self.intensities.append(self.intensity)
            yield self.intensity

    def addResponse(self, correct: int) -> None:
        self._run = self._run + 1 if correct else 0
        move = 0
        if correct and self._run >= self.n_down:
            move, self._run = -1, 0
        elif not correct:
            move = 1
        if move:
            if self._direction and move != self._direction:
                self.reversalIntensities.append(self.intensity)
            self._direction = move
            self.intensity = min(self.max, max(self.min, self.intensity * 10 ** (move * self.step)))


def make_staircase(start: float, trials: int):
    try:
        from psychopy.data import StairHandler  # type: ignore[import-not-found]
    except ImportError:
        print("PsychoPy is not installed: using the stand-in staircase of this script (not PsychoPy)")
        return StandInStairHandler(startVal=start, stepSizes=0.1, nTrials=trials, nUp=1, nDown=2)
    print("using psychopy.data.StairHandler")
    return StairHandler(startVal=start, stepSizes=[0.1], stepType="log", nTrials=trials, nUp=1, nDown=2,
                        minVal=1.0, maxVal=5000.0)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=60, help="trials of the staircase")
    ap.add_argument("--seed", type=int, default=1, help="seed of the model observer and interval order")
    args = ap.parse_args()
    rng = random.Random(args.seed)
    sigma = math.log(1 + WEBER) / (math.sqrt(2) * Z75)  # the model's percept noise (log units)
    felt_cache: dict[float, float] = {}

    def felt(delta: float | None) -> float:
        key = -1.0 if delta is None else delta
        if key not in felt_cache:
            felt_cache[key] = haptic2d.present(STUDY, CONDITION, delta)["stiffness"]
        return felt_cache[key]

    def answer(k1: float, k2: float) -> int:
        # The MODEL observer: which interval felt stiffer, with Weber-law noise (not a person).
        p1 = math.log(k1) + sigma * rng.gauss(0, 1)
        p2 = math.log(k2) + sigma * rng.gauss(0, 1)
        return 1 if p1 > p2 else 2

    k_ref = felt(None)
    stairs = make_staircase(400.0, args.trials)
    for n, intensity in enumerate(stairs, 1):
        delta = round(float(intensity), 3)
        comparison_interval = rng.choice([1, 2])
        k_cmp = felt(delta)
        ks = (k_cmp, k_ref) if comparison_interval == 1 else (k_ref, k_cmp)
        correct = int(answer(*ks) == comparison_interval)
        stairs.addResponse(correct)
        print(f"trial {n:3d}: delta {delta:8.2f} N/m, felt {ks[0]:7.1f} / {ks[1]:7.1f} N/m, "
              f"comparison in {comparison_interval}, {'correct' if correct else 'wrong'}")
    rev = list(stairs.reversalIntensities)[2:]
    # The model's 70.7 % point: Phi(ln(1 + D/kc)/(sigma*sqrt2)) = 0.707 (felt stiffness is 2 kc).
    model = 1000.0 * (math.exp(sigma * math.sqrt(2) * 0.5450) - 1)
    if rev:
        est = math.exp(sum(math.log(r) for r in rev) / len(rev))
        print(f"threshold (70.7 % point, geometric mean of {len(rev)} reversals after the second): "
              f"{est:.1f} N/m; the model observer's: {model:.1f} N/m")
    else:
        print(f"no reversals after the second in {args.trials} trials; the model observer's 70.7 % point: "
              f"{model:.1f} N/m")
    return 0


if __name__ == "__main__":
    sys.exit(main())

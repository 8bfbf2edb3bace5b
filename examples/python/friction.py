"""Friction-model comparison on the Fig. 7 peg harness: a 0.2 kg peg on two contacts (2 N normal force
each) pushed by a unidirectional sinusoid F_pk (1 - cos 2 pi t) / 2 at 1 Hz.

    python examples/python/friction.py [--out reproduction/python]

Prints creep (stick-phase drift), advance per cycle and max |x| for every model at F_pk = 2.1 N (above
breakaway) and 1.8 N (below), and, if matplotlib is installed, writes OUT/friction.png with x(t).
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

from haptic2d import harness

MODELS = ["classical", "salcudean-vlaar", "reset-integrator", "hayward-armstrong", "dahl", "nahvi"]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join("reproduction", "python"), help="output folder for PNGs")
    args = ap.parse_args()

    runs = {}
    for f_pk in (2.1, 1.8):
        print(f"F_pk = {f_pk} N")
        for m in MODELS:
            r = harness.peg(m, f_pk=f_pk, duration=5.2)
            runs[m, f_pk] = r
            creep = ", ".join(f"{c * 1e3:.2f}" for c in r.metrics["creep"])
            adv = ", ".join(f"{a * 1e3:.1f}" for a in r.metrics["advance"])
            print(f"  {m:18s} creep (mm) {creep:28s} advance (mm) {adv:18s} max|x| {r.metrics['max_abs_x'] * 1e3:7.3f} mm")

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no figure written (pip install matplotlib)")
        return 0
    os.makedirs(args.out, exist_ok=True)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for ax, f_pk in zip(axes, (2.1, 1.8)):
        for m in MODELS:
            r = runs[m, f_pk]
            ax.plot(r.t, np.asarray(r.x) * 1e3, label=m)
        ax.set(title=f"F_pk = {f_pk} N", xlabel="t (s)", ylabel="peg position x (mm)")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    path = os.path.join(args.out, "friction.png")
    fig.savefig(path, dpi=100)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

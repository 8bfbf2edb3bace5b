"""Wall-stiffness study, Z-width style: which stiffness x damping pairs keep each virtual wall from
gaining energy at a given sample rate (the Fig. 4 harness: a 0.5 kg mass pushed by 2 N into a wall).

    python examples/python/walls.py [--rate 500] [--points 10] [--out reproduction/python]

Prints a table per wall law and, if matplotlib is installed, writes OUT/walls.png: one panel per law
with each grid point coloured by class, and Colgate's passivity bound b = K*T/2 where the damping is
the plant's. A second figure, OUT/walls_seh_bounce.png, shows the SEH wall's contact ratios against K.
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

import haptic2d
from haptic2d import harness

CLASS_COLOURS = {"dissipative": "tab:green", "marginal": "tab:orange", "gains_energy": "tab:red"}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rate", type=float, default=500.0, help="sample rate (Hz)")
    ap.add_argument("--points", type=int, default=10, help="grid points per axis")
    ap.add_argument("--out", default=os.path.join("reproduction", "python"), help="output folder for PNGs")
    args = ap.parse_args()

    models = ["zoh", "seh", "minsky", "colgate", "paper"]
    s = haptic2d.sweep_walls(models, rate=args.rate, points=args.points)
    T = 1.0 / args.rate
    # Z-width table: for each stiffness, the least damping on the grid that keeps the wall dissipative.
    ks = np.unique(s["k_n_m"])
    print(f"least dissipative damping (N s/m) at {args.rate:g} Hz; '-' = none on the grid")
    print("K (N/m)   " + "".join(f"{m + ' (' + s['damping_kind'][s['model'] == m][0] + ')':>18s}" for m in models))
    for k in ks:
        cells = []
        for m in models:
            sel = (s["model"] == m) & (s["k_n_m"] == k) & (s["class"] == "dissipative")
            cells.append(f"{s['damping_n_s_m'][sel].min():18.3g}" if sel.any() else f"{'-':>18s}")
        print(f"{k:9.0f} " + "".join(cells))

    # The SEH wall alone: contact ratio of the first bounce against stiffness (no damping).
    ks = np.geomspace(200, 20000, 15)
    ratios = []
    for k in ks:
        r = harness.wall("seh", K=k, m=0.5, T=T, push=2.0, duration=10)
        ratios.append(r.metrics["ratios"][0] if len(r.metrics["ratios"]) else np.nan)
    print("seh first-bounce exit/entry speed ratio vs K:")
    for k, q in zip(ks, ratios):
        print(f"  K = {k:8.0f} N/m  ratio = {q:.3f}")

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no figure written (pip install matplotlib)")
        return 0
    os.makedirs(args.out, exist_ok=True)
    fig, axes = plt.subplots(1, len(models), figsize=(4 * len(models), 4), sharey=True)
    for ax, m in zip(axes, models):
        sel = s["model"] == m
        for c, colour in CLASS_COLOURS.items():
            pick = sel & (s["class"] == c)
            ax.scatter(s["k_n_m"][pick], s["damping_n_s_m"][pick], c=colour, marker="s", label=c)
        if s["damping_kind"][sel][0] == "plant":
            k = np.geomspace(s["k_n_m"].min(), s["k_n_m"].max(), 50)
            ax.plot(k, k * T / 2, "k--", label="b = K T / 2")
        ax.set(xscale="log", yscale="log", title=m, xlabel="stiffness K (N/m)")
    axes[0].set_ylabel("damping (N s/m)")
    axes[-1].legend(fontsize=8)
    fig.suptitle(f"Wall sweep at {args.rate:g} Hz (Fig. 4 harness)")
    fig.tight_layout()
    path = os.path.join(args.out, "walls.png")
    fig.savefig(path, dpi=100)
    fig2, ax = plt.subplots(figsize=(5, 4))
    ax.semilogx(ks, ratios, "o-")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set(xlabel="stiffness K (N/m)", ylabel="first bounce exit/entry speed", title="SEH wall")
    fig2.tight_layout()
    path2 = os.path.join(args.out, "walls_seh_bounce.png")
    fig2.savefig(path2, dpi=100)
    print(f"wrote {path} and {path2}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

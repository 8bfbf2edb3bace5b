#!/usr/bin/env python3
"""Instructions of every world step, by function: the landing's worst samples, load-independent.

`haptic2d-bench`'s phase table times the steps on a clock, which a shared machine's load
inflates. This reads callgrind's instruction counts instead, one dump per world step
(`--dump-before` at `World::begin_step`), and prints the median and the worst 1 % of a range of
steps, and the functions that cost them (self instructions, inlined code included) averaged over
the steps near the median (the middle 10 %) and over the worst 1 %. The
summary's overlap report (`max_overlap` and its SAT test `sat_depth_above`, not the step) is left
out.

Usage (docs/PERFORMANCE.md, session 30):

    cargo build --release -p haptic2d-cli
    mkdir -p /tmp/steps && valgrind --tool=callgrind --dump-before='*World>::begin_step' \\
        --callgrind-out-file=/tmp/steps/s.out target/release/haptic2d simulate pile:1000 --duration 1.2
    python3 scripts/sample_profile.py /tmp/steps/s.out --from 0 --to 1000 --top 16

Dump `s.out.K` (K ≥ 2) holds the work from the start of step K − 2 to the start of step K − 1.
"""

import argparse
import collections
import glob
import re
import sys

# Functions that are the simulate command's per-sample reports, not the world step. The overlap
# report's separating-axis test (`collide::clip::sat_depth_above` and its `sat_depth_rest`) is
# called only by `collide/overlap.rs`, so it is the report's too (counted as the step's before
# session 31: 0.41 M instructions a settled pile:1000 step).
NOT_THE_STEP = (
    "world_mcap",
    "max_overlap",
    "OverlapSummary",
    "overlap::",
    "sat_depth_above",
    "sat_depth_rest",
)


def self_costs(path):
    """Self instructions by function name in one callgrind dump (the cost lines after `calls=`
    are the callee's inclusive cost and are skipped)."""
    names, by, current, skip = {}, collections.Counter(), "?", False
    name_re = re.compile(r"c?fn=\((\d+)\)(?: (.*))?")
    with open(path, errors="replace") as f:
        for line in f:
            if skip:
                skip = False
                continue
            if line.startswith(("fn=", "cfn=")):
                m = name_re.match(line.strip())
                if m and m.group(2):
                    names[m.group(1)] = m.group(2)
                if m and line.startswith("fn="):
                    current = names.get(m.group(1), "?")
                continue
            if line.startswith("calls="):
                skip = True
                continue
            if line[:1].isdigit() or line[:1] in "+-*":
                parts = line.split()
                if len(parts) >= 2 and parts[1].isdigit():
                    by[current] += int(parts[1])
    return by


def short(name):
    return re.sub(r"<impl [^>]*>", "", name).replace("haptic2d::", "")[:72]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", help="the --callgrind-out-file given to valgrind (its dumps are OUT.K)")
    ap.add_argument("--from", dest="lo", type=int, default=0, help="first step (default 0)")
    ap.add_argument("--to", dest="hi", type=int, default=1000, help="end step (default 1000)")
    ap.add_argument("--top", type=int, default=16, help="functions to list (default 16)")
    a = ap.parse_args()
    dumps = {}
    for p in glob.glob(a.out + ".*"):
        k = p.rsplit(".", 1)[1]
        if k.isdigit() and a.lo <= int(k) - 2 < a.hi:
            dumps[int(k) - 2] = p
    if not dumps:
        sys.exit(f"no dumps {a.out}.K for steps {a.lo}..{a.hi}: run valgrind as the usage says")
    steps = []
    for k in sorted(dumps):
        by = self_costs(dumps[k])
        cost = sum(v for f, v in by.items() if not any(x in f for x in NOT_THE_STEP))
        steps.append((cost, k, by))
    steps.sort(key=lambda s: s[0])
    n = len(steps)
    median, p99 = steps[n // 2][0], steps[max(0, -(-99 * n // 100) - 1)][0]
    worst = [s for s in steps if s[0] >= p99]
    middle = steps[max(0, n // 2 - n // 20): n // 2 + n // 20 + 1]
    print(f"steps {a.lo}..{a.hi} ({n}): median {median / 1e6:.2f} M instructions, "
          f"p99 {p99 / 1e6:.2f} M, max {steps[-1][0] / 1e6:.2f} M, p99/median {p99 / median:.2f}")
    print("worst 1 %: steps", sorted(k for _, k, _ in worst))

    def mean(group):
        c = collections.Counter()
        for _, _, by in group:
            for f, v in by.items():
                c[short(f)] += v
        return {f: v / len(group) for f, v in c.items()}

    m, w = mean(middle), mean(worst)
    print(f"{'function (self, M instructions a step)':<72} {'mid 10%':>8} {'worst1%':>8}")
    for f in sorted(set(m) | set(w), key=lambda f: -w.get(f, 0))[: a.top]:
        print(f"{f:<72} {m.get(f, 0) / 1e6:>8.3f} {w.get(f, 0) / 1e6:>8.3f}")


if __name__ == "__main__":
    main()

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

`--self-test` checks the reader on a small profile written both ways callgrind writes one (with and
without `--dump-instr=yes`).

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
    are the callee's inclusive cost and are skipped). A cost line holds the positions named by
    the dump's `positions:` header (`line`, or `instr line` with `--dump-instr=yes`), then the
    events (`Ir` first)."""
    names, by, current, skip = {}, collections.Counter(), "?", False
    cost_at = 1
    name_re = re.compile(r"c?fn=\((\d+)\)(?: (.*))?")
    with open(path, errors="replace") as f:
        for line in f:
            if line.startswith("positions:"):
                cost_at = len(line.split()) - 1
                continue
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
                if len(parts) > cost_at and parts[cost_at].isdigit():
                    by[current] += int(parts[cost_at])
    return by


def self_test():
    """Reads the same small profile written both ways callgrind writes it (`positions: line`, and
    `positions: instr line` with `--dump-instr=yes`) and fails unless both give each function's
    self cost as written into it: alpha 100 + 50 (the 999 after `calls=` is beta's inclusive cost,
    not alpha's), beta 7."""
    import os
    import tempfile

    by_line = (
        "version: 1\npositions: line\nevents: Ir\nfl=(1) a.rs\nfn=(1) alpha\n10 100\n+1 50\n"
        "cfn=(2) beta\ncalls=3 20\n12 999\nfn=(2)\n20 7\n"
    )
    by_instr = (
        "version: 1\npositions: instr line\nevents: Ir\nfl=(1) a.rs\nfn=(1) alpha\n0x10 10 100\n"
        "+4 +1 50\ncfn=(2) beta\ncalls=3 0x20 20\n+4 12 999\nfn=(2)\n0x20 20 7\n"
    )
    for text in (by_line, by_instr):
        with tempfile.NamedTemporaryFile("w", suffix=".out", delete=False) as f:
            f.write(text)
        try:
            got = dict(self_costs(f.name))
        finally:
            os.unlink(f.name)
        want = {"alpha": 150, "beta": 7}
        if got != want:
            sys.exit(f"sample_profile self-test: {text.split(chr(10))[1]!r} read as {got}, want {want}")
    print("sample_profile self-test: both dump formats read alike")


def short(name):
    return re.sub(r"<impl [^>]*>", "", name).replace("haptic2d::", "")[:72]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    if sys.argv[1:] == ["--self-test"]:
        self_test()
        return
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

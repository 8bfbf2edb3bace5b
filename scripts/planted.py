"""The verdict of a checker's `--self-test`: it planted `expected` problems in a small tree it made
and must report exactly those (imported by check_refs.py and check_architecture.py)."""


def verdict(name, expected, found, what):
    """Prints what `name` missed and what it reported beyond `expected`; 0 if the two sets are
    equal (with one line naming how many `what` were found), 1 otherwise."""
    expected, found = set(expected), set(found)
    if found != expected:
        print(f"{name} self-test FAILED")
        for p in sorted(expected - found):
            print(f"  not found: {p}")
        for p in sorted(found - expected):
            print(f"  unexpected: {p}")
        return 1
    print(f"{name} self-test: the {len(expected)} {what} found, nothing else reported")
    return 0

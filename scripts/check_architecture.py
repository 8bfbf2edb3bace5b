#!/usr/bin/env python3
"""Checks that docs/ARCHITECTURE.md §2 describes the crates as Cargo.toml has them (CI runs it: .ci/run).

1. The crate list (the code block that starts with `crates/`) names every folder of crates/ that holds
   a Cargo.toml, and nothing else.
2. The dependency diagram (the code block whose lines read `CRATE ───► A, B, …`) has one line per
   crate with a library or binary of the workspace (every crate but the dev-only test-support and the
   excluded measuring tools, which the text describes on their own) and, on each line, exactly the
   workspace crates of that crate's `[dependencies]` (parenthesised notes are ignored; names after a
   `;` are outside crates that must be among its dependencies too; `(no workspace crate)` means none).
3. `haptic2d-test-support` is a `[dev-dependencies]` entry only: no crate lists it under
   `[dependencies]`, and the crates the text names as its users are exactly those that list it.

Prints every mismatch as `docs/ARCHITECTURE.md: what` and exits 1 if there is any; 0 otherwise.
Usage: python3 scripts/check_architecture.py [--verbose] [--self-test]
(`--self-test` runs the check on a small tree it makes, with each kind of mismatch, and fails unless
it reports exactly those.)
"""

import re
import sys
import tempfile
import tomllib
from pathlib import Path

from planted import verdict

ROOT = Path(__file__).resolve().parent.parent
TEST_SUPPORT = "haptic2d-test-support"


def code_blocks(text):
    """The fenced code blocks of a Markdown text, each as a list of lines."""
    blocks, cur = [], None
    for line in text.split("\n"):
        if line.startswith("```"):
            if cur is None:
                cur = []
            else:
                blocks.append(cur)
                cur = None
        elif cur is not None:
            cur.append(line)
    return blocks


def crates(root):
    """{crate folder name: parsed Cargo.toml} for every crates/*/Cargo.toml."""
    out = {}
    for toml in sorted((root / "crates").glob("*/Cargo.toml")):
        out[toml.parent.name] = tomllib.loads(toml.read_text(encoding="utf-8"))
    return out


def deps(manifest, table="dependencies"):
    """The dependency names of one table of a manifest (a `package = "…"` rename counts by package)."""
    out = set()
    for name, spec in manifest.get(table, {}).items():
        if isinstance(spec, dict) and "package" in spec:
            name = spec["package"]
        out.add(name)
    return out


def comma_list(text):
    """The names of a comma-separated list, blanks dropped."""
    return {n.strip() for n in text.split(",") if n.strip()}


def diagram(blocks):
    """{crate: (workspace deps, outside deps)} from the block of `X ───► …` lines."""
    arrow = re.compile(r"^(haptic2d[\w-]*)\s+─+►\s*(.*)$")
    for b in blocks:
        lines = [arrow.match(l) for l in b if l.strip()]
        if lines and all(lines):
            out = {}
            for m in lines:
                rest = m.group(2)
                while re.search(r"\([^()]*\)", rest):  # notes, innermost first: `devices()`
                    rest = re.sub(r"\([^()]*\)", "", rest)
                inside, _, outside = rest.partition(";")
                out[m.group(1)] = (comma_list(inside), comma_list(outside))
            return out
    return None


def check(root):
    arch = (root / "docs/ARCHITECTURE.md").read_text(encoding="utf-8")
    section = arch.split("\n## 2.", 1)[1].split("\n## 3.", 1)[0] if "\n## 2." in arch else ""
    blocks = code_blocks(section)
    manifests = crates(root)
    names = {m.get("package", {}).get("name", d): d for d, m in manifests.items()}
    errors = []

    listing = next((b for b in blocks if b and b[0].strip() == "crates/"), None)
    if listing is None:
        errors.append("§2 has no crate list (a code block starting with `crates/`)")
    else:
        listed = {l.split()[0].rstrip("/") for l in listing[1:] if l.startswith("  ") and l.split()}
        for d in sorted(set(manifests) - listed):
            errors.append(f"§2's crate list does not name crates/{d}/")
        for d in sorted(listed - set(manifests)):
            errors.append(f"§2's crate list names crates/{d}/, which has no Cargo.toml")

    drawn = diagram(blocks)
    if drawn is None:
        errors.append("§2 has no dependency diagram (a code block of `CRATE ───► …` lines)")
        drawn = {}
    workspace = set(names)
    outside_workspace = excluded_members(root)
    excluded = {n for n, d in names.items() if d in outside_workspace}
    for name in sorted(workspace - {TEST_SUPPORT} - excluded - set(drawn)):
        errors.append(f"the dependency diagram has no line for {name}")
    for name, (inside, outside) in sorted(drawn.items()):
        if name not in names:
            errors.append(f"the dependency diagram draws {name}, which is not a crate of crates/")
            continue
        m = manifests[names[name]]
        real = deps(m) & workspace
        if inside == {"no workspace crate"}:
            inside = set()
        for n in sorted(inside - real):
            errors.append(f"the diagram says {name} depends on {n}; its Cargo.toml does not")
        for n in sorted(real - inside):
            errors.append(f"{name}'s Cargo.toml depends on {n}; the diagram does not say so")
        for n in sorted(outside - deps(m)):
            errors.append(f"the diagram says {name} depends on {n}; its Cargo.toml does not")

    users = {n for n, d in names.items() if TEST_SUPPORT in deps(manifests[d], "dev-dependencies")}
    for n in sorted(n for n, d in names.items() if TEST_SUPPORT in deps(manifests[d])):
        errors.append(f"{n} lists {TEST_SUPPORT} under [dependencies]; it is dev-only")
    said = re.search(r"`haptic2d-test-support`[^.]*?\(of ([^)]*)\)", section)
    if said:
        named = set(re.findall(r"haptic2d[\w-]*", said.group(1)))
        if named != users:
            errors.append(
                f"the text names the users of {TEST_SUPPORT} as {sorted(named)}; "
                f"the Cargo.toml files: {sorted(users)}"
            )
    return errors


def excluded_members(root):
    """The crate folders the root workspace excludes (`exclude = [...]`)."""
    ws = tomllib.loads((root / "Cargo.toml").read_text(encoding="utf-8")).get("workspace", {})
    return {Path(p).name for p in ws.get("exclude", [])}


def self_test():
    with tempfile.TemporaryDirectory() as d:
        root = Path(d)
        (root / "docs").mkdir()
        for name, body in {
            "core": "",
            "rt": '[dependencies]\nhaptic2d = { path = "../core" }\n',
            "app": '[dependencies]\nhaptic2d-rt = { path = "../rt" }\nserde = "1"\n'
            '[dev-dependencies]\nhaptic2d-test-support = { path = "../support" }\n',
            "support": "",
            "lost": "",
        }.items():
            (root / "crates" / name).mkdir(parents=True)
            pkg = {"core": "haptic2d", "support": TEST_SUPPORT}.get(name, f"haptic2d-{name}")
            (root / "crates" / name / "Cargo.toml").write_text(
                f'[package]\nname = "{pkg}"\n{body}', encoding="utf-8"
            )
        (root / "Cargo.toml").write_text("[workspace]\n", encoding="utf-8")
        (root / "docs/ARCHITECTURE.md").write_text(
            "# A\n\n## 2. Layout\n\n```\ncrates/\n  core/ x\n  rt/ x\n  app/ x\n  support/ x\n  ghost/ x\n```\n\n"
            "```\nhaptic2d-app ──► haptic2d; serde, toml\nhaptic2d-rt ──► haptic2d\n"
            "haptic2d ──► (no workspace crate)\n```\n\n"
            "`haptic2d-test-support` is dev-only (of haptic2d-app, haptic2d-rt).\n\n## 3. Next\n",
            encoding="utf-8",
        )
        got = check(root)
    want = sorted([
        "§2's crate list does not name crates/lost/",
        "§2's crate list names crates/ghost/, which has no Cargo.toml",
        "the dependency diagram has no line for haptic2d-lost",
        "the diagram says haptic2d-app depends on haptic2d; its Cargo.toml does not",
        "haptic2d-app's Cargo.toml depends on haptic2d-rt; the diagram does not say so",
        "the diagram says haptic2d-app depends on toml; its Cargo.toml does not",
        "the text names the users of haptic2d-test-support as ['haptic2d-app', 'haptic2d-rt']; "
        "the Cargo.toml files: ['haptic2d-app']",
    ])
    return verdict("check_architecture", want, got, "planted mismatches")


def main():
    if "--self-test" in sys.argv:
        return self_test()
    errors = check(ROOT)
    for e in errors:
        print(f"docs/ARCHITECTURE.md: {e}")
    if errors:
        return 1
    if "--verbose" in sys.argv:
        n = len(crates(ROOT))
        print(f"docs/ARCHITECTURE.md §2: the crate list and the dependency diagram match the {n} Cargo.toml files")
    return 0


if __name__ == "__main__":
    sys.exit(main())

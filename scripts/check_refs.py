#!/usr/bin/env python3
"""Checks that the project's cross-references resolve (CI runs it: .ci/run).

1. Relative Markdown links `[text](path)` and `[text](path#anchor)` in every tracked *.md file name a
   file that exists, and an anchor names a heading of that file (GitHub's slug rules).
2. Section references in code, docs, scenes and device files:
   - `DESIGN §N[.M]`   -> a numbered heading of docs/ARCHITECTURE.md,
   - `DEVICES §N[.M]`  -> a numbered heading of docs/DEVICES.md,
   - `MODELS §X` and a bare `§X` -> a numbered heading of docs/MODELS.md (`## 7.`, `### 7.3`, and the
     appendices' letters: `§A`, `§E`),
   where a reference to `§7.3.2` is satisfied by `7.3.2`, and one to a section whose number exists only
   as a part of a heading list (e.g. `§1–§4`) is checked number by number.
   References to the paper's own sections are written `paper §N` and are not checked.

Prints every broken reference as `file:line: what` and exits 1 if there is any; 0 otherwise.
Usage: python3 scripts/check_refs.py [--verbose] [--self-test]
(`--self-test` runs the checker on a small repository it makes, with one reference of each kind
broken and one of each kind sound, and fails unless it finds exactly the broken ones.)
"""

import re
import subprocess
import sys
from pathlib import Path

from planted import verdict

ROOT = Path(__file__).resolve().parent.parent
SKIP_DIRS = ("docs/archive/", "scripts/check_refs.py")


def tracked(pattern_suffixes):
    out = subprocess.run(
        ["git", "ls-files"], cwd=ROOT, check=True, capture_output=True, text=True
    ).stdout.split("\n")
    return [
        ROOT / p
        for p in out
        if p and p.endswith(pattern_suffixes) and not p.startswith(SKIP_DIRS)
    ]


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    s = heading.strip().lower()
    s = re.sub(r"[^\w\- ]", "", s, flags=re.UNICODE)
    return s.replace(" ", "-")


def headings(path):
    """(slugs, section numbers) of a Markdown file. A numbered list item `3. …` at the start of a line
    under a numbered heading `1.3` is section `1.3.3` (DEVICES.md numbers its facts so)."""
    slugs, numbers = set(), set()
    counts = {}
    in_code = False
    current = None
    for line in path.read_text(encoding="utf-8").split("\n"):
        if line.startswith("```"):
            in_code = not in_code
            continue
        if in_code:
            continue
        item = re.match(r"^([0-9]+)\. ", line)
        if item and current:
            numbers.add(f"{current}.{item.group(1)}")
        m = re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        text = m.group(2)
        base = slug(re.sub(r"`", "", text))
        n = counts.get(base, 0)
        counts[base] = n + 1
        slugs.add(base if n == 0 else f"{base}-{n}")
        # "7.3 The LCP solver", "0. Conventions", "Appendix E. Frictional impacts", "F. …", "9.5a …"
        num = re.match(r"^(?:Part\s+)?(?:Appendix\s+)?([0-9]+(?:\.[0-9]+)*[a-z]?|[A-Z])[.\s:]", text)
        current = num.group(1).rstrip(".") if num else None
        if current:
            numbers.add(current)
    return slugs, numbers


def self_test():
    """The checker against a repository with known sound and broken references."""
    global ROOT
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        (root / "docs").mkdir()
        (root / "docs/MODELS.md").write_text(
            "# Models\n\n## 1. Friction\n\n### 1.2 Dahl\n\n## Appendix E. Impacts\n", encoding="utf-8"
        )
        (root / "docs/ARCHITECTURE.md").write_text("# Map\n\n## 3. Commands\n", encoding="utf-8")
        (root / "docs/GOOD.md").write_text(
            "[m](MODELS.md#12-dahl), [a](ARCHITECTURE.md), §1.2, §E, MODELS §1, DESIGN §3, paper §9\n",
            encoding="utf-8",
        )
        (root / "docs/BAD.md").write_text(
            "[x](NOPE.md)\n[y](MODELS.md#no-such-heading)\nsee §9.9\nsee DESIGN §4\n", encoding="utf-8"
        )
        (root / "lib.rs").write_text("//! the order of §1.3 and §F\n", encoding="utf-8")
        subprocess.run(["git", "init", "-q"], cwd=root, check=True)
        subprocess.run(["git", "add", "-A"], cwd=root, check=True)
        saved, ROOT = ROOT, root
        try:
            problems = find_problems()
        finally:
            ROOT = saved
    expected = {
        "docs/BAD.md:1: link to a missing file `NOPE.md`",
        "docs/BAD.md:2: no heading `#no-such-heading` in MODELS.md",
        "docs/BAD.md:3: `MODELS §9.9`: no section 9.9 in docs/MODELS.md",
        "docs/BAD.md:4: `DESIGN §4`: no section 4 in docs/ARCHITECTURE.md",
        "lib.rs:1: `MODELS §1.3`: no section 1.3 in docs/MODELS.md",
        "lib.rs:1: `MODELS §F`: no section F in docs/MODELS.md",
    }
    return verdict("check_refs", expected, problems, "broken references")


def main():
    if "--self-test" in sys.argv:
        return self_test()
    verbose = "--verbose" in sys.argv
    problems, md_count, count = find_problems(with_counts=True)
    if verbose:
        print(f"check_refs: {md_count} Markdown files, {count} section references")
    for p in problems:
        print(p)
    print(f"check_refs: {len(problems)} broken reference(s)")
    return 1 if problems else 0


def find_problems(with_counts=False):
    """Every broken reference as `file:line: what` (with the counts of files and references read)."""
    problems = []
    md_files = tracked((".md",))
    cache = {}

    def heads(p):
        if p not in cache:
            cache[p] = headings(p)
        return cache[p]

    # 1. Markdown links.
    link = re.compile(r"\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
    for f in md_files:
        in_code = False
        for i, line in enumerate(f.read_text(encoding="utf-8").split("\n"), 1):
            if line.startswith("```"):
                in_code = not in_code
                continue
            if in_code:
                continue
            for target in link.findall(line):
                if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("<"):
                    continue  # http:, https:, mailto:
                path, _, anchor = target.partition("#")
                dest = f if path == "" else (f.parent / path)
                if not dest.exists():
                    problems.append(f"{f.relative_to(ROOT)}:{i}: link to a missing file `{target}`")
                    continue
                if anchor and dest.suffix == ".md" and anchor not in heads(dest.resolve())[0]:
                    problems.append(f"{f.relative_to(ROOT)}:{i}: no heading `#{anchor}` in {path or f.name}")

    # 2. Section references.
    docs = {
        "DESIGN": ROOT / "docs/ARCHITECTURE.md",
        "DEVICES": ROOT / "docs/DEVICES.md",
        "MODELS": ROOT / "docs/MODELS.md",
    }
    # A book's own sections are cited with the book: "Stronge §4.3", "Impact Mechanics, §4.3",
    # "*Numerical Recipes* §11.5"; `§N` is a placeholder in prose about the references.
    ref = re.compile(r"§\s?([0-9]+(?:\.[0-9]+)*[a-z]?|[A-F]\b)")
    external = re.compile(r"(Stronge|Impact Mechanics\*?,?( 2000,)?|Numerical Recipes\*?|Brogliato|Glocker|paper|Paper|PAPER|STYLE(\.md)?)\s*$")
    # Which document a reference means: the nearest name before it on the line ("DESIGN §1",
    # "docs/DEVICES.md §1.3", "[DEVICES.md](DEVICES.md) §6"), else the file's own kind (a bare § in
    # DEVICES.md is DEVICES.md's own), else MODELS.
    names = re.compile(r"(DESIGN|ARCHITECTURE(?:\.md)?|DEVICES(?:\.md)?|MODELS(?:\.md)?)(?:\]\([^)]*\))?\s*$")
    kinds = {"DESIGN": "DESIGN", "ARCHITECTURE": "DESIGN", "DEVICES": "DEVICES", "MODELS": "MODELS"}
    sources = tracked((".rs", ".md", ".toml", ".py", ".pyi", ".js", ".html", ".c", ".h", ".sh"))
    count = 0
    for f in sources:
        text = f.read_text(encoding="utf-8", errors="replace")
        own = {"DEVICES.md": "DEVICES"}.get(f.name, "MODELS")
        for i, line in enumerate(text.split("\n"), 1):
            for m in ref.finditer(line):
                num = m.group(1)
                before = line[: m.start()]
                if external.search(before):
                    continue
                named = names.search(before)
                kind = kinds[named.group(1).split(".")[0]] if named else own
                doc = docs[kind]
                count += 1
                if not doc.exists():
                    problems.append(f"{f.relative_to(ROOT)}:{i}: `{kind} §{num}` points at {doc.relative_to(ROOT)}, which does not exist")
                    continue
                if num not in heads(doc)[1]:
                    problems.append(f"{f.relative_to(ROOT)}:{i}: `{kind} §{num}`: no section {num} in {doc.relative_to(ROOT)}")
    if with_counts:
        return problems, len(md_files), count
    return problems


if __name__ == "__main__":
    sys.exit(main())

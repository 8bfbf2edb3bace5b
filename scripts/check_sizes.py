#!/usr/bin/env python3
"""Checks that no non-test Rust function and no source file outgrows its documented limit.

Usage: python3 scripts/check_sizes.py [--verbose] [--report]

Limits (docs/ARCHITECTURE.md, "Size limits"):
- a function outside test code: at most FN_LIMIT lines, from its `fn` line to its closing brace;
- a source file under crates/*/src: at most FILE_LIMIT lines, not counting its `#[cfg(test)]` modules.

Exceptions live in scripts/size_allowlist.txt, one per line: `fn PATH::NAME LINES  # why` or
`file PATH LINES  # why`. An exception names the size it was allowed at; growing past it fails
too, so an allow-listed item cannot quietly get longer. An entry that no longer exceeds the limit
is reported as stale (and fails), so the list only shrinks.

Test code (files under tests/, benches/, examples/, `#[cfg(test)]` modules, and the files of modules
declared `#[cfg(test)] mod NAME;`) is not checked.
The parser is a brace counter that skips strings, chars, and comments; it is not a Rust parser, but
it only has to find where a `fn` body ends.
"""

import os
import re
import sys

FN_LIMIT = 120
FILE_LIMIT = 900
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ALLOW = os.path.join(ROOT, "scripts", "size_allowlist.txt")

FN_RE = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?(?:const\s+)?(?:async\s+)?(?:unsafe\s+)?"
                   r"(?:extern\s+\"[^\"]*\"\s+)?fn\s+([A-Za-z_][A-Za-z0-9_]*)")
CFG_TEST_RE = re.compile(r"^\s*#\[cfg\((?:all\()?test")


def strip_code(text):
    """Returns the text with string, char literal and comment contents blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'r(#*)"', text[i:])
            close = '"' + m.group(1)
            j = text.find(close, i + len(m.group(0)))
            j = n if j < 0 else j + len(close)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append('"' + re.sub(r"[^\n]", " ", text[i + 1:j - 1]) + '"')
            i = j
        elif c == "'":
            # A char literal ('a', '\n', '\u{..}') or a lifetime ('a); only blank the literal.
            m = re.match(r"'(?:\\.|\\u\{[0-9a-fA-F]+\}|[^\\'])'", text[i:])
            if m:
                out.append(" " * len(m.group(0)))
                i += len(m.group(0))
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def block_end(lines, start):
    """Index of the line that closes the first `{` at or after line `start` (None if a `;` ends it first)."""
    depth, opened, nest = 0, False, 0
    for k in range(start, len(lines)):
        for ch in lines[k]:
            if ch == "{":
                depth, opened = depth + 1, True
            elif ch == "}":
                depth -= 1
                if opened and depth == 0:
                    return k
            elif ch in "([" and not opened:
                nest += 1
            elif ch in ")]" and not opened:
                nest -= 1
            # A `;` inside the signature's brackets (`-> [f64; 2]`) does not end a declaration.
            elif ch == ";" and not opened and depth == 0 and nest == 0:
                return None
    return None


TEST_MOD_RE = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;")


def test_module_files(path, lines, k):
    """The files of the module declared `mod NAME;` on line k of `path` (NAME.rs, NAME/mod.rs)."""
    m = TEST_MOD_RE.match(lines[k]) if k < len(lines) else None
    if not m:
        return []
    d, f = os.path.split(path)
    if f not in ("mod.rs", "lib.rs", "main.rs"):
        d = os.path.join(d, f[:-3])
    return [os.path.normpath(os.path.join(d, m.group(1) + ".rs")),
            os.path.normpath(os.path.join(d, m.group(1), "mod.rs"))]


TEST_FILES = set()


def scan(path):
    """Returns (non-test line count, [(fn name, first line, length)]) for one file."""
    text = strip_code(open(path, encoding="utf-8").read())
    lines = text.split("\n")
    test_lines = set()
    if os.path.normpath(path) in TEST_FILES:
        test_lines = set(range(len(lines)))
    k = 0
    while k < len(lines):
        if CFG_TEST_RE.match(lines[k]):
            # `#[cfg(test)] mod NAME;`: the module's file is test code.
            for f in test_module_files(path, lines, k + 1):
                TEST_FILES.add(f)
            end = block_end(lines, k + 1)
            if end is not None:
                test_lines.update(range(k, end + 1))
                k = end + 1
                continue
        k += 1
    fns = []
    for k, line in enumerate(lines):
        if k in test_lines:
            continue
        m = FN_RE.match(line)
        if m:
            end = block_end(lines, k)
            if end is not None:
                fns.append((m.group(1), k + 1, end - k + 1))
    raw = open(path, encoding="utf-8").read().split("\n")
    counted = sum(1 for k in range(len(raw)) if k not in test_lines)
    return counted, fns


def sources():
    crates = os.path.join(ROOT, "crates")
    for dirpath, dirnames, filenames in os.walk(crates):
        dirnames[:] = sorted(d for d in dirnames if d not in ("target", "tests", "benches", "examples", "node_modules"))
        rel = os.path.relpath(dirpath, ROOT)
        if "/src" not in "/" + rel.replace(os.sep, "/") + "/":
            continue
        for f in sorted(filenames):
            if f.endswith(".rs"):
                yield os.path.relpath(os.path.join(dirpath, f), ROOT).replace(os.sep, "/")


def load_allow():
    allow = {}
    if not os.path.exists(ALLOW):
        return allow
    for no, line in enumerate(open(ALLOW, encoding="utf-8"), 1):
        body = line.split("#", 1)[0].strip()
        if not body:
            continue
        parts = body.split()
        if len(parts) != 3 or parts[0] not in ("fn", "file") or "#" not in line:
            sys.exit(f"{ALLOW}:{no}: expected `fn PATH::NAME LINES  # why` or `file PATH LINES  # why`")
        allow[(parts[0], parts[1])] = int(parts[2])
    return allow


def judge(key, label, size, limit, allow, seen, errors):
    """Records the problem, if any, of one item of `size` lines against `limit` and the allow-list."""
    if size <= limit and key not in allow:
        return
    seen.add(key)
    if key not in allow:
        errors.append(f"{label}: {size} lines > {limit}")
    elif size > allow[key]:
        errors.append(f"{label}: {size} lines, allow-listed at {allow[key]}")
    elif size <= limit:
        errors.append(f"{label}: {size} lines is within the limit of {limit}; remove its allow-list entry")


def main():
    verbose = "--verbose" in sys.argv
    report = "--report" in sys.argv
    allow = load_allow()
    seen = set()
    errors = []
    longest_fn = (0, "")
    longest_file = (0, "")
    nfiles = nfns = 0
    for path in sources():
        counted, fns = scan(os.path.join(ROOT, path))
        nfiles += 1
        longest_file = max(longest_file, (counted, path))
        judge(("file", path), f"file {path}", counted, FILE_LIMIT, allow, seen, errors)
        # Functions of the same name in one file (methods of different types) are judged by the
        # longest of them.
        longest_of = {}
        for name, line, length in fns:
            nfns += 1
            longest_fn = max(longest_fn, (length, f"{path}::{name}"))
            if length > longest_of.get(name, (0, 0))[0]:
                longest_of[name] = (length, line)
        for name, (length, line) in longest_of.items():
            judge(("fn", f"{path}::{name}"), f"fn {path}:{line} {name}", length, FN_LIMIT, allow, seen, errors)
            if report and length > FN_LIMIT:
                print(f"fn {path}::{name} {length}")
        if report and counted > FILE_LIMIT:
            print(f"file {path} {counted}")
    for key in sorted(set(allow) - seen):
        errors.append(f"{key[0]} {key[1]}: allow-listed but not found; remove its entry")
    if verbose or errors:
        print(f"check_sizes: {nfiles} files, {nfns} functions; limits {FN_LIMIT} lines a function, "
              f"{FILE_LIMIT} a file; {len(allow)} allow-listed")
        print(f"  longest function: {longest_fn[1]} ({longest_fn[0]} lines); "
              f"longest file: {longest_file[1]} ({longest_file[0]} non-test lines)")
    for e in errors:
        print("  " + e)
    if errors:
        print(f"check_sizes: {len(errors)} problem(s); split the item, or allow-list it with the reason "
              f"in scripts/size_allowlist.txt")
        sys.exit(1)


if __name__ == "__main__":
    main()

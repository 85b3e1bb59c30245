#!/usr/bin/env python3
"""The documentation against the repository and the executable.

Checks, and exits with status 1 listing every failure:
  1. every relative link and image in every tracked Markdown file resolves
     to a tracked file (or a folder holding tracked files), and a link's
     #fragment to a heading of the Markdown file it names;
  2. every flag that `mcrt --help` and `mcrt render|samples|diff --help`
     print appears in docs/cli.md;
  3. every strategy name `mcrt render --light-sampling` accepts appears, in
     backticks, in docs/samplers.md;
  4. CITATION.cff is valid CFF 1.2 (with --cffconvert, the validator of the
     Citation File Format's authors);
  5. every message in a string literal of src/, include/, tests/, scripts/
     and bench/ that points to the documentation names a tracked Markdown
     file and a section of it that exists (no bare "see README").

Usage: docs_check.py --root SOURCE_DIR --mcrt PATH/TO/mcrt [--cffconvert PATH]
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
from pathlib import Path

LINK = re.compile(r"!?\[(?:[^\]\\]|\\.)*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
HTML_SRC = re.compile(r"<(?:img|a)\b[^>]*?\b(?:src|href)\s*=\s*\"([^\"]+)\"", re.IGNORECASE)
FENCE = re.compile(r"^(```|~~~)")


def tracked_files(root: Path) -> set[str]:
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=root, check=True, capture_output=True).stdout
        # (Tracked files deleted from the work tree do not count.)
        return {p for p in out.decode().split("\0") if p and (root / p).exists()}
    except (OSError, subprocess.CalledProcessError):
        # Not a git checkout (a source archive): every file on disk.
        files = set()
        for d, dirs, names in os.walk(root):
            dirs[:] = [x for x in dirs if x not in (".git", ".venv") and not x.startswith("build")]
            files.update(str((Path(d) / n).relative_to(root)) for n in names)
        return files


def prose(text: str) -> str:
    """The text without fenced code blocks and inline code spans."""
    lines, fenced = [], False
    for line in text.splitlines():
        if FENCE.match(line.strip()):
            fenced = not fenced
            lines.append("")
            continue
        lines.append("" if fenced else re.sub(r"`[^`]*`", "", line))
    return "\n".join(lines)


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    h = re.sub(r"<[^>]+>", "", heading).strip().lower()
    h = re.sub(r"[^\w\- ]", "", h, flags=re.UNICODE)
    return h.replace(" ", "-")


def anchors(text: str) -> set[str]:
    seen: dict[str, int] = {}
    result = set()
    fenced = False
    for line in text.splitlines():
        if FENCE.match(line.strip()):
            fenced = not fenced
            continue
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if fenced or not m:
            continue
        s = slug(m.group(1))
        n = seen.get(s, 0)
        seen[s] = n + 1
        result.add(s if n == 0 else f"{s}-{n}")
    return result


def check_links(root: Path, files: set[str]) -> list[str]:
    folders = {str(Path(f).parent) for f in files}
    folders |= {str(p) for f in files for p in Path(f).parents}
    errors = []
    for md in sorted(f for f in files if f.endswith(".md")):
        text = (root / md).read_text(encoding="utf-8")
        body = prose(text)
        for lineno, line in enumerate(body.splitlines(), 1):
            for target in LINK.findall(line) + HTML_SRC.findall(line):
                if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.IGNORECASE):  # http:, https:, mailto:
                    continue
                path, _, fragment = target.partition("#")
                if not path:  # a heading of this file
                    if fragment and fragment not in anchors(text):
                        errors.append(f"{md}:{lineno}: no heading '#{fragment}' in this file")
                    continue
                resolved = os.path.normpath(str(Path(md).parent / path))
                if resolved.startswith(".."):
                    errors.append(f"{md}:{lineno}: link outside the repository: {target}")
                elif resolved not in files and resolved.rstrip("/") not in folders:
                    errors.append(f"{md}:{lineno}: link to a file that is not tracked: {target}")
                elif fragment and resolved.endswith(".md") and resolved in files:
                    if fragment not in anchors((root / resolved).read_text(encoding="utf-8")):
                        errors.append(f"{md}:{lineno}: no heading '#{fragment}' in {resolved}")
    return errors


# A message's pointer into the documentation, inside a string literal of
# the sources: "see README", "see docs/cli.md#input-files", a Markdown file
# of the repository and perhaps its section.
POINTER = re.compile(r"(?<![\w/.-])((?:[\w-]+/)*[\w-]+\.md)(#[\w-]+)?|\b(README)\b(?!\.md)")
SEE = re.compile(r"\bsee\s+(?:the\s+)?(?=README|(?:[\w-]+/)*[\w-]+\.md)")
STRING = {".cpp": re.compile(r'"(?:[^"\\\n]|\\.)*"'), ".hpp": re.compile(r'"(?:[^"\\\n]|\\.)*"'),
          ".py": re.compile(r'"(?:[^"\\\n]|\\.)*"|\'(?:[^\'\\\n]|\\.)*\''),
          ".sh": re.compile(r'"(?:[^"\\\n]|\\.)*"')}


def check_message_pointers(root: Path, files: set[str]) -> list[str]:
    """Every message that points to the documentation names a tracked
    Markdown file and a section of it that exists (a bare "see README"
    points nowhere in particular): any Markdown file named in a string
    literal of the program (src/, include/), and anything after "see" in a
    string literal of the tests, scripts and benchmarks (which also name the
    Markdown files they write)."""
    errors = []
    for f in sorted(files):
        ext = Path(f).suffix
        program = f.startswith(("src/", "include/"))
        if ext not in STRING or not (program or f.startswith(("tests/", "scripts/", "bench/"))):
            continue
        if f == "tests/docs_check.py":  # (its own docstrings quote the rule)
            continue
        text = (root / f).read_text(encoding="utf-8", errors="replace")
        for lineno, line in enumerate(text.splitlines(), 1):
            if line.strip().startswith(("//", "#")):
                continue
            for literal in STRING[ext].findall(line):
                starts = [m.end() for m in SEE.finditer(literal)] if not program else None
                for m in POINTER.finditer(literal):
                    if starts is not None and m.start() not in starts:
                        continue
                    doc, fragment, bare = m.group(1), m.group(2), m.group(3)
                    if bare:
                        errors.append(f"{f}:{lineno}: a message points to the README without naming its section")
                        continue
                    # Relative to the source file's folder, the repository's root, or docs/.
                    here = os.path.normpath(str(Path(f).parent / doc))
                    path = next((c for c in (here, doc, "docs/" + doc) if c in files), None)
                    if path is None:
                        errors.append(f"{f}:{lineno}: a message points to {doc}, which is not a tracked file")
                    elif not fragment:
                        errors.append(f"{f}:{lineno}: a message points to {doc} without naming its section (#...)")
                    elif fragment[1:] not in anchors((root / path).read_text(encoding="utf-8")):
                        errors.append(f"{f}:{lineno}: a message points to {doc}{fragment}, a section {path} does not have")
    return errors


def help_text(mcrt: str, *args: str) -> str:
    r = subprocess.run([mcrt, *args, "--help"], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"docs_check: {mcrt} {' '.join(args)} --help failed: {r.stderr.strip()}")
    return r.stdout


def check_flags(root: Path, mcrt: str) -> list[str]:
    reference = (root / "docs" / "cli.md").read_text(encoding="utf-8")
    errors = []
    for command in ([], ["render"], ["samples"], ["diff"]):
        for flag in sorted(set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*|-[a-z])\b", help_text(mcrt, *command)))):
            if flag in ("-h", "--help"):
                continue
            if not re.search(r"(?<![\w-])" + re.escape(flag) + r"(?![\w-])", reference):
                errors.append(f"docs/cli.md: the flag {flag} of 'mcrt {' '.join(command) or '(no command)'}' is not documented")
    return errors


def check_strategies(root: Path, mcrt: str) -> list[str]:
    reference = (root / "docs" / "samplers.md").read_text(encoding="utf-8")
    m = re.search(r"--light-sampling\s+TEXT:\{([^}]*)\}", help_text(mcrt, "render"))
    if not m:
        return ["mcrt render --help: no list of --light-sampling strategies found"]
    names = [s.strip() for s in m.group(1).split(",") if s.strip()]
    return [f"docs/samplers.md: the strategy `{s}` is not described" for s in names if f"`{s}`" not in reference]


def check_citation(root: Path, cffconvert: str | None) -> list[str]:
    if not cffconvert:
        return []
    r = subprocess.run([cffconvert, "--validate", "-i", str(root / "CITATION.cff")], capture_output=True, text=True)
    return [] if r.returncode == 0 else [f"CITATION.cff: not valid CFF: {(r.stdout + r.stderr).strip()[-400:]}"]


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--root", required=True, type=Path)
    p.add_argument("--mcrt", required=True)
    p.add_argument("--cffconvert")
    a = p.parse_args()
    files = tracked_files(a.root)
    errors = (check_links(a.root, files) + check_message_pointers(a.root, files) + check_flags(a.root, a.mcrt)
              + check_strategies(a.root, a.mcrt) + check_citation(a.root, a.cffconvert))
    for e in errors:
        print(e)
    n_md = sum(f.endswith(".md") for f in files)
    print(f"docs_check: {n_md} Markdown files, {len(errors)} problem(s)")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())

"""The run's outputs: a console summary, a JSON report and a Markdown table.

Besides every non-ok case, the report groups them into *findings*: cases
of one class whose first stderr line is the same once file names, numbers
and quoted text are masked (and, for hangs, crashes and memory, the attacked
family), so that one cause found by many cases is read once.
"""

from __future__ import annotations

import json
import re
from collections import Counter, defaultdict

from .model import ALL_CLASSES

STDERR_CHARS = 300


def signature(res) -> str:
    """What a finding is keyed by: the class and the masked first stderr
    line (or the reasons when stderr says nothing useful)."""
    line = res.first_stderr_line[:400]  # (bounded: the patterns below backtrack on long words)
    line = re.sub(r'"[^"]*"|\'[^\']*\'', '"…"', line)
    line = re.sub(r"[\w./-]+\.(pbrt|json|ply|png|exr|pfm|gz|ppm|csv|tiff|obj)\b", "FILE", line)
    line = re.sub(r"\d+(\.\d+)?(e[-+]?\d+)?", "N", line)
    line = line[:160]
    reasons = [re.sub(r"\d+(\.\d+)?", "N", r) for r in res.reasons]
    if res.cls in ("hang", "memory", "crash"):
        return f"{res.cls} | {res.case.family} | {line}"
    if not line:
        # Nothing on stderr (non-finite samples, unexpected renders): the
        # attacked thing is the case name without its value.
        name = res.case.id.split("/", 1)[1]
        stem = re.sub(r"-[-+]?(\d|\^|inf|nan|neg|huge|empty|zero).*$", "", name)
        return f"{res.cls} | {res.case.family}/{stem} | {'; '.join(reasons)[:80]}"
    return f"{res.cls} | {line} | {'; '.join(reasons)[:200]}"


def case_record(res) -> dict:
    err = res.stderr.decode("utf-8", "replace")
    return {
        "id": res.case.id,
        "family": res.case.family,
        "class": res.cls,
        "observed": res.observed,
        "expected": list(res.case.expect) if res.case.expect else None,
        "note": res.case.note,
        "reasons": res.reasons,
        "command": res.reproducer,
        "exit_status": res.exit_status,
        "stderr": err[:STDERR_CHARS],
        "stderr_bytes": res.stderr_size,
        "wall_seconds": round(res.wall, 3),
        "peak_rss_mib": round(res.peak_rss / 2 ** 20, 1),
        "reproducer_dir": str(res.case_dir),
    }


def findings(bad: list) -> list[dict]:
    groups: dict[str, list] = defaultdict(list)
    for r in bad:
        groups[signature(r)].append(r)
    out = []
    for sig, rs in sorted(groups.items(), key=lambda kv: (kv[1][0].cls, -len(kv[1]))):
        first = min(rs, key=lambda r: (len(r.case.id), r.case.id))
        out.append({"class": first.cls, "count": len(rs), "families": sorted({r.case.family for r in rs}),
                    "example": first.case.id, "note": first.case.note, "reasons": first.reasons,
                    "stderr": first.first_stderr_line[:STDERR_CHARS], "command": first.reproducer,
                    "cases": [r.case.id for r in rs]})
    return out


def summary(results: list, wall: float, meta: dict) -> dict:
    per_class = Counter(r.cls for r in results)
    per_family: dict[str, Counter] = defaultdict(Counter)
    for r in results:
        per_family[r.case.family][r.cls] += 1
    bad = [r for r in results if r.cls not in ("rendered", "clean_refusal")]
    return {
        **meta,
        "cases": len(results),
        "wall_seconds": round(wall, 1),
        "per_class": {c: per_class[c] for c in (*ALL_CLASSES, "harness_error") if per_class[c]},
        "per_family": {f: dict(c) for f, c in sorted(per_family.items())},
        "case_seconds_total": round(sum(r.wall for r in results), 1),
        "slowest": [{"id": r.case.id, "class": r.cls, "wall_seconds": round(r.wall, 2)}
                    for r in sorted(results, key=lambda r: -r.wall)[:10]],
        "not_ok": [case_record(r) for r in sorted(bad, key=lambda r: (r.cls, r.case.id))],
        "findings": findings(bad),
        # Every case: [id, class, wall seconds] (ok ones included, for statistics).
        "all": [[r.case.id, r.cls, round(r.wall, 2)] for r in results],
    }


def write_json(path, data: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=1) + "\n")


def _md(text) -> str:
    """A table cell: pipes escaped, control characters shown as escapes."""
    text = re.sub(r"[\x00-\x1f\x7f]", lambda m: m.group().encode("unicode_escape").decode(), str(text))
    return text.replace("|", "\\|").replace("`", "'")


def write_markdown(path, data: dict) -> None:
    lines = [f"# mcrt fuzz results", "",
             f"{data['cases']} cases, seed {data['seed']}, {data['mutations']} mutations, "
             f"{data['wall_seconds']} s, jobs {data['jobs']}, binary `{data['mcrt']}`.", "",
             "| class | cases |", "|---|---|"]
    lines += [f"| {c} | {n} |" for c, n in data["per_class"].items()]
    classes = [c for c in ALL_CLASSES if c in data["per_class"]]
    lines += ["", "| family | " + " | ".join(classes) + " |", "|---|" + "---|" * len(classes)]
    for fam, counts in data["per_family"].items():
        lines.append(f"| {fam} | " + " | ".join(str(counts.get(c, 0)) for c in classes) + " |")
    lines += ["", "## Findings (grouped by class and message)", "",
              "| class | cases | families | example | why | first stderr line |", "|---|---|---|---|---|---|"]
    for f in data["findings"]:
        lines.append(f"| {f['class']} | {f['count']} | {', '.join(f['families'])} | `{_md(f['example'])}` | "
                     f"{_md('; '.join(f['reasons']))[:200]} | {_md(f['stderr'])[:200]} |")
    lines += ["", "## Every case that is not ok", "",
              "| id | class | exit | why | stderr | reproducer |", "|---|---|---|---|---|---|"]
    for c in data["not_ok"]:
        lines.append(f"| `{_md(c['id'])}` | {c['class']} | {c['exit_status']} | {_md('; '.join(c['reasons']))[:200]} "
                     f"| {_md(c['stderr'])[:200]} | `{_md(c['command'])}` |")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")


def print_summary(data: dict, out) -> None:
    print(f"\n{data['cases']} cases in {data['wall_seconds']} s (mcrt runs: {data['case_seconds_total']} s; "
          f"slowest: " + ", ".join(f"{s['id']} {s['wall_seconds']} s" for s in data["slowest"][:3]) + ")",
          file=out)
    for c, n in data["per_class"].items():
        print(f"  {c:15s} {n}", file=out)
    if data["findings"]:
        print(f"\n{len(data['findings'])} findings (not-ok cases grouped by class and message):", file=out)
        for f in data["findings"]:
            print(f"  [{f['class']}] x{f['count']} {f['example']}: {f['stderr'][:140]}", file=out)
            print(f"      why: {'; '.join(f['reasons'])[:160]}", file=out)

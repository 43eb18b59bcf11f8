"""How much glue: the lines of the study package, the config schema, the commands and the workflow's rules,
against the method's, and the modules over the size limit (issue 60: glue <= 4,500 lines, no module over 400).

    python benchmarks/glue_lines.py [--check]

Counts every line of each file as it stands (blank lines and comments included), so it measures the code
at the line length it is written to (ruff's 120). Groups: `study/` (src/shockcal/study/*.py), the schema
(src/shockcal/config.schema.yaml), `cli/` (src/shockcal/cli/*.py), the rules (workflow/rules/* and the
Snakefile); the method (hydro, simulators, design, velocimetry, emulator, inference, campaign) for
comparison. Then every Python module of the package, the schema and every rule file over
MAX_MODULE_LINES.
Prints; with --check, exits 1 when the glue is over GLUE_GOAL_LINES or a module is over the limit.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "src" / "shockcal"
GLUE_GOAL_LINES = 4500
MAX_MODULE_LINES = 400
GLUE = {
    "study/": sorted((PACKAGE / "study").rglob("*.py")),
    "config.schema.yaml": [PACKAGE / "config.schema.yaml"],
    "cli/": sorted((PACKAGE / "cli").rglob("*.py")),
    "workflow rules + Snakefile": [*sorted((REPO / "workflow" / "rules").glob("*")), REPO / "Snakefile"],
}
METHOD = ("hydro", "simulators", "design", "velocimetry", "emulator", "inference", "campaign")


def lines(path: Path) -> int:
    """The file's line count (a last line without a newline counts)."""
    return len(path.read_text().splitlines())


def over_limit() -> list[tuple[str, int]]:
    """(path relative to the repository, lines) of every package module, the schema and every rule file over
    MAX_MODULE_LINES, longest first."""
    files = [*PACKAGE.rglob("*.py"), *GLUE["config.schema.yaml"], *GLUE["workflow rules + Snakefile"]]
    found = [(path.relative_to(REPO).as_posix(), lines(path)) for path in files if path.is_file()]
    return sorted(((name, n) for name, n in found if n > MAX_MODULE_LINES), key=lambda item: -item[1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 when over the goal or a module over the limit")
    args = parser.parse_args(argv)
    glue = {group: sum(lines(p) for p in paths if p.is_file()) for group, paths in GLUE.items()}
    method = sum(lines(p) for room in METHOD for p in (PACKAGE / room).rglob("*.py"))
    for group, n in glue.items():
        print(f"{group:28s} {n:6d}")
    total = sum(glue.values())
    print(f"{'glue':28s} {total:6d}  (goal {GLUE_GOAL_LINES})")
    print(f"{'method':28s} {method:6d}  ({', '.join(METHOD)})")
    big = over_limit()
    print(f"over {MAX_MODULE_LINES} lines: {len(big)}")
    for name, n in big:
        print(f"  {n:6d}  {name}")
    return int(args.check and (total > GLUE_GOAL_LINES or bool(big)))


if __name__ == "__main__":
    sys.exit(main())

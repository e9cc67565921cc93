"""Compare ``affinity check --format json`` of two commits on a folder of meshes.

Used for issue 15 (one place per concept): the restructure must not change what
the check says. Each commit is checked out into a temporary git worktree and run
with its own package first on ``PYTHONPATH``; findings are compared per file as
(code, face, value, threshold) rows, and the per-file counts as they are.

    python benchmarks/compare_check_json.py BEFORE AFTER ../shared/meshes [--arg=--threshold --arg=Q301=0.01]

Prints one line per file and a closing line; exits 1 when any file differs.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def check_json(tree: Path, meshes: list[str], extra: list[str]) -> dict:
    env = {**os.environ, "PYTHONPATH": str(tree)}
    result = subprocess.run([sys.executable, "-m", "affinity.cli", "check", "--format", "json", "--select", "ALL",
                             *extra, *meshes], capture_output=True, text=True, env=env, cwd=tree)
    if result.returncode not in (0, 1):
        raise SystemExit(f"{tree}: exit {result.returncode}: {result.stderr.strip()}")
    return json.loads(result.stdout)


def by_file(document: dict) -> dict[str, tuple[dict, list[tuple]]]:
    files = {entry["path"]: ({k: v for k, v in entry.items() if k != "path"}, []) for entry in document["files"]}
    for f in document["findings"]:
        files[f["path"]][1].append((f["code"], f["face"], round(f["value"], 9), f["threshold"]))
    return {path: (counts, sorted(rows)) for path, (counts, rows) in files.items()}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("folder")
    parser.add_argument("--arg", action="append", default=[], help="an extra argument for affinity check")
    args = parser.parse_args()
    meshes = sorted(str(Path(args.folder, name).resolve()) for name in os.listdir(args.folder)
                    if name.endswith((".obj", ".ply", ".off")))
    results = {}
    with tempfile.TemporaryDirectory() as scratch:
        for label, revision in (("before", args.before), ("after", args.after)):
            tree = Path(scratch) / label
            subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(tree), revision],
                           check=True)
            try:
                results[label] = by_file(check_json(tree, meshes, args.arg))
            finally:
                subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], check=True)
    differing = 0
    for path in meshes:
        before, after = results["before"].get(path), results["after"].get(path)
        same = before == after
        differing += not same
        rows = len(after[1]) if after else 0
        print(f"{'same' if same else 'DIFFERS'}  {os.path.basename(path)}: {rows} findings")
        if not same and before and after:
            gone, new = set(before[1]) - set(after[1]), set(after[1]) - set(before[1])
            codes = sorted({row[0] for row in gone | new})
            print(f"         {len(gone)} findings gone, {len(new)} new ({', '.join(codes)})")
    print(f"{len(meshes) - differing} of {len(meshes)} files give the same JSON findings and counts")
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main())

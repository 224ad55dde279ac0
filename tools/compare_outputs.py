"""Compare two tribokin output trees (two `make demo` folders, or two output folders) byte for byte.

    python tools/compare_outputs.py demo-before demo-after [--root-a DIR --root-b DIR]

Only what names the output folder or a machine's absolute path is normalised, and every place
where that happened is listed:

- ``summary.json``: ``reproduce.command`` (it holds the ``--out`` folder);
- any text file: the absolute and given paths of the two trees (and of ``--root-a``/``--root-b``,
  the checkouts the runs were made from, when they differ) are replaced by one placeholder.

Everything else is compared byte for byte. Exit status 0 when the trees agree, 1 when they do not.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

TEXT_SUFFIXES = {".json", ".csv", ".html", ".toml", ".txt"}


def _replacements(tree: Path, root: Path | None) -> list[tuple[bytes, bytes]]:
    """The byte strings naming ``tree`` (and ``root``) in a file, longest first, each to its placeholder."""
    pairs = {str(tree.resolve()): "<tree>", str(tree): "<tree>"}
    if root is not None:
        pairs[str(root.resolve())] = "<root>"
    return sorted(((k.encode(), v.encode()) for k, v in pairs.items() if k not in ("", ".")),
                  key=lambda pair: -len(pair[0]))


def _normalised_summary(data: bytes) -> tuple[bytes, list[str]]:
    """``summary.json`` with ``reproduce.command`` replaced, and the fields that were."""
    summary = json.loads(data)
    fields = []
    for key in ("reproduce",):
        if isinstance(summary.get(key), dict) and "command" in summary[key]:
            summary[key]["command"] = "<command>"
            fields.append(f"{key}.command")
    return json.dumps(summary, indent=2, sort_keys=True).encode(), fields


def normalised(path: Path, tree: Path, root: Path | None) -> tuple[bytes, list[str]]:
    """The bytes of ``path`` with tree- and machine-specific names replaced, and what was replaced."""
    data = path.read_bytes()
    notes = []
    if path.suffix in TEXT_SUFFIXES:
        for old, new in _replacements(tree, root):
            if old in data:
                notes.append(f"path '{old.decode()}' -> {new.decode()} ({data.count(old)}x)")
                data = data.replace(old, new)
    if path.name == "summary.json":
        data, fields = _normalised_summary(data)
        notes += fields
    return data, notes


def compare(a: Path, b: Path, root_a: Path | None = None, root_b: Path | None = None) -> list[str]:
    """Lines describing every difference between trees ``a`` and ``b`` (empty when they agree); prints
    what was normalised."""
    files_a = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
    files_b = {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
    problems = [f"only in {a}: {p}" for p in sorted(files_a - files_b)]
    problems += [f"only in {b}: {p}" for p in sorted(files_b - files_a)]
    for relative in sorted(files_a & files_b):
        data_a, notes_a = normalised(a / relative, a, root_a)
        data_b, notes_b = normalised(b / relative, b, root_b)
        for note in dict.fromkeys(notes_a + notes_b):
            print(f"normalised {relative}: {note}")
        if data_a != data_b:
            problems.append(f"differs: {relative}")
    print(f"compared {len(files_a & files_b)} files")
    return problems


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("a", type=Path)
    parser.add_argument("b", type=Path)
    parser.add_argument("--root-a", type=Path, help="checkout the runs of A were made from")
    parser.add_argument("--root-b", type=Path, help="checkout the runs of B were made from")
    args = parser.parse_args(argv)
    problems = compare(args.a, args.b, args.root_a, args.root_b)
    for line in problems:
        print(line)
    print("same bytes" if not problems else f"{len(problems)} difference(s)")
    return 0 if not problems else 1


if __name__ == "__main__":
    sys.exit(main())

"""The JSON files of an output folder (``summary.json``, ``fit.json``, ``surface.json``, ``calibration.json``)."""

from __future__ import annotations

import json
from pathlib import Path


def write_json(content: dict, path: Path) -> None:
    """``content`` as indented JSON with a final newline."""
    path.write_text(json.dumps(content, indent=2) + "\n", encoding="utf-8")

"""Finished chunks of a long run kept on disk, so an interrupted run can resume (``--resume``).

The folder holds ``manifest.json`` (a fingerprint of the settings that determine the
numbers) and one ``chunk_<k>.npz`` per finished chunk; each file is written under a
temporary name and renamed, so it is either complete or absent.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from pathlib import Path

import numpy as np

from tribokin.errors import InputError


def chunk_folder(out) -> Path:
    """The chunk folder of output folder ``out``: ``<out>.chunks`` beside it."""
    out = Path(out)
    return out.with_name(out.name + ".chunks")


def check_chunk_folder(folder, resume: bool) -> None:
    """Refuse, without ``resume``, a chunk folder an interrupted run left (nothing is deleted unasked)."""
    if Path(folder).exists() and not resume:
        raise InputError("an interrupted run left its finished chunks here; pass --resume to finish it or --force "
                         "to start over", folder, "--resume")


def discard(folder) -> None:
    """Delete a chunk folder (once the results are written, or to start over)."""
    shutil.rmtree(folder, ignore_errors=True)


def fingerprint(settings: dict) -> str:
    """SHA-256 of ``settings`` as canonical JSON."""
    return hashlib.sha256(json.dumps(settings, sort_keys=True, default=str).encode()).hexdigest()


class ChunkStore:
    """Chunk results saved as they finish, in ``folder``.

    Args:
        folder: the chunk folder.
        key: fingerprint of the settings the chunks were computed with.
        resume: keep the chunks of an earlier, interrupted run with the same ``key``; without it an
            existing folder is an error.
    """

    def __init__(self, folder, key: str, resume: bool = False):
        self.folder = Path(folder)
        manifest = self.folder / "manifest.json"
        check_chunk_folder(self.folder, resume)
        if self.folder.exists():
            saved = json.loads(manifest.read_text()).get("key") if manifest.is_file() else None
            if saved != key:
                raise InputError("these chunks were computed with other settings (study file, cycles, seed or "
                                 "chunk size); rerun with the same ones, or pass --force without --resume to "
                                 "start over", self.folder, "--resume")
        else:
            self.folder.mkdir()
            manifest.write_text(json.dumps({"key": key}) + "\n")

    def _path(self, chunk: int) -> Path:
        return self.folder / f"chunk_{chunk:06d}.npz"

    def finished(self) -> list[int]:
        """Indices of the chunks already saved."""
        return sorted(int(p.stem.split("_")[1]) for p in self.folder.glob("chunk_*.npz"))

    def save(self, chunk: int, arrays: dict[str, np.ndarray]) -> None:
        """Save chunk ``chunk``'s arrays, atomically."""
        temporary = self.folder / f".chunk_{chunk:06d}.tmp.npz"
        np.savez(temporary, **arrays)
        os.replace(temporary, self._path(chunk))

    def load(self, chunk: int) -> dict[str, np.ndarray]:
        with np.load(self._path(chunk)) as saved:
            return {name: saved[name] for name in saved.files}

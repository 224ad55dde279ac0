"""tools/compare_outputs.py: two output trees agree up to the folder's name, and any other byte differs."""

from __future__ import annotations

import importlib.util
import json

from conftest import ROOT

_spec = importlib.util.spec_from_file_location("compare_outputs", ROOT / "tools" / "compare_outputs.py")
compare_outputs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(compare_outputs)


def _tree(folder, out_name, png=b"\x89PNG-1"):
    out = folder / out_name
    (out / "study").mkdir(parents=True)
    summary = {"study": {"name": "s"}, "reproduce": {"seed": 1, "command": ["tribokin", "run", "--out", str(out)]}}
    (out / "study" / "summary.json").write_text(json.dumps(summary))
    (out / "study" / "report.html").write_text(f"<p>results in {out}/study</p>")
    (out / "study" / "field_P1.png").write_bytes(png)
    return out


def test_trees_differing_only_in_their_folder_name_agree(tmp_path, capsys):
    assert compare_outputs.main([str(_tree(tmp_path, "a")), str(_tree(tmp_path, "b"))]) == 0
    printed = capsys.readouterr().out
    assert "reproduce.command" in printed and "same bytes" in printed


def test_any_other_byte_differs(tmp_path, capsys):
    a, b = _tree(tmp_path, "a"), _tree(tmp_path, "b", png=b"\x89PNG-2")
    assert compare_outputs.main([str(a), str(b)]) == 1
    assert "differs: study/field_P1.png" in capsys.readouterr().out


def test_a_changed_figure_in_the_summary_differs(tmp_path):
    a, b = _tree(tmp_path, "a"), _tree(tmp_path, "b")
    summary = json.loads((b / "study" / "summary.json").read_text())
    summary["reproduce"]["seed"] = 2
    (b / "study" / "summary.json").write_text(json.dumps(summary))
    assert compare_outputs.compare(a, b) == ["differs: study/summary.json"]


def test_a_missing_file_is_named(tmp_path):
    a, b = _tree(tmp_path, "a"), _tree(tmp_path, "b")
    (b / "study" / "report.html").unlink()
    assert compare_outputs.compare(a, b) == [f"only in {a}: study/report.html"]

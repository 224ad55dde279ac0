"""The docs site (mkdocs.yml, docs/) builds in strict mode: every page in the nav, every link and anchor found,
every docstring the API page shows readable; a broken anchor fails the build."""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import sys

from conftest import ROOT


def build(config_dir, site_dir) -> subprocess.CompletedProcess:
    """``mkdocs build --strict`` of the site configured in ``config_dir`` into ``site_dir``."""
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site_dir)],
                          cwd=config_dir, capture_output=True, text=True, timeout=300,
                          env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})


def test_the_site_builds_in_strict_mode_with_the_api_and_the_formulas(tmp_path):
    done = build(ROOT, tmp_path / "site")
    assert done.returncode == 0, done.stderr
    assert "WARNING" not in done.stderr
    site = tmp_path / "site"
    api = (site / "api" / "index.html").read_text(encoding="utf-8")
    assert "Run a study from a TOML path, a mapping or a" in api  # run_study's docstring
    assert "Base class of every error tribokin raises on purpose." in api
    concepts = (site / "concepts" / "index.html").read_text(encoding="utf-8")
    assert r"RP_l = \bar l + 3 S_l" in concepts and 'class="arithmatex"' in concepts
    reference = (site / "reference" / "study-file" / "index.html").read_text(encoding="utf-8")
    assert "study.cycles" in reference and "ISO 9283 needs at least 2" in reference
    # offline: every script and linked file (stylesheets, fonts) from the site itself, MathJax's vendored bundle
    # among them
    sources = {page: re.findall(r'<(?:script|link)[^>]*\s(?:src|href)="([^"]*)"', page.read_text(encoding="utf-8"))
               for page in site.rglob("*.html")}
    assert not [(page, src) for page, found in sources.items() for src in found if re.match(r"(https?:)?//", src)]
    assert any(src.endswith("javascripts/mathjax/tex-svg.js") for src in sources[site / "concepts" / "index.html"])
    assert (site / "javascripts" / "mathjax" / "tex-svg.js").is_file()
    assert (site / "javascripts" / "mathjax" / "LICENSE").is_file()
    assert not (site / "javascripts" / "mathjax" / "PROVENANCE.md").exists()


def test_the_vendored_mathjax_is_the_upstream_file_its_note_names():
    """docs/javascripts/mathjax/tex-svg.js is byte for byte the upstream file: its git blob hash is the one its
    PROVENANCE.md gives (that of es5/tex-svg.js at mathjax/MathJax's tag 3.2.2), as is its LICENSE's."""
    folder = ROOT / "docs" / "javascripts" / "mathjax"
    note = (folder / "PROVENANCE.md").read_text(encoding="utf-8")
    for name in ("tex-svg.js", "LICENSE"):
        data = (folder / name).read_bytes()
        blob = hashlib.sha1(b"blob %d\0" % len(data) + data).hexdigest()
        assert f"| `{name}` | {len(data)} | `{blob}` |" in note
    assert sorted(path.name for path in folder.iterdir()) == ["LICENSE", "PROVENANCE.md", "tex-svg.js"]


def test_a_broken_anchor_fails_the_build(tmp_path):
    shutil.copytree(ROOT / "docs", tmp_path / "docs")
    shutil.copy(ROOT / "mkdocs.yml", tmp_path)
    (tmp_path / "src").symlink_to(ROOT / "src")
    with open(tmp_path / "docs" / "index.md", "a", encoding="utf-8") as page:
        page.write("\n[the grid](maps.md#no-such-section)\n")
    done = build(tmp_path, tmp_path / "site")
    assert done.returncode != 0
    assert "does not contain an anchor '#no-such-section'" in done.stderr


def test_the_docs_pages_the_code_cites_hold_the_sections_it_names():
    """A citation ``docs/<page>.md, "<section>"`` in the code or the tests names a page and a heading that exist."""
    cited = 0
    for path in [*(ROOT / "src").rglob("*.py"), *(ROOT / "tests").rglob("*.py")]:
        for page, section in re.findall(r'docs/([\w/-]+\.md), "([^"]+)"', path.read_text(encoding="utf-8")):
            text = (ROOT / "docs" / page).read_text(encoding="utf-8")
            assert re.search(rf"^#+ {re.escape(section)}$", text, re.MULTILINE), (path, page, section)
            cited += 1
    assert cited >= 4  # the joint model: joint_errors, calibration.model and two tests

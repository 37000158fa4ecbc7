"""Every ```python block of README.md and of the pages in docs/ (docs/*.md, docs/experiments/*.md)
runs: those that need gymnasium or Stable-Baselines3 only where they are importable (CI has
neither; they were run by hand with Gymnasium 1.0 and SB3 2.4.1)."""

import glob
import importlib.util
import os
import re
import subprocess
import sys

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
PAGES = ["README.md"] + sorted(
    os.path.relpath(path, ROOT)
    for pattern in ("docs/*.md", "docs/experiments/*.md")
    for path in glob.glob(os.path.join(ROOT, pattern)))


def python_blocks(page, section=None):
    """The ```python blocks of a page, or of its `## section` alone (test_wheel runs the README's
    tour in a venv)."""
    with open(os.path.join(ROOT, page), encoding="utf-8") as file:
        text = file.read()
    if section is not None:
        match = re.search(rf"^## {re.escape(section)}\n(.*?)(?=^## |\Z)", text, re.S | re.M)
        assert match, f"{page}: no section \"## {section}\""
        text = match.group(1)
    return re.findall(r"```python\n(.*?)\n```", text, re.S)


# (page, block number from 1, block text) for every block of every page.
BLOCKS = [(page, number, block) for page in PAGES
          for number, block in enumerate(python_blocks(page), start=1)]


def test_the_readme_and_the_docs_have_python_blocks():
    pages = {page for page, _, _ in BLOCKS}
    assert "README.md" in pages, "README.md: no ```python block (its tour)"
    assert "docs/python.md" in pages, "docs/python.md: no ```python block"


@pytest.mark.parametrize("page,number,block", BLOCKS,
                         ids=[f"{page}:{number}" for page, number, _ in BLOCKS])
def test_python_block_runs(page, number, block, tmp_path):
    for module in ("stable_baselines3", "gymnasium"):
        if re.search(rf"^\s*(import|from) {module}\b", block, re.M) and \
                importlib.util.find_spec(module) is None:
            pytest.skip(f"{page} block {number} needs {module}")
    script = tmp_path / f"block_{number}.py"
    script.write_text(block + "\nprint('block ran to the end')\n")
    # The block runs in a folder of its own, with PYTHONPATH made absolute.
    path = os.pathsep.join(os.path.abspath(entry)
                           for entry in os.environ.get("PYTHONPATH", "").split(os.pathsep) if entry)
    result = subprocess.run([sys.executable, "-W", "ignore", str(script)], capture_output=True,
                            text=True, cwd=str(tmp_path), timeout=600,
                            env=dict(os.environ, PYTHONPATH=path))
    assert result.returncode == 0, f"{page} block {number}:\n{result.stderr}"
    assert result.stdout.endswith("block ran to the end\n"), f"{page} block {number}"

"""Every ```python block of README.md runs: those that need gymnasium or Stable-Baselines3 only
where they are importable (CI has neither; they were run by hand with Gymnasium 1.0 and SB3
2.4.1)."""

import importlib.util
import os
import re
import subprocess
import sys

import pytest

README = os.path.join(os.path.dirname(__file__), "..", "..", "README.md")
BLOCKS = re.findall(r"```python\n(.*?)\n```", open(README).read(), re.S)


def test_the_readme_has_python_blocks():
    assert len(BLOCKS) >= 2


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs(index, tmp_path):
    block = BLOCKS[index]
    for module in ("stable_baselines3", "gymnasium"):
        if re.search(rf"^\s*(import|from) {module}\b", block, re.M) and \
                importlib.util.find_spec(module) is None:
            pytest.skip(f"block {index + 1} needs {module}")
    script = tmp_path / f"readme_block_{index + 1}.py"
    script.write_text(block + "\nprint('README block ran to the end')\n")
    # The block runs in a folder of its own, with PYTHONPATH made absolute.
    path = os.pathsep.join(os.path.abspath(entry)
                           for entry in os.environ.get("PYTHONPATH", "").split(os.pathsep) if entry)
    result = subprocess.run([sys.executable, "-W", "ignore", str(script)], capture_output=True,
                            text=True, cwd=str(tmp_path), timeout=600,
                            env=dict(os.environ, PYTHONPATH=path))
    assert result.returncode == 0, result.stderr
    assert result.stdout.endswith("README block ran to the end\n")

"""`cmake --install` puts an importable package pixelgym into the Python install folder."""

import glob
import os
import subprocess
import sys

import pytest

from conftest import ENV_IDS

BUILD_DIR = os.environ.get("PIXELGYM_BUILD_DIR")


@pytest.mark.skipif(not BUILD_DIR, reason="PIXELGYM_BUILD_DIR is set by ctest")
def test_installed_package_imports_and_makes_an_env(tmp_path):
    subprocess.run(["cmake", "--install", BUILD_DIR, "--prefix", str(tmp_path)], check=True,
                   capture_output=True)
    (site,) = glob.glob(str(tmp_path / "lib" / "python3*" / "dist-packages"))
    assert any(name.startswith("_core.") for name in os.listdir(os.path.join(site, "pixelgym")))
    env = dict(os.environ, PYTHONPATH=site)
    out = subprocess.run(
        [sys.executable, "-W", "ignore", "-c",
         "import pixelgym; env = pixelgym.make('GridWorld-v0'); "
         "print(pixelgym.__file__); print(env.reset(seed=0)[0], len(pixelgym.ids()))"],
        check=True, capture_output=True, text=True, env=env, cwd=str(tmp_path)).stdout.split("\n")
    # The installed package registers the ids the build tree's does.
    assert out[0].startswith(site) and out[1] == f"0 {len(ENV_IDS)}"

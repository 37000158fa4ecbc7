"""`pip install .` (pyproject.toml, python/backend/): a wheel built with Debian's Python installs
into a fresh venv, where the README's Python tour runs with nothing from the source or build tree;
and, where a pyenv Python 3.12 is installed, a wheel built for it installs into its own venv, where
`import pixelgym` works or, lacking numpy, says how to get numpy.

Both reuse build folders: Debian's Python the project's build (PIXELGYM_BUILD_DIR, so only the
packing is new), the pyenv Python a folder of its own inside it (compiled once, then kept)."""

import glob
import os
import subprocess
import sys
import tarfile
import zipfile

import pytest

from test_readme import ROOT, python_blocks

BUILD_DIR = os.environ.get("PIXELGYM_BUILD_DIR")
# A pyenv Python 3.12 with its headers (pyenv builds have them); CI's Debian has none.
PYENV_PYTHONS = sorted(glob.glob(os.path.join(
    os.environ.get("PYENV_ROOT", os.path.expanduser("~/.pyenv")), "versions", "3.12*", "bin",
    "python3.12")))

pytestmark = pytest.mark.skipif(not BUILD_DIR, reason="PIXELGYM_BUILD_DIR is set by ctest")


def run(command, **kwargs):
    """command's output; a failure shows all of it."""
    result = subprocess.run(command, capture_output=True, text=True, **kwargs)
    assert result.returncode == 0, (f"{' '.join(command)} exited {result.returncode}:\n"
                                    f"{result.stdout[-6000:]}\n{result.stderr[-6000:]}")
    return result.stdout


def outside_the_tree():
    """The environment of a user's shell: no PYTHONPATH to the build tree, no asset folder."""
    return {name: value for name, value in os.environ.items()
            if name not in ("PYTHONPATH", "PIXELGYM_ASSET_PATH")}


def build_wheel(python, build_dir, wheel_dir, *pip_options):
    """pip wheel of the source tree for `python` (offline), reusing build_dir; the wheel's path."""
    run([python, "-m", "pip", "wheel", ROOT, "--no-deps", "--no-index", "--no-cache-dir",
         "--wheel-dir", str(wheel_dir), "--config-settings", f"build-dir={build_dir}",
         *pip_options],
        env=outside_the_tree())
    (wheel,) = glob.glob(str(wheel_dir / "pixelgym-*.whl"))
    return wheel


def install_into_venv(python, venv, wheel, venv_options=(), pip_options=()):
    """A fresh venv of `python` with the wheel installed (pip --no-index); its interpreter."""
    run([python, "-m", "venv", *venv_options, str(venv)])
    venv_python = str(venv / "bin" / "python")
    run([venv_python, "-m", "pip", "install", "--no-index", "--no-cache-dir", *pip_options, wheel],
        env=outside_the_tree())
    return venv_python


def test_a_wheel_for_debians_python_runs_the_readme_tour_in_a_venv(tmp_path):
    wheel = build_wheel("/usr/bin/python3", BUILD_DIR, tmp_path / "dist", "--no-build-isolation")
    assert os.path.basename(wheel).startswith("pixelgym-0.") and \
        os.path.basename(wheel).endswith(
            f"-cp3{sys.version_info.minor}-cp3{sys.version_info.minor}-linux_x86_64.whl"), wheel
    with zipfile.ZipFile(wheel) as archive:
        names = archive.namelist()
        metadata = archive.read(next(n for n in names if n.endswith(".dist-info/METADATA")))
    # pixelgym's own libraries and assets, no system library, nothing outside the package.
    assert {os.path.basename(n) for n in names if "/lib/" in n} == {
        f"libpixelgym_{name}.so.0.1" for name in ("engine", "render", "envs", "tasks", "wrappers")}
    assert "pixelgym/share/pixelgym/assets/cartpole/cartpole.urdf" in names
    assert all(n.startswith(("pixelgym/", "pixelgym-0.")) for n in names), names
    assert b"\nRequires-Dist: numpy" in metadata

    # --system-site-packages: Debian's numpy (python3-numpy) meets the wheel's requirement, offline.
    python = install_into_venv("/usr/bin/python3", tmp_path / "venv", wheel,
                               venv_options=["--system-site-packages"])
    where = run([python, "-W", "ignore", "-c", "import pixelgym; print(pixelgym.__file__); "
                 "print(pixelgym._core.assets_folder()); "
                 "print(sorted({line.split()[-1] for line in open('/proc/self/maps') "
                 "if 'libpixelgym_' in line}))"],
                cwd=str(tmp_path), env=outside_the_tree()).split("\n")
    package = os.path.join(str(tmp_path / "venv"), "lib", f"python3.{sys.version_info.minor}",
                           "site-packages", "pixelgym")
    assert where[0] == os.path.join(package, "__init__.py")
    # The module loads the wheel's libraries (RPATH $ORIGIN/lib), not the build tree's.
    assert where[2] == str(sorted(os.path.join(package, "lib", f"libpixelgym_{name}.so.0.1")
                                  for name in ("engine", "envs", "render", "tasks", "wrappers")))
    # The engine finds the wheel's assets from its library's folder (not the source tree's).
    assert where[1] == os.path.join(package, "share", "pixelgym", "assets")

    (tour,) = python_blocks("README.md", "Five minutes in Python")
    script = tmp_path / "tour.py"
    script.write_text(tour + "\nprint('the tour ran to the end')\n")
    out = run([python, "-W", "ignore", str(script)], cwd=str(tmp_path), env=outside_the_tree())
    assert out.endswith("the tour ran to the end\n"), out


@pytest.mark.skipif(not PYENV_PYTHONS, reason="no pyenv Python 3.12 (~/.pyenv/versions/3.12*)")
def test_a_wheel_for_a_pyenv_python_installs_into_its_venv(tmp_path):
    pyenv_python = PYENV_PYTHONS[-1]
    # pip's isolated build (the default): the backend asks for nothing to install.
    wheel = build_wheel(pyenv_python, os.path.join(BUILD_DIR, "wheel-python3.12"),
                        tmp_path / "dist")
    assert os.path.basename(wheel).endswith("-cp312-cp312-linux_x86_64.whl"), wheel
    # --no-deps: with no index, pip could not get the numpy the wheel requires.
    python = install_into_venv(pyenv_python, tmp_path / "venv", wheel, pip_options=["--no-deps"])
    has_numpy = subprocess.run([python, "-c", "import numpy"], capture_output=True).returncode == 0
    result = subprocess.run(
        [python, "-W", "ignore", "-c",
         "import pixelgym; env = pixelgym.make('GridWorld-v0'); print(env.reset(seed=0)[0])"],
        capture_output=True, text=True, cwd=str(tmp_path), env=outside_the_tree())
    if has_numpy:
        assert result.returncode == 0 and result.stdout == "0\n", result.stderr
    else:
        # No numpy in a pyenv venv (no index to get it from here): the import says what to do.
        assert result.returncode != 0
        message = result.stderr.strip().splitlines()[-1]
        assert message.startswith("ImportError: pixelgym needs numpy"), result.stderr
        assert "pip install" in message and python in message, message


def backend():
    """python/backend/pixelgym_backend.py, imported as pip imports it (backend-path)."""
    sys.path.insert(0, os.path.join(ROOT, "python", "backend"))
    try:
        import pixelgym_backend
    finally:
        sys.path.pop(0)
    return pixelgym_backend


def test_the_backend_asks_pip_for_nothing_to_install():
    assert backend().get_requires_for_build_wheel() == []
    assert backend().get_requires_for_build_sdist() == []


def test_a_build_folder_of_another_python_or_without_shared_libraries_is_refused(tmp_path):
    module = backend()
    (tmp_path / "CMakeCache.txt").write_text(
        "PIXELGYM_PYTHON_EXECUTABLE:FILEPATH=/opt/other/bin/python3\n")
    with pytest.raises(module.BuildError, match=r"configured for the Python "
                       rf"/opt/other/bin/python3, not for {sys.executable}"):
        module._build_dir({"build-dir": str(tmp_path)}, "tag")
    (tmp_path / "CMakeCache.txt").write_text(
        f"PIXELGYM_PYTHON_EXECUTABLE:FILEPATH={sys.executable}\nPIXELGYM_SHARED_LIBS:BOOL=OFF\n")
    with pytest.raises(module.BuildError,
                       match="has PIXELGYM_SHARED_LIBS=OFF: a wheel needs it ON"):
        module._build_dir({"build-dir": str(tmp_path)}, "tag")


def test_the_sdist_holds_the_tracked_sources_and_no_build_output(tmp_path):
    name = backend().build_sdist(str(tmp_path))
    with tarfile.open(tmp_path / name) as archive:
        names = archive.getnames()
    base = name[:-len(".tar.gz")]
    for needed in ("PKG-INFO", "pyproject.toml", "CMakeLists.txt",
                   "python/backend/pixelgym_backend.py", "python/pixelgym/__init__.py",
                   "assets/cartpole/cartpole.urdf"):
        assert f"{base}/{needed}" in names, needed
    assert not [n for n in names if n.startswith((f"{base}/build/", f"{base}/build-wheel/"))]

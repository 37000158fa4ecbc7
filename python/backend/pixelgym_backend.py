"""pixelgym's PEP 517 build backend (pyproject.toml names it, with backend-path): `pip install .`
and `pip wheel .` from a clone, for the interpreter that runs pip, with the Python standard library
alone, so that any CPython >= 3.9 with its headers builds offline (pip's isolated build installs
nothing: the get_requires hooks return []).

build_wheel configures a CMake build folder for that interpreter (the binding's pybind11 module
needs its headers), builds the module and the libraries it loads, lays out the package with
`cmake --install --component wheel` (python/CMakeLists.txt: the module, pixelgym's libraries with
RPATH $ORIGIN, the assets) and zips it with the wheel's METADATA, WHEEL and RECORD.

Settings (pip's --config-settings KEY=VALUE, or the environment variable):
  build-dir (PIXELGYM_WHEEL_BUILD_DIR)  the CMake build folder; default build-wheel/<tag> in the
      source tree. An existing build folder (`build`, configured for the same interpreter) is
      reused as it is: only what changed is compiled.
  jobs (PIXELGYM_WHEEL_JOBS)  parallel compile jobs; default the number of cores.
"""

import base64
import hashlib
import io
import os
import re
import shutil
import stat
import subprocess
import sys
import sysconfig
import tarfile
import tempfile
import time
import zipfile

SOURCE_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
NAME = "pixelgym"
SUMMARY = "Pixel-based RL environments: Bullet physics, OSMesa rendering, Gymnasium API, in C++"
# Folders of the source tree an sdist leaves out, when there is no git to list its files.
UNPACKAGED = {".git", "build", "dist", "runs", "__pycache__"}


class BuildError(RuntimeError):
    """A build that cannot go on, with what was expected and what was found."""


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    tag = _wheel_tag()
    build_dir = _build_dir(config_settings, tag)
    _configure(build_dir)
    jobs = _setting(config_settings, "jobs", "PIXELGYM_WHEEL_JOBS") or str(os.cpu_count() or 1)
    _run(["cmake", "--build", build_dir, "--parallel", jobs, "--target", "pixelgym_python"])
    with open(os.path.join(build_dir, "python", "wheel_requires.txt"), encoding="utf-8") as file:
        requires = [line.strip() for line in file if line.strip()]
    version = _version()
    with tempfile.TemporaryDirectory(prefix="pixelgym-wheel-") as stage:
        _run(["cmake", "--install", build_dir, "--prefix", stage, "--component", "wheel"])
        _replace_links(stage)
        dist_info = f"{NAME}-{version}.dist-info"
        os.mkdir(os.path.join(stage, dist_info))
        _write(stage, f"{dist_info}/METADATA", _metadata(version, requires))
        _write(stage, f"{dist_info}/WHEEL",
               "Wheel-Version: 1.0\n"
               f"Generator: pixelgym_backend {version}\n"
               "Root-Is-Purelib: false\n"
               f"Tag: {tag}\n")
        name = f"{NAME}-{version}-{tag}.whl"
        _zip_wheel(stage, dist_info, os.path.join(wheel_directory, name))
    return name


def build_sdist(sdist_directory, config_settings=None):
    version = _version()
    base = f"{NAME}-{version}"
    name = f"{base}.tar.gz"
    path = os.path.join(sdist_directory, name)
    with tarfile.open(path, "w:gz", format=tarfile.PAX_FORMAT) as tar:
        for relative in _source_files():
            tar.add(os.path.join(SOURCE_DIR, relative), arcname=f"{base}/{relative}",
                    recursive=False)
        metadata = _metadata(version, []).encode()
        info = tarfile.TarInfo(f"{base}/PKG-INFO")
        info.size = len(metadata)
        info.mode = 0o644
        info.mtime = _timestamp()
        tar.addfile(info, io.BytesIO(metadata))
    return name


def _setting(config_settings, key, variable):
    value = (config_settings or {}).get(key) or os.environ.get(variable)
    return value if value else None


def _wheel_tag():
    """The tag of a wheel for the running interpreter: cp312-cp312-linux_x86_64."""
    if sys.implementation.name != "cpython":
        raise BuildError(f"pixelgym's binding is built for CPython, got {sys.implementation.name} "
                         f"({sys.executable})")
    if sys.version_info < (3, 9):
        raise BuildError(f"pixelgym needs Python >= 3.9, got {sys.version.split()[0]} "
                         f"({sys.executable})")
    python = f"cp{sys.version_info.major}{sys.version_info.minor}"
    platform = re.sub(r"[^A-Za-z0-9_]", "_", sysconfig.get_platform())
    return f"{python}-{python}{sys.abiflags}-{platform}"


def _build_dir(config_settings, tag):
    given = _setting(config_settings, "build-dir", "PIXELGYM_WHEEL_BUILD_DIR")
    build_dir = os.path.abspath(given or os.path.join(SOURCE_DIR, "build-wheel", tag))
    cache = _cmake_cache(build_dir)
    if cache:
        built_for = cache.get("PIXELGYM_PYTHON_EXECUTABLE", "")
        if os.path.realpath(built_for) != os.path.realpath(sys.executable):
            if given:
                raise BuildError(
                    f"the build folder {build_dir} is configured for the Python {built_for}, not "
                    f"for {sys.executable} (which runs this build): give a build folder of its own "
                    "(--config-settings build-dir=FOLDER, or PIXELGYM_WHEEL_BUILD_DIR) or none")
            os.remove(os.path.join(build_dir, "CMakeCache.txt"))  # ours: configure it afresh
            return build_dir
        for option in ("PIXELGYM_SHARED_LIBS", "PIXELGYM_BUILD_PYTHON"):
            if cache.get(option, "ON").upper() not in ("ON", "1", "TRUE", "YES"):
                raise BuildError(f"the build folder {build_dir} has {option}={cache[option]}: a "
                                 "wheel needs it ON (give another build folder, or none)")
    return build_dir


def _cmake_cache(build_dir):
    """The entries of build_dir's CMakeCache.txt ({} when it has none)."""
    entries = {}
    try:
        with open(os.path.join(build_dir, "CMakeCache.txt"), encoding="utf-8") as file:
            for line in file:
                match = re.match(r"([A-Za-z0-9_]+):[A-Z]+=(.*)$", line.rstrip("\n"))
                if match:
                    entries[match.group(1)] = match.group(2)
    except FileNotFoundError:
        pass
    return entries


def _configure(build_dir):
    if shutil.which("cmake") is None:
        raise BuildError("CMake (>= 3.22) is not on PATH: `apt install cmake` (Debian), and the "
                         "other packages of scripts/install-deps.sh")
    header = os.path.join(sysconfig.get_paths()["include"], "Python.h")
    if not os.path.exists(header):
        raise BuildError(
            f"this Python's headers are missing ({header} does not exist): for Debian's python3 "
            f"`apt install python3-dev`; for another Python, its development files (pyenv and "
            f"conda Pythons have them)")
    if os.path.exists(os.path.join(build_dir, "CMakeCache.txt")):
        return
    _run(["cmake", "-S", SOURCE_DIR, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
          f"-DPIXELGYM_PYTHON_EXECUTABLE={sys.executable}", "-DPIXELGYM_BUILD_PYTHON=ON",
          "-DPIXELGYM_SHARED_LIBS=ON", "-DPIXELGYM_BUILD_TESTS=OFF",
          "-DPIXELGYM_BUILD_EXAMPLES=OFF", "-DPIXELGYM_BUILD_BENCH=OFF",
          # A user's compiler may warn where CI's does not: that is no reason to fail an install.
          "-DPIXELGYM_WERROR=OFF"])


def _run(command):
    # pip shows this output with -v, and all of it when the build fails.
    print("pixelgym_backend:", " ".join(command), flush=True)
    result = subprocess.run(command, stderr=subprocess.STDOUT)
    if result.returncode != 0:
        raise BuildError(f"`{' '.join(command)}` failed (exit status {result.returncode}); its "
                         "output is above (pip shows it with -v)")


def _version():
    with open(os.path.join(SOURCE_DIR, "CMakeLists.txt"), encoding="utf-8") as file:
        match = re.search(r"project\(\s*pixelgym\s+VERSION\s+([0-9.]+)", file.read())
    if not match:
        raise BuildError("CMakeLists.txt: no `project(pixelgym VERSION X.Y.Z` to take the "
                         "version from")
    return match.group(1)


def _metadata(version, requires):
    lines = ["Metadata-Version: 2.1", f"Name: {NAME}", f"Version: {version}",
             f"Summary: {SUMMARY}", "Requires-Python: >=3.9"]
    lines += [f"Requires-Dist: {requirement}" for requirement in requires]
    return "\n".join(lines) + "\n"


def _replace_links(stage):
    """A wheel holds no symbolic links: each library is kept under the name its link had (the
    soname the loader asks for), in place of the link."""
    for folder, _, files in os.walk(stage):
        for name in files:
            path = os.path.join(folder, name)
            if os.path.islink(path):
                target = os.path.realpath(path)
                if not target.startswith(os.path.realpath(stage) + os.sep):
                    raise BuildError(f"{path} links outside the wheel, to {target}")
                os.remove(path)
                os.replace(target, path)


def _write(stage, relative, text):
    with open(os.path.join(stage, relative), "w", encoding="utf-8") as file:
        file.write(text)


def _timestamp():
    """SOURCE_DATE_EPOCH when set (reproducible builds), else 1980-01-01, the zip format's first
    date: the same files give the same wheel."""
    return max(int(os.environ.get("SOURCE_DATE_EPOCH", "315532800")), 315532800)


def _zip_wheel(stage, dist_info, path):
    """The wheel: every file of stage with its sha256 and size in RECORD; the .dist-info files
    last, RECORD at the very end."""
    relatives = sorted((os.path.relpath(os.path.join(folder, name), stage).replace(os.sep, "/")
                        for folder, _, files in os.walk(stage) for name in files),
                       key=lambda relative: (relative.startswith(dist_info), relative))
    date = time.gmtime(_timestamp())[:6]
    record = []
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as wheel:
        for relative in relatives:
            with open(os.path.join(stage, relative), "rb") as file:
                data = file.read()
            info = zipfile.ZipInfo(relative, date_time=date)
            info.external_attr = (stat.S_IFREG | _mode(os.path.join(stage, relative))) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            wheel.writestr(info, data)
            digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
            record.append(f"{relative},sha256={digest},{len(data)}")
        record.append(f"{dist_info}/RECORD,,")
        info = zipfile.ZipInfo(f"{dist_info}/RECORD", date_time=date)
        info.external_attr = (stat.S_IFREG | 0o644) << 16
        info.compress_type = zipfile.ZIP_DEFLATED
        wheel.writestr(info, "\n".join(record) + "\n")


def _mode(path):
    """0o755 for a file anyone may run (the libraries), else 0o644."""
    return 0o755 if os.stat(path).st_mode & stat.S_IXUSR else 0o644


def _source_files():
    """The files of an sdist: git's tracked files that exist, or, without git (an unpacked
    sdist), every file outside UNPACKAGED and build-*/ folders."""
    try:
        listed = subprocess.run(["git", "-C", SOURCE_DIR, "ls-files", "-z"], check=True,
                                capture_output=True).stdout.decode().split("\0")
        return sorted(name for name in listed
                      if name and os.path.isfile(os.path.join(SOURCE_DIR, name)))
    except (OSError, subprocess.CalledProcessError):
        pass
    found = []
    for folder, folders, files in os.walk(SOURCE_DIR):
        folders[:] = sorted(name for name in folders
                            if name not in UNPACKAGED and not name.startswith("build-"))
        found += [os.path.relpath(os.path.join(folder, name), SOURCE_DIR) for name in files]
    return sorted(found)

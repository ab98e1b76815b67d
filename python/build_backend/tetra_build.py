"""The build backend of ``pip install .`` (PEP 517; pyproject.toml, docs/python.md "Getting it").

It needs nothing beyond Python's standard library and the project's own build (CMake and the packages of
scripts/setup.sh), so ``pip install .`` and ``python3 -m build`` work offline, with or without build
isolation. The wheel is built by the project's CMake for the interpreter running pip: the target
``tetra_python`` only (the libraries it links and the module), in the folder ``build/python-<abi>`` of
the source tree, configured without tests and reused by the next install; but in ``build`` itself when
the module there (``scripts/build.sh``'s) has this interpreter's extension suffix. ``TETRA_BUILD_DIR``
(or ``--config-settings build-dir=DIR``) names the build folder to build the module in: only what changed
is rebuilt, provided that folder builds the module for this interpreter (same extension suffix).
"""
from __future__ import annotations

import base64
import hashlib
import io
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tarfile
import zipfile
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[2]
PACKAGE_FILES = ("__init__.py", "__init__.pyi", "_tetra.pyi", "py.typed", "dds.py")


def _version() -> str:
    text = (SOURCE / "CMakeLists.txt").read_text()
    match = re.search(r"project\(tetra VERSION ([0-9.]+)", text)
    if not match:
        raise RuntimeError("CMakeLists.txt: no 'project(tetra VERSION x.y.z' line")
    return match.group(1)


def _metadata() -> str:
    summary = ("Calibration, Allan analysis, simulation, fault-tolerant fusion and fault-injection "
               "campaigns for redundant gyro packages")
    return "\n".join([
        "Metadata-Version: 2.1",
        "Name: tetra",
        f"Version: {_version()}",
        f"Summary: {summary}",
        "Requires-Python: >=3.8",
        "Provides-Extra: arrays",
        'Requires-Dist: numpy; extra == "arrays"',
        'Requires-Dist: pandas; extra == "arrays"',
        "Description-Content-Type: text/markdown",
        "",
        (SOURCE / "docs" / "python.md").read_text(),
    ])


def _tag() -> str:
    """The wheel's tag for this interpreter: the module is compiled for its ABI and this platform."""
    impl = {"cpython": "cp", "pypy": "pp"}.get(sys.implementation.name, sys.implementation.name)
    version = f"{sys.version_info.major}{sys.version_info.minor}"
    abi = f"{impl}{version}{getattr(sys, 'abiflags', '')}"
    platform = re.sub(r"[^A-Za-z0-9]", "_", sysconfig.get_platform())
    return f"{impl}{version}-{abi}-{platform}"


def _setting(config_settings, key: str, env: str):
    value = (config_settings or {}).get(key) or os.environ.get(env)
    return Path(value).resolve() if value else None


def _run(cmd: list) -> None:
    print("tetra build:", " ".join(str(c) for c in cmd), file=sys.stderr, flush=True)
    subprocess.run([str(c) for c in cmd], check=True, stdout=sys.stderr)


def _build_module(config_settings) -> Path:
    """Builds the module for this interpreter; returns its file."""
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    given = _setting(config_settings, "build-dir", "TETRA_BUILD_DIR")
    if not given and (SOURCE / "build" / "python" / "tetra" / f"_tetra{suffix}").exists():
        given = SOURCE / "build"  # scripts/build.sh's folder already builds the module for this suffix
    build = given or SOURCE / "build" / f"python-{suffix.strip('.').rsplit('.', 1)[0]}"
    # The interpreter itself, not a venv's link to it (a venv may be gone by the next install).
    python = getattr(sys, "_base_executable", "") or sys.executable
    cache = build / "CMakeCache.txt"
    if not cache.exists() and given:
        raise RuntimeError(f"{build}: not a configured build folder (no CMakeCache.txt)")
    cached = re.search(r"^Python3_EXECUTABLE:\w+=(.*)$", cache.read_text(), re.M) if cache.exists() else None
    if not given and not (cached and Path(cached.group(1)).exists()):
        configure = ["cmake", "-S", SOURCE, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DTETRA_BUILD_TESTS=OFF",
                     "-DTETRA_BUILD_BENCH=OFF", "-DTETRA_PYTHON=ON", f"-DPython3_EXECUTABLE={python}"]
        if shutil.which("ccache"):
            configure += ["-DCMAKE_C_COMPILER_LAUNCHER=ccache", "-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"]
        _run(configure)
    _run(["cmake", "--build", build, "--target", "tetra_python", "-j", str(os.cpu_count() or 1)])
    module = build / "python" / "tetra" / f"_tetra{suffix}"
    if not module.exists():
        found = sorted(p.name for p in (build / "python" / "tetra").glob("_tetra*.so"))
        raise RuntimeError(f"{build} builds the module for another Python ({', '.join(found) or 'none'}; "
                           f"{sys.executable} loads _tetra{suffix}): configure it with "
                           f"-DPython3_EXECUTABLE={sys.executable}, or leave TETRA_BUILD_DIR unset")
    return module


def _record_line(name: str, data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def _dist_info_files() -> dict:
    return {
        "METADATA": _metadata().encode(),
        "WHEEL": (f"Wheel-Version: 1.0\nGenerator: tetra_build\nRoot-Is-Purelib: false\nTag: {_tag()}\n").encode(),
        "top_level.txt": b"tetra\n",
    }


def _dist_info() -> str:
    return f"tetra-{_version()}.dist-info"


# --- PEP 517 hooks ------------------------------------------------------------------------------------

def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    target = Path(metadata_directory) / _dist_info()
    target.mkdir(parents=True, exist_ok=True)
    for name, data in _dist_info_files().items():
        (target / name).write_bytes(data)
    return _dist_info()


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    module = _build_module(config_settings)
    files = {f"tetra/{name}": (SOURCE / "python" / "tetra" / name).read_bytes() for name in PACKAGE_FILES}
    files[f"tetra/{module.name}"] = module.read_bytes()
    for name, data in _dist_info_files().items():
        files[f"{_dist_info()}/{name}"] = data
    record = [_record_line(name, data) for name, data in files.items()]
    record.append(f"{_dist_info()}/RECORD,,")
    files[f"{_dist_info()}/RECORD"] = ("\n".join(record) + "\n").encode()
    wheel = f"tetra-{_version()}-{_tag()}.whl"
    with zipfile.ZipFile(Path(wheel_directory) / wheel, "w", zipfile.ZIP_DEFLATED) as z:
        for name, data in files.items():
            info = zipfile.ZipInfo(name, date_time=(2020, 1, 1, 0, 0, 0))
            info.external_attr = (0o755 if name.endswith(".so") else 0o644) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, data)
    return wheel


def _sdist_files() -> list:
    """The files of the source tree: git's list in a clone, else every file but build folders."""
    try:
        out = subprocess.run(["git", "-C", SOURCE, "ls-files", "-z"], check=True, capture_output=True).stdout
        return [Path(p) for p in out.decode().split("\0") if p and (SOURCE / p).is_file()]
    except (OSError, subprocess.CalledProcessError):
        skip = {".git", "build", "node_modules", "__pycache__"}
        return [p.relative_to(SOURCE) for p in SOURCE.rglob("*")
                if p.is_file() and not skip.intersection(p.relative_to(SOURCE).parts)]


def build_sdist(sdist_directory, config_settings=None):
    base = f"tetra-{_version()}"
    name = f"{base}.tar.gz"
    with tarfile.open(Path(sdist_directory) / name, "w:gz") as tar:
        for rel in _sdist_files():
            tar.add(SOURCE / rel, arcname=f"{base}/{rel}", recursive=False)
        info = tarfile.TarInfo(f"{base}/PKG-INFO")
        data = _metadata().encode()
        info.size = len(data)
        tar.addfile(info, io.BytesIO(data))
    return name

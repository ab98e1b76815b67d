#!/usr/bin/env python3
"""ctest python_pip_install (docs/python.md, "Getting it"): `pip install .` of the source tree into a fresh
venv, offline, then `import tetra` from the venv and a small call; and the same into a plain venv of every
other CPython given with --python (e.g. pyenv's python3), with pip's build isolation, which needs nothing
from an index either.

The module is built in the test's build folder (TETRA_BUILD_DIR): the libraries and the module the suite
already built are reused, so the install costs the copy and pip's own work, not a compilation.
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CHECK = """
import sys, tetra
assert tetra.__file__.startswith(sys.prefix), tetra.__file__
cal = tetra.Calibration.seed_unit()
assert cal.gyro_count == 4 and 'scale_factor' in cal.to_yaml()
print(tetra.__version__, tetra.__file__)
"""
CHECK_NUMPY = CHECK + """
import numpy as np
run = tetra.sim('static', duration_s=30, seed=2)
r = tetra.allan(run.log.values[:, 0], 0.1)
assert len(r.adev) > 3 and np.all(np.isfinite(r.adev))
"""


def install(python, venv, source, build_dir, isolation, system_site):
    args = [python, "-m", "venv", venv] + (["--system-site-packages"] if system_site else [])
    subprocess.run(args, check=True)
    env = dict(os.environ, TETRA_BUILD_DIR=str(build_dir), PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    env.pop("PYTHONPATH", None)
    pip = [str(Path(venv) / "bin" / "python"), "-m", "pip", "install", "-q"]
    if not isolation:
        pip.append("--no-build-isolation")
    t0 = time.monotonic()
    subprocess.run(pip + [str(source)], check=True, env=env, cwd=venv)
    return time.monotonic() - t0, env


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", required=True)
    ap.add_argument("--build", required=True, help="the configured build folder")
    ap.add_argument("--python", action="append", default=[], help="another CPython to install into")
    ap.add_argument("--path-python", action="store_true",
                    help="also install into the python3 first on PATH when it is another interpreter (pyenv's)")
    ap.add_argument("--notebook", action="store_true", help="run examples/python/notebook.py from the venv")
    a = ap.parse_args()
    if a.path_python:
        found = shutil.which("python3")
        if found:
            exe = subprocess.run([found, "-c", "import sys; print(sys.executable)"], capture_output=True,
                                 text=True).stdout.strip()
            if exe and os.path.realpath(exe) != os.path.realpath(sys.executable):
                a.python.append(exe)
    with tempfile.TemporaryDirectory() as tmp:
        venv = Path(tmp) / "venv"
        seconds, env = install(sys.executable, venv, a.source, a.build, isolation=False, system_site=True)
        py = str(venv / "bin" / "python")
        subprocess.run([py, "-c", CHECK_NUMPY], check=True, env=env, cwd=tmp)
        print(f"pip install . ({sys.executable}, venv --system-site-packages): {seconds:.1f} s")
        if a.notebook:
            notebook = Path(a.source) / "examples" / "python" / "notebook.py"
            subprocess.run([py, str(notebook), "--out", str(Path(tmp) / "plots")], check=True,
                           env=dict(env, MPLBACKEND="Agg"), cwd=tmp)
        for other in a.python:
            other_venv = Path(tmp) / ("venv-" + Path(other).name)
            seconds, env = install(other, other_venv, a.source, a.build, isolation=True, system_site=False)
            subprocess.run([str(other_venv / "bin" / "python"), "-c", CHECK], check=True, env=env, cwd=tmp)
            print(f"pip install . ({other}, plain venv, build isolation): {seconds:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

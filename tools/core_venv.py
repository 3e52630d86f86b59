"""splinevis installed from its wheel into a new virtual environment that holds only the core dependencies.

What a user gets from ``pip install splinevis`` (no extras), built without the network and in seconds:

1. the sources the wheel is made of (the packages of ``pyproject.toml``, its readme) are copied to a scratch
   folder, so the build writes nothing into the repository, and ``pip wheel --no-deps --no-build-isolation
   --no-index`` builds the wheel there with the setuptools of the running environment;
2. ``python -m venv --without-pip`` makes the environment (no system site-packages);
3. the core dependencies come from the running environment without copying or downloading them: the
   ``dependencies`` of ``pyproject.toml`` (what the wheel declares; the metadata of the editable install is only
   as new as its last ``pip install``), and recursively the requirements of their installed distributions
   (markers evaluated with no extra), are resolved to their distributions; each top-level entry of their files
   (package folder, module, ``.libs`` folder, ``.dist-info``) is symlinked into one folder, which a ``.pth`` file
   puts on the new environment's path. Nothing else of the running environment is visible there: the extras'
   modules are not;
4. the wheel goes in with ``pip --python <new python> install --no-deps --no-index``.

Used by ``tests/test_wheel_core_install.py`` and ``benchmarks/bench_import.py``.
"""

from __future__ import annotations

import importlib.metadata as metadata
import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]


def build_wheel(out: Path) -> Path:
    """Build splinevis's wheel from a copy of its sources in ``out`` (no network, no build isolation)."""
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())
    tool = cfg["tool"]["setuptools"]
    package_dir = tool["package-dir"]
    tops = {package_dir.get(p, p.split(".")[0]).split("/")[0] for p in tool["packages"]}
    src = out / "src"
    src.mkdir(parents=True)
    for name in ("pyproject.toml", cfg["project"]["readme"]):
        shutil.copy2(ROOT / name, src / name)
    for top in sorted(tops):
        shutil.copytree(ROOT / top, src / top, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    wheels = out / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(src), "--no-deps", "--no-build-isolation", "--no-index",
                    "-q", "-w", str(wheels)], check=True, capture_output=True, env=clean_env())
    (wheel,) = wheels.glob("splinevis-*.whl")
    return wheel


def core_distributions() -> dict:
    """Name -> installed distribution of the core dependencies of splinevis and everything they need."""
    core = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    todo = [r for r in map(Requirement, core) if r.marker is None or r.marker.evaluate({"extra": ""})]
    found = {}
    while todo:
        req = todo.pop()
        name = canonicalize_name(req.name)
        if name in found:
            continue
        found[name] = dist = metadata.distribution(req.name)
        todo += [r for r in map(Requirement, dist.requires or [])
                 if r.marker is None or r.marker.evaluate({"extra": ""})]
    return found


def core_only_venv(out: Path, wheel: Path) -> Path:
    """A new environment in ``out/venv`` with ``wheel`` and only the core dependencies; its python."""
    links = out / "core-site-packages"
    links.mkdir(parents=True)
    for dist in core_distributions().values():
        if dist.files is None:
            raise RuntimeError(f"{dist.metadata['Name']} has no RECORD: its files cannot be linked.")
        for top in {f.parts[0] for f in dist.files} - {"..", "__pycache__"}:
            target = Path(dist.locate_file(top))
            if target.exists() and not (links / top).exists():
                (links / top).symlink_to(target)
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(out / "venv")], check=True)
    python = out / "venv" / "bin" / "python"
    purelib = subprocess.run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                             capture_output=True, text=True, check=True, env=clean_env()).stdout.strip()
    Path(purelib, "splinevis_core_dependencies.pth").write_text(f"{links}\n")
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps", "--no-index", "-q",
                    str(wheel)], check=True, capture_output=True, env=clean_env())
    return python


def clean_env() -> dict:
    """The environment variables with nothing that would add to a Python's path (``PYTHONPATH``, user site)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env["PYTHONNOUSERSITE"] = "1"
    return env

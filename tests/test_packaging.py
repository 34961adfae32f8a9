"""Packaging: one import namespace. The wheel installs next to PyPI's own ``robots``, ``optim``,
``planning`` and ``viz`` in a fresh virtualenv, and the README's quickstart runs there from
outside the repository; the editable install maps the repository's folders to ``pinarms.*``.

The fresh virtualenv takes pinarms' dependencies (Pinocchio, coal, numba, ...) from the
environment running the tests, behind its own site-packages, instead of installing them again
(minutes): what is checked is the wheel's content and its namespace beside the namesakes. That the
wheel asks for the same dependencies as ``pyproject.toml`` is checked on its metadata. The test
environment's pip installs into it (``pip --python``: no pip of its own to set up), and the
quickstart loads the compiled kernels that ``pinarms warm`` left beside the checkout's sources
(numba's cache, copied beside the wheel's identical sources), as after ``pinarms warm`` on a fresh
install, instead of compiling them again (the cold compile is measured by benchmarks/first_use.py).
"""

from __future__ import annotations

import json
import os
import site
import tomllib
import zipfile
import re
import shutil
import subprocess
import sys
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NAMESAKES = ("robots", "optim", "planning", "viz")  # PyPI projects unrelated to pinarms
PINARMS_PACKAGES = ("robots", "planning", "optim", "viz", "urdf")
#: the checkout's folders and where the wheel puts them (pyproject.toml's package-dir)
LAYOUT = {"pinarms": "pinarms", "robots": "pinarms/robots", "planning": "pinarms/planning", "optim": "pinarms/optim",
          "viz": "pinarms/viz"}

PROBE = f"""
import importlib, importlib.resources, importlib.util, json, sys
out = {{}}
for name in {NAMESAKES!r}:
    spec = importlib.util.find_spec(name)
    out[name] = None if spec is None else spec.origin
import pinarms
for name in {PINARMS_PACKAGES!r}:
    out["pinarms." + name] = importlib.import_module("pinarms." + name).__file__
out["page.js"] = importlib.resources.files("pinarms.viz").joinpath("page.js").is_file()
out["koji urdf"] = importlib.resources.files("pinarms.urdf").joinpath("koji_turner.urdf").is_file()
from pinarms import optim
out["minimize_time"] = callable(optim.minimize_time)
print(json.dumps(out))
"""


def _quickstart() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    return re.findall(r"```python\n(.*?)```", text, flags=re.DOTALL)[0]


def _run(cmd: list, cwd: Path, timeout: float = 900) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    result = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert result.returncode == 0, f"{cmd}\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    return result


def _source_copy(dest: Path) -> Path:
    """The repository's files as a clone has them, in ``dest``: the wheel is built from there, so that
    its build/ and pinarms.egg-info/ never land in the repository that the other tests read meanwhile."""
    junk = shutil.ignore_patterns(".git", ".venv", "build", "dist", "*.egg-info", "demo-output", "__pycache__",
                                  ".pytest_cache", ".hypothesis", "*.pyc")
    shutil.copytree(ROOT, dest, ignore=junk)
    return dest


def _requirements(wheel: Path) -> set[str]:
    """The ``Requires-Dist`` lines of the wheel's metadata without extras markers (its run-time dependencies)."""
    with zipfile.ZipFile(wheel) as archive:
        (name,) = [n for n in archive.namelist() if n.endswith(".dist-info/METADATA")]
        metadata = archive.read(name).decode("utf-8")
    lines = re.findall(r"^Requires-Dist: (.+)$", metadata, flags=re.MULTILINE)
    return {line.replace(" ", "") for line in lines if "extra ==" not in line}


def _dependencies_behind(env_dir: Path) -> None:
    """Make the test environment's packages importable in ``env_dir``, after its own site-packages
    (a ``.pth`` line run by ``site``; the ``.pth`` files there, e.g. Pinocchio's, are processed too)."""
    (own,) = (env_dir / "lib").glob("python3*/site-packages")
    folders = [f for f in site.getsitepackages() if Path(f).is_dir()]
    lines = "".join(f"import site; site.addsitedir({folder!r})\n" for folder in folders)
    (own / "zz_test_dependencies.pth").write_text(lines, encoding="utf-8")


def _kernel_caches_beside(site_packages: Path) -> int:
    """Copy numba's caches of the checkout's kernels (and the stale-cache guards' digests) beside the installed
    copies of their sources, each source stamped with its checkout twin's modification time (numba's cache key is
    the source's time and size, the guards' the sources' bytes); only where the two sources are the same bytes.
    Return the number of cache files copied (0 where the checkout has none: the kernels then compile there)."""
    copied = 0
    for folder, target in LAYOUT.items():
        for cache in (ROOT / folder).rglob("__pycache__"):
            source_dir = cache.parent
            installed = site_packages / target / source_dir.relative_to(ROOT / folder)
            files = [f for f in cache.iterdir() if f.suffix in (".nbi", ".nbc", ".sha256")]
            if not files or not installed.is_dir():
                continue
            for source in source_dir.glob("*.py"):
                twin = installed / source.name
                if twin.is_file() and twin.read_bytes() == source.read_bytes():
                    os.utime(twin, ns=(source.stat().st_atime_ns, source.stat().st_mtime_ns))
            (installed / "__pycache__").mkdir(exist_ok=True)
            for f in files:
                shutil.copy2(f, installed / "__pycache__" / f.name)
                copied += 1
    return copied


@pytest.mark.slow
def test_wheel_beside_pypi_namesakes_runs_the_quickstart(tmp_path):
    """About half a minute with a warm pip cache (the dependencies come from the test environment)."""
    dist = tmp_path / "dist"
    source = _source_copy(tmp_path / "source")
    _run([sys.executable, "-m", "pip", "wheel", source, "--no-deps", "-w", dist, "-q"], tmp_path)
    (wheel,) = dist.glob("pinarms-*.whl")
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["dependencies"]
    assert _requirements(wheel) == {d.replace(" ", "") for d in declared}
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=False)
    py = env_dir / "bin" / "python"
    pip = [sys.executable, "-m", "pip", "--python", py, "install", "-q", "--no-compile"]
    # pinarms first, then the namesakes: pip would silently overwrite a top-level package of the same name
    _run([*pip, "--no-deps", wheel], tmp_path)
    _run([*pip, *NAMESAKES], tmp_path)
    _dependencies_behind(env_dir)
    (own,) = (env_dir / "lib").glob("python3*/site-packages")
    _kernel_caches_beside(own)
    work = tmp_path / "outside"
    work.mkdir()
    found = json.loads(_run([py, "-c", PROBE], work).stdout)
    site = str(env_dir)
    for name in NAMESAKES:  # PyPI's packages, untouched
        assert found[name] and found[name].startswith(site) and "pinarms" not in found[name]
    for name in PINARMS_PACKAGES:  # pinarms' packages, from the wheel (not from the repository)
        origin = found[f"pinarms.{name}"]
        assert origin.startswith(site) and f"pinarms{os.sep}{name}{os.sep}__init__.py" in origin
    assert found["page.js"] and found["koji urdf"] and found["minimize_time"]
    (work / "quickstart.py").write_text(_quickstart(), encoding="utf-8")
    out = _run([py, "quickstart.py"], work).stdout
    assert "[1197.3  250.  -929.2]" in out
    assert (work / "study.pinarms").is_file() and (work / "study.html").stat().st_size > 100_000


def test_editable_install_maps_the_folders(tmp_path):
    """The development install (``make install``): ``pinarms.robots`` is the repository's robots/ folder,
    and no top-level ``robots``/``optim``/... is installed by pinarms."""
    found = json.loads(_run([sys.executable, "-c", PROBE], tmp_path).stdout)
    for name in PINARMS_PACKAGES:
        assert Path(found[f"pinarms.{name}"]) == ROOT / name / "__init__.py"
    for name in NAMESAKES:
        assert found[name] is None or not found[name].startswith(str(ROOT))
    assert found["page.js"] and found["koji urdf"]

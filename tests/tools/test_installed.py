"""cranefmu as a user gets it: the sdist and wheel built from this checkout, the wheel installed (not
editable) into a fresh venv whose site-packages is then made read-only, everything run from a
temporary directory outside the checkout with the build cache in a temporary folder.

Each run's rows are compared with the same run in the checkout (value for value: the FMUs built in
the cache come from the same sources).  Every command is followed by a check that site-packages is
unchanged file for file (size and mtime): root ignores the read-only bits, so this is what proves
"never writes into site-packages" when the tests run as root.

The venv is made without pip and gets the test venv's site-packages (numpy, fmpy, pythonfmu, ...)
through a .pth line, which appends it after the venv's own site-packages: the installed cranefmu is
the wheel's (asserted), the dependencies are the versions the checkout is tested with.  .ci/run
also installs the wheel with its dependencies from the registry into a clean venv.
"""
from __future__ import annotations

import csv
import fcntl
import os
import re
import shutil
import stat
import subprocess
import sys
import sysconfig
import textwrap
from pathlib import Path

import numpy as np
import pytest

CHECKOUT = Path(__file__).resolve().parents[2]
SCENE = "elastic_pendulum"
STOP = 0.5          # s: 500 steps of H
H = 1e-3            # s (the scene stores a longer step: given, so the row counts below hold)
SCRIPT = textwrap.dedent(f"""\
    import numpy as np
    import cranefmu

    rows = cranefmu.simulate({SCENE!r}, stop_time={STOP}, step_size={H}, progress=False)
    np.save("rows.npy", rows)
    """)


def _tree(folder: Path) -> dict[str, tuple[int, int]]:
    return {p.relative_to(folder).as_posix(): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in sorted(folder.rglob("*"))}


def _must(cmd: list[str]) -> None:
    res = subprocess.run(cmd, capture_output=True, text=True)
    assert res.returncode == 0, f"{' '.join(cmd)} failed:\n{res.stdout}\n{res.stderr}"


class Installed:
    """A venv with the wheel installed; runs commands in ``work`` with the cache in ``cache``."""

    def __init__(self, root: Path):
        self.root = root
        dist = root / "dist"
        # one build of the checkout at a time: two test workers building at once share its build/ and egg-info
        # folders, and one lost files the other had just removed ("No such file or directory: ...analysis.toml")
        with open(CHECKOUT / ".pytest_wheel.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            _must([sys.executable, "-m", "build", "--no-isolation", "--outdir", str(dist), str(CHECKOUT)])
        (self.sdist,) = dist.glob("cranefmu-*.tar.gz")
        (self.wheel,) = dist.glob("cranefmu-*.whl")
        self.venv = root / "venv"
        subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(self.venv)], check=True)
        self.python = self.venv / "bin" / "python"
        self.site = Path(subprocess.run([str(self.python), "-c", "import sysconfig; print(sysconfig.get_paths()"
                                         "['purelib'])"], check=True, capture_output=True, text=True).stdout.strip())
        deps = dict.fromkeys([sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]])
        (self.site / "_test_dependencies.pth").write_text("\n".join(deps) + "\n")
        # pip comes from the test venv through the .pth; --ignore-installed: never touch the editable install
        _must([str(self.python), "-m", "pip", "install", "--quiet", "--no-deps", "--ignore-installed",
               "--disable-pip-version-check", str(self.wheel)])
        for path in [self.site, *self.site.rglob("*")]:
            path.chmod(path.stat().st_mode & ~(stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH))
        self.files = _tree(self.site)
        self.work = root / "work"
        self.work.mkdir()
        self.cache = root / "cache"
        self.env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
        self.env.update(CRANEFMU_CACHE_DIR=str(self.cache), MPLCONFIGDIR=str(root / "mpl"),
                        PATH=f"{self.venv / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}")

    def run(self, *cmd: str, stdin: str | None = None, env: dict | None = None) -> subprocess.CompletedProcess:
        res = subprocess.run(list(cmd), cwd=self.work, env={**self.env, **(env or {})}, input=stdin,
                             capture_output=True, text=True, timeout=300)
        assert _tree(self.site) == self.files, f"{' '.join(cmd)} changed site-packages"
        return res

    def cranefmu(self, *args: str) -> subprocess.CompletedProcess:
        res = self.run(str(self.venv / "bin" / "cranefmu"), *args)
        assert res.returncode == 0, res.stderr
        return res

    def remove(self) -> None:
        for path in [self.site, *self.site.rglob("*")]:
            if path.is_dir():
                path.chmod(path.stat().st_mode | stat.S_IWUSR)
        shutil.rmtree(self.root, ignore_errors=True)


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    inst = Installed(tmp_path_factory.mktemp("installed"))
    yield inst
    inst.remove()


@pytest.fixture(scope="module")
def checkout_rows(built, tmp_path_factory):
    """The same run in the checkout: its result array and its CSV."""
    from cranefmu.master.run import run

    out = tmp_path_factory.mktemp("checkout") / "rows.csv"
    return run(SCENE, stop_time=STOP, step_size=H, output=out, progress=False).result, out


def _csv(path: Path) -> tuple[list[str], np.ndarray]:
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(v) for v in r] for r in rows[1:]])


# test and benchmark scaffolding moved to support/cranefmu_support (issue 36): never in the wheel
SCAFFOLDING = re.compile(r"cranefmu/studies/(fmu_child|foreign_ssp|model_cases)\.py|cranefmu/studies/(oscillator|c_host|c_fmu|late)/")


def test_the_wheel_carries_the_sources_and_is_what_runs(installed):
    import zipfile

    names = set(zipfile.ZipFile(installed.wheel).namelist())
    from cranefmu.sources import scene_dirs, scene_files

    sources = [p.relative_to(CHECKOUT).as_posix() for p in
               [*CHECKOUT.glob("fmus/*.py"), *(f for d in scene_dirs() for f in scene_files(d))]]
    assert sources and all(f"cranefmu/_sources/{s}" in names for s in sources)
    assert not any(n.endswith((".fmu", ".ssp")) for n in names)
    assert not [n for n in names if n.startswith("cranefmu_support/") or SCAFFOLDING.match(n)]  # tests' scaffolding
    assert "cranefmu/adapter/fmi_adapter.py" in names and "cranefmu/studies/hosts.py" in names
    import tarfile

    members = {m.split("/", 1)[1] for m in tarfile.open(installed.sdist).getnames() if "/" in m}
    assert all(s in members for s in sources)
    where = installed.run(str(installed.python), "-c", "import cranefmu; print(cranefmu.__file__)").stdout.strip()
    assert Path(where).is_relative_to(installed.site) and not Path(where).is_relative_to(CHECKOUT)
    from cranefmu import __version__

    assert installed.cranefmu("--version").stdout.strip() == f"cranefmu {__version__}"


def test_cli_run_gives_the_checkout_rows(installed, checkout_rows):
    res = installed.cranefmu("run", SCENE, "--stop-time", str(STOP), "--step", str(H), "--output", "cli.csv",
                            "--no-progress")
    assert "results: cli.csv (501 rows" in res.stdout
    header, rows = _csv(installed.work / "cli.csv")
    ref_header, ref = _csv(checkout_rows[1])
    assert header == ref_header and rows.shape == (501, len(header))
    assert np.array_equal(rows, ref)
    # built on first use into this version's cache folder, beside the copied scene sources
    # (beside it the compiled exchange kernel, cache_root()/kernel/<digest>: cranefmu.master.kernel)
    (folder,) = (p for p in installed.cache.iterdir() if p.name != "kernel")
    assert folder.name.startswith(checkout_version()) and (folder / "ssp" / f"{SCENE}.ssp").is_file()
    assert (folder / "ssp" / SCENE / "SystemStructure.ssd").is_file()


def checkout_version() -> str:
    from cranefmu import __version__

    return __version__


def _same_rows(rows: np.ndarray, ref: np.ndarray) -> None:
    assert rows.dtype.names == ref.dtype.names and len(rows) == len(ref) == 501
    for name in ref.dtype.names:
        assert np.array_equal(rows[name], ref[name]), name


def test_guardless_script_gives_the_checkout_rows(installed, checkout_rows):
    (installed.work / "plain.py").write_text(SCRIPT)
    (installed.work / "rows.npy").unlink(missing_ok=True)
    res = installed.run(str(installed.python), "plain.py")
    assert res.returncode == 0, res.stderr
    _same_rows(np.load(installed.work / "rows.npy"), checkout_rows[0])


def test_script_on_stdin_gives_the_checkout_rows(installed, checkout_rows):
    (installed.work / "rows.npy").unlink(missing_ok=True)
    res = installed.run(str(installed.python), "-", stdin=SCRIPT)
    assert res.returncode == 0, res.stderr
    _same_rows(np.load(installed.work / "rows.npy"), checkout_rows[0])


def test_python_c_gives_the_checkout_rows(installed, checkout_rows):
    (installed.work / "rows.npy").unlink(missing_ok=True)
    res = installed.run(str(installed.python), "-c", SCRIPT)
    assert res.returncode == 0, res.stderr
    _same_rows(np.load(installed.work / "rows.npy"), checkout_rows[0])


def test_reference_solve_gives_the_checkout_solution(installed, tmp_path):
    # both solves in a fresh process.  The checkout's solve ran in this test process, after whatever
    # tests ran before in it, and its rope.tension differed in the last bit once in five runs (issue 23;
    # the cause not found).  Fresh processes agreed bit for bit: 14 of them, over 8 hash seeds and
    # 1, 2 and 4 OpenBLAS threads, and 6 solves in one process between allocations of other sizes.  Ruled
    # out since (the solve repeated in one process, compared bit for bit): denormals flushed (MXCSR FTZ/DAZ
    # set), the x87 unit at 53 bits or rounding to zero, two threads busy in BLAS meanwhile, and in-process
    # co-simulations of all four scenes before it.  The cause is still not found.
    code = f"import numpy as np; from cranefmu.analysis.reference import solve; np.savez('ref.npz', **solve({SCENE!r}, {STOP}))"
    res = installed.run(str(installed.python), "-c", code)
    assert res.returncode == 0, res.stderr
    here = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert here.returncode == 0, here.stderr
    ours, ref = np.load(installed.work / "ref.npz"), np.load(tmp_path / "ref.npz")
    assert sorted(ours.files) == sorted(ref.files) and len(ref["time"]) == 2001
    for name in ref.files:
        assert np.array_equal(ours[name], ref[name]), name


def test_info_converge_docs_and_build(installed, built):
    info = installed.cranefmu("info", SCENE).stdout
    assert f"scene {SCENE} ({installed.cache}" in info and "rope (Rope.fmu)" in info
    # Jacobi with zero-order hold is first order: halving the step halves the error
    installed.cranefmu("converge", SCENE, "--steps", "2e-3,1e-3", "--stop-time", str(STOP), "--output", "conv")
    with open(installed.work / "conv" / "converge.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["run"] for r in rows] == ["H=0.002", "H=0.001"]
    assert 0.8 < float(rows[1]["rope.tension.order"]) < 1.2
    # pages rendered from the cache's FMUs are the checkout's pages
    installed.cranefmu("docs", "--output", "pages", "Rope", "Pendulum")
    for name in ("Rope", "Pendulum"):
        assert (installed.work / "pages" / f"{name}.md").read_text() == \
            (CHECKOUT / "docs" / "fmus" / f"{name}.md").read_text()
    (installed.work / "a_file").write_text("")
    res = installed.run(str(installed.venv / "bin" / "cranefmu"), "docs", "--output", "a_file/pages", "Rope")
    assert res.returncode == 2 and res.stderr.startswith("cranefmu: error: cannot write the FMU pages into a_file")
    out = installed.cranefmu("build").stdout
    fmus = sorted(p.stem for p in installed.cache.glob("*/fmus/*.fmu"))
    assert fmus == sorted(p.stem for p in CHECKOUT.glob("fmus/[!_]*.py")), out
    assert "is up to date" in installed.cranefmu("build").stdout
    where = installed.cranefmu("build", "--where").stdout.split()
    assert [Path(w).name for w in where] == ["fmus", "ssp"] and Path(where[0]).parent.parent == installed.cache
    (installed.cache / "other.txt").write_text("not a build")
    assert installed.cranefmu("build", "--clear-cache").stdout.startswith("removed ")
    assert [p.name for p in installed.cache.iterdir()] == ["other.txt"]


def test_concurrent_first_uses_share_one_cache(installed, checkout_rows):
    """Two runs starting together on an empty cache: both succeed with the checkout's rows (one builds
    under the lock, the other waits and uses its files)."""
    cache = installed.root / "cache2"
    cmd = [str(installed.venv / "bin" / "cranefmu"), "run", SCENE, "--stop-time", str(STOP), "--step", str(H),
           "--no-progress"]
    env = {**installed.env, "CRANEFMU_CACHE_DIR": str(cache)}
    procs = [subprocess.Popen([*cmd, "--output", f"c{i}.csv"], cwd=installed.work, env=env, text=True,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE) for i in (1, 2)]
    for p in procs:
        _, err = p.communicate(timeout=300)
        assert p.returncode == 0, err
    ref = _csv(checkout_rows[1])[1]
    for i in (1, 2):
        assert np.array_equal(_csv(installed.work / f"c{i}.csv")[1], ref)
    assert not list(cache.rglob("*.tmp"))


def test_an_unwritable_cache_is_one_line_saying_what_to_do(installed):
    blocker = installed.root / "not_a_folder"
    blocker.write_text("")
    res = installed.run(str(installed.venv / "bin" / "cranefmu"), "run", SCENE, "--stop-time", str(STOP),
                        env={"CRANEFMU_CACHE_DIR": str(blocker / "cache")})
    assert res.returncode == 2 and "Traceback" not in res.stderr
    last = res.stderr.strip().splitlines()[-1]
    assert last.startswith("cranefmu: error: cannot build") and "set CRANEFMU_CACHE_DIR" in last


def test_a_read_only_checkout_with_stale_builds_runs_from_the_cache(built, checkout_rows, tmp_path, monkeypatch):
    """The checkout cannot be written and its FMUs count as stale: the build goes to the user cache,
    and the scene run from there gives the checkout's rows.  Built and current, it is used as it is."""
    from cranefmu import build as b
    from cranefmu.master.run import run

    monkeypatch.setenv("CRANEFMU_CACHE_DIR", str(tmp_path / "cache"))
    before = b.FMU_DIR, b.SSP_DIR
    try:
        assert b._choose_build_dirs(checkout_writable=False) == (b.FMU_SOURCES, b.SSP_SOURCES)
        real = b.fmu_is_stale
        monkeypatch.setattr(b, "fmu_is_stale", lambda script, *a: b.FMU_DIR == b.FMU_SOURCES or real(script, *a))
        fmu_dir, ssp_dir = b._choose_build_dirs(checkout_writable=False)
        assert fmu_dir.parent.parent == tmp_path / "cache" and ssp_dir.parent == fmu_dir.parent
        b.set_build_dirs(fmu_dir, ssp_dir)
        res = run(SCENE, stop_time=STOP, step_size=H, progress=False)
        assert (ssp_dir / f"{SCENE}.ssp").is_file()
        _same_rows(res.result, checkout_rows[0])
    finally:
        b.set_build_dirs(*before)


def test_the_master_resolves_names_only_through_the_registered_resolver(built, monkeypatch):
    """Names reach the master through the resolver `import cranefmu` registers; without it only .ssp
    paths are accepted, and no master module imports the build or the scene catalog."""
    import ast

    from cranefmu import build as b
    from cranefmu.errors import SceneError
    from cranefmu.master import scene_names

    ssp = b.SSP_DIR / f"{SCENE}.ssp"
    assert scene_names.resolve_scene(SCENE, "python") == ssp   # the pythonfmu scene (a name alone: native where built)
    monkeypatch.setattr(scene_names, "_resolver", None)
    with pytest.raises(SceneError, match=f"scene '{SCENE}' is not allowed: a path to an .ssp file"):
        scene_names.resolve_scene(SCENE)
    assert scene_names.resolve_scene(ssp) == ssp
    imported = set()
    for path in (CHECKOUT / "src" / "cranefmu" / "master").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level == 2:   # from ..x import y / from .. import x
                imported |= {node.module} if node.module else {a.name for a in node.names}
    assert not {m.split(".")[0] for m in imported} & {"build", "scenes", "sources", "cache"}, imported

"""A process that ran pythonfmu FMUs in-process exits cleanly (issue 23): pythonfmu 0.7.0's binary resets a
static ``std::shared_ptr`` that C++ already destroyed (its ELF destructor runs after ``exit()``'s handlers) and
writes into freed heap, which aborts the process at exit when glibc has put that block in its unsorted bin.
The master empties the pointer from Python's ``atexit`` (:func:`cranefmu.master.fmu.release_pythonfmu_libraries`);
``benchmarks/exit_valgrind.py`` shows the invalid access under valgrind before and after."""
from __future__ import annotations

import shutil
import subprocess
import sys
import textwrap

import pytest

# Run in a child: scenes in-process, then, in an atexit handler registered before cranefmu's (so it runs
# after them), the 16 bytes of every loaded pythonfmu binary's static ``pyState`` (pointer, control block):
# what its ELF destructor will read once C++ has destroyed the object.
_CHILD = textwrap.dedent("""
    import atexit, ctypes, re, subprocess, sys

    def report():
        maps = {}
        for line in open("/proc/self/maps"):
            parts = line.split()
            if len(parts) >= 6 and parts[5].endswith(".so") and "/binaries/" in parts[5]:
                start = int(parts[0].split("-")[0], 16)
                if int(parts[2], 16) == 0:
                    maps.setdefault(parts[5], start)
        held = 0
        for path, base in maps.items():
            symbols = subprocess.run(["nm", path], capture_output=True, text=True).stdout
            found = re.search(r"^([0-9a-f]+) [bB] _ZN12_GLOBAL__N_17pyStateE$", symbols, re.M)
            if found and any(ctypes.string_at(base + int(found.group(1), 16), 16)):
                held += 1
        print(f"libraries {len(maps)} held {held}")

    atexit.register(report)
    import cranefmu
    for scene in sys.argv[1:]:
        cranefmu.simulate(scene, stop_time=0.05, fmus="python")   # the pythonfmu binaries, not the native default
""")


@pytest.mark.skipif(not sys.platform.startswith("linux") or shutil.which("nm") is None,
                    reason="reads /proc/self/maps and the binaries' symbols (Linux, binutils)")
def test_no_pythonfmu_binary_holds_its_interpreter_guard_into_the_c_exit_handlers(built, tmp_path):
    out = subprocess.run([sys.executable, "-c", _CHILD, "elastic_pendulum", "hook_sway"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0 and out.stderr == "", out.stderr
    libraries, held = map(int, out.stdout.split()[1::2])
    assert libraries >= 3          # elastic_pendulum's and hook_sway's binaries are all loaded at exit ...
    assert held == 0               # ... and none keeps a PyState for its destructor to reset after C++ freed it


def test_processes_that_run_scenes_in_process_always_exit_cleanly(built, tmp_path):
    """Repeated: the abort depended on heap layout (glibc's unsorted bin), so a few processes of each kind."""
    script = "import cranefmu, sys\nfor s in sys.argv[1:]: cranefmu.simulate(s, stop_time=0.05)\n"
    for scenes in (["elastic_pendulum"], ["elastic_pendulum", "hook_sway"], ["hook_sway", "elastic_pendulum"]) * 2:
        out = subprocess.run([sys.executable, "-c", script, *scenes], cwd=tmp_path, capture_output=True,
                             text=True, timeout=300)
        assert (out.returncode, out.stderr) == (0, ""), (scenes, out.returncode, out.stderr)

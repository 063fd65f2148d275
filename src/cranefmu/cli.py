"""The ``cranefmu`` command: a table of its sub-commands (name -> the module with their ``add_parser(sub)``
and ``main(args) -> int``), the parser built from it, and the process around the command (signals, exit
codes, one-line errors)."""
from __future__ import annotations

import argparse
import sys
from types import ModuleType

from .errors import CraneFmuError

# every subcommand, in the order of the parser's help: the module that registers (``add_parser``) and runs
# (``main``) it; only the one asked for is imported (``cranefmu run`` starts without the sweep, compose and
# study code).  A command with a package of its own has it in the package's ``command.py``.
COMMAND_MODULES = {
    "build": "cranefmu.subcommands.build",
    "run": "cranefmu.subcommands.run",
    "info": "cranefmu.subcommands.info",
    "converge": "cranefmu.subcommands.converge",
    "fit-boucwen": "cranefmu.subcommands.fit_boucwen",
    "docs": "cranefmu.subcommands.docs",
    "build-fmi3": "cranefmu.subcommands.build_fmi3",
    "scenes": "cranefmu.subcommands.scenes",
    "sweep": "cranefmu.sweep.command",
    "export": "cranefmu.subcommands.export",
    "report": "cranefmu.report.command",
    "study": "cranefmu.studies.command",
    "check": "cranefmu.experiments.command",
    "compose": "cranefmu.compose.command",
}
COMMANDS = tuple(COMMAND_MODULES)
ONE_BLAS_THREAD = ("run", "converge")   # the commands whose process pins numpy's BLAS to one thread
ENDS_AT_ONCE = ("run",)   # as the program: ends with _end_now; a stop signal ends the run at the next step


def _module(command: str) -> ModuleType:
    """The module of ``command`` (one of :data:`COMMANDS`), imported now."""
    import importlib

    return importlib.import_module(COMMAND_MODULES[command])


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The command line's parser; ``command`` (one of :data:`COMMANDS`): only that subcommand's (the others'
    modules are then not imported)."""
    from .version import __version__

    p = argparse.ArgumentParser(prog="cranefmu", description="Crane dynamics as FMI co-simulation components.")
    p.add_argument("--version", action="version", version=f"cranefmu {__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    for name in COMMANDS if command is None else (command,):
        _module(name).add_parser(sub)
    return p


STOP = ("SIGINT", "SIGTERM", "SIGHUP")   # end a run at the next step, rows kept (exit 130, 143, 129)


def _say(text: str) -> None:
    """One line on stderr; a closed terminal (SIGHUP, a broken pipe) is not an error of its own."""
    try:
        print(text, file=sys.stderr, flush=True)
    except (OSError, ValueError):
        pass


def main(argv: list[str] | None = None) -> int:
    """The command line (``argv``: its arguments, default ``sys.argv[1:]``); returns the exit code.  As the
    program (``argv`` None) a ``run`` ends the process at once after its output and exit handlers
    (:func:`_end_now`)."""
    code = _main(argv)
    if argv is None and _END_AT_ONCE:
        _end_now(code)
    return code


_END_AT_ONCE: list[bool] = []   # set for a command of ENDS_AT_ONCE: the program ends with _end_now


def _end_now(code: int) -> None:
    """End the process now with ``code``: Python's exit handlers run (temporary folders removed, pythonfmu's
    libraries released), the streams are flushed, and the interpreter's teardown, which frees every module
    one by one (about 0.03 s of CPU with numpy and fmpy loaded, a tenth of a cold native run), and the loaded
    FMU libraries' C destructors are skipped, as the worker processes (:mod:`.master.worker`) and the test
    session end."""
    import atexit
    import os

    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            pass
    os._exit(code if isinstance(code, int) else 1)


def _main(argv: list[str] | None) -> int:
    import signal

    from .master.interrupt import OUTSIDE, wanted

    # first of all, so that no signal gives a traceback; SIGHUP stays ignored under nohup
    old = {s: signal.signal(s, OUTSIDE) for s in wanted(getattr(signal, name) for name in STOP)}
    try:
        _check_working_directory()
        if (sys.argv[1:] if argv is None else argv) == ["--version"]:   # without building the whole parser
            from .version import __version__

            print(f"cranefmu {__version__}")
            return 0
        given = sys.argv[1:] if argv is None else argv
        args = build_parser(given[0] if given and given[0] in COMMANDS else None).parse_args(argv)
        command = _module(args.command)
        if args.command in ONE_BLAS_THREAD:
            _one_blas_thread()
        if args.command in ENDS_AT_ONCE:
            from .master.interrupt import stop_on

            _END_AT_ONCE.append(True)

            stop_on(*old)   # during the run: stop between steps, keep the rows
        else:   # the other commands: Ctrl-C as Python has it; SIGTERM and SIGHUP raise as Ctrl-C does (the
            # commands' cleanup runs: no temporary folders left), reported in one line, exit 128 + signal
            from .master.interrupt import raise_first, stop_on

            stop_on(*old)   # a run in this process (check inline, a study) stops between steps, never inside an FMU
            for signum, handler in old.items():
                signal.signal(signum, handler if signum == signal.SIGINT else raise_first)
        return command.main(args)
    except CraneFmuError as err:
        _say(f"cranefmu: error: {err}")
        return 2
    except KeyboardInterrupt as err:
        _say(f"cranefmu: {str(err) or 'interrupted'}")
        return getattr(err, "exit_code", 130)
    except BrokenPipeError:   # the reader went away (`cranefmu scenes | head -1`): no message, as `ls | head`
        return 141            # 128 + SIGPIPE: what a shell reports for a writer whose pipe closed
    except OSError as err:   # a file system refusal no check foresaw: one line naming the file
        where = f" ({err.filename})" if err.filename else _full_temporary_folder(err)
        _say(f"cranefmu: error: {err.strerror or err}{where}")
        return 2
    finally:
        _quiet_streams()
        for signum, handler in old.items():   # as the program: it ends now, a late signal must not replace
            signal.signal(signum, signal.SIG_IGN if argv is None else handler)   # its exit code


def _one_blas_thread() -> None:
    """Pin this process's BLAS and OpenMP pools (numpy's) to one thread: the master's arrays are small, and
    a pythonfmu FMU run here pins the libraries it loads itself (``fmi_adapter.one_blas_thread``).  Nothing
    without threadpoolctl."""
    try:
        import numpy  # noqa: F401 - its BLAS must be loaded to be pinned
        from threadpoolctl import threadpool_limits
    except ImportError:
        return
    threadpool_limits(1)


def _full_temporary_folder(err: OSError) -> str:
    """For a full disk with no file named (a temporary file written through a library): the temporary
    folder, if that is where the room ran out ('' otherwise)."""
    import errno
    import os
    import tempfile

    if err.errno not in (errno.ENOSPC, errno.EDQUOT):
        return ""
    folder = tempfile.gettempdir()
    try:
        st = os.statvfs(folder)
    except OSError:
        return ""
    free = st.f_bavail * st.f_frsize
    if free > 256 << 20:   # room there: another file system filled
        return ""
    return (f" in the temporary folder {folder} ({free // 1024} KiB free): free space there, or set TMPDIR to a "
            "folder with room")


def _check_working_directory() -> None:
    import os

    try:
        os.getcwd()
    except FileNotFoundError:
        raise CraneFmuError("the working directory does not exist any more (deleted or moved away): "
                            "cd to an existing directory and run again") from None


def _quiet_streams() -> None:
    """Flush stdout now; if it is gone (a closed terminal, ``| head``), stop Python from reporting it at exit."""
    import os

    try:
        sys.stdout.flush()
    except (OSError, ValueError):
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):
            pass


if __name__ == "__main__":
    sys.exit(main())

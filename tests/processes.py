"""Fresh Python processes a test starts early and reads later (a helper module, not a test module).

Tests that check a property of a *fresh* process (what it loads, compiles or logs) pay a
Python start and the numba start-up for each one. The tests' own process computes on one
core and only waits meanwhile, so a module starts the processes it needs at once (a fixture)
and each test reads its own; they run side by side on the other cores. Output goes to
temporary files, not pipes, so that no process blocks on a full pipe nobody reads yet.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import textwrap


class Started:
    """``python -c script *args``, started now; :meth:`result` waits for it."""

    def __init__(self, script: str, *args: str, env: dict | None = None) -> None:
        self._out = tempfile.TemporaryFile("w+")
        self._err = tempfile.TemporaryFile("w+")
        self.proc = subprocess.Popen(
            [sys.executable, "-c", textwrap.dedent(script), *args],
            stdout=self._out,
            stderr=self._err,
            text=True,
            env=env,
        )
        self._done: subprocess.CompletedProcess | None = None

    def result(self, timeout: float | None = 600.0) -> subprocess.CompletedProcess:
        """The finished process, its stdout and stderr (as ``subprocess.run`` returns them)."""
        if self._done is None:
            self.proc.wait(timeout)
            text = []
            for f in (self._out, self._err):
                f.seek(0)
                text.append(f.read())
                f.close()
            self._done = subprocess.CompletedProcess(self.proc.args, self.proc.returncode, *text)
        return self._done

    def stop(self) -> None:
        """Kill the process if it still runs (a failed or interrupted session)."""
        if self.proc.poll() is None:
            self.proc.kill()
        self.result()


def selected_params(request, test_name: str, param: str) -> list:
    """The values of ``param`` of the selected tests ``test_name`` in the requesting module."""
    return [
        i.callspec.params[param]
        for i in request.session.items
        if getattr(i, "originalname", None) == test_name
        and getattr(i, "module", None) is request.module
    ]

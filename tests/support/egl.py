"""Whether polyscope's EGL backend starts on this machine: the ``egl`` marker's skip in
``tests/conftest.py`` and the tests that check pictures the viewer drew ask it."""

from __future__ import annotations

import functools
import subprocess
import sys
import tempfile

EGL_SKIP = "polyscope's EGL backend cannot start on this machine (no EGL/Mesa)"


@functools.cache
def egl_available() -> bool:
    """Whether polyscope's ``openGL3_egl`` backend starts here (probed once, in a subprocess:
    a failing backend can abort the interpreter)."""
    code = "import polyscope as ps; ps.set_allow_headless_backends(True); ps.init('openGL3_egl')"
    try:
        with tempfile.TemporaryDirectory() as tmp:  # polyscope writes .ini files into the cwd
            res = subprocess.run(
                [sys.executable, "-c", code], capture_output=True, timeout=120, cwd=tmp
            )
    except subprocess.TimeoutExpired:
        return False
    return res.returncode == 0

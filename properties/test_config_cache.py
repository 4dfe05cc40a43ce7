"""The engine's compiled-kernel cache: keyed by the engine's sources, without touching numba's global settings.

- ``import engine`` leaves ``numba.config.CACHE_DIR`` as the user had it (a user's own ``@njit(cache=True)``
  functions keep their cache folder), while the engine's kernels are cached under ``engine._config.CACHE_DIR``;
- the first real compilation in a process says so once on stderr; a process that finds every kernel in the
  cache prints nothing.
Each check runs in a fresh interpreter (this one has imported the engine already).
"""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap


def python(code: str, folder, **env) -> subprocess.CompletedProcess:
    """Run ``code`` as a script file in ``folder`` (numba caches only functions defined in a file)."""
    script = folder / "script.py"
    script.write_text(textwrap.dedent(code))
    return subprocess.run([sys.executable, str(script)], capture_output=True, text=True, cwd=os.getcwd(),
                          env={**os.environ, "PYTHONPATH": os.getcwd(), **env}, timeout=600)


def test_import_leaves_numba_cache_dir_alone(tmp_path):
    done = python("""
        import numba
        before = numba.config.CACHE_DIR
        import engine
        from engine._config import CACHE_DIR
        from engine.bounding.sphere import spheres_touch
        assert numba.config.CACHE_DIR == before, (before, numba.config.CACHE_DIR)
        @numba.njit(cache=True)
        def user(x):
            return x + 1
        print(before, CACHE_DIR, spheres_touch._cache._cache_path, user._cache._cache_path, sep="\\n")
    """, tmp_path, NUMBA_CACHE_DIR=str(tmp_path / "user"))
    assert done.returncode == 0, done.stderr
    before, engine_dir, kernel_path, user_path = done.stdout.split()
    assert before == str(tmp_path / "user")
    assert engine_dir.startswith(before + os.sep) and kernel_path.startswith(engine_dir)
    assert not user_path.startswith(engine_dir)


def test_compile_notice_once_then_silent_when_cached(tmp_path):
    code = """
        import engine
        engine.sweep_intervals([3.0, 7.7, 1.0], [7.0, 18.0, 8.0])
        engine.sweep_intervals([3.0, 7.7], [7.0, 18.0])
    """
    cold = python(code, tmp_path, NUMBA_CACHE_DIR=str(tmp_path), COLLDET_COMPILE_NOTICE="1")
    assert cold.returncode == 0, cold.stderr
    assert cold.stderr.count("colldet: compiling the engine's kernels") == 1
    warm = python(code, tmp_path, NUMBA_CACHE_DIR=str(tmp_path), COLLDET_COMPILE_NOTICE="1")
    assert warm.returncode == 0 and warm.stderr == ""
    quiet = python(code, tmp_path, NUMBA_CACHE_DIR=str(tmp_path / "other"), COLLDET_COMPILE_NOTICE="0")
    assert quiet.returncode == 0 and quiet.stderr == ""

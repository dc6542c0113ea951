"""Compiled copies of CasADi functions: a hot path's SX function as machine code, built in the background.

CasADi evaluates an SX function by interpreting its instructions, about 17 machine instructions per
operation. For a function evaluated at every step of a long closed loop (the acceptance checks of the
warm SQP step, :mod:`orrc.solvers.warm_sqp`: about 1500 operations, 4.5 µs interpreted, 1.4 µs
compiled on this project's machine), orrc compiles a copy: CasADi's code generator writes the C code,
the system's C compiler builds a shared library (:data:`FLAGS`), and ``casadi.external`` loads it.

* **The same numbers.** The C code performs the interpreter's floating-point operations in the same
  order, compiled without contraction into fused multiply-adds (``-ffp-contract=off``) or other
  value-changing optimisations, so every output has the interpreted value (tests/test_jit.py checks
  it on random, infinite and NaN inputs; only the sign bit of a NaN may differ).
* **In the background, and only when it pays.** Compiling takes about 0.4 s of the compiler's CPU time
  (a child process: not the caller's ``process_time``) and saves about 3 µs per step, so a caller
  starts it (:class:`Compiled`) only after :data:`COMPILE_AFTER` evaluations, and keeps the interpreted
  function until :meth:`Compiled.function` has the compiled one. The compiler runs in a thread that
  waits on a child process, so the caller's loop goes on meanwhile.
* **Once per machine.** The library is cached in :func:`cache_dir`, named by a hash of the C code,
  the flags, the compiler and CasADi's version: another process, or another controller with the same
  problem, loads it in under a millisecond.
* **Optional.** Without a C compiler (``$CC``, else ``cc``), with ``ORRC_JIT=0``, in a process forked
  while a build ran, or when a build fails (:attr:`Compiled.error` says why), the interpreted
  function is used: the same results, without the speed.
"""
from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import casadi as ca

#: the compiler's flags: optimised, position-independent, and no value-changing optimisation
FLAGS = ("-O1", "-fPIC", "-shared", "-ffp-contract=off", "-fno-fast-math")
#: evaluations (steps of closed loops) of a function before a caller compiles it; ``ORRC_JIT_AFTER``
#: sets another number (0: at once)
COMPILE_AFTER = int(os.environ.get("ORRC_JIT_AFTER", "1000"))
#: seconds a build may take before it is abandoned (the interpreted function stays)
BUILD_SECONDS = 120.0
#: the longest C code compiled (characters): the compiler's time grows with it (the pendulum's NLP at
#: M = 20, 90 000 characters, takes about 0.9 s), and past this it would rarely be paid back
CODE_LIMIT = 2_000_000


def cache_dir() -> Path:
    """Where compiled libraries are kept: ``$ORRC_CACHE_DIR``, else ``$XDG_CACHE_HOME/orrc/jit``, else
    ``~/.cache/orrc/jit``."""
    given = os.environ.get("ORRC_CACHE_DIR")
    if given:
        return Path(given)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "orrc" / "jit"


def compiler() -> str | None:
    """The C compiler's path (``$CC``, else ``cc``), or None: none found, or ``ORRC_JIT=0``."""
    if os.environ.get("ORRC_JIT", "1") == "0" or sys.platform == "win32":
        return None
    return shutil.which(os.environ.get("CC") or "cc")


class Compiled:
    """A compiled copy of CasADi functions: the C code ``code`` built into a shared library, loaded at once
    from the cache, else built in a background thread, and made a ``casadi.Function`` by ``load(path)``.
    :meth:`function` is that function once it is ready, else None (not ready yet, or not available:
    :attr:`error`). :func:`compiled_function` and :func:`compiled_nlpsol` make one."""

    def __init__(self, name: str, code: str | None, load, error: str | None = None, counter: str | None = None):
        self.name, self.error, self._load, self._counter, self.from_cache = name, None, load, counter, False
        self._fn, self._lib, self._thread, self._pid, self.path = None, None, None, os.getpid(), None
        cc = compiler()
        if cc is None or code is None:
            self.error = error or "no C compiler (ORRC_JIT=0, or no cc and no $CC)"
            return
        if len(code) > CODE_LIMIT:
            self.error = f"{len(code)} characters of C code, more than CODE_LIMIT = {CODE_LIMIT}"
            return
        key = hashlib.sha256("\0".join([code, *FLAGS, cc, ca.__version__, sys.platform]).encode()).hexdigest()
        self.path = cache_dir() / f"{name}-{key[:24]}.so"
        #: the library was in the cache already (else it is built here)
        self.from_cache = self.path.exists()
        if not self.from_cache:
            self._thread = threading.Thread(target=self._build, args=(cc, code), name=f"orrc-jit-{name}", daemon=True)
            self._thread.start()

    def _build(self, cc: str, code: str) -> None:
        """Compile ``code`` into :attr:`path` (written under a temporary name, then renamed: another process
        building the same library at the same time is harmless)."""
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            _remove_stale_builds(self.path.parent)
            with tempfile.TemporaryDirectory(dir=self.path.parent, prefix=_BUILD_PREFIX) as tmp:
                src, lib = Path(tmp) / f"{self.name}.c", Path(tmp) / f"{self.name}.so"
                src.write_text(code)
                out = subprocess.run([cc, *FLAGS, str(src), "-o", str(lib), "-lm"], capture_output=True, text=True,
                                     timeout=BUILD_SECONDS)
                if out.returncode != 0:
                    self.error = f"{cc} failed ({out.returncode}): {out.stderr.strip()[-500:]}"
                    return
                os.replace(lib, self.path)
        except (OSError, subprocess.SubprocessError) as exc:
            self.error = f"the build failed: {exc}"

    @property
    def building(self) -> bool:
        """The build is still running (in this process)."""
        return self._thread is not None and self._thread.is_alive() and os.getpid() == self._pid

    def function(self) -> ca.Function | None:
        """The compiled function, or None (still building, or not available: :attr:`error`)."""
        if self._fn is None and self.error is None and not self.building and self.path is not None:
            if not self.path.exists():   # a build of another process (a fork) that never finished here
                self.error = "the build did not finish in this process"
                return None
            try:
                self._fn = self._load(str(self.path))
                # the same library, opened again to read its counter (the loader hands back the same copy)
                self._lib = ctypes.CDLL(str(self.path)) if self._counter else None
            except (RuntimeError, OSError) as exc:
                self._fn, self.error = None, f"the library did not load: {exc}"
        return self._fn

    def counter(self) -> ctypes.c_longlong | None:
        """The calling thread's count of evaluations of the counted function (:func:`compiled_nlpsol`), or
        None (no counter, or not loaded)."""
        if self._lib is None:
            return None
        return ctypes.c_longlong.in_dll(self._lib, self._counter)

    def wait(self, timeout: float = BUILD_SECONDS) -> ca.Function | None:
        """:meth:`function`, after waiting up to ``timeout`` seconds for the build."""
        if self._thread is not None and os.getpid() == self._pid:
            self._thread.join(timeout)
        return self.function()


#: the folders of builds under way in the cache (a build's own, removed when it ends)
_BUILD_PREFIX = "building-"


def _remove_stale_builds(folder: Path) -> None:
    """Remove the folders of builds that can no longer be running (older than twice :data:`BUILD_SECONDS`:
    left by a process that ended while its compiler ran)."""
    now = time.time()
    for stale in folder.glob(_BUILD_PREFIX + "*"):
        try:
            if now - stale.stat().st_mtime > 2 * BUILD_SECONDS:
                shutil.rmtree(stale, ignore_errors=True)
        except OSError:
            pass


def _c_code(name: str, functions) -> str:
    """The C code of ``functions`` in one file (CasADi's code generator, no header)."""
    gen = ca.CodeGenerator(name, {"with_header": False})
    for fn in functions:
        gen.add(fn)
    return gen.dump()


def compiled_function(fn: ca.Function) -> Compiled:
    """A compiled copy of the SX function ``fn`` (CasADi's code generator; ``casadi.external`` loads it)."""
    name = fn.name()
    if compiler() is None:
        return Compiled(name, None, None)
    return Compiled(name, _c_code(name, [fn]), lambda path: ca.external(name, path))


def compiled_nlpsol(solver: ca.Function, plugin: str, options: dict) -> Compiled:
    """A copy of the NLP solver ``solver`` (CasADi's ``plugin`` with ``options``) whose functions of the NLP
    (its oracle, the objective and constraints, and the derivatives the solver evaluates) are compiled:
    CasADi's code generator writes them as ``generate_dependencies`` does, and ``casadi.nlpsol`` builds the
    same solver on the library (the solver's own algorithm is CasADi's compiled code either way).

    The library also counts, per thread, the evaluations of the Hessian of the Lagrangian (``nlp_hess_l``,
    one per iteration of SQP with the exact Hessian): :data:`ITERATIONS` in :meth:`Compiled.counter`, read
    in 0.1 µs where CasADi's statistics take 7 µs (:mod:`orrc.solvers.warm_sqp` checks it against them)."""
    name = solver.name()
    if compiler() is None:
        return Compiled(name, None, None)
    code = _c_code(name, [solver.oracle(), *(solver.get_function(fn) for fn in solver.get_function())])
    counted = None
    if code.count(_HESSIAN) == 1:
        code = f"_Thread_local long long {ITERATIONS} = 0;\n" + code.replace(_HESSIAN, _HESSIAN + f"  {ITERATIONS}++;\n")
        counted = ITERATIONS
    return Compiled(name, code, lambda lib: ca.nlpsol(name, plugin, lib, options), counter=counted)


#: a compiled solver's iteration counter is checked against its statistics on its first solves in a thread
#: (in :mod:`orrc.solvers.warm_sqp` and :meth:`orrc.solvers.nlp.ShootingNLP.solve`) before it is trusted alone
COUNTER_CHECKS = 2
#: the counter of Hessian evaluations in a compiled NLP's library (:func:`compiled_nlpsol`)
ITERATIONS = "orrc_hess_l_calls"
#: where the generated Hessian function starts (the counter goes at the top of its body)
_HESSIAN = ("CASADI_SYMBOL_EXPORT int nlp_hess_l(const casadi_real** arg, casadi_real** res, casadi_int* iw, "
            "casadi_real* w, int mem){\n")

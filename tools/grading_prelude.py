"""The grading prelude: what every test of an assignment owns instead of taking it from the
student's notebook.

otter's exception-based tests take their arguments by name from the namespace the student's
notebook left behind, so a test that asks for ``np`` or ``orrc`` gets the student's: a notebook
that sets ``np.isclose = lambda *a, **k: True`` would pass every comparison. :func:`with_prelude`
rewrites a test cell before ``otter assign`` sees it: ``np``, ``orrc`` and ``certify`` leave the
test's parameters, and the test's body starts with :data:`PRELUDE`, which

- imports its own ``numpy`` (as ``np``), ``orrc`` and ``orrc.certify`` and refuses to grade
  when the notebook replaced a numpy function the tests use (a function whose module is not
  numpy's);
- defines ``close(a, b, rtol, atol)``, a comparison written in plain Python on the values'
  ``float`` entries (numpy's ``isclose`` defaults), which the tests use for every tolerance;
- defines ``forbidden(*targets)``, a context manager under which every Python function of the
  targets (a function, a class, or a module with its submodules) raises
  ``RuntimeError`` when called, wherever the notebook keeps a reference to it (the function's
  code is swapped, not its name): a test grades a student's function inside it, so a wrapper of
  the package function the question asks the student to write loses the points.

Examples
--------
>>> src = 'def test_q(f, np):\\n    assert close(f(1.0), 2.0)\\n'
>>> print(with_prelude(src).splitlines()[0])
def test_q(f):
"""
from __future__ import annotations

import ast
import re

#: parameters a test may not take from the student's namespace: the prelude gives them
OWNED = ("np", "orrc", "certify")

PRELUDE = '''
    import sys as _sys
    import types as _types
    import numpy as np
    import orrc
    from orrc import certify
    for _name in ("isclose", "allclose", "polyfit", "cumsum", "sum", "max", "min", "mean", "abs", "asarray", "array", "shape", "isscalar", "all", "any", "log", "sqrt", "zeros", "linalg"):
        _f = getattr(np, _name)
        _mod = getattr(_f, "__module__", None) or getattr(_f, "__name__", "")
        if not str(_mod).startswith("numpy"):
            raise AssertionError("the notebook replaced numpy." + _name + "; nothing can be graded")

    def _flat(v):
        if isinstance(v, np.ndarray):
            v = v.tolist()
        if isinstance(v, (list, tuple)):
            return [y for x in v for y in _flat(x)]
        return [float(v)]

    def close(a, b, rtol=1e-05, atol=1e-08):
        fa, fb = _flat(a), _flat(b)
        if len(fa) != len(fb) and len(fa) != 1 and len(fb) != 1:
            return False
        n = max(len(fa), len(fb))
        fa, fb = fa * (n if len(fa) == 1 else 1), fb * (n if len(fb) == 1 else 1)
        return all(abs(x - y) <= atol + rtol * abs(y) for x, y in zip(fa, fb))

    def _functions(target):
        found = []
        if isinstance(target, _types.ModuleType):
            for mname, mod in list(_sys.modules.items()):
                if mod is not None and (mname == target.__name__ or mname.startswith(target.__name__ + ".")):
                    for value in list(vars(mod).values()):
                        if getattr(value, "__module__", None) == mname:
                            found += _functions(value)
        elif isinstance(target, type):
            for value in vars(target).values():
                value = getattr(value, "__func__", value)
                if isinstance(value, property):
                    found += [f for f in (value.fget, value.fset) if f is not None]
                elif isinstance(value, _types.FunctionType):
                    found.append(value)
        elif isinstance(target, _types.FunctionType):
            found.append(target)
            if isinstance(getattr(target, "__wrapped__", None), _types.FunctionType):
                found.append(target.__wrapped__)
        return found

    class forbidden:
        def __init__(self, *targets):
            self.functions = list({id(f): f for t in targets for f in _functions(t)}.values())
            self.saved = []

        def __enter__(self):
            def _stub(*args, **kwargs):
                raise RuntimeError("a package function this question asks you to write yourself was called")
            for f in self.functions:
                if not f.__closure__:
                    self.saved.append((f, f.__code__))
                    f.__code__ = _stub.__code__
            return self

        def __exit__(self, *exc):
            for f, code in self.saved:
                f.__code__ = code
            return False
'''


def with_prelude(source: str) -> str:
    """A test cell's source with the prelude at the top of its test function's body and the
    owned names (:data:`OWNED`) removed from its parameters."""
    tree = ast.parse(source)
    fn = next(n for n in tree.body if isinstance(n, ast.FunctionDef))
    lines = source.split("\n")
    start, end = fn.lineno - 1, fn.body[0].lineno - 1   # the def line(s), then the first statement
    header = "\n".join(lines[start:end])
    params = [a.arg for a in fn.args.args if a.arg not in OWNED]
    header = re.sub(rf"def\s+{fn.name}\s*\(.*\)\s*:", f"def {fn.name}({', '.join(params)}):", header, flags=re.S)
    return "\n".join(lines[:start] + [header, PRELUDE.strip("\n")] + lines[end:])

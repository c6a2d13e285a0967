# SPDX-License-Identifier: MIT
"""Stated bounds for the guard tests (accuracy_guard, track_guard, installed_flight): one line per figure, and the
process exits non-zero naming every figure outside its bound."""
import sys


def check(prefix, checks):
    """checks: (figure, measured value, bound, True when the value must be at least the bound, False: at most).
    Prints '<prefix>: <figure>: <value> (>= or <= <bound>) ok|FAIL' per check; exits 1 naming the failures."""
    failed = []
    for name, value, bound, at_least in checks:
        ok = value >= bound if at_least else value <= bound
        shown = f"{value:.3f}" if isinstance(value, float) else f"{value}"
        print(f"{prefix}: {name}: {shown} ({'>=' if at_least else '<='} {bound}) {'ok' if ok else 'FAIL'}")
        if not ok:
            failed.append(name)
    if failed:
        sys.exit(f"{prefix}: FAIL: outside the bound: " + "; ".join(failed))

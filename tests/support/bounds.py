# SPDX-License-Identifier: MIT
"""Stated bounds for the guard tests (accuracy_guard, track_guard, installed_flight, installed_supervisord): one line
per figure, and the process exits non-zero naming every figure outside its bound."""
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


def installed_flight_checks(e):
    """The installed stack's flight bounds (installed_flight and installed_supervisord) over `wingman eval`'s JSON `e`:
    localization RMS <= 0.45 m, formation RMS <= 0.60 m, estimates in >= 90 % of the frames with the leader visible,
    one track id on the leader, no false target."""
    visible = e["frames_leader_visible"]
    return [
        ("localization RMS (m)", e["localization"]["rms_m"], 0.45, False),
        ("formation RMS, horizontal (m)", e["formation_horizontal"]["rms_m"], 0.60, False),
        ("target estimates / frames with the leader visible", e["target_estimates"] / max(1, visible), 0.90, True),
        ("track ids on the leader", e["track_ids_on_leader"], 1, False),
        ("track ids on the leader (at least)", e["track_ids_on_leader"], 1, True),
        ("false targets", e["false_targets"], 0, False),
    ]

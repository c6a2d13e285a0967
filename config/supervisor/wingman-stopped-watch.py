#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# supervisord event listener of config/supervisor/wingman.conf: restarts a Wingman process that is stopped.
#
# supervisord reaps exits only (waitpid without WUNTRACED): a process stopped by SIGSTOP (or SIGTSTP, SIGTTIN,
# SIGTTOU) stays RUNNING in its eyes forever, and the process's own --watchdog thread is stopped with it. This
# listener looks at supervisord's children in /proc every POLL_S (0.5 s, on a thread of its own: supervisord's
# shortest event, TICK_5, would leave a stopped process 5 to 10 s) and sends SIGKILL to a wingman-* process it has
# seen stopped (state T) for STOPPED_LIMIT_S (1.5 s) or more; autorestart then starts it again like after any crash.
# A process stopped by a debugger (state t, tracing stop) is left alone. The main thread answers supervisord's
# events (TICK_5, the listener protocol). Standard library only (Debian's supervisor brings python3). One line on
# stderr per kill.
import os
import signal
import sys
import threading
import time

PREFIX = "wingman-"
POLL_S = 0.5  # how often supervisord's children are looked at
STOPPED_LIMIT_S = 1.5  # a process seen stopped for this long (monotonic clock) is killed


def stopped_children(parent):
    """{pid: program} of parent's wingman-* children in state T (stopped)."""
    found = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as f:
                stat = f.read().decode("utf-8", "replace")
            with open(f"/proc/{entry}/cmdline", "rb") as f:
                argv0 = f.read().split(b"\0", 1)[0].decode("utf-8", "replace")
        except OSError:
            continue  # gone meanwhile
        # "pid (comm) state ppid ...": comm may hold spaces and parentheses, so the fields start after the last ')'.
        fields = stat[stat.rfind(")") + 2:].split()
        if len(fields) < 2 or fields[0] != "T" or int(fields[1]) != parent:
            continue
        name = os.path.basename(argv0)
        if name.startswith(PREFIX) and not name.startswith("wingman-stopped-watch"):
            found[int(entry)] = name
    return found


def watch(parent):
    """Polls for stopped children and kills those stopped for STOPPED_LIMIT_S; runs until the process exits."""
    first_seen = {}  # pid: monotonic time it was first seen stopped
    while True:
        now = time.monotonic()
        stopped = stopped_children(parent)
        first_seen = {pid: first_seen.get(pid, now) for pid in stopped}
        for pid, since in list(first_seen.items()):
            if now - since >= STOPPED_LIMIT_S:
                sys.stderr.write(f"wingman-stopped-watch: {stopped[pid]} (pid {pid}) is stopped (SIGSTOP) and cannot "
                                 f"run its watchdog: SIGKILL, supervisord restarts it\n")
                sys.stderr.flush()
                try:
                    os.kill(pid, signal.SIGKILL)
                except OSError as e:
                    sys.stderr.write(f"wingman-stopped-watch: kill {pid}: {e}\n")
                del first_seen[pid]
        time.sleep(POLL_S)


def main():
    parent = os.getppid()
    threading.Thread(target=watch, args=(parent,), daemon=True).start()
    while True:
        sys.stdout.write("READY\n")
        sys.stdout.flush()
        line = sys.stdin.readline()
        if not line:
            return  # supervisord has gone
        header = dict(token.split(":", 1) for token in line.split())
        sys.stdin.read(int(header.get("len", "0")))  # the event's payload (unused)
        sys.stdout.write("RESULT 2\nOK")
        sys.stdout.flush()


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# supervisord event listener of config/supervisor/wingman.conf: restarts a Wingman process that is stopped.
#
# supervisord reaps exits only (waitpid without WUNTRACED): a process stopped by SIGSTOP (or SIGTSTP, SIGTTIN,
# SIGTTOU) stays RUNNING in its eyes forever, and the process's own --watchdog thread is stopped with it. This
# listener wakes on supervisord's TICK_5 event, looks at supervisord's children in /proc, and sends SIGKILL to a
# wingman-* process it finds stopped (state T) at two ticks in a row, i.e. stopped for 5 to 10 s; autorestart then
# starts it again like after any crash. A process stopped by a debugger (state t, tracing stop) is left alone.
# Standard library only (Debian's supervisor brings python3). One line on stderr per kill.
import os
import signal
import sys

PREFIX = "wingman-"
STRIKES = 2  # ticks in a row a process must be seen stopped before it is killed


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


def main():
    parent = os.getppid()
    strikes = {}
    while True:
        sys.stdout.write("READY\n")
        sys.stdout.flush()
        line = sys.stdin.readline()
        if not line:
            return  # supervisord has gone
        header = dict(token.split(":", 1) for token in line.split())
        sys.stdin.read(int(header.get("len", "0")))  # the event's payload (unused)
        stopped = stopped_children(parent)
        strikes = {pid: strikes.get(pid, 0) + 1 for pid in stopped}
        for pid, count in list(strikes.items()):
            if count >= STRIKES:
                sys.stderr.write(f"wingman-stopped-watch: {stopped[pid]} (pid {pid}) is stopped (SIGSTOP) and cannot "
                                 f"run its watchdog: SIGKILL, supervisord restarts it\n")
                sys.stderr.flush()
                try:
                    os.kill(pid, signal.SIGKILL)
                except OSError as e:
                    sys.stderr.write(f"wingman-stopped-watch: kill {pid}: {e}\n")
                del strikes[pid]
        sys.stdout.write("RESULT 2\nOK")
        sys.stdout.flush()


if __name__ == "__main__":
    main()

"""Warming numba's kernel cache from a terminal (``./dev`` runs ``python -m app.ui.warm_cache
--if-needed`` after installing), so the studio's first start loads its kernels instead of
compiling them: the warm-up's lanes (:data:`app.ui.kernel_warmup.LANES`) run side by side as
child processes and one line shows their progress. No Qt here.
"""

from __future__ import annotations

import subprocess
import sys
import threading
import time

from app.ui import kernel_warmup


def _line(done: int, total: int, label: str, started: float) -> str:
    bar = "#" * done + "." * (total - done)
    took = time.time() - started
    return f"Compiling the studio's kernels (once) [{bar}] {done}/{total} {label}, {took:.0f} s"


def lane_command(lane: int) -> list[str]:
    """The command line of warm-up lane ``lane`` (1-based)."""
    return [sys.executable, "-m", "app.ui.kernel_warmup", "--lane", str(lane), "--no-quick"]


def warm(if_needed: bool = False, out=None) -> int:
    """Run every lane; print progress on ``out`` (standard output). ``if_needed``: nothing when
    the kernels are cached already. 0 when every lane finished, else the first failure's code."""
    out = sys.stdout if out is None else out
    if if_needed and kernel_warmup.kernels_cached():
        return 0
    started = time.time()
    total = len(kernel_warmup.lane_labels(None, quick=False))  # the serial twins are not needed
    done: list[str] = []
    lock = threading.Lock()
    tty = out.isatty()
    lanes = range(1, len(kernel_warmup.LANES) + 1)
    procs = [subprocess.Popen(lane_command(k), stdout=subprocess.PIPE, text=True) for k in lanes]

    def follow(proc: subprocess.Popen) -> None:
        for raw in proc.stdout:
            parts = raw.split(maxsplit=3)
            if len(parts) == 4 and parts[0] == "step":
                with lock:
                    done.append(parts[3].strip())
                    line = _line(len(done), total, done[-1], started)
                    print(f"\r{line}\033[K" if tty else line, end="" if tty else "\n", file=out, flush=True)

    readers = [threading.Thread(target=follow, args=(p,), daemon=True) for p in procs]
    for r in readers:
        r.start()
    try:
        codes = [p.wait() for p in procs]
    except KeyboardInterrupt:  # Ctrl+C reaches the children too; what they compiled stays cached
        for p in procs:
            p.wait()
        print(file=out)
        return 130
    for r in readers:
        r.join(timeout=5)
    if tty:
        print(file=out)
    failed = [c for c in codes if c != 0]
    if failed:
        print("The studio's kernels were not all compiled: the studio compiles the rest at its first start",
              file=out, flush=True)  # fmt: skip
        return failed[0]
    print(f"The studio's kernels are cached ({time.time() - started:.0f} s)", file=out, flush=True)
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    return warm(if_needed="--if-needed" in argv)


if __name__ == "__main__":
    sys.exit(main())

"""The command lines whose runs compile every numba kernel the ``hairtool`` commands use.

A command's first run on an empty kernel cache spends nearly all its time compiling: a cold
``hairtool freeze`` of Sintel's guides took 38.8 s, 38.3 s of it in numba's compiler, against
1.9 s warm (2-core VM, loaded). numba compiles a kernel for the argument types it is called
with, and which kernels a command calls depends on its options and its input's size (a dense or
hashed grid, children on a scalp or around the roots). So the surest list of what to compile is
a run of each command, on inputs like a user's: :data:`RECIPES` are those runs, on a seeded
scalp sample (a ``.hair`` file, as a user's grooms are files) and a hemisphere scalp mesh,
and ``freeze`` once more on a sample large enough for its parallel kernels
(:func:`hairtool.serial_twins.for_size`: a smaller groom runs their serial twins).

``hairtool cache warm`` runs them (a farm image's build step, a Dask worker's start), and
``hairtool bench cold`` times each one on an empty cache and again on the one it filled. Each run
is a child process ``python -m hairtool ARGS``: the cache a run fills is what a later command
loads, and one failing command leaves the others to warm.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

#: Strands × vertices of the warm-up groom: the bundled Sintel guides' order of size, and the
#: children's count of a typical ``--count`` (both pick the grids a user's grooms pick).
STRANDS, VERTICES, CHILDREN = 2000, 24, 3000
#: Strands of the large warm-up groom (× VERTICES: 1,008,000 vertices), past
#: :data:`hairtool.serial_twins.PARALLEL_FROM_VERTICES`: ``freeze`` runs the serial twins on the
#: small one and the parallel kernels on this one, and a warm-up compiles both.
LARGE_STRANDS = 42_000

_SCALP = ("--count", str(CHILDREN), "--scalp", "{d}/head.obj")
#: (label, arguments): each a ``hairtool`` command line, in the order they run. ``{d}`` is the
#: folder of the inputs and outputs; a later line may read an earlier one's output.
RECIPES: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("sample", ("sample", "scalp", "{d}/groom.hair", "--strands", str(STRANDS), "--vertices", str(VERTICES))),
    ("freeze", ("freeze", "{d}/groom.hair", "{d}/frozen.hair")),
    ("freeze --keep-lengths", ("freeze", "{d}/groom.hair", "{d}/kept.hair", "--keep-lengths")),
    ("freeze --count --scalp", ("freeze", "{d}/groom.hair", "{d}/frozen-children.hair", *_SCALP)),
    (
        "sample large",
        ("sample", "scalp", "{d}/large.hair", "--strands", str(LARGE_STRANDS), "--vertices", str(VERTICES)),
    ),
    ("freeze large", ("freeze", "{d}/large.hair", "{d}/large-frozen.hair", "--keep-lengths")),
    ("interpolate", ("interpolate", "{d}/groom.hair", "{d}/children.hair", "--count", str(CHILDREN))),
    ("interpolate --scalp", ("interpolate", "{d}/groom.hair", "{d}/scalp-children.hair", *_SCALP)),
    ("simulate", ("simulate", "{d}/groom.hair", "{d}/simulated.npz", "--frames", "12")),
    ("anime", ("anime", "{d}/groom.hair", "{d}/anime.npz", "--frames", "12")),
    ("keys", ("keys", "{d}/simulated.npz", "--keys", "4", "--json")),
    ("convert", ("convert", "{d}/groom.hair", "{d}/groom.usda")),
)
#: Environment variable that turns a farm's worker warm-up off when ``0`` (:mod:`hairtool.farm.warm`).
WARM_WORKERS_VARIABLE = "HAIRTOOL_WARM_WORKERS"
#: Rings × segments of the hemisphere scalp mesh written beside the groom.
SCALP_RINGS, SCALP_SEGMENTS = 12, 32


def labels() -> list[str]:
    return [label for label, _ in RECIPES]


def argv(label: str, folder: Path) -> list[str]:
    """The arguments of recipe ``label`` with its files in ``folder``."""
    args = dict(RECIPES)[label]
    return [a.replace("{d}", str(folder)) for a in args]


def write_scalp(path: Path) -> None:
    """A hemisphere of the sample scalp's radius (y up, rings from the crown down to y = 0) as
    an OBJ file: the head the sample groom's roots stand on."""
    import math

    from hairtool.samples import HEAD_RADIUS

    lines = [f"v 0 {HEAD_RADIUS:.9g} 0"]
    for i in range(1, SCALP_RINGS + 1):
        polar = 0.5 * math.pi * i / SCALP_RINGS
        y, r = HEAD_RADIUS * math.cos(polar), HEAD_RADIUS * math.sin(polar)
        for j in range(SCALP_SEGMENTS):
            a = 2.0 * math.pi * j / SCALP_SEGMENTS
            lines.append(f"v {r * math.cos(a):.9g} {y:.9g} {r * math.sin(a):.9g}")

    def vid(i: int, j: int) -> int:  # 1-based OBJ index of ring i (0 = crown), segment j
        return 1 if i == 0 else 2 + (i - 1) * SCALP_SEGMENTS + j % SCALP_SEGMENTS

    for j in range(SCALP_SEGMENTS):
        lines.append(f"f {vid(0, 0)} {vid(1, j + 1)} {vid(1, j)}")
    for i in range(1, SCALP_RINGS):
        for j in range(SCALP_SEGMENTS):
            lines.append(f"f {vid(i, j)} {vid(i, j + 1)} {vid(i + 1, j + 1)} {vid(i + 1, j)}")
    path.write_text("\n".join(lines) + "\n")


def child_env(cache_dir: str | os.PathLike[str] | None = None) -> dict[str, str]:
    """This process's environment for a child run, with ``NUMBA_CACHE_DIR`` set to ``cache_dir``
    when given, and this process's ``hairtool`` first on the path (the code that is warmed)."""
    env = dict(os.environ)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = str(cache_dir)
    here = str(Path(__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(p for p in (here, env.get("PYTHONPATH")) if p)
    return env


def run_child(args: list[str], env: dict[str, str], module: str = "hairtool") -> tuple[int, float, str]:
    """``(exit status, wall seconds, last stderr line)`` of ``python -m MODULE ARGS``."""
    t0 = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-m", module, *args],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    seconds = time.perf_counter() - t0
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    return proc.returncode, seconds, lines[-1] if lines else ""


def prepare(folder: Path) -> None:
    """The files the recipes read that no recipe writes (the scalp mesh)."""
    write_scalp(folder / "head.obj")


#: Recipes whose output a later recipe reads: what each needs run before it (besides
#: ``sample``, whose groom most read: :func:`with_inputs`).
NEEDS = {"keys": ("simulate",), "freeze large": ("sample large",)}


def for_commands(commands: list[str] | tuple[str, ...] | None) -> list[str]:
    """The recipe labels that warm ``commands`` (command names; None: all), with what they read."""
    if commands is None:
        return labels()
    return with_inputs(["sample", *(label for label, args in RECIPES if args[0] in commands)])


def with_inputs(chosen: list[str]) -> list[str]:
    """The recipe labels ``chosen`` with the ones that write what they read, in recipe order."""
    wanted = set(chosen)
    for label in chosen:
        wanted.update(NEEDS.get(label, ()))
    recipes = dict(RECIPES)
    if any(label != "sample" and "{d}/groom.hair" in recipes[label] for label in wanted):
        wanted.add("sample")
    return [label for label in labels() if label in wanted]


def warm(
    folder: Path,
    cache_dir: str | os.PathLike[str] | None = None,
    report: Callable[[str, int, float, str], None] | None = None,
    chosen: list[str] | None = None,
) -> list[str]:
    """Run the recipes ``chosen`` (labels, default all) in ``folder`` (``cache_dir``: the kernel
    cache to fill, default numba's own choice); ``report(label, status, seconds, message)``
    after each. The labels that failed."""
    prepare(folder)
    env = child_env(cache_dir)
    failed = []
    for label in labels() if chosen is None else chosen:
        rc, seconds, message = run_child(argv(label, folder), env)
        if report is not None:
            report(label, rc, seconds, message)
        if rc != 0:
            failed.append(label)
    return failed


def source_digest() -> str:
    """A digest of every ``hairtool`` source file and of numba's version: a warm cache built
    from other code is not warm."""
    import numba

    h = hashlib.sha256(numba.__version__.encode())
    root = Path(__file__).resolve().parent
    for path in sorted(root.rglob("*.py")):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def stamp_path() -> Path:
    """Where a finished warm-up is recorded: in ``NUMBA_CACHE_DIR`` when set, else the user's
    cache folder (the kernels themselves go where numba puts them)."""
    chosen = os.environ.get("NUMBA_CACHE_DIR")
    if chosen:
        return Path(chosen) / "hairtool-warm.txt"
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "hairtool" / "warm.txt"


def warmed() -> set[str]:
    """The recipe labels whose warm-up of this code finished into this cache."""
    try:
        digest, *done = stamp_path().read_text().splitlines()
    except (OSError, ValueError):
        return set()
    return set(done) if digest == source_digest() else set()


@contextlib.contextmanager
def _locked(path: Path):
    """An exclusive lock on ``path`` (the processes of one machine warm one after the other)."""
    import fcntl

    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)


def warm_once(
    report: Callable[[str, int, float, str], None] | None = None,
    force: bool = False,
    commands: list[str] | tuple[str, ...] | None = None,
) -> list[str] | None:
    """:func:`warm` for ``commands`` (command names, default all) unless this code's warm-up of
    them already finished into this cache (None then; ``force``: warm all the same), and record
    the recipes that ran. Processes of one machine that start together (a farm's workers) wait
    for the first one's warm-up instead of compiling the same kernels side by side, and then
    find it done."""
    import tempfile

    stamp = stamp_path()
    with _locked(stamp.with_suffix(".lock")):
        done = warmed()
        chosen = for_commands(commands)
        if not force and set(chosen) <= done:
            return None
        with tempfile.TemporaryDirectory(prefix="hairtool-warm-") as folder:
            failed = warm(Path(folder), report=report, chosen=chosen)
        done |= set(chosen) - set(failed)
        tmp = stamp.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text("\n".join([source_digest(), *sorted(done)]) + "\n")  # a label a line
        os.replace(tmp, stamp)
        return failed

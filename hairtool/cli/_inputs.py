"""Argument parsing shared by the subcommands (not a subcommand itself: the leading underscore
keeps :func:`hairtool.cli.command_names` from listing it).

:func:`parse_vector` (``"x,y,z"`` → three floats) raises a
:class:`~hairtool.errors.ParameterError`, which the CLI turns into exit code 2 and one line;
groom inputs are read by :func:`hairtool.io.specs.load_groom`.
"""

from __future__ import annotations

from hairtool.errors import ParameterError

#: ``help=`` text of an IN argument read by :func:`hairtool.io.specs.load_groom`.
GROOM_INPUT_HELP = "groom/animation file or sample:NAME[:S[:V]]"


def parse_vector(name: str, text: str) -> tuple[float, float, float]:
    """``"x,y,z"`` → ``(x, y, z)``; anything else is a :class:`ParameterError` naming ``name``."""
    try:
        v = tuple(float(c) for c in text.split(","))
    except ValueError:
        v = ()
    if len(v) != 3:
        raise ParameterError(name, text, "three numbers x,y,z")
    return v  # type: ignore[return-value]


def read_frames(spec: str, frame: int | None):
    """IN for a command that carries an animation: a groom, an animation (a file with time
    samples), or with ``frame`` (``--frame F``, 0 = the first) that frame's pose as a static
    groom without the animation's time range. A frame outside the input is refused naming
    ``--frame``."""
    from hairtool.groom import Animation
    from hairtool.io.specs import SAMPLE_PREFIX, load_groom

    if spec.startswith(SAMPLE_PREFIX):
        obj = load_groom(spec)
    else:
        from hairtool import io

        obj = io.read(spec)
    frames = obj.n_frames if isinstance(obj, Animation) else 1
    if frame is None:
        return obj
    if not 0 <= frame < frames:
        raise ParameterError("frame", frame, f"a frame of {spec} in [0, {frames - 1}]")
    if not isinstance(obj, Animation):
        return obj
    pose = obj.frame(frame)
    return pose.with_metadata(pose.metadata.derived())

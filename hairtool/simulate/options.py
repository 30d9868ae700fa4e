"""The options of one simulation as a value (what the studio's Simulate dialog edits and the
project file stores), and the cancellable run that a background job or a script calls."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from hairtool.errors import Cancelled, ParameterError
from hairtool.groom import Animation, Groom
from hairtool.simulate.dynamics import GRAVITY, scaled_accelerations, simulate
from hairtool.simulate.head_motion import fit_head, parse_motion

GRAVITY_UNIT = "m/s²"


@dataclass(frozen=True)
class SimulateOptions:
    """The dialog's values; field names follow :func:`hairtool.simulate.dynamics.simulate`."""

    motion: str = "turn"
    frames: int = 72
    fps: float = 24.0
    substeps: int = 8
    gravity: float = GRAVITY  # m/s² along the stage's −up
    damping: float = 2.0
    stiffness: float = 0.05
    wind: tuple[float, float, float] = (0.0, 0.0, 0.0)  # constant acceleration, units/s²
    gusts: int = 0
    gust_strength: float = 300.0
    gust_duration: float = 0.25
    seed: int = 0
    collide: bool = True
    head_center: tuple[float, float, float] = (0.0, 0.0, 0.0)
    head_radius: float = 1.0

    def kwargs(self) -> dict:
        """Keyword arguments for :func:`simulate` (the wind as direction and strength)."""
        d = dataclasses.asdict(self)
        w = np.asarray(d.pop("wind"), dtype=np.float64)
        strength = float(np.linalg.norm(w))
        d["wind"] = (w, strength) if strength > 0 else None
        d["motion"] = parse_motion(self.motion)
        return d

    def to_dict(self) -> dict:
        # The unit is written so that a reader can tell these from the gravity of projects saved
        # before it was in m/s² (scene units/s², 98.1 by default), which :meth:`from_dict` converts.
        return dataclasses.asdict(self) | {"gravity_unit": GRAVITY_UNIT}

    def fitted_to(self, groom: Groom) -> SimulateOptions:
        """The head sphere fitted to ``groom``'s roots, with wind and gusts scaled by the change
        of head radius, so the hair moves alike on a head of any size (gravity is in m/s² and
        follows the groom's unit by itself).

        Parameters
        ----------
        groom : Groom
            The groom the head is fitted to.

        Returns
        -------
        SimulateOptions
            These options on that head.
        """
        centre, radius = fit_head(groom.roots)
        radius = max(round(radius, 3), 0.001)  # what the dialog's fields hold
        scale = radius / self.head_radius if self.head_radius > 0 else radius
        return dataclasses.replace(
            self,
            head_center=tuple(round(float(v), 3) for v in centre),
            head_radius=radius,
            **scaled_accelerations(scale, self.gust_strength, self.wind),
        )

    @classmethod
    def from_dict(cls, d: dict, units_per_meter: float = 1.0) -> SimulateOptions:
        """The options :meth:`to_dict` wrote. A gravity without ``gravity_unit`` is from a project
        saved when gravity was in scene units/s²: it is converted with the groom's
        ``units_per_meter``, so a reopened simulation falls as it did.

        Parameters
        ----------
        d : dict
            What :meth:`to_dict` wrote.
        units_per_meter : float, default 1.0
            The groom's scene units per metre, for an old project's gravity.

        Returns
        -------
        SimulateOptions
            The options.
        """
        d = dict(d)
        unit = d.pop("gravity_unit", None)
        if unit is None and "gravity" in d:
            d["gravity"] = float(d["gravity"]) / units_per_meter
        elif unit is not None and unit != GRAVITY_UNIT:
            raise ParameterError("simulate options gravity_unit", unit, f"{GRAVITY_UNIT!r}")
        for name in ("wind", "head_center"):
            if name in d:
                d[name] = tuple(float(v) for v in d[name])
        try:
            return cls(**d)
        except TypeError as e:
            raise ParameterError(
                "simulate options", sorted(d), f"the fields of SimulateOptions ({e})"
            ) from None


def run_simulation(
    groom: Groom, options: SimulateOptions, progress: Callable[..., None], cancelled: Callable[[], bool]
) -> Animation:
    """The job body: simulate ``groom``; raises :class:`Cancelled` soon after a cancel.

    Parameters
    ----------
    groom : Groom
        The hair at rest.
    options : SimulateOptions
        Everything :func:`~hairtool.simulate.dynamics.simulate` takes.
    progress : callable
        ``progress(share, words)`` after each frame.
    cancelled : callable
        Asked after each frame; True stops the run.

    Returns
    -------
    Animation
        The simulated frames.
    """

    def per_frame(done: int, total: int) -> None:
        if cancelled():
            raise Cancelled
        progress(done / total, f"frame {done}/{total}")

    progress(0.0, "preparing")
    return simulate(groom, progress=per_frame, **options.kwargs())

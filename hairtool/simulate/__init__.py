"""Animations to key: strand dynamics on a moving head, and a procedural sway.

Not one of the seed methods: they make the motion the keyframe methods summarise.
- :mod:`.dynamics` inextensible strands (dynamic follow-the-leader) with gravity, wind, gusts, head collision;
- :mod:`.head_motion` the head's rigid motions (turn, nod, shake, hop) and a fitted head sphere;
- :mod:`.options` one simulation's options as a value, and the cancellable run;
- :mod:`.sway` a cheap analytic sway with a flick, for tests and benchmarks.
"""

from hairtool.simulate.dynamics import GRAVITY, Gust, simulate, simulate_reference
from hairtool.simulate.head_motion import fit_head, head_motion, parse_motion
from hairtool.simulate.options import SimulateOptions, run_simulation
from hairtool.simulate.sway import sway_animation

__all__ = [
    "GRAVITY",
    "Gust",
    "SimulateOptions",
    "fit_head",
    "head_motion",
    "parse_motion",
    "run_simulation",
    "simulate",
    "simulate_reference",
    "sway_animation",
]

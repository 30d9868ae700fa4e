"""Studio actions past the first screen load every kernel they use from the warm-up's cache
(``./dev`` runs the warm-up; :mod:`app.ui.action_warmup` holds these actions' steps): after the
warm-up's steps, in one fresh process, each action below, run through the code the studio runs
for it, adds no kernel signature to the process. A signature it added would be one the warm-up
left out, compiled inside the studio at the action's first use: seconds with the window frozen
(a character's spring bones: 12 s on a loaded two-core host).

The actions (and the thread the studio runs them on):

- File ▸ New from sample ▸ Character (a ``.vrm``, or a ``.glb`` whose chains are found by name),
  the Character dock's Show ▸ Both (the springs beside the cycle, the paper's measure), File ▸
  Export character ▸ Springs' optimal keys (GUI thread);
- Colour ▸ Clump membership (GUI thread);
- Groom ▸ Grow render hair… ▸ Pick guides among these strands (a job's thread);
- the timeline's Price per key (tau) (GUI thread);
- File ▸ Open of a BVH capture: its keys' errors (GUI thread for a capture this short), and the
  graph editor's per-channel keys at the timeline's price (GUI thread);
- an Add stroke on a groom with a head and no render hair (Sintel's, after Remove render hair):
  the new strands look up their nearest old roots, in the groom's precision and in float64
  (the engine's thread; compiled there it took 17 s).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from app.ui import kernel_warmup

pytestmark = pytest.mark.gui

DATA = Path(__file__).parents[1] / "data"

#: The warm-up's steps that these actions need, in the order the script runs them (the rest of
#: the warm-up compiles the first screen, the brushes and the render hair, whose kernels these
#: actions reach only where these steps reach them too).
STEPS = (
    "grooming brushes",
    "animation and keys",
    kernel_warmup.PICKED_GUIDES_STEP,
    kernel_warmup.CLUMP_COLOURS_STEP,
    kernel_warmup.CHARACTER_STEP,
)

#: argv: the test data folder, then the warm-up steps to run (all of :data:`STEPS` but one: that
#: one's action should fail). Each action runs right after its step, before the later steps load
#: their kernels, so that each step is seen to hold its action's. Prints, as its last line, each
#: action's name with the kernel signatures it added to the process.
SCRIPT = r"""
import gc, json, sys
from pathlib import Path
import numpy as np
from numba.core.dispatcher import Dispatcher

def sigs():
    return {
        f"{d.py_func.__module__}:{d.py_func.__qualname__} {s}"
        for d in gc.get_objects() if isinstance(d, Dispatcher) for s in d.signatures
    }

from app.ui import kernel_warmup
data, steps = Path(sys.argv[1]), dict(kernel_warmup.STEPS)
added = {}

def after(label, name, only=""):
    def run(body):
        if label in sys.argv[2:]:
            steps[label]()
        before = sigs()
        body()
        added[name] = sorted(s for s in sigs() - before if s.startswith(only))
    return run

# the root search alone: planting on the head is the render hair steps' (not run here)
@after("grooming brushes", "add without render hair", only="hairtool.frozen.root_grid:")
def _():
    from hairtool import io
    from hairtool.frozen.brushes import BrushSample, falloff_lut
    from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
    from hairtool.guides.planting import HeadSurface
    from hairtool.io.obj import read_mesh
    groom = io.read_groom(data / "grooms" / "sintel_hair.tfx")
    head = HeadSurface(read_mesh(data / "grooms" / "sintel_head.obj"))
    pipe = FrozenPipeline(groom, FrozenParams(freeze=False, clump=False), head)
    lut = tuple(falloff_lut("smooth").tolist())
    cursor = tuple(float(v) for v in groom.roots[40])
    pipe.brush(BrushSample("add", cursor, (0.0, 0.0, 0.0), 2.0, 1.0, lut, None, count=4, seed=5))

@after("animation and keys", "price per key")
def _():
    from hairtool import samples
    from hairtool.keys import session as ks
    from hairtool.simulate.sway import sway_animation
    anim = sway_animation(samples.portrait(strands=6, vertices=6), 30, 24.0, flick_frame=20)
    settings = ks.KeySettings(mode="tau", tau=0.05)
    ks.solve(anim, settings).keys_for(settings)

@after(None, "capture")
def _():
    from app.document.capture import skeleton_animation
    from hairtool.keys import session as ks
    from hairtool.keys.channels import per_channel_keys
    from hairtool.mocap.bvh import read_bvh
    from hairtool.mocap.channel_edit import channel_features
    motion = read_bvh(data / "motion" / "freebvh.bvh")
    anim = skeleton_animation(motion)
    settings = ks.KeySettings()
    keys = ks.solve(anim, settings).keys_for(settings)
    ks.analyse(anim, keys, settings.interp)
    per_channel_keys(channel_features(motion)[:, :6], 0.05, interp="linear", relative=True)

@after(kernel_warmup.PICKED_GUIDES_STEP, "picked guides")
def _():
    from app.ui.render_hair_dialog import DENSE, GrowOptions, grow
    from hairtool import samples
    grow(GrowOptions(mode=DENSE, guides=12, seed=1), samples.portrait(strands=30, vertices=10))

from hairtool import samples
from hairtool.frozen.pipeline import FrozenParams, FrozenPipeline
# a groom open in the studio's engine (its kernels are the first screen's steps', not run here)
engine = FrozenPipeline(samples.portrait(strands=30, vertices=10), FrozenParams())

@after(kernel_warmup.CLUMP_COLOURS_STEP, "clump colours")
def _():
    engine.clump_ids()

@after(kernel_warmup.CHARACTER_STEP, "character")
def _():
    from app.document.character import CharacterDocument
    from hairtool.character.read import load_character
    for name in ("bunches.vrm", "bunches.glb"):
        doc = CharacterDocument(load_character(data / "characters" / name))
        doc.set_view("both")
        doc.springs()
        doc.measure()
        doc.spring_keys()

print(json.dumps(added))
"""


#: The actions the script runs, in its order.
ACTIONS = (
    "add without render hair", "price per key", "capture", "picked guides", "clump colours", "character"
)


@pytest.fixture(scope="module")
def added() -> dict:
    command = [sys.executable, "-c", SCRIPT, str(DATA), *STEPS]
    out = subprocess.run(command, capture_output=True, text=True, timeout=900, check=False)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.mark.slow(seconds=2)  # each: one process for them all, about 8 s warm
@pytest.mark.parametrize("action", ACTIONS)
def test_a_studio_action_needs_no_kernel_the_warm_up_left_out(added, action):
    assert not added[action], f"{action}: kernels the warm-up does not compile:\n" + "\n".join(added[action])

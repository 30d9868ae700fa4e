"""Every numba kernel of the core releases the GIL: the studio runs key solves, simulations and
video exports in worker threads, and a kernel that kept the GIL would freeze the window."""

from __future__ import annotations

import importlib
import pkgutil

from numba.core.registry import CPUDispatcher

import hairtool


def _kernels():
    for info in pkgutil.walk_packages(hairtool.__path__, "hairtool."):
        if info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if isinstance(obj, CPUDispatcher) and obj.__module__ == module.__name__:
                yield f"{module.__name__}.{name}", obj


def test_every_kernel_is_compiled_without_the_gil():
    kernels = dict(_kernels())
    assert len(kernels) > 30  # the engine's kernels were found
    # Functions inlined into kernels (inline="always") take the caller's setting.
    holding = sorted(
        k
        for k, d in kernels.items()
        if not d.targetoptions.get("nogil") and d.targetoptions.get("inline") != "always"
    )
    assert not holding, f"kernels that keep the GIL: {holding}"

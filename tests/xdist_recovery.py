"""xdist's file scheduling made to finish after a worker dies, so a crash costs one failed test,
never the whole run.

``./dev test`` hands each worker whole files (``--dist loadfile``). When a worker dies (a
segfault, a test's timeout), pytest-xdist 3.8 puts every file that worker was ever given back on
the queue, the finished ones included; a finished file reaches a worker as an empty batch that
never reports done, and at the end of the run every worker waits for work that never comes
(pytest-xdist issues 1323 and 1378: CI sat at 99 % until its limit). It also runs the test that
took the worker down once more. Here a dead worker's files go back with only their unfinished
tests, the one it died on reported failed (by xdist) and not run again.
"""

from __future__ import annotations

from xdist.scheduler import LoadFileScheduling


class RecoveringFileScheduling(LoadFileScheduling):
    """:class:`LoadFileScheduling` whose :meth:`remove_node` requeues unfinished tests only."""

    def remove_node(self, node) -> str | None:
        workload = self.assigned_work.pop(node)
        crashitem = next(
            (nodeid for unit in workload.values() for nodeid, done in unit.items() if not done), None
        )
        if crashitem is None:  # a normal shutdown: everything it was given has run
            return None
        for unit in workload.values():
            if crashitem in unit:
                unit[crashitem] = True  # failed by xdist's crash report; not run a second time
        for scope, unit in workload.items():
            if not all(unit.values()):
                self.workqueue[scope] = unit
                self.workqueue.move_to_end(scope, last=False)  # before files nobody started
        for other in self.assigned_work:
            self._reschedule(other)
        return crashitem


class Plugin:
    """Registered by ``tests/conftest.py`` where xdist runs the suite."""

    def pytest_xdist_make_scheduler(self, config, log):
        if config.getvalue("dist") == "loadfile":
            return RecoveringFileScheduling(config, log)
        return None

"""The document works with Qt and OpenGL absent: its modules import, and a capture opened, posed
by IK, a comb stroke, saved and reopened give the same document (the model tests need no display)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

SCRIPT = textwrap.dedent(
    """
    import sys

    BLOCKED = ("PySide6", "shiboken6", "moderngl", "pyrr")

    class Block:
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in BLOCKED:
                raise ImportError(f"{name} is blocked in this test")
            return None

    sys.meta_path.insert(0, Block())

    from app.document import project_io
    from app.document.animation import Document
    from app.document.character import CharacterDocument  # noqa: F401 (Qt-free too)
    from hairtool import samples
    from hairtool.mocap.bvh import read_bvh
    from hairtool.mocap.pose_edit import PoseEdit

    bvh, out = sys.argv[1], sys.argv[2]
    m = read_bvh(bvh)
    m = m.with_values(m.values[:20])
    doc = Document(samples.portrait(strands=4, vertices=4))
    assert doc.replace_animation(None, "walk.bvh", capture=m) and doc.changed
    f = int(doc.keys[1])
    j = m.joint_names.index("LeftWrist")
    target = tuple(float(v) for v in m.joint_positions()[f, j] + [2.0, 1.0, 0.0])
    doc.edit(PoseEdit(f, "LeftWrist", target, 2))
    from app.ui.brush_tool import BrushTool  # the studio's sampling of a brush: no Qt either

    tool = BrushTool(brush="comb", symmetry=True)
    tool.reset_radius(1.0)
    at = doc.hair.pipeline.aligned.points[2].astype(float)
    doc.hair.stroke(tool.samples(at, (0.3, 0.0, 0.0), None, 0.0, start=True), stroke=1)
    doc.hair.end_stroke()
    project_io.save(doc, out)
    assert not doc.changed
    back = project_io.load(out)
    assert back.state.edits == doc.state.edits
    assert back.keyed().motion.values.tobytes() == doc.keyed().motion.values.tobytes()
    a, b = doc.hair.state.strokes, back.hair.state.strokes
    assert a.log == b.log and a.aligned.points.tobytes() == b.aligned.points.tobytes()
    assert not any(n.split(".")[0] in BLOCKED for n in sys.modules), "a blocked module got in"
    """
)


def test_the_document_needs_no_qt(tmp_path):
    bvh = Path(__file__).resolve().parents[1] / "data" / "motion" / "mocapbank_walk.bvh"
    out = tmp_path / "doc.hairproj"
    root = Path(__file__).resolve().parents[2]
    run = subprocess.run(
        [sys.executable, "-c", SCRIPT, str(bvh), str(out)], cwd=root, capture_output=True, text=True
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert out.is_file()

"""The shader loader's ``#include``: a line naming another file of shaders/ is replaced by it,
the including file's line numbers resume after it, a file that includes itself is refused, and
the strand programs that share their fragment stage compile it from the one file."""

from __future__ import annotations

import pytest

from app.render import shaders
from hairtool.errors import ParameterError


@pytest.fixture
def files(monkeypatch):
    texts: dict[str, str] = {}
    shaders.expanded_source.cache_clear()
    monkeypatch.setattr(shaders, "shader_source", lambda name: texts[name])
    yield texts
    shaders.expanded_source.cache_clear()


def test_an_include_is_replaced_by_its_file_and_the_line_numbers_resume(files):
    files["prog"] = '#version 330 core\n// one\n#include "piece.glsl"\nvoid main() {}\n'
    files["piece"] = "float x;\nfloat y;\n"
    assert (
        shaders.expanded_source("prog")
        == "#version 330 core\n// one\nfloat x;\nfloat y;\n#line 4\nvoid main() {}\n"
    )


def test_a_file_that_includes_itself_is_refused(files):
    files["a"] = '#version 330 core\n#include "b.glsl"\n'
    files["b"] = '#include "a.glsl"\n'
    with pytest.raises(ParameterError, match="shader"):
        shaders.expanded_source("a")


def test_the_strand_programs_share_one_fragment_stage():
    quads, thin = shaders.stage_sources("strands_quads"), shaders.stage_sources("strands_thin")
    for stages in (quads, thin):
        assert '#include "' not in stages["fragment_shader"]
        assert (
            "f_color = vec4(v_color, u_use_flat_color ? u_flat_color.a : 1.0);" in stages["fragment_shader"]
        )

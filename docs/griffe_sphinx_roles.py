"""A griffe extension for the API pages: the core's docstrings cross-reference in Sphinx's
roles (``:func:`~hairtool.io.read```), which Markdown would print as they stand. Each role
becomes a code span of the name a reader sees (the last part after ``~``, as Sphinx shows it),
and a literal block's ``::`` a colon."""

from __future__ import annotations

import re

import griffe

ROLE = re.compile(r":(?:py:)?(?:func|class|mod|meth|attr|data|obj|exc|const|ref):`(~?)([^`]+)`")
LITERAL_BLOCK = re.compile(r"::$", re.M)


def _plain(text: str) -> str:
    text = ROLE.sub(lambda m: f"`{m.group(2).rsplit('.', 1)[-1] if m.group(1) else m.group(2)}`", text)
    return LITERAL_BLOCK.sub(":", text)


class SphinxRoles(griffe.Extension):
    def on_instance(self, *, obj: griffe.Object, **kwargs) -> None:
        if obj.docstring is not None:
            obj.docstring.value = _plain(obj.docstring.value)

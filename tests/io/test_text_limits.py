"""hairtool.io.text_limits: nesting and digits measured outside strings and comments."""

from __future__ import annotations

import json
import tomllib

import pytest

from hairtool.errors import FormatError
from hairtool.io import text_limits
from hairtool.io.text_limits import MAX_DIGITS, check_text, nesting_depth
from hairtool.io.text_limits import _structure as structure


@pytest.mark.parametrize(
    "value",
    [[], [[1]], {"a": [{"b": [[[]]]}]}, ["[[[", "{{", "]]"], {"k": '"[\\"[' * 3}, [1, [2, [3]], 4]],
)
@pytest.mark.parametrize("chunk", [1 << 22, 1, 3], ids=["whole", "chunks-of-1", "chunks-of-3"])
def test_json_depth_is_the_parsers(monkeypatch, value, chunk):
    monkeypatch.setattr(text_limits, "_CHUNK", chunk)  # the sum carried across chunks

    def depth(v):
        children = v.values() if isinstance(v, dict) else v if isinstance(v, list) else []
        return 1 + max(map(depth, children), default=0) if isinstance(v, dict | list) else 0

    assert nesting_depth(structure(json.dumps(value), "json")) == depth(value)


def test_toml_strings_and_comments_do_not_count():
    text = """# [[[[[[ a comment
glob = "shots/[abc]*.usdc"   # ]]]]
lit = 'C:\\[x'
long = \"\"\"
[[[[
\"\"\"
args = [[1, 2], ["[", "]"]]
"""
    tomllib.loads(text)  # valid TOML
    assert nesting_depth(structure(text, "toml")) == 2
    assert structure(text, "toml").count("\n") == text.count("\n")  # lines kept for the messages


def test_limits_and_their_messages(tmp_path):
    p = tmp_path / "x.json"
    check_text(p, "[" * 64 + "]" * 64, "json", "a log")
    with pytest.raises(FormatError, match="nested 65 levels deep; a log nests at most 64"):
        check_text(p, "[" * 65 + "]" * 65, "json", "a log")
    ok = "1" * MAX_DIGITS
    check_text(p, f'[{ok}, "{"9" * 5000}", 0.{ok}]', "json", "a log")  # digits in a string are text
    with pytest.raises(FormatError, match=f"line 3: a number of {MAX_DIGITS + 1} digits"):
        check_text(p, f"[\n1,\n{ok}1]", "json", "a log")
    with pytest.raises(FormatError, match="line 2: a number of 50 digits"):
        check_text(p, "# 1\nx = 1_" + "0" * 49 + "\n", "toml", "a jobs file")


def test_toml_dotted_keys(tmp_path):
    """tomllib's time and memory grow with the square of a dotted key's parts (22 GB for 100,000)."""
    p = tmp_path / "x.toml"
    key = ".".join(["a"] * 16)
    valid = f'[{key}]\n{key} = 1.5\nb = {{ {key} = "x.y.z" }}\nd = 1979-05-27T07:32:00.5\n'
    tomllib.loads(valid)
    check_text(p, valid, "toml", "jobs")
    long = '"q".' + key
    spaced = long.replace(".", " . ")
    for text in (f"[{long}]\n", f"{long} = 1\n", f"x = {{ {long} = 1 }}\n", f"x = {{ {spaced} = 1 }}\n"):
        with pytest.raises(FormatError, match="line 1: a dotted key of 17 parts; jobs has none longer"):
            check_text(p, text, "toml", "jobs")
    check_text(p, f"[{long}]", "json", "jobs")  # JSON has no dotted keys

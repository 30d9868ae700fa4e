"""hairtool.io.user_text: one reader, the same limits for every JSON and TOML a user writes
(issue 45): digits in any base, control characters, string length, special files."""

from __future__ import annotations

import json
import os

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hairtool.errors import FormatError, quoted
from hairtool.io import user_text
from hairtool.io.text_limits import MAX_DIGITS


@pytest.mark.parametrize(
    "text",
    [
        "x = 0x" + "f" * 4301 + "\n",  # the jobs file's hex integer: Python reads any length in base 16
        "x = 0o" + "7" * 4301 + "\n",
        "x = 0b" + "1" * 4301 + "\n",
        "x = 0x" + "dead_beef_" * 8 + "1\n",
        "x = 1" + "0" * 4301 + "\n",
    ],
)
def test_digits_in_any_base(tmp_path, text):
    p = tmp_path / "jobs.toml"
    p.write_text(text)
    words = f"line 1: a number of .* digits; a jobs file holds none longer than {MAX_DIGITS}"
    with pytest.raises(FormatError, match=words):
        user_text.read(p, "a jobs file")


def test_short_numbers_in_every_base_read(tmp_path):
    p = tmp_path / "x.toml"
    p.write_text('a = 0xdead_beef\nb = 0o755\nc = 0b1010\nd = 1_000\ne = 1979-05-27T07:32:00Z\nf = 6.02e23\n')
    assert user_text.read(p, "settings")["a"] == 0xDEADBEEF


@pytest.mark.parametrize("char", ["\n", "\r", "\x1b", "\x00", "\x7f", "\x85", "\u009b"])
@pytest.mark.parametrize("where", ["key", "value", "list"])
def test_control_characters_in_names_are_refused_naming_where(tmp_path, char, where):
    name = f"hips{char}[2J"
    doc = {"key": {name: 1}, "value": {"joint": name}, "list": {"args": ["a", name]}}[where]
    p = tmp_path / "edits.json"
    p.write_text(json.dumps(doc))
    with pytest.raises(FormatError) as e:
        user_text.read(p, "an edit file")
    message = str(e.value)
    assert "control character" in message and message.isprintable() and "\n" not in message


def test_tab_and_unicode_are_text(tmp_path):
    p = tmp_path / "x.json"
    p.write_text(json.dumps({"joint": "Kopf\tlinks é 頭"}))
    assert user_text.read(p, "an edit file") == {"joint": "Kopf\tlinks é 頭"}


def test_long_strings_are_refused(tmp_path):
    p = tmp_path / "x.json"
    p.write_text(json.dumps({"args": ["x" * (user_text.MAX_STRING + 1)]}))
    with pytest.raises(FormatError, match=r"a string at 'args\[0\]' of 4097 characters; at most 4096"):
        user_text.read(p, "a jobs file")


def test_special_files_are_refused_before_they_are_opened(tmp_path):
    fifo = tmp_path / "edits.json"
    os.mkfifo(fifo)  # opening it for reading would block forever
    with pytest.raises(FormatError, match="not a regular file"):
        user_text.read(fifo, "an edit file")
    with pytest.raises(FormatError, match="not a regular file"):
        user_text.read("/dev/zero", "an edit file")
    with pytest.raises(FormatError, match="not a regular file"):
        user_text.read(tmp_path, "an edit file")


@settings(max_examples=200, deadline=None, derandomize=True, database=None)
@given(st.text(min_size=0, max_size=80))
def test_quoted_is_always_one_printable_line(s):
    shown = quoted(s, 40)
    assert shown.isprintable()  # no newline, no control character: one line stays one line
    assert len(shown) <= 40 * 10 + 3  # repr escapes a character into at most 10


@pytest.mark.parametrize("reader", ["bvh", "project", "stroke log"])
def test_each_reader_of_a_users_file_refuses_through_read_bytes(tmp_path, reader, monkeypatch):
    """The BVH reader, the project loader and the JSON readers open a user's file in one place
    (:func:`user_text.read_bytes`): a FIFO is refused before it is opened (it would block),
    a missing file names the system's reason, and none is read past that helper."""
    from hairtool import project
    from hairtool.frozen.strokes import read_strokes
    from hairtool.mocap.bvh import read_bvh

    read = {"bvh": read_bvh, "project": project.load, "stroke log": read_strokes}[reader]
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(FormatError, match="not a regular file"):
        read(fifo)
    asked = []
    real = user_text.read_bytes

    def spy(path, what, max_bytes=user_text.MAX_BYTES):
        asked.append(what)
        return real(path, what, max_bytes)

    monkeypatch.setattr(user_text, "read_bytes", spy)
    empty = tmp_path / "empty"
    empty.write_bytes(b"")
    with pytest.raises(FormatError):
        read(empty)
    assert len(asked) == 1
    monkeypatch.setattr(user_text, "read_bytes", real)
    if reader != "project":  # (the project loader says "no such file" first)
        with pytest.raises(FormatError, match="cannot read: No such file"):
            read(tmp_path / "absent")

"""The command line's help speaks as the studio does: artists' words first, the paper's symbol
after them, and no references to the project's seed-paper numbering."""

from __future__ import annotations

import re

import pytest

from hairtool.cli import command_names, command_parser


@pytest.mark.parametrize("command", command_names())
def test_help_names_no_seed_paper_numbers(command):
    text = command_parser(command).format_help()
    assert not re.search(r"seed 00\d", text), command


def test_freeze_help_uses_the_studio_words_with_the_symbols():
    text = " ".join(command_parser("freeze").format_help().split())
    for words in (
        "stiffness (stretch) k_s",
        "stiffness (bend) k_b",
        "max bend angle θ_max",
        "clump strength Δt²/m",
        "keep gaps between clumps",
        "brush size r",
    ):
        assert words in text, words

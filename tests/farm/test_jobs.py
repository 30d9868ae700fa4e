"""Jobs files: JSON and TOML, glob templates, paths relative to the file, and one clear error for
every mistake (the CLI's exit status 2 and one line)."""

from __future__ import annotations

import json

import pytest

from hairtool.cli import main
from hairtool.errors import FormatError
from hairtool.farm.jobs import job_commands, load_jobs


def write(path, data) -> str:
    path.write_text(json.dumps(data) if path.suffix == ".json" else data)
    return str(path)


def test_listed_jobs_keep_their_arguments_and_numbers_become_text(tmp_path):
    jobs = load_jobs(
        write(
            tmp_path / "j.json",
            {"jobs": [{"command": "keys", "args": ["s.npz", "--keys", 12, "--penalty", 0.5]}]},
        )
    )
    assert len(jobs) == 1
    job = jobs[0]
    assert job.argv == ["keys", "s.npz", "--keys", "12", "--penalty", "0.5"]
    assert job.base == str(tmp_path) and job.input == "s.npz"


@pytest.mark.parametrize(
    ("command", "args", "expected"),
    [
        ("keys", ["--keys", "4", "shot.usdc", "--out", "x.json"], "shot.usdc"),
        ("keys", ["-k", "4", "--pin", "0,3", "shot.usdc"], "shot.usdc"),
        ("keys", ["--out=x.json", "--export", "k.usdc", "shot.npz"], "shot.npz"),
        ("convert", ["--up-axis", "z", "in.hair", "out.usda"], "in.hair"),
        ("freeze", ["--seed", "3", "--clump-radius", "auto", "g.tfx", "f.npz"], "g.tfx"),
        ("anime", ["--period", "0.5", "sample:portrait", "a.npz"], "sample:portrait"),
        ("anime", ["--period", "0.5"], None),  # the schedule only: no input
        ("info", ["shot.npz"], "shot.npz"),
        ("keys", ["shot.npz", "--keys", "2", "--penalty", "1"], "shot.npz"),  # refused, after the input
        ("keys", ["--keys", "four", "shot.npz"], None),  # refused before the input
        ("convert", ["in.hair"], "in.hair"),  # OUT missing: refused at the end
        ("keys", ["shot.npz", "--help"], "shot.npz"),  # nothing printed, nothing exits
    ],
)
def test_the_input_is_read_by_the_commands_own_parser(command, args, expected, capsys):
    from hairtool.cli import quiet_parser

    assert load_one(command, args).input == expected
    assert capsys.readouterr() == ("", "")
    assert quiet_parser(command) is quiet_parser(command)  # built once per command


def load_one(command: str, args: list[str]):
    from hairtool.farm.jobs import Job

    return Job(0, command, tuple(args), "/")


def test_a_glob_fills_the_template_for_each_match_in_order(project):
    path = write(
        project / "jobs.json",
        {
            "jobs": [
                {
                    "glob": "shots/*.npz",
                    "command": "keys",
                    "args": ["{path}", "--out", "{dir}/{stem}.keys.json"],
                },
                {"command": "convert", "args": ["grooms/scalp.npz", "out/scalp.usda"]},
            ]
        },
    )
    jobs = load_jobs(path)
    assert [j.args for j in jobs] == [
        ("shots/a.npz", "--out", "shots/a.keys.json"),
        ("shots/b.npz", "--out", "shots/b.keys.json"),
        ("shots/c.npz", "--out", "shots/c.keys.json"),
        ("grooms/scalp.npz", "out/scalp.usda"),
    ]
    assert [j.index for j in jobs] == [0, 1, 2, 3]
    assert len({j.key for j in jobs}) == 4


def test_toml_gives_the_same_jobs_as_json(project):
    toml = write(
        project / "jobs.toml",
        '[[jobs]]\nglob = "shots/*.npz"\ncommand = "keys"\nargs = ["{path}", "--keys", 4, "--out", '
        '"out/{name}{{x}}{suffix}.json"]\n',
    )
    js = write(
        project / "jobs.json",
        {
            "jobs": [
                {
                    "glob": "shots/*.npz",
                    "command": "keys",
                    "args": ["{path}", "--keys", "4", "--out", "out/{name}{{x}}{suffix}.json"],
                }
            ]
        },
    )
    from_toml, from_json = load_jobs(toml), load_jobs(js)
    assert [j.argv for j in from_toml] == [j.argv for j in from_json]
    assert from_toml[0].args[-1] == "out/a.npz{x}.npz.json"


def test_one_glob_entry_at_the_top_level_is_a_batch(project):
    jobs = load_jobs(write(project / "j.json", {"glob": "shots/a.*", "command": "keys", "args": ["{path}"]}))
    assert [j.argv for j in jobs] == [["keys", "shots/a.npz"]]


def test_every_existing_command_but_batch_and_bench_is_a_job():
    from hairtool.cli import command_names

    commands = job_commands()
    assert {"keys", "freeze", "convert", "simulate", "anime", "sample"} <= set(commands)
    assert set(commands) == set(command_names()) - {"batch", "bench"}


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("j.yaml", "jobs: []", "a jobs file is .json or .toml"),
        ("j.json", "{not json", "not valid JSON"),
        ("j.toml", "[[jobs]\n", "not valid TOML"),
        ("j.json", [1, 2], 'expected an object with a "jobs" list'),
        ("j.json", {"job": []}, 'expected a "jobs" list'),
        ("j.json", {"jobs": {"command": "keys"}}, '"jobs" must be a list'),
        ("j.json", {"jobs": []}, "no jobs"),
        ("j.json", {"jobs": ["keys a.npz"]}, "jobs[0]: expected an object"),
        ("j.json", {"jobs": [{"args": ["a"]}]}, "jobs[0]: command missing is not one of"),
        ("j.json", {"jobs": [{"command": "render", "args": []}]}, "command 'render' is not one of"),
        ("j.json", {"jobs": [{"command": "batch", "args": ["x.json"]}]}, "command 'batch' is not one of"),
        ("j.json", {"jobs": [{"command": "keys", "arg": ["a"]}]}, "unknown key 'arg'"),
        ("j.json", {"jobs": [{"command": "keys", "args": "a.npz"}]}, "args must be a list"),
        ("j.json", {"jobs": [{"command": "keys", "args": ["a", None]}]}, "args[1] must be a string"),
        ("j.json", {"jobs": [{"command": "keys", "args": [True]}]}, "args[0] must be a string"),
        ("j.json", {"jobs": [{"glob": "nothing/*.usd", "command": "keys"}]}, "matches no file"),
        ("j.json", {"jobs": [{"glob": 3, "command": "keys"}]}, "glob must be a non-empty string"),
        (
            "j.json",
            {"glob": "shots/*.npz", "command": "keys", "args": ["{stme}"]},
            "unknown placeholder '{stme}'",
        ),
        ("j.json", {"jobs": [{"command": "keys", "args": ["a"]}] * 2}, "jobs[1]: repeats jobs[0]"),
        ("j.json", {"jobs": [], "extra": 1}, "unknown top-level key 'extra'"),
    ],
)
def test_a_bad_jobs_file_is_one_format_error_naming_it(project, name, content, message):
    path = project / name
    path.write_text(content if isinstance(content, str) else json.dumps(content))
    with pytest.raises(FormatError) as e:
        load_jobs(path)
    assert str(path) in str(e.value) and message in str(e.value)
    assert "\n" not in str(e.value)


def test_the_cli_reports_a_bad_jobs_file_in_one_line_with_status_2(project, capsys):
    path = write(project / "j.json", {"jobs": [{"command": "render"}]})
    assert main(["batch", path]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("hairtool batch: error: ") and "render" in err and "\n" not in err


def test_a_missing_or_unreadable_jobs_file_is_one_line(tmp_path, capsys):
    assert main(["batch", str(tmp_path / "none.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert "none.json: cannot read" in err and "\n" not in err
    (tmp_path / "bin.json").write_bytes(b"\xff\xfe\x00")
    with pytest.raises(FormatError, match="not UTF-8"):
        load_jobs(tmp_path / "bin.json")

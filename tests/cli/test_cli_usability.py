"""The command line a new user meets: --version, descriptions, launch files by name, init, docs."""

import argparse
from pathlib import Path

import pytest

from g1_control import resources
from g1_control.cli.main import build_parser, main
from g1_control.errors import LaunchFileError
from tests.paths import LAUNCH_DIR, REPO


def _subparsers(parser, path=()):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield (*path, name), sub
                yield from _subparsers(sub, (*path, name))


def test_every_subcommand_has_a_description():
    missing = [" ".join(path) for path, sub in _subparsers(build_parser()) if not sub.description]
    assert not missing, f"subcommands without a description: {missing}"
    names = {path[0] for path, _ in _subparsers(build_parser())}
    assert {"launch", "replay", "view", "init", "docs"} <= names


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.startswith("g1-control 0.1.0")


def test_launch_files_by_name_and_by_readme_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # an unrelated directory: no launch/ here
    assert resources.resolve_launch("sim_walk") == (LAUNCH_DIR / "sim_walk.yaml", True)
    assert resources.resolve_launch("sim_walk.yaml")[0] == LAUNCH_DIR / "sim_walk.yaml"
    assert resources.resolve_launch("launch/sim_walk.yaml")[0] == LAUNCH_DIR / "sim_walk.yaml"
    mine = tmp_path / "sim_walk.yaml"
    mine.write_text("name: mine\n")
    path, shipped = resources.resolve_launch("sim_walk.yaml")
    assert path.resolve() == mine and not shipped  # a real file wins
    with pytest.raises(LaunchFileError, match="no such launch file.*sim_walk"):
        resources.resolve_launch("other/sim_walk.yaml")
    with pytest.raises(LaunchFileError, match="no such launch file"):
        resources.resolve_launch("sim_wlak")


def test_launch_list_and_check_by_name(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["launch", "--list"]) == 0
    listed = capsys.readouterr().out
    assert all(p.stem in listed for p in LAUNCH_DIR.glob("*.yaml"))
    assert main(["launch", "sim_walk", "--check", "--set", "tracker.policy=holosoma_loco_fastsac"]) == 0
    assert "policy holosoma-loco-fastsac" in capsys.readouterr().out
    assert main(["launch", "sim_walk", "--check", "--set", "tracker.polcy=x"]) == 1
    assert "unknown key 'polcy'" in capsys.readouterr().err


def test_init_copies_and_keeps_edits(tmp_path, capsys):
    dest = tmp_path / "mine"
    assert main(["init", str(dest)]) == 0
    assert sorted(p.name for p in dest.glob("*.yaml")) == sorted(p.name for p in LAUNCH_DIR.glob("*.yaml"))
    (dest / "sim_walk.yaml").write_text("edited")
    assert main(["init", str(dest)]) == 1  # refuses to overwrite
    assert "already there" in capsys.readouterr().err
    assert (dest / "sim_walk.yaml").read_text() == "edited"


def test_docs_lists_and_prints(capsys):
    assert main(["docs"]) == 0
    topics = capsys.readouterr().out
    for topic in ("readme", "license", "architecture", "api", "robot_facts", "deploy", "teleop"):
        assert topic in topics
    assert main(["docs", "license"]) == 0
    assert "BSD 3-Clause" in capsys.readouterr().out


def test_readme_links_resolve():
    import re

    for doc in [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]:
        for target in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", doc.read_text()):
            if "://" in target:
                continue
            assert (doc.parent / target).exists(), f"{doc.name} links to missing {target}"


def test_code_cites_only_files_in_this_repository():
    """Comments point at docs/ in this repository, not at team documents outside it."""
    outside = ("FACTS.md", "DESIGN.md", "STYLE.md")
    offenders = []
    for folder in ("g1_control", "tests", "launch", "scripts", "examples", "docs"):
        for path in (REPO / folder).rglob("*"):
            if path.suffix in (".py", ".yaml", ".sh", ".md") and path.name != "test_cli_usability.py":
                text = path.read_text(errors="replace")
                offenders += [f"{path.relative_to(REPO)}: {name}" for name in outside if name in text]
    assert not offenders, offenders



@pytest.fixture
def deploy_paths(tmp_path, monkeypatch):
    """The launch-file paths `g1 deploy` hands to the deploy session, which stops there (nothing reaches a robot)."""
    from g1_control.deploy import session

    monkeypatch.chdir(tmp_path)  # no launch/ folder here
    given: list[Path] = []

    def fake_deploy(path, options, **_):
        given.append(path)
        raise SystemExit(7)

    monkeypatch.setattr(session, "deploy", fake_deploy)
    return given


@pytest.mark.parametrize("name", ["robot", "sim2sim.yaml", "launch/robot.yaml"])
def test_deploy_takes_a_shipped_launch_file_by_name(name, deploy_paths, capsys):
    """`g1 deploy robot` runs the shipped robot.yaml (it said "robot.yaml: no such launch file")."""
    with pytest.raises(SystemExit):
        main(["deploy", name, "--preflight-only"])
    path = LAUNCH_DIR / (name.rsplit("/", 1)[-1].removesuffix(".yaml") + ".yaml")
    assert deploy_paths == [path]
    assert f"launch file: {path}" in capsys.readouterr().out


def test_deploy_leaves_a_missing_launch_file_to_the_preflight(deploy_paths):
    with pytest.raises(SystemExit):
        main(["deploy", "robto", "--preflight-only"])
    assert deploy_paths == [Path("robto")]  # refused by the preflight's launch_file check, into its report

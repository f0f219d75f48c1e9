"""`g1 library` and `g1 bench generator` command lines."""

import pytest

from g1_control.cli.main import main


def test_library_help_explains_sources_and_split(capsys):
    with pytest.raises(SystemExit):
        main(["library", "build", "--help"])
    out = capsys.readouterr().out
    assert "rollouts" in out and "held out" in out and "--force" in out


def test_library_show_names_a_missing_library(capsys, tmp_path):
    assert main(["library", "show", str(tmp_path)]) == 1
    assert "no index.json; build the library with `g1 library build`" in capsys.readouterr().err


def test_bench_lists_the_generator_benchmark(capsys):
    with pytest.raises(SystemExit):
        main(["bench", "--help"])
    assert "generator" in capsys.readouterr().out

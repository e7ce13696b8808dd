"""The README's five-minute walk-through works as written: each `stablepush` line of its shell
block runs from a fresh directory holding the repository's data/, exits 0, and leaves the file
it names."""
import re
import shlex

from click.testing import CliRunner

from stablepush_cli.main import cli

from conftest import ROOT


def _walkthrough() -> list:
    text = (ROOT / "README.md").read_text()
    section = text.split("## Five minutes", 1)[1].split("\n## ", 1)[0]
    block = re.search(r"```sh\n(.*?)```", section, re.S).group(1)
    return [shlex.split(line)[1:] for line in block.splitlines() if line.startswith("stablepush ")]


def test_the_walkthrough_runs_as_written(tmp_path, monkeypatch):
    commands = _walkthrough()
    assert [c[0] for c in commands] == ["plan", "show", "trajectory", "trajectory", "execute", "evaluate", "reach"]
    (tmp_path / "data").symlink_to(ROOT / "data")
    monkeypatch.chdir(tmp_path)
    for args in commands:
        result = CliRunner().invoke(cli, args)
        assert result.exit_code == 0, (args, result.output)
        outputs = [a for a, option in zip(args[1:], args) if option in ("-o", "--json", "--plot", "--video")]
        for name in outputs:
            assert (tmp_path / name).stat().st_size > 0, (args, name)

"""docs/cli.md is generated from the commands' own --help by scripts/cli_docs.py: it must be current."""
import difflib
import importlib.util

import click
import pytest

from conftest import ROOT


def _cli_docs():
    spec = importlib.util.spec_from_file_location("cli_docs", ROOT / "scripts" / "cli_docs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_docs_cli_md_is_the_commands_help_as_it_is_now():
    cli_docs = _cli_docs()
    expected = cli_docs.render()
    actual = cli_docs.CLI_MD.read_text(encoding="utf-8")
    if actual != expected:
        diff = list(difflib.unified_diff(actual.splitlines(), expected.splitlines(), "docs/cli.md",
                                         "scripts/cli_docs.py", lineterm="", n=1))
        shown = "\n".join(diff[:40]) + ("\n..." if len(diff) > 40 else "")
        pytest.fail(f"docs/cli.md is not current; regenerate it with `{cli_docs.REGENERATE}`\n{shown}",
                    pytrace=False)


def test_the_page_does_not_depend_on_the_terminal(monkeypatch):
    cli_docs = _cli_docs()
    wide = cli_docs.render()
    monkeypatch.setenv("COLUMNS", "40")
    assert cli_docs.render() == wide


def test_every_command_has_its_section():
    cli_docs = _cli_docs()
    group = cli_docs.load_group()
    text = cli_docs.render(group)
    names = group.list_commands(click.Context(group))
    assert names
    for name in names:
        assert f"\n## stablepush {name}\n\n```text\nUsage: stablepush {name} " in text, name

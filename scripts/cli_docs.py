"""Generate docs/cli.md from the commands' own --help.

    python scripts/cli_docs.py > docs/cli.md     # print the page
    python scripts/cli_docs.py --write           # the same, written to docs/cli.md
    python scripts/cli_docs.py --check           # exit 1 when docs/cli.md is not current

The page is a fixed header (HEADER below: how the page is made, and the exit statuses of every
command) and then, for each command sorted by name, its --help as click renders it at a fixed width.
What else the commands' --help does not say is in docs/cli-notes.md, written by hand. The commands
are found through the click group itself (its `list_commands` and `get_command`), so the page does
not depend on how the CLI is split into modules; the group is the `stablepush` entry point named in
pyproject.toml. `tests/test_cli_docs.py` checks that docs/cli.md is current.
"""
import argparse
import importlib
import sys
from pathlib import Path

import click

ROOT = Path(__file__).resolve().parent.parent
CLI_MD = ROOT / "docs" / "cli.md"
PROG = "stablepush"
WIDTH = 100  # the help's width, fixed so that the page does not depend on the terminal
REGENERATE = "python scripts/cli_docs.py --write"
FALLBACK_ENTRY = "stablepush_cli.main:cli"

EXIT_STATUSES = (
    (0, "done"),
    (1, "not solved"),
    (2, "bad input: a task, plan file, option or output path; a `--ray` address where no Ray head answers "
        "within 5 s, or a Ray that cannot start"),
    (3, "arm fault"),
    (4, "internal error: a bug, reported in one line (`STABLEPUSH_DEBUG=1` shows the traceback)"),
    (5, "`execute` ran to the end and the object missed the goal tolerance (`cause` in the report)"),
    (130, "`evaluate` stopped by Ctrl-C (the trials done are summarized and written)"),
    (141, "the output's reader went away (`stablepush check ... \\| head`: the command stops quietly, as a "
          "process ended by SIGPIPE)"),
)

# The page's head: how it is made, and what the commands' --help does not say (the exit statuses of
# every command; the rest, at more length, is docs/cli-notes.md, written by hand).
HEADER = """# The command line

<!-- Generated from the commands' --help by `python scripts/cli_docs.py > docs/cli.md` (or `--write`);
do not edit by hand: edit the commands' help, or HEADER in scripts/cli_docs.py, and generate it again. -->

This page is generated from the commands' own `--help` by `python scripts/cli_docs.py >
docs/cli.md` (or `python scripts/cli_docs.py --write`); `tests/test_cli_docs.py` fails when it is
not current. How every command reports bad input and treats its outputs, and the fields of the
files and reports the commands write: [cli-notes.md](cli-notes.md). `stablepush --help` lists the
commands below, `stablepush --version` prints the version.

Exit statuses, for every command:

""" + "\n".join(["| status | meaning |", "|---:|---|"]
                + [f"| {status} | {meaning} |" for status, meaning in EXIT_STATUSES]) + "\n"


def load_group() -> click.Group:
    """The click group of the `stablepush` command, as pyproject.toml's [project.scripts] names it."""
    entry = FALLBACK_ENTRY
    try:
        import tomllib
    except ImportError:  # Python < 3.11: the entry point as it is today
        tomllib = None
    if tomllib is not None:
        with open(ROOT / "pyproject.toml", "rb") as file:
            entry = tomllib.load(file).get("project", {}).get("scripts", {}).get(PROG, entry)
    module, _, attribute = entry.partition(":")
    group = importlib.import_module(module)
    for name in attribute.split("."):
        group = getattr(group, name)
    return group


def _context(command: click.Command, name: str, parent=None) -> click.Context:
    """The context `stablepush ... NAME --help` would make (the command's own context settings, such as
    its help option names), at the fixed width."""
    settings = {**command.context_settings, "terminal_width": WIDTH, "max_content_width": WIDTH}
    return click.Context(command, info_name=name, parent=parent, **settings)


def _commands(group: click.Group, ctx: click.Context):
    """(context, command) for every command under the group, depth first, sorted by name."""
    for name in sorted(group.list_commands(ctx)):
        command = group.get_command(ctx, name)
        if command is None or command.hidden:
            continue
        sub = _context(command, name, parent=ctx)
        yield sub, command
        if isinstance(command, click.Group):
            yield from _commands(command, sub)


def _section(ctx: click.Context, command: click.Command) -> str:
    text = command.get_help(ctx).rstrip()
    return f"## {ctx.command_path}\n\n```text\n{text}\n```\n"


def render(group=None) -> str:
    """docs/cli.md as it should read: the header, then each command's --help, sorted by name."""
    group = load_group() if group is None else group
    root = _context(group, PROG)
    return "\n".join([HEADER] + [_section(ctx, command) for ctx, command in _commands(group, root)])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    action = parser.add_mutually_exclusive_group()
    action.add_argument("--write", action="store_true", help=f"write {CLI_MD.relative_to(ROOT)}")
    action.add_argument("--check", action="store_true", help=f"exit 1 when {CLI_MD.relative_to(ROOT)} is not current")
    args = parser.parse_args()
    text = render()
    if args.write:
        CLI_MD.write_text(text, encoding="utf-8")
    elif args.check:
        if CLI_MD.read_text(encoding="utf-8") != text:
            sys.exit(f"{CLI_MD.relative_to(ROOT)} is not current: run `{REGENERATE}`")
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()

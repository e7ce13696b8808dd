"""The house's rules for the code itself, read from its source."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = (ROOT / "python" / "stablepush", ROOT / "cli" / "stablepush_cli")
# Past this many a call no longer reads: the arguments that belong together travel as one value
# (a frozen dataclass; a command takes its options as groups, stablepush_cli.groups).
MAX_PARAMETERS = 8


def _parameters(node: ast.AST) -> int:
    """A function's parameters, self and cls not counted, *args and **kwargs one each."""
    a = node.args
    named = [x for x in a.posonlyargs + a.args + a.kwonlyargs if x.arg not in ("self", "cls")]
    return len(named) + (a.vararg is not None) + (a.kwarg is not None)


def test_no_function_takes_more_than_eight_parameters():
    over = {}
    for package in PACKAGES:
        for path in sorted(package.rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and _parameters(node) > MAX_PARAMETERS:
                    over[f"{path.relative_to(ROOT).as_posix()} {node.name}"] = _parameters(node)
    assert not over, f"functions of more than {MAX_PARAMETERS} parameters: {over}"

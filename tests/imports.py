"""What a source file imports, read with ``ast`` (for the architectural tests: who may import what)."""

from __future__ import annotations

import ast
from pathlib import Path

#: The repository's root (the directory holding ``mbs_models`` and ``validation``).
REPO = Path(__file__).resolve().parents[1]


def module_name(path: Path) -> str:
    """The dotted module name of the file ``path`` inside the repository."""
    parts = path.relative_to(REPO).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports_of(path: Path, source: str | None = None) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import statement in ``path`` (relative ones resolved; ``from p import
    m`` also gives ``p.m``, which may be a module); ``source``: the text to read instead of the file's."""
    tree = ast.parse(path.read_text() if source is None else source, filename=str(path))
    package = module_name(path) if path.name == "__init__.py" else module_name(path).rpartition(".")[0]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module
            found.append((node.lineno, module))
            found += [(node.lineno, f"{module}.{alias.name}") for alias in node.names if alias.name != "*"]
    return found

#!/usr/bin/env python
"""The numbers the documentation quotes, computed from the code (the numbers contract of issue #25).

    python scripts/docs_numbers.py            # compute and print every number
    python scripts/docs_numbers.py --write    # ... and write docs/_generated/numbers.json (committed)

Every ``docs/numbers_<area>.py`` defines ``NUMBERS = {name: {"compute": callable -> float, "format": "{:.1f} kN",
"rel_tol": float, "why": "what the number is"}}`` (optionally ``"abs_tol"``: an absolute bound for a number near
zero; stale means farther than ``max(rel_tol * |value|, abs_tol)``).  A page quotes a number as the MyST substitution
``{{ name }}``; ``docs/conf.py`` loads the JSON's texts, so the build never simulates for numbers, and
``tests/docs/test_numbers.py`` recomputes every entry and fails on a stale value, an unknown name or an unused entry.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
OUTPUT = DOCS / "_generated" / "numbers.json"
REQUIRED = ("compute", "format", "rel_tol", "why")


def load_modules(docs: Path = DOCS) -> dict[str, dict]:
    """``{area: NUMBERS}`` of every ``docs/numbers_<area>.py``; a name defined twice or an entry without
    ``compute``, ``format``, ``rel_tol`` and ``why`` is a ValueError."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    out: dict[str, dict] = {}
    seen: dict[str, str] = {}
    for path in sorted(docs.glob("numbers_*.py")):
        spec = importlib.util.spec_from_file_location(f"docs_{path.stem}", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        numbers = getattr(module, "NUMBERS")
        for name, entry in numbers.items():
            missing = [key for key in REQUIRED if key not in entry]
            if missing:
                raise ValueError(f"{path.name}: {name} lacks {', '.join(missing)}")
            if name in seen:
                raise ValueError(f"{name} is defined in both {seen[name]} and {path.name}")
            seen[name] = path.name
        out[path.stem.removeprefix("numbers_")] = numbers
    return out


def compute_all(modules: dict[str, dict] | None = None, progress=None) -> dict[str, dict]:
    """``{name: {"value": float, "text": str}}`` of every entry, names sorted."""
    modules = load_modules() if modules is None else modules
    out = {}
    for area, numbers in modules.items():
        for name, entry in numbers.items():
            started = time.perf_counter()
            value = float(entry["compute"]())
            out[name] = {"value": value, "text": entry["format"].format(value)}
            if progress:
                progress(f"{area}.{name} = {out[name]['text']} ({time.perf_counter() - started:.1f} s)")
    return dict(sorted(out.items()))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--write", action="store_true", help=f"write {OUTPUT.relative_to(ROOT)}")
    args = parser.parse_args(argv)
    numbers = compute_all(progress=lambda line: print(line, flush=True))
    if args.write:
        OUTPUT.parent.mkdir(parents=True, exist_ok=True)
        OUTPUT.write_text(json.dumps(numbers, indent=1) + "\n")
        print(f"wrote {OUTPUT.relative_to(ROOT)} ({len(numbers)} numbers)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

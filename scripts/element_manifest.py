"""Print the element manifest the element modules define, or write it (``--write``) to
``mbs_models/elements/_manifest.py``: run after adding an element module or changing a table's ``TABLE``,
``ORDER``, ``MANY`` or nesting (the registry then defers importing the module; ``mbs_models/elements/registry.py``).

    python scripts/element_manifest.py [--write]
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mbs_models.elements import registry  # noqa: E402

MANIFEST = Path(registry.__file__).with_name("_manifest.py")


def main(argv: list[str]) -> int:
    if argv not in ([], ["--write"]):
        print("usage: python scripts/element_manifest.py [--write]", file=sys.stderr)
        return 2
    source = registry.manifest_source(registry.discover(), registry._package_modules())
    if argv:
        MANIFEST.write_text(source, encoding="utf-8")
        print(f"wrote {MANIFEST}")
    else:
        print(source, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""``recoil --plugin MODULE``: elements defined outside the package, loaded before the command runs.

``MODULE`` is an importable module name (``my_elements``, looked up on ``sys.path`` and the current
directory) or the path of a Python file (``./progressive_spring.py``).  Importing it must register its
elements (:func:`mbs_models.register_element`) and, for ``recoil validate``, their reference terms
(:func:`validation.reference.terms.register_term`).  The option may be repeated; it goes before the command
(``recoil --plugin my_elements run scene.toml``).  A module that cannot be imported is bad input (exit 2).
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path

from ..errors import SceneError


def add_plugin_argument(parser) -> None:
    """The ``--plugin MODULE`` option (repeatable) on the top-level ``recoil`` parser."""
    parser.add_argument("--plugin", action="append", default=[], metavar="MODULE",
                        help="import MODULE (a module name or a .py file) before the command: it registers "
                             "elements of your own (mbs_models.register_element); repeatable")


def load_plugins(names) -> None:
    """Import every plugin module of ``names`` (module names or ``.py`` paths), in order."""
    for name in names:
        try:
            if name.endswith(".py") or "/" in name or "\\" in name:
                path = Path(name)
                if not path.is_file():
                    raise SceneError("--plugin", f"no such file {name!r}")
                module_name = f"recoil_plugin_{path.stem}"
                if module_name in sys.modules:
                    continue
                spec = importlib.util.spec_from_file_location(module_name, path)
                module = importlib.util.module_from_spec(spec)
                sys.modules[module_name] = module
                spec.loader.exec_module(module)
            else:
                if "" not in sys.path and str(Path.cwd()) not in sys.path:
                    sys.path.insert(0, str(Path.cwd()))
                importlib.import_module(name)
        except SceneError:
            raise
        except Exception as exc:  # a plugin's own error: one line naming the option and the module
            raise SceneError("--plugin", f"cannot import {name!r}: {type(exc).__name__}: {exc}") from None

"""Scenes: the validated description of a recoil mechanism, its TOML formats, and ready-made models.

* :class:`Scene` and :class:`Conventions` (:mod:`.container`): the element tables of
  :mod:`mbs_models.elements` and the paper's readings;
* :func:`load_scene`, :func:`scene_from_dict`, :func:`scene_to_dict`, :func:`scene_to_toml`
  (:mod:`.io`): TOML versions 1 and 2;
* :func:`apply_overrides`, :func:`parse_spec`, :func:`parse_value` (:mod:`.overrides`): dotted keys
  (``contact.gap``, ``absorber.0.mass``) that change a scene's fields, and sweep specs;
* :func:`simplified_model`, :func:`model_i`, :func:`model_ii`, :func:`paper_model` (:mod:`.models`): the
  paper's three models with Table 1's parameters.

No Exudyn is needed to build, read or write scenes.
"""

from ..elements import TABLES
from ..elements.absorber import MOUNTS
from ..elements.contact_laws import CONTACT_LAWS
from .container import PAPER_ROUNDED_INITIAL_VELOCITY, Conventions, Scene
from .io import FORMAT_VERSION, FORMAT_VERSIONS, load_scene, scene_from_dict, scene_to_dict, scene_to_toml
from .overrides import apply_overrides, parse_spec, parse_value
from .models import model_i, model_ii, paper_model, simplified_model

#: Every shipped element's table class by its class name (``Barrel``, ``RecoilSpring``, ``Contact``, ...):
#: re-exported from the element registry, so that a new element is public without being named here.  A read-only
#: mapping that imports a table's element module when its class is first looked up (:mod:`mbs_models.elements
#: .registry`); the classes are this module's and the package's attributes (PEP 562).
TABLE_CLASSES = TABLES.by_class_name()


def __getattr__(name: str):
    if name in TABLE_CLASSES:
        return TABLE_CLASSES[name]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = ["Scene", "Conventions", *TABLE_CLASSES, "TABLE_CLASSES", "CONTACT_LAWS", "MOUNTS",
           "PAPER_ROUNDED_INITIAL_VELOCITY", "FORMAT_VERSION", "FORMAT_VERSIONS", "load_scene", "scene_from_dict",
           "scene_to_dict", "scene_to_toml", "apply_overrides", "parse_spec", "parse_value", "model_i", "model_ii", "paper_model", "simplified_model"]

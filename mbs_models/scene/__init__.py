"""Scenes: the validated description of a recoil mechanism, its TOML formats, and ready-made models.

* :class:`Scene` and :class:`Conventions` (:mod:`.container`): the element tables of
  :mod:`mbs_models.elements` and the paper's readings;
* :func:`load_scene`, :func:`scene_from_dict`, :func:`scene_to_dict`, :func:`scene_to_toml`
  (:mod:`.io`): TOML versions 1 and 2;
* :func:`simplified_model`, :func:`model_i`, :func:`model_ii`, :func:`paper_model` (:mod:`.models`): the
  paper's three models with Table 1's parameters.

No Exudyn is needed to build, read or write scenes.
"""

from ..elements.absorber import MOUNTS, Absorber
from ..elements.barrel import Barrel
from ..elements.contact_laws import CONTACT_LAWS, Contact
from ..elements.end_stops import BatteryStop, RecoilStop
from ..elements.firing import Firing
from ..elements.recoil_damper import RecoilDamper
from ..elements.recoil_spring import RecoilSpring
from .container import PAPER_ROUNDED_INITIAL_VELOCITY, Conventions, Scene
from .io import FORMAT_VERSION, FORMAT_VERSIONS, load_scene, scene_from_dict, scene_to_dict, scene_to_toml
from .models import model_i, model_ii, paper_model, simplified_model

__all__ = ["Scene", "Conventions", "Barrel", "Firing", "RecoilSpring", "RecoilDamper", "Absorber", "Contact",
           "RecoilStop", "BatteryStop", "CONTACT_LAWS", "MOUNTS", "PAPER_ROUNDED_INITIAL_VELOCITY",
           "FORMAT_VERSION", "FORMAT_VERSIONS", "load_scene", "scene_from_dict", "scene_to_dict", "scene_to_toml",
           "model_i", "model_ii", "paper_model", "simplified_model"]

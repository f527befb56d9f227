"""Shared fixtures: paper scenes as TOML mappings, the table of bad-scene cases, a scene of every element
composed from the shipped examples (``every_element``) and DESIGN.md's names and contact laws written out for the
reference's tests (``design_connectors``, ``design``, ``assert_sound``).  Nothing here names an effect beyond
the paper's: an effect's own tests are in its test file (tests/elements/)."""

from __future__ import annotations

import copy
import math

import pytest

import tomllib

from mbs_models.scenes import scene_path


def _import_every_project_module() -> None:
    """Import every module of ``mbs_models`` and ``validation`` before any test runs.

    Hypothesis draws some values from the literals of the local modules imported so far
    (``hypothesis.internal.conjecture.providers._get_local_constants``): without this, a derandomized
    property test draws other examples when run alone than in the whole suite (``test_properties.py``
    alone once drew a chattering 1-kg absorber the suite never drew)."""
    import importlib
    import pkgutil

    for name in ("mbs_models", "validation"):
        package = importlib.import_module(name)
        for module in pkgutil.walk_packages(package.__path__, f"{name}."):
            if not module.name.endswith("__main__"):
                importlib.import_module(module.name)


_import_every_project_module()


def paper_scene_dict() -> dict:
    """Model (ii), m = 1000 kg, gap 0: the shipped version-1 file as a TOML mapping."""
    return tomllib.loads(scene_path("model_ii").read_text())


def edit(path: str, value):
    """An edit of a mapping: set the value at a dotted path (list indices as numbers)."""
    def apply(data: dict) -> dict:
        data = copy.deepcopy(data)
        *tables, key = path.split(".")
        target = data
        for table in tables:
            target = target[int(table)] if isinstance(target, list) else target[table]
        target[key] = value
        return data
    return apply


def delete(path: str):
    """An edit of a mapping: remove the key at a dotted path."""
    def apply(data: dict) -> dict:
        data = copy.deepcopy(data)
        *tables, key = path.split(".")
        target = data
        for table in tables:
            target = target[int(table)] if isinstance(target, list) else target[table]
        del target[key]
        return data
    return apply


#: (case id, edit of the valid mapping, key the error must name, text the message must contain)
BAD_SCENES = [
    ("unknown-key", edit("contact.stifness", 1.0), "contact.stifness", "did you mean 'stiffness'"),
    ("unknown-table", edit("absorbr", {}), "absorbr", "did you mean 'absorber'"),
    ("missing-key", delete("absorber.damping"), "absorber.damping", "missing"),
    ("missing-table", delete("recoil_spring"), "recoil_spring", "missing"),
    ("missing-velocity", delete("firing"), "barrel.initial_velocity", "missing"),
    ("wrong-type-string", edit("barrel.mass", "heavy"), "barrel.mass", "must be a number"),
    ("wrong-type-bool", edit("recoil_spring.stiffness", True), "recoil_spring.stiffness", "must be a number"),
    ("wrong-type-table", edit("contact", 3.0), "contact", "must be a table"),
    ("nan", edit("contact.damping_factor", math.nan), "contact.damping_factor", "finite"),
    ("infinite", edit("absorber.stiffness", math.inf), "absorber.stiffness", "finite"),
    ("zero-barrel-mass", edit("barrel.mass", 0.0), "barrel.mass", "> 0"),
    ("negative-absorber-mass", edit("absorber.mass", -5.0), "absorber.mass", "> 0"),
    ("negative-stiffness", edit("recoil_spring.stiffness", -1.0), "recoil_spring.stiffness", ">= 0"),
    ("negative-damping", edit("recoil_damper.counter_recoil", -1.0), "recoil_damper.counter_recoil", ">= 0"),
    ("negative-absorber-damping", edit("absorber.damping", -3.0), "absorber.damping", ">= 0"),
    ("zero-contact-stiffness", edit("contact.stiffness", 0.0), "contact.stiffness", "> 0"),
    ("zero-exponent", edit("contact.exponent", 0.0), "contact.exponent", "> 0"),
    ("negative-gap", edit("contact.gap", -0.001), "contact.gap", ">= 0"),
    ("absorber-without-contact", delete("contact"), "contact", "needs a [contact]"),
    ("contact-without-absorber", delete("absorber"), "absorber", "needs an [absorber]"),
    ("unknown-mount", edit("absorber.mount", "roof"), "absorber.mount", "unknown mount"),
    ("unknown-law", edit("contact.law", "hertzian"), "contact.law", "unknown law"),
    ("law-of-version-2", edit("contact.law", "hertz"), "contact.law", "version-2 scene"),
    ("zero-projectile-mass", edit("firing.projectile_mass", 0.0), "firing.projectile_mass", "> 0"),
    ("both-velocities", edit("barrel.initial_velocity", 0.7), "barrel.initial_velocity", "not both"),
    ("bad-version", edit("version", 3), "version", "unsupported"),
    ("bad-convention", edit("conventions", {"literal_lambda_sign": "yes"}), "conventions.literal_lambda_sign",
     "true or false"),
]


@pytest.fixture(params=BAD_SCENES, ids=[case[0] for case in BAD_SCENES])
def bad_scene(request):
    """(mapping, key, text) of one invalid scene."""
    _, edit, key, text = request.param
    return edit(paper_scene_dict()), key, text


def v2_scene_dict() -> dict:
    """A version-2 mapping: two absorbers (Hunt-Crossley on the ground, Flores on the barrel)."""
    return tomllib.loads('''
version = 2
name = "every table"
[barrel]
mass = 5600.0
[firing]
projectile_mass = 6.86
muzzle_velocity = 564.0
[recoil_spring]
stiffness = 27500.0
[recoil_damper]
recoil = 6239.0
counter_recoil = 14050.0
[[absorber]]
name = "front"
mass = 600.0
mount = "ground"
stiffness = 8100.0
damping = 2205.0
[absorber.contact]
gap = 0.0
stiffness = 2.1e8
exponent = 1.3
damping_factor = 0.6
[[absorber]]
name = "rear"
mass = 400.0
mount = "barrel"
stiffness = 5400.0
damping = 1470.0
[absorber.contact]
law = "flores"
gap = 0.02
stiffness = 2.1e8
exponent = 1.3
restitution = 0.5
''')


@pytest.fixture
def bad_input(tmp_path, capsys):
    """``check(mapping, key, text)``: the mapping is refused with a SceneError naming ``key`` whose message
    contains ``text`` -- by the API, and by the command line (one line on stderr, exit 2, no traceback)."""
    from mbs_models import SceneError, scene_from_dict
    from mbs_models.cli import main
    from mbs_models.scene.io import mapping_to_toml

    def check(mapping: dict, key: str, text: str) -> None:
        with pytest.raises(SceneError) as info:
            scene_from_dict(mapping)
        assert info.value.key == key, info.value
        assert text in info.value.message, info.value
        path = tmp_path / "scene.toml"
        path.write_text(mapping_to_toml(mapping))
        code = main(["run", str(path)])
        captured = capsys.readouterr()
        assert code == 2 and captured.out == ""
        lines = captured.err.strip().splitlines()
        assert len(lines) == 1 and key in lines[0] and "Traceback" not in captured.err, captured.err

    return check


#: The value that deletes a key in :func:`changed`.
DELETED = "<delete>"


@pytest.fixture
def v2_mapping() -> dict:
    """A fresh version-2 mapping (see :func:`v2_scene_dict`)."""
    return v2_scene_dict()


@pytest.fixture
def v1_mapping() -> dict:
    """A fresh version-1 mapping: the shipped model (ii)."""
    return paper_scene_dict()


@pytest.fixture
def changed():
    """``changed(mapping, path, value)``: a copy with the value at a dotted path set (``"<delete>"``: removed)."""
    def apply(mapping: dict, path: str, value) -> dict:
        return delete(path)(mapping) if value == DELETED else edit(path, value)(mapping)
    return apply


@pytest.fixture
def agrees_with_reference():
    """``check(scene, end_time, accuracy)``: the engine's result meets the README's guarantee against the
    independent reference (:mod:`validation.studies.guarantee`); returns the errors."""
    from mbs_models import simulate
    from validation.studies.guarantee import (TOLERANCES, errors_against_reference, physical_violations, reference_for,
                                              violations)

    def check(scene, end_time: float, accuracy: str) -> dict:
        result = simulate(scene, end_time, accuracy)
        problems = physical_violations(result, TOLERANCES[accuracy]["energy"])
        assert not problems, problems
        errors = errors_against_reference(result, reference_for(scene, end_time, (), accuracy),
                                          TOLERANCES[accuracy]["time"])
        problems = violations(errors, accuracy)
        assert not problems, (problems, errors)
        return errors

    return check


# ------------------------------------------------------------------ a scene of every element, composed generically
def _shipped_scenes() -> list:
    from mbs_models import load_scene
    from mbs_models.scenes import list_scenes

    return [load_scene(scene_path(name)) for name in list_scenes()]


def with_every_element(scene=None, without=(), **law):
    """``scene`` (default: the shipped scene with the most absorbers) with every table of the shipped example scenes
    that it lacks (an array other than the absorbers, ``[[tabulated_spring]]``, as a whole), each as the first
    shipped scene (by name) that has it gives it.
    The shipped examples together have every element table of the library (test_terms.py checks it), so the
    result is a scene of every element, composed without naming one.  ``law`` (e.g. ``law="hertz",
    stiffness=1e9, exponent=1.5``): every added table with a contact law takes that law and those fields.

    If the scene refuses the whole set (two examples whose numbers do not go together, e.g. a light preload
    that cannot hold the barrel on a steep cradle), the table last in the elements' order whose absence
    makes it acceptable is left out.  ``without``: table names not to add.  The ``[carriage]`` (the planar model, a
    model of its own: tests/engine/test_planar*.py) is never added."""
    from dataclasses import replace

    from mbs_models.elements import ELEMENT_TABLES
    from mbs_models.elements.contact_laws import LAW_FIELDS, LawFields

    # the "realistic" example combines many elements with numbers of its own: each table is taken from the
    # example that shows that element alone
    shipped = [s for s in _shipped_scenes() if not s.name.startswith("realistic")]
    scene = max(shipped, key=lambda s: len(s.absorbers)) if scene is None else scene
    added: dict = {}
    table_of = {}  # the keyword of an array of tables (``tabulated_springs``) -> its table name
    for other in shipped:
        for key, table in other.tables():
            name = key.split(".")[0]
            if name in ELEMENT_TABLES and not ELEMENT_TABLES[name].MANY and getattr(scene, key) is None:
                added.setdefault(key, table)
            elif name in ELEMENT_TABLES and ELEMENT_TABLES[name].MANY and name != "absorber" \
                    and not getattr(scene, name + "s"):
                added.setdefault(name + "s", getattr(other, name + "s"))  # an array other than the absorbers
                table_of[name + "s"] = name
    if law:
        added = {key: replace(table, **{**dict.fromkeys(LAW_FIELDS), **law}) if isinstance(table, LawFields) else table
                 for key, table in added.items()}
    from mbs_models import SceneError

    without = (*without, "carriage")
    added = {key: table for key, table in added.items() if table_of.get(key, key) not in without}
    try:
        return scene.with_changes(**added)
    except SceneError:
        pass
    for key in sorted(added, key=lambda k: -ELEMENT_TABLES[table_of.get(k, k)].ORDER):  # leave one out, the last in order first
        try:
            return scene.with_changes(**{k: t for k, t in added.items() if k != key})
        except SceneError:
            continue
    return scene.with_changes(**added)  # raises: no single table explains the refusal


@pytest.fixture(scope="session")
def every_element():
    """``every_element(scene=None, **law)``: see :func:`with_every_element`."""
    return with_every_element


def design_connector_names(scene) -> tuple[str, ...]:
    """DESIGN.md's connector names of ``scene`` in assembly order: ``recoil_spring`` and ``recoil_damper``, an
    absorber's ``<name>_damper`` and ``<name>_contact`` (``absorber_damper`` and ``contact`` with one absorber),
    and for every other table but the barrel, the firing and the burst one connector named like its table.  (Every
    coefficient non-zero: a zero spring or damper adds no connector.)"""
    several = len(scene.absorbers) > 1
    absorbers = set(scene.absorber_names())
    names: list[str] = []
    for name, _ in scene.elements():
        if name in absorbers:
            names += [f"{name}_damper", f"{name}_contact"] if several else ["absorber_damper", "contact"]
        elif name not in ("barrel", "firing", "burst"):  # the shots add no connector
            names.append(name)
    return tuple(names)


@pytest.fixture(scope="session")
def design_connectors():
    """``design_connectors(scene)``: see :func:`design_connector_names`."""
    return design_connector_names


# ------------------------------------------------------------------ DESIGN.md's contact laws, written out here
def design_chi(law: str, e: float) -> float:
    """chi of the restitution laws as DESIGN.md's table gives them (exact-restitution by bisection of its
    defining relation chi - ln(1 + chi) = -chi e - ln(1 - chi e) on (0, 1/e))."""
    if law == "lankarani-nikravesh":
        return 3 * (1 - e * e) / 4
    if law == "flores":
        return 8 * (1 - e) / (5 * e)
    if law == "gonthier":
        return (1 - e * e) / e
    lo, hi = 1e-12, (1 - 1e-15) / e
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid - math.log1p(mid) - (-mid * e - math.log1p(-mid * e)) > 0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def design_law_force(table, p: float, rate: float, state, lam_sign: float = 1.0) -> tuple[float, float]:
    """(F, elastic) of a contact table in a reference contact state: DESIGN.md's law, unclipped, on its
    smooth extension."""
    if state.phase == "off" and not state.penetrated:
        return 0.0, 0.0
    n = 1.0 if table.law == "kelvin-voigt" else table.exponent
    elastic = table.stiffness * math.copysign(abs(p) ** n, p)
    if state.phase == "off":
        return 0.0, elastic
    if table.law == "kelvin-voigt":
        return elastic + table.damping * rate, elastic
    if table.law == "hunt-crossley":
        a = lam_sign * table.damping_factor
    elif table.law == "hertz":
        a = 0.0
    else:
        a = design_chi(table.law, table.restitution) / max(state.onset_rate, table.minimum_impact_velocity or 1e-3)
    return elastic * (1 + a * rate), elastic


def reference_modes(model) -> list:
    """Every combination of a reference model's connector states worth checking (contacts x damper
    branches; a fixed sample of 48 when there are more)."""
    import itertools

    import numpy as np

    from validation.reference.model import Mode
    from validation.reference.terms.contact_laws import ContactMode

    options = []
    for c in model.connectors:
        if c.is_contact:
            choices = [ContactMode("off"), ContactMode("off", True, True, 0.0, 0.3),
                       ContactMode("on", True, False, c.contact_law.episode_factor(0.3), 0.3),
                       ContactMode("on", True, False, c.contact_law.episode_factor(0.0), 0.0)]
            if c.compression_only:
                choices.append(ContactMode("stick", True, False, c.contact_law.damping_factor, 0.3))
            options.append(choices)
        elif c.classify_pass == 2:
            options.append([True, False])
        else:
            options.append([None])
    modes = [Mode(model.names, states) for states in itertools.product(*options)]
    if len(modes) > 48:  # a fixed sample of the combinations, always with the first and the last
        keep = np.random.default_rng(3).choice(len(modes) - 2, 46, replace=False) + 1
        modes = [modes[0], *(modes[k] for k in sorted(keep)), modes[-1]]
    return modes


def check_rhs_is(scene, design_rhs, label: str = "") -> None:
    """The reference's fast right-hand side of ``scene`` (and its numpy twin, used in post-processing) equals
    ``design_rhs(scene, y, states) -> (dy/dt of the bodies, dissipated power per connector)`` -- DESIGN.md's
    equations written out in a test -- in every mode (:func:`reference_modes`), on random states."""
    import numpy as np

    from validation.reference.assembly import build_model

    model = build_model(scene)
    rng = np.random.default_rng(7)
    nb = model.n_bodies
    dissipating = [c.name for c in model.dissipating]
    for mode in reference_modes(model):
        states = dict(zip(mode.names, mode.states))
        rhs = model.rhs(mode)
        batch = []
        for _ in range(30):
            y = rng.normal(size=model.n_states) * np.array([0.05, 1.0] * nb + [10.0] * len(dissipating))
            expected, power = design_rhs(scene, y, states)
            assert sorted(power) == sorted(dissipating)
            expected += [power.get(name, 0.0) for name in dissipating]
            np.testing.assert_allclose(rhs(0.0, y), expected, rtol=1e-12, atol=1e-9, err_msg=f"{label} {mode}")
            batch.append(y)
        batch = np.array(batch).T
        evaluation = model.evaluate(mode, batch)
        for i in range(nb):
            rows = evaluation.accelerations[i] + 0 * batch[0]
            floats = np.array([rhs(0.0, y)[2 * i + 1] for y in batch.T])
            assert_few_ulps(rows, floats, f"{label} {mode} acceleration of body {i}")


#: Units in the last place by which the reference's row and float evaluations of one state may differ: the
#: same source on numpy rows and on floats, but numpy's SIMD kernels (``x ** n``, ``exp``) round differently
#: from the scalar ones on some CPUs (AVX-512), by an ulp or two of each term; a body's acceleration sums a
#: few terms.
ROW_VS_FLOAT_ULPS = 16


def assert_few_ulps(rows, floats, label: str = "") -> None:
    """``rows`` equals ``floats`` to :data:`ROW_VS_FLOAT_ULPS` units in the last place of the largest magnitude
    of the batch (the scale of the terms the values sum)."""
    import numpy as np

    rows, floats = np.asarray(rows, dtype=float), np.asarray(floats, dtype=float)
    scale = max(float(np.max(np.abs(floats), initial=0.0)), float(np.finfo(float).tiny))
    np.testing.assert_allclose(rows, floats, rtol=0, atol=ROW_VS_FLOAT_ULPS * np.spacing(scale), err_msg=label)


@pytest.fixture(scope="session")
def design():
    """DESIGN.md written out for the reference's tests: ``chi(law, e)``, ``law_force(table, p, rate, state,
    lam_sign=1.0)``, ``modes(model)`` and ``check_rhs(scene, design_rhs, label)`` (see the functions above)."""
    from types import SimpleNamespace

    return SimpleNamespace(chi=design_chi, law_force=design_law_force, modes=reference_modes, check_rhs=check_rhs_is)


# ------------------------------------------------------------------ a sound reference result
def assert_sound_reference(r, end: float, balance: float = 1e-8) -> None:
    """Finite, non-negative contact forces of a reference result over [0, end]; the energy balance closes
    to ``balance`` of the initial energy (or of 1 J)."""
    import numpy as np

    t = np.linspace(0.0, end, 20001)
    for name in r.contacts:
        force = r.connector_force(name, t)
        assert np.all(np.isfinite(force)) and np.all(force >= 0), name
    energy = r.energy_balance(t)
    assert np.all(np.isfinite(energy))
    assert np.max(np.abs(energy - r.initial_energy)) <= balance * max(r.initial_energy, 1.0)


@pytest.fixture(scope="session")
def assert_sound():
    """``assert_sound(reference_result, end, balance=1e-8)``: see :func:`assert_sound_reference`."""
    return assert_sound_reference
